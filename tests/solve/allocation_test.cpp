// The per-frame path allocates nothing: a counting global operator new (for this test
// executable) proves that frame_solver::solve, pose_filter::apply, the resampler and the pose
// stream that chains them make no heap allocation once constructed.
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
#include "avatarmap/solve/pose_stream.hpp"
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

// The pose stream (solve -> filter -> resample, the chain every caller uses) allocates nothing
// per frame in any filter mode, with and without a grid, once constructed.
TEST(Allocation, PoseStreamAllocatesNothingPerFrame) {
  landmark_synth synth;
  std::mt19937 rng(4);
  std::vector<landmark_frame> frames(24);
  for (size_t i = 0; i < frames.size(); ++i) {
    synth.generate(random_pose(rng), frames[i]);
    frames[i].t = double(i) / 30.0;
  }
  frames[4].set(frame_part::face, false);
  frames[9].parts = 0;
  struct setup {
    pose_filter_mode mode;
    bool points;
    double fps;
  };
  for (const setup& c :
       {setup{pose_filter_mode::live, false, 0.0}, setup{pose_filter_mode::live, false, 60.0},
        setup{pose_filter_mode::none, true, 0.0}, setup{pose_filter_mode::offline, false, 0.0},
        setup{pose_filter_mode::offline, false, 45.0}}) {
    pose_stream_options o;
    o.filters.filter_mode = c.mode;
    o.filters.landmark_filter.enabled = c.points;
    o.output_fps = c.fps;
    pose_stream stream(o);
    proxy_pose out, sampled;
    long emitted = 0;
    auto emit = [&](const proxy_pose& p) {
      out = p;
      ++emitted;
      return status{};
    };
    ASSERT_TRUE(stream.push(frames[0], emit).ok());  // warm-up
    const long before = g_allocations.load();
    for (int round = 0; round < 3; ++round) {
      for (size_t i = 1; i < frames.size(); ++i) {
        frames[i].t = round * 2.0 + double(i) / 30.0;
        ASSERT_TRUE(stream.push(frames[i], emit).ok());
        stream.sample(frames[i].t + 0.01, sampled);
      }
    }
    ASSERT_TRUE(stream.finish(emit).ok());
    EXPECT_EQ(g_allocations.load() - before, 0)
        << "mode " << int(c.mode) << " points " << c.points << " fps " << c.fps;
    EXPECT_GT(emitted, 0);
  }
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
