// Frame blocks <-> landmark frames (c_frame_block.hpp).
#include "c_frame_block.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

namespace avatarmap::c_api {

namespace {

constexpr int k_stride = k_block_floats_per_point;

// The block's arrays with their part and points per frame, in frame_part order.
struct block_part {
  frame_part part;
  float* avm_frame_block::*array;
  int points;
};
constexpr block_part k_parts[] = {
    {frame_part::pose, &avm_frame_block::pose, AVM_POSE_LANDMARK_COUNT},
    {frame_part::pose_world, &avm_frame_block::pose_world, AVM_POSE_LANDMARK_COUNT},
    {frame_part::left_hand, &avm_frame_block::left_hand, AVM_HAND_LANDMARK_COUNT},
    {frame_part::left_hand_world, &avm_frame_block::left_hand_world, AVM_HAND_LANDMARK_COUNT},
    {frame_part::right_hand, &avm_frame_block::right_hand, AVM_HAND_LANDMARK_COUNT},
    {frame_part::right_hand_world, &avm_frame_block::right_hand_world, AVM_HAND_LANDMARK_COUNT},
    {frame_part::face, &avm_frame_block::face, AVM_FACE_IRIS_LANDMARK_COUNT},
};

// Start of frame i's rows in a part's array (i checked by the caller against count).
float* row(float* array, int points, std::int64_t i) {
  return array + static_cast<std::ptrdiff_t>(i) * points * k_stride;
}

}  // namespace

std::int32_t* block_person(const avm_frame_block& block) noexcept {
  // A caller compiled before the column existed passes the shorter struct: its struct_size
  // ends at face, and the bytes past it are not its own.
  if (block.struct_size < offsetof(avm_frame_block, person) + sizeof(block.person)) return nullptr;
  return block.person;
}

const char* check_block_to_fill(const avm_frame_block& block) noexcept {
  if (block.struct_size < offsetof(avm_frame_block, person))
    return "avm_frame_block.struct_size must be sizeof(avm_frame_block)";
  if (block.count < 0) return "avm_frame_block.count must be >= 0";
  if (block.count > 0 && block.t == nullptr)
    return "avm_frame_block.t must not be NULL when count > 0";
  return nullptr;
}

const char* check_block(const avm_frame_block& block) noexcept {
  if (const char* bad = check_block_to_fill(block)) return bad;
  const std::int32_t* person = block_person(block);
  if (person == nullptr) return nullptr;
  for (std::int64_t i = 1; i < block.count; ++i)
    if (person[i] != person[0])
      return "avm_frame_block.person holds more than one person id: the rows of several "
             "people cannot be solved as one take; solve each person's rows on their own (a "
             "block of one id), or solve the file with avm_solve_file and "
             "avm_solver_options.person";
  return nullptr;
}

void block_row_to_frame(const avm_frame_block& block, std::int64_t i,
                        landmark_frame& out) noexcept {
  out.clear();
  out.t = block.t[i];
  if (const std::int32_t* person = block_person(block)) out.person = person[i];
  for (const block_part& bp : k_parts) {
    const float* array = block.*bp.array;
    if (array == nullptr) continue;
    const float* src = row(const_cast<float*>(array), bp.points, i);
    if (std::isnan(src[0])) continue;
    int n = bp.points;
    if (bp.part == frame_part::face)
      n = std::isnan(src[AVM_FACE_LANDMARK_COUNT * k_stride]) ? AVM_FACE_LANDMARK_COUNT
                                                              : AVM_FACE_IRIS_LANDMARK_COUNT;
    landmark* dst = out.points(bp.part);
    for (int k = 0; k < n; ++k, src += k_stride) dst[k] = {src[0], src[1], src[2], src[3], src[4]};
    out.set(bp.part, true);
    if (bp.part == frame_part::face) out.face_count = n;
  }
}

void frame_to_block_row(const landmark_frame& in, const avm_frame_block& block,
                        std::int64_t i) noexcept {
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  block.t[i] = in.t;
  if (std::int32_t* person = block_person(block)) person[i] = in.person;
  for (const block_part& bp : k_parts) {
    float* dst = block.*bp.array;
    if (dst == nullptr) continue;
    dst = row(dst, bp.points, i);
    int n = in.has(bp.part) ? bp.points : 0;
    if (bp.part == frame_part::face && n > 0)
      n = in.face_count == AVM_FACE_LANDMARK_COUNT ? AVM_FACE_LANDMARK_COUNT
                                                   : AVM_FACE_IRIS_LANDMARK_COUNT;
    const landmark* src = in.points(bp.part);
    int k = 0;
    for (; k < n; ++k, dst += k_stride) {
      dst[0] = src[k].x;
      dst[1] = src[k].y;
      dst[2] = src[k].z;
      dst[3] = src[k].visibility;
      dst[4] = src[k].presence;
    }
    for (; k < bp.points; ++k, dst += k_stride)
      for (int c = 0; c < k_stride; ++c) dst[c] = nan;
  }
}

}  // namespace avatarmap::c_api
