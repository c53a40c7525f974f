// avm_frame_block (avatarmap.h): frames as arrays, one row per frame, converted to and from the
// library's landmark_frame. Nothing here allocates.
#pragma once

#include <cstdint>

#include "avatarmap/avatarmap.h"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap::c_api {

/// Floats per landmark in a block's arrays: x, y, z, visibility, presence.
constexpr int k_block_floats_per_point = 5;

/// The block's person column, or NULL when the caller's struct_size ends before it (a caller
/// built before the column existed) or it is NULL.
std::int32_t* block_person(const avm_frame_block& block) noexcept;
/// NULL when a reader can fill `block` (struct_size covers the fields up to face, count >= 0,
/// t set when count > 0), else a static message naming the bad field. The person column is
/// not read.
const char* check_block_to_fill(const avm_frame_block& block) noexcept;
/// check_block_to_fill() for a block of frames to solve (avm_solve_frames), and its person
/// column, when it has one, holds one id: NULL, else a static message naming the bad field and
/// what to do. Reads the column once; allocates nothing.
const char* check_block(const avm_frame_block& block) noexcept;
/// Row `i` of the block as a landmark frame: a part whose array is NULL or whose first x is
/// NaN is absent; a face whose row 468 x is NaN has 468 points; the person from the person
/// column (0 without one).
void block_row_to_frame(const avm_frame_block& block, std::int64_t i, landmark_frame& out) noexcept;
/// The frame into row `i` of the block's non-NULL arrays; parts it lacks (and rows 468..477
/// of a 468-point face) are NaN; its person into the person column when there is one.
void frame_to_block_row(const landmark_frame& in, const avm_frame_block& block,
                        std::int64_t i) noexcept;

}  // namespace avatarmap::c_api
