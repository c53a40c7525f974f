// Draws a landmark_frame (and optionally regions of interest) onto an RGB8 image the caller
// owns: skeleton lines for the 33 pose points and the 21 points of each hand, dots for the
// face mesh, the outlines of rotated rectangles. For previews and `avatarmap capture
// --overlay`; no anti-aliasing.
//
// Geometry: normalised image coordinates (x right, y down, see image_crop.hpp) are scaled by
// the image width and height and rounded to the nearest pixel, pixel (i, j) being the integer
// point (i, j). Every shape is clipped to the image before it is rasterised: points far
// outside, huge or non-finite coordinates never write outside the buffer and never cost more
// than a line across the image. A point with a non-finite x or y is "not seen": it gets no
// dot and no line touches it.
//
// Colours: the person's left side (pose points 1-3 and odd points from 7 on, the left hand)
// in options.left_color, the right side in options.right_color, lines across the body (both
// shoulders, both hips, the mouth) in options.center_color, the face mesh in
// options.face_color, rectangles in options.rect_color. Sides follow the landmark indices,
// not the image: in a mirrored image the left colour is drawn on the person's left all the
// same.
//
// Several people (overlay_job::people): each person in one colour of its own,
// person_color(its id), its lines and joints over a black outline, and its id written in
// digits (a seven-segment font of lines) above the top of its points.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "avatarmap/capture/image_crop.hpp"  // normalized_rect
#include "avatarmap/landmarks/hand_landmark.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/landmarks/pose_landmark.hpp"

namespace avatarmap {

/// A line between two landmarks of the same set (indices into pose or hand points).
struct landmark_connection {
  std::uint8_t a = 0;
  std::uint8_t b = 0;
};

namespace overlay_detail {
constexpr landmark_connection pc(pose_landmark a, pose_landmark b) {
  return {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
}
constexpr landmark_connection hc(hand_landmark a, hand_landmark b) {
  return {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
}
}  // namespace overlay_detail

/// The body skeleton MediaPipe draws for BlazePose (its POSE_CONNECTIONS): 35 lines.
inline constexpr std::array<landmark_connection, 35> k_pose_connections = [] {
  using overlay_detail::pc;
  using p = pose_landmark;
  return std::array<landmark_connection, 35>{{
      // Face: nose to each eye's inner, centre and outer point, then to the ear; the mouth.
      pc(p::nose, p::left_eye_inner),
      pc(p::left_eye_inner, p::left_eye),
      pc(p::left_eye, p::left_eye_outer),
      pc(p::left_eye_outer, p::left_ear),
      pc(p::nose, p::right_eye_inner),
      pc(p::right_eye_inner, p::right_eye),
      pc(p::right_eye, p::right_eye_outer),
      pc(p::right_eye_outer, p::right_ear),
      pc(p::mouth_left, p::mouth_right),
      // Torso.
      pc(p::left_shoulder, p::right_shoulder),
      pc(p::left_shoulder, p::left_hip),
      pc(p::right_shoulder, p::right_hip),
      pc(p::left_hip, p::right_hip),
      // Left arm and the hand's three points (pinky, index, thumb; pinky-index closes it).
      pc(p::left_shoulder, p::left_elbow),
      pc(p::left_elbow, p::left_wrist),
      pc(p::left_wrist, p::left_pinky),
      pc(p::left_wrist, p::left_index),
      pc(p::left_wrist, p::left_thumb),
      pc(p::left_pinky, p::left_index),
      // Right arm.
      pc(p::right_shoulder, p::right_elbow),
      pc(p::right_elbow, p::right_wrist),
      pc(p::right_wrist, p::right_pinky),
      pc(p::right_wrist, p::right_index),
      pc(p::right_wrist, p::right_thumb),
      pc(p::right_pinky, p::right_index),
      // Left leg and foot (ankle, heel and toe form a triangle).
      pc(p::left_hip, p::left_knee),
      pc(p::left_knee, p::left_ankle),
      pc(p::left_ankle, p::left_heel),
      pc(p::left_heel, p::left_foot_index),
      pc(p::left_ankle, p::left_foot_index),
      // Right leg and foot.
      pc(p::right_hip, p::right_knee),
      pc(p::right_knee, p::right_ankle),
      pc(p::right_ankle, p::right_heel),
      pc(p::right_heel, p::right_foot_index),
      pc(p::right_ankle, p::right_foot_index),
  }};
}();

/// The hand skeleton MediaPipe draws (its HAND_CONNECTIONS): 21 lines. The palm (wrist to
/// the thumb's CMC, to the index and pinky MCPs, and MCP to MCP across the knuckles), then
/// each finger's chain of four points.
inline constexpr std::array<landmark_connection, 21> k_hand_connections = [] {
  using overlay_detail::hc;
  using h = hand_landmark;
  std::array<landmark_connection, 21> r{{
      hc(h::wrist, h::thumb_cmc),
      hc(h::wrist, h::index_mcp),
      hc(h::wrist, h::pinky_mcp),
      hc(h::index_mcp, h::middle_mcp),
      hc(h::middle_mcp, h::ring_mcp),
      hc(h::ring_mcp, h::pinky_mcp),
  }};
  std::size_t n = 6;
  for (int finger = 0; finger < 5; ++finger) {
    const int base = finger_base_landmark(finger);
    for (int j = 0; j < 3; ++j)
      r[n++] = {static_cast<std::uint8_t>(base + j), static_cast<std::uint8_t>(base + j + 1)};
  }
  return r;
}();

/// Which side of the body a pose point belongs to: -1 the person's right, +1 the left,
/// 0 the nose (on the midline). Points 1-3 are the left eye, 4-6 the right one, and from 7
/// on odd indices are the left side.
constexpr int pose_landmark_side(int i) {
  if (i <= 0 || i >= k_pose_landmark_count) return 0;
  if (i <= 3) return 1;
  if (i <= 6) return -1;
  return (i % 2 == 1) ? 1 : -1;
}

/// An 8-bit RGB colour.
struct rgb8_color {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

/// The colours of people when several are drawn (overlay_job::people), by id modulo 8:
/// eight hues far apart from each other, light and saturated enough to read on dark video;
/// the black outline drawn under them keeps them readable on light video.
inline constexpr std::array<rgb8_color, 8> k_person_palette = {{
    {255, 64, 64},    // red
    {64, 220, 64},    // green
    {64, 144, 255},   // blue
    {255, 200, 0},    // amber
    {220, 64, 255},   // violet
    {0, 230, 230},    // cyan
    {255, 128, 192},  // pink
    {176, 255, 96},   // lime
}};

/// The colour of person `id` (>= 0; a negative id gets the first colour).
constexpr rgb8_color person_color(int id) {
  return k_person_palette[id < 0 ? 0 : static_cast<std::size_t>(id) % k_person_palette.size()];
}

/// What happens to pose points whose visibility is below overlay_options::min_visibility
/// (and to the lines that touch them).
enum class overlay_low_visibility : std::uint8_t {
  dim,   // drawn with every channel of the colour halved
  skip,  // not drawn
};

/// Options of overlay_job; a struct so that fields can be added compatibly.
struct overlay_options {
  bool draw_pose = true;
  bool draw_hands = true;
  bool draw_face = true;
  bool draw_rects = true;
  /// Dots on the pose and hand points (on top of the lines).
  bool draw_joints = true;
  /// Line thickness in pixels, 0..64; 0 = automatic: max(1, round(min(width, height) / 360)),
  /// i.e. 1 below 540 pixels (480p), 2 from 540 (720p), 3 from 900 (1080p). A line of thickness T
  /// covers T pixels across its main direction: for a horizontal line at row y, rows y - (T - 1) /
  /// 2 .. y + T / 2 (integer division) between its end points, no more.
  int thickness = 0;
  /// Joint dots are discs of this radius in pixels (pixels at distance <= radius from the
  /// point); -1 = automatic: the line thickness. Face points get radius thickness / 2
  /// (a single pixel up to a thickness of 1).
  int joint_radius = -1;
  /// Pose points (and lines touching them) with visibility below this (or non-finite
  /// visibility: not seen, not drawn) are handled by `low_visibility`. Hands and face have
  /// no visibility of their own and are always drawn in full.
  float min_visibility = 0.5f;
  overlay_low_visibility low_visibility = overlay_low_visibility::dim;
  rgb8_color left_color{255, 128, 0};      // orange: the person's left
  rgb8_color right_color{0, 160, 255};     // azure: the person's right
  rgb8_color center_color{255, 255, 255};  // white: lines across the body, the nose
  rgb8_color face_color{200, 200, 200};    // light grey
  rgb8_color rect_color{255, 255, 0};      // yellow
};

/// An RGB8 image the caller owns and lets overlay_job draw into: `height` rows of `width`
/// pixels (r, g, b bytes), rows `stride_bytes` apart (>= width * 3). Bytes between
/// width * 3 and stride_bytes are never touched.
struct rgb8_image_ref {
  std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride_bytes = 0;
};

/// Draws one frame's landmarks (the image parts: pose, left_hand, right_hand, face; world
/// parts are ignored) and optionally rectangles (e.g. the estimator's regions of interest:
/// centre, size as fractions of the image width and height, rotation in radians clockwise
/// on screen as in image_crop.hpp) onto `image`. Parts missing from `frame` draw nothing.
/// Order: rectangles, face, pose lines, hand lines, then pose and hand joints.
///
/// Several people (`people` set, e.g. estimator::last_people()): `frame` is not drawn; each
/// of the `people_count` frames is, in its list order (a later one over an earlier one), every
/// part of it in person_color(frame.person) (the left/right/center/face colours are not
/// used; low-visibility pose points dim or skip as options say): first a black outline (pose
/// and hand lines 2 pixels thicker, joints 1 pixel wider in radius), then the face, lines and
/// joints in the colour, then its id in decimal digits over a black outline, centred above
/// the top of its drawn points (pose points that are drawn, hand and face points), kept
/// inside the image. Digits are 9 * thickness + 6 pixels tall, strokes thickness + 1 wide. A
/// person with no point drawn gets no label.
/// Owns no buffer, allocates nothing; the caller keeps everything alive during run().
/// Safe to run concurrently on distinct images.
struct overlay_job {
  rgb8_image_ref image{};
  const landmark_frame* frame = nullptr;   // may be null: only rectangles are drawn
  const normalized_rect* rects = nullptr;  // `rect_count` rectangles, or null
  std::size_t rect_count = 0;
  overlay_options options{};
  /// Several people: `people_count` frames, one per person (null: draw `frame`).
  const landmark_frame* people = nullptr;
  std::size_t people_count = 0;

  /// True when image data is set, width and height are in 1..65535, stride_bytes >=
  /// width * 3, rects is set when rect_count > 0, people is set when people_count > 0,
  /// thickness is in 0..64 and joint_radius in -1..64. A non-finite min_visibility or
  /// rectangle field is not an error (nothing is drawn for such a rectangle; a NaN threshold
  /// dims nothing).
  bool validate() const;
  /// Draws; returns false (image untouched) when validate() fails.
  bool run() const;
};

/// The automatic line thickness for an image of this size (see overlay_options::thickness).
int overlay_auto_thickness(int width, int height);

/// Which of the seven segments light digit `d` (0..9) in the people's labels: bit 0 top, 1
/// top right, 2 bottom right, 3 bottom, 4 bottom left, 5 top left, 6 middle (0 for others).
constexpr std::uint8_t overlay_digit_segments(int d) {
  constexpr std::uint8_t k[10] = {0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07, 0x7F, 0x6F};
  return d >= 0 && d <= 9 ? k[d] : 0;
}

}  // namespace avatarmap
