// The per-frame path allocates nothing: a counting global operator new (for this test
// executable) proves that frame_solver::solve, pose_filter::apply and the resampler make no
// heap allocation once constructed.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "avatarmap/rig/formula.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "support/counting_new.hpp"

namespace avatarmap {
namespace {

TEST(Allocation, CountingAllocatorSeesAllocations) {
  long before = g_allocations.load();
  void* p = ::operator new(16);  // a direct call: not elided like a new-expression may be
  ::operator delete(p);
  EXPECT_EQ(g_allocations.load() - before, 1);  // the counter works, so 0 below means 0
}

TEST(Allocation, SolveFilterAndResampleAllocateNothingPerFrame) {
  landmark_synth synth;  // full frames: pose, world, both hands, 478-point face
  std::mt19937 rng(3);
  std::vector<landmark_frame> frames(32);
  for (size_t i = 0; i < frames.size(); ++i) {
    proxy_pose p = random_pose(rng);
    synth.generate(p, frames[i]);
    frames[i].t = double(i) / 30.0;
  }
  // Some frames with missing parts and bad values to exercise the fallbacks too.
  frames[5].set(frame_part::face, false);
  frames[6].pose_world[13].x = std::numeric_limits<float>::quiet_NaN();
  frames[7].parts = 0;
  frame_solver solver;
  pose_filter filter;
  pose_resampler resampler;
  proxy_pose solved, filtered, sampled;
  solver.solve(frames[0], solved);  // warm-up
  long before = g_allocations.load();
  for (int round = 0; round < 4; ++round) {
    for (size_t i = 0; i < frames.size(); ++i) {
      landmark_frame& f = frames[i];
      f.t = round * 2.0 + double(i) / 30.0;
      solver.solve(f, solved);
      filter.apply(solved, filtered);
      resampler.push(filtered);
      resampler.sample(f.t - 0.01, sampled);
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
}

// Retargeting onto a rig (rest-aware path and table formulas) allocates nothing per frame
// once the output is prepared.
TEST(Allocation, RetargetAllocatesNothingPerFrame) {
  const proxy_skeleton sk = make_proxy_skeleton(1.7f);
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f, standing_hips_height(sk), 0.f);
  std::array<glm::vec3, k_bone_count> joints;
  joint_world_positions(sk, rest, joints);
  raw_rig raw;
  for (int b = 0; b < k_bone_count; ++b) {
    raw_rig::node n;
    n.name = std::string(bone_name(static_cast<bone>(b)));
    n.parent = bone_parent(b);
    n.rest.translation = joints[b] - (n.parent < 0 ? glm::vec3(0.f) : joints[n.parent]);
    raw.nodes.push_back(n);
  }
  rig r;
  ASSERT_TRUE(build_rig(raw, r).ok());
  bone_binding binding;
  for (int b = 0; b < k_bone_count; ++b)
    binding[b] = r.find(std::string(bone_name(static_cast<bone>(b))));
  mapping_table table;
  const char* k_table =
      "{\"format_version\": 1, \"name\": \"t\", \"bones\": {\"hips\": {\"rig\": \"hips\"}, "
      "\"leftUpperArm\": {\"rig\": \"leftUpperArm\", \"order\": \"ZXY\", "
      "\"f\": [\"sin(x)\", \"-y\", \"clamp(z, -1, 1)\"]}}}";
  ASSERT_TRUE(load_mapping_json(k_table, "t", table).ok());
  retargeter rt;
  retarget_options o;
  o.keep_feet_on_ground = true;
  ASSERT_TRUE(rt.build(r, binding, o, &table).ok());
  rig_pose out;
  rt.prepare(out);
  std::mt19937 rng(5);
  std::vector<proxy_pose> poses;
  for (int i = 0; i < 16; ++i) poses.push_back(random_pose(rng));
  long before = g_allocations.load();
  for (int round = 0; round < 8; ++round)
    for (const proxy_pose& p : poses) rt.apply(p, out);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace avatarmap
