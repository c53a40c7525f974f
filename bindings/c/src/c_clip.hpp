// The C API's clip handle (avm_clip), shared by the clip functions (c_clip.cpp) and
// avm_solve_file_to_clip (c_solver.cpp).
#pragma once
#include <vector>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "c_guard.hpp"

struct avm_clip : avatarmap::c_api::error_slot {
  std::vector<avatarmap::proxy_pose> frames;
  /// The nominal rate of the *.pose.jsonl it was read from (0: none, or made by avm_clip_add):
  /// a .pose.jsonl written at fps 0 keeps it in its header, as `avatarmap convert` does.
  double source_fps = 0.0;
};
