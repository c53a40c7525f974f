// Applying one proxy pose to a 55-bone humanoid rig (one joint per proxy bone, non-identity
// rest rotations) — the per-frame cost of driving an avatar.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/rig/foot_lock.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace {

using namespace avatarmap;

// A rig with a joint per proxy bone at the synthetic skeleton's T-pose positions and random
// rest rotations.
rig make_rig(bone_binding& binding) {
  const proxy_skeleton sk = make_proxy_skeleton(1.7f);
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f, standing_hips_height(sk), 0.f);
  std::array<glm::vec3, k_bone_count> joints;
  joint_world_positions(sk, rest, joints);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  raw_rig raw;
  std::vector<glm::quat> world(k_bone_count);
  for (int b = 0; b < k_bone_count; ++b) {
    world[b] = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
    raw_rig::node n;
    n.name = std::string(bone_name(static_cast<bone>(b)));
    n.parent = bone_parent(b);
    const glm::quat pw = n.parent < 0 ? identity_quat() : world[n.parent];
    const glm::vec3 pp = n.parent < 0 ? glm::vec3(0.f) : joints[n.parent];
    n.rest.rotation = glm::conjugate(pw) * world[b];
    n.rest.translation = glm::conjugate(pw) * (joints[b] - pp);
    raw.nodes.push_back(n);
  }
  rig r;
  build_rig(raw, r);
  for (int b = 0; b < k_bone_count; ++b)
    binding[b] = r.find(std::string(bone_name(static_cast<bone>(b))));
  return r;
}

void BM_retarget_55_bones(benchmark::State& state) {
  bone_binding binding;
  const rig r = make_rig(binding);
  retargeter rt;
  retarget_options o;
  o.keep_feet_on_ground = state.range(0) != 0;
  if (!rt.build(r, binding, o).ok()) state.SkipWithError("build failed");
  rig_pose out;
  rt.prepare(out);
  std::mt19937 rng(4);
  std::vector<proxy_pose> poses;
  for (int i = 0; i < 64; ++i) poses.push_back(random_pose(rng));
  size_t i = 0;
  for (auto _ : state) {
    rt.apply(poses[i++ & 63], out);
    benchmark::DoNotOptimize(out.local_rotations.data());
  }
}
BENCHMARK(BM_retarget_55_bones)->Arg(0)->Arg(1);

// The retarget followed by foot locking (rig/foot_lock.hpp) with both feet planted (Arg 1:
// two legs of IK, the hips lowered where needed, the floor clamp) or free (Arg 0: the forward
// kinematics and the floor check only). The difference to BM_retarget_55_bones/0 is the lock's
// cost per frame.
void BM_retarget_foot_lock(benchmark::State& state) {
  bone_binding binding;
  const rig r = make_rig(binding);
  retargeter rt;
  if (!rt.build(r, binding).ok()) state.SkipWithError("build failed");
  foot_lock lock;
  if (!lock.build(rt).ok() || !lock.leg_enabled(0) || !lock.leg_enabled(1))
    state.SkipWithError("foot lock build failed");
  rig_pose out;
  rt.prepare(out);
  std::mt19937 rng(4);
  std::vector<proxy_pose> poses;
  for (int i = 0; i < 64; ++i) poses.push_back(random_pose(rng));
  const float c = state.range(0) != 0 ? 1.f : 0.f;
  const std::array<float, 2> contact = {c, c};
  size_t i = 0;
  for (auto _ : state) {
    rt.apply(poses[i++ & 63], out);
    lock.apply(contact, out);
    benchmark::DoNotOptimize(out.local_rotations.data());
  }
}
BENCHMARK(BM_retarget_foot_lock)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
