// Internal: one proxy pose as one line of *.pose.jsonl (docs/file-formats.md), written into
// any output with text_output's appending interface (reserve / put / put_number): the file
// writer's text_output, or a fixed memory buffer (memory_text below) for the pose server's
// WebSocket messages. One formatter, so a message is exactly a line the pose reader reads.
// No stability promise.
#pragma once

#include <cmath>
#include <cstddef>
#include <string_view>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "common/float_text.hpp"

namespace avatarmap::io_detail {

/// Appends `pose` as one line ("{...}" and, when `newline`, "\n"): t, hips_position,
/// foot_contact ([left, right]), every
/// bone (VRM 1.0 names, enum order, [x, y, z, w]; identity ones left out with
/// options.skip_identity), every expression, ARKit's 52 blendshapes (all of them, by ARKit
/// name, when any weight is non-zero; left out when all are 0, which readers take as 0), and
/// confidence with options.write_confidence. Non-finite numbers are written as null. False when
/// out.reserve() fails (the output says why); the line is then incomplete.
template <class Out>
bool put_pose_line(Out& o, const proxy_pose& pose, const pose_write_options& options,
                   bool newline = true) {
  // One bone entry: name (<= 24) + 4 numbers (<= 16 each) + punctuation.
  if (!o.reserve(128)) return false;
  o.put("{\"t\":");
  o.put_number(pose.t);
  o.put(",\"hips_position\":[");
  o.put_number(pose.hips_position.x);
  o.put(',');
  o.put_number(pose.hips_position.y);
  o.put(',');
  o.put_number(pose.hips_position.z);
  // Two numbers (<= 16 each) + the key.
  if (!o.reserve(64)) return false;
  o.put("],\"foot_contact\":[");
  o.put_number(pose.foot_contact[0]);
  o.put(',');
  o.put_number(pose.foot_contact[1]);
  o.put("],\"bones\":{");
  bool first = true;
  for (int b = 0; b < k_bone_count; ++b) {
    const glm::quat& q = pose.rotations[b];
    if (options.skip_identity && q.w == 1.f && q.x == 0.f && q.y == 0.f && q.z == 0.f) continue;
    if (!o.reserve(128)) return false;
    if (!first) o.put(',');
    first = false;
    o.put('"');
    o.put(bone_name(static_cast<bone>(b)));
    o.put("\":[");
    float v[4];
    store_xyzw(q, v);
    for (int i = 0; i < 4; ++i) {
      if (i) o.put(',');
      o.put_number(v[i]);
    }
    o.put(']');
  }
  if (!o.reserve(32)) return false;
  o.put("},\"expressions\":{");
  for (int e = 0; e < k_expression_count; ++e) {
    if (!o.reserve(64)) return false;
    if (e) o.put(',');
    o.put('"');
    o.put(expression_name(static_cast<expression>(e)));
    o.put("\":");
    o.put_number(pose.expressions[e]);
  }
  o.put('}');
  bool any_blendshape = false;
  // `!= 0` is also true for NaN, so a non-finite weight is written (as null), not hidden.
  for (float w : pose.blendshapes) any_blendshape = any_blendshape || w != 0.f;
  if (any_blendshape) {
    if (!o.reserve(32)) return false;
    o.put(",\"blendshapes\":{");
    for (int s = 0; s < k_blendshape_count; ++s) {
      if (!o.reserve(64)) return false;
      if (s) o.put(',');
      o.put('"');
      o.put(blendshape_name(static_cast<blendshape>(s)));
      o.put("\":");
      o.put_number(pose.blendshapes[s]);
    }
    o.put('}');
  }
  if (options.write_confidence) {
    if (!o.reserve(32)) return false;
    o.put(",\"confidence\":{");
    for (int b = 0; b < k_bone_count; ++b) {
      if (!o.reserve(64)) return false;
      if (b) o.put(',');
      o.put('"');
      o.put(bone_name(static_cast<bone>(b)));
      o.put("\":");
      o.put_number(pose.confidence[b]);
    }
    o.put('}');
  }
  if (!o.reserve(2)) return false;
  o.put('}');
  if (newline) o.put('\n');
  return true;
}

/// A fixed memory buffer with text_output's appending interface, for put_pose_line. It never
/// allocates: reserve() fails when the text would not fit in `capacity` bytes. The buffer
/// (the caller's, `capacity + k_shortest_float_room` bytes) outlives it.
class memory_text {
 public:
  memory_text(char* buffer, std::size_t capacity) : buf_(buffer), capacity_(capacity) {}
  bool reserve(std::size_t n) const { return pos_ + n <= capacity_; }
  void put(char c) { buf_[pos_++] = c; }
  void put(std::string_view s) {
    std::char_traits<char>::copy(buf_ + pos_, s.data(), s.size());
    pos_ += s.size();
  }
  void put_number(float v) {
    if (!std::isfinite(v)) return put("null");
    pos_ = static_cast<std::size_t>(write_shortest_float(buf_ + pos_, v) - buf_);
  }
  void put_number(double v) {
    if (!std::isfinite(v)) return put("null");
    // Shortest round-trip text of a double is at most 24 characters.
    pos_ = static_cast<std::size_t>(std::to_chars(buf_ + pos_, buf_ + pos_ + 32, v).ptr - buf_);
  }
  std::size_t size() const { return pos_; }
  const char* data() const { return buf_; }

 private:
  char* buf_;
  std::size_t capacity_;
  std::size_t pos_ = 0;
};

/// Bytes a pose line can take with every bone, blendshape and confidence written (the bound the
/// pose server's buffers are sized by; reserve()'s per-entry room is what makes it a bound).
inline constexpr std::size_t k_pose_line_max = 128 + 64 + k_bone_count * 128 + 32 +
                                               k_expression_count * 64 + 32 +
                                               k_blendshape_count * 64 + 32 + k_bone_count * 64 + 2;

}  // namespace avatarmap::io_detail
