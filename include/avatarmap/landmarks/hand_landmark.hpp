// MediaPipe Hands' 21 landmarks with MediaPipe's indices.
#pragma once

#include <cstdint>

namespace avatarmap {

inline constexpr int k_hand_landmark_count = 21;

enum class hand_landmark : std::uint8_t {
  wrist = 0,
  thumb_cmc = 1,
  thumb_mcp = 2,
  thumb_ip = 3,
  thumb_tip = 4,
  index_mcp = 5,
  index_pip = 6,
  index_dip = 7,
  index_tip = 8,
  middle_mcp = 9,
  middle_pip = 10,
  middle_dip = 11,
  middle_tip = 12,
  ring_mcp = 13,
  ring_pip = 14,
  ring_dip = 15,
  ring_tip = 16,
  pinky_mcp = 17,
  pinky_pip = 18,
  pinky_dip = 19,
  pinky_tip = 20,
};

constexpr int idx(hand_landmark h) { return static_cast<int>(h); }

/// First landmark of finger f (0 thumb, 1 index, 2 middle, 3 ring, 4 pinky); its four
/// points are base + 0..3 (CMC/MCP/IP/tip for the thumb, MCP/PIP/DIP/tip for the others).
constexpr int finger_base_landmark(int finger) { return 1 + 4 * finger; }

}  // namespace avatarmap
