// Foot locking on rigs built here (legs 20 % longer and 20 % shorter than the performer's, in
// centimetres under a 0.01 Armature, every joint with an arbitrary rest rotation) and on the
// proxy skeleton through a .vrma written and read back. Positions are checked with the tests'
// own forward kinematics (support/rig_fk.hpp), not the lock's.
#include "avatarmap/rig/foot_lock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "support/rig_fk.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;
constexpr float k_mm = 1e-3f;

struct test_rig {
  rig r;
  bone_binding binding;
};

// A rig with the proxy's bones from the hips down plus a spine: legs scaled by `leg_scale`,
// standing on Y = 0; `toes` / `lower_leg` false leave those joints out.
test_rig make_leg_rig(float leg_scale, bool toes = true, bool lower_leg = true, uint32_t seed = 3,
                      bool toe_tips = false) {
  const proxy_skeleton sk = make_proxy_skeleton(1.70f);
  const bone kept[] = {
      bone::hips,       bone::spine,     bone::left_upper_leg,  bone::left_lower_leg,
      bone::left_foot,  bone::left_toes, bone::right_upper_leg, bone::right_lower_leg,
      bone::right_foot, bone::right_toes};
  auto is_leg = [](bone b) {
    return b == bone::left_lower_leg || b == bone::left_foot || b == bone::left_toes ||
           b == bone::right_lower_leg || b == bone::right_foot || b == bone::right_toes;
  };
  // Joint positions (metres): the proxy's rest offsets, the leg bones scaled.
  std::array<glm::vec3, k_bone_count> pos{};
  for (bone b : kept) {
    const int p = bone_parent(idx(b));
    pos[idx(b)] =
        p < 0 ? glm::vec3(0.f) : pos[p] + sk.offsets[idx(b)] * (is_leg(b) ? leg_scale : 1.f);
  }
  // Stand: the lowest of the ankle's sole and the toe joint on Y = 0.
  const float lowest = pos[idx(bone::left_toes)].y;
  const float ankle_sole = pos[idx(bone::left_foot)].y + sk.heel_offset.y * leg_scale;
  const float lift = -std::min(lowest, ankle_sole);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  raw_rig raw;
  raw_rig::node armature;
  armature.name = "Armature";
  armature.rest.scale = glm::vec3(0.01f);
  raw.nodes.push_back(armature);
  std::vector<glm::quat> world_rot(1, identity_quat());
  std::vector<glm::vec3> world_pos(1, glm::vec3(0.f));
  std::array<int, k_bone_count> node_of{};
  node_of.fill(-1);
  for (bone b : kept) {
    if ((!toes && (b == bone::left_toes || b == bone::right_toes)) ||
        (!lower_leg && (b == bone::left_lower_leg || b == bone::right_lower_leg)))
      continue;
    int pb = bone_parent(idx(b));
    while (pb >= 0 && node_of[pb] < 0) pb = bone_parent(pb);
    const int parent = pb < 0 ? 0 : node_of[pb];
    const glm::quat wr = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
    const glm::vec3 wp = pos[idx(b)] + glm::vec3(0.f, lift, 0.f);
    raw_rig::node n;
    n.name = std::string(bone_name(b));
    n.parent = parent;
    n.rest.rotation = glm::normalize(glm::conjugate(world_rot[parent]) * wr);
    n.rest.translation = glm::conjugate(world_rot[parent]) * (wp - world_pos[parent]) * 100.f;
    // The toes' tips (as a BVH's End Sites), 6 cm ahead of the toe joint, level at rest.
    if (toe_tips && (b == bone::left_toes || b == bone::right_toes))
      n.tip = glm::conjugate(wr) * glm::vec3(0.f, 0.f, 6.f);
    node_of[idx(b)] = static_cast<int>(raw.nodes.size());
    raw.nodes.push_back(n);
    world_rot.push_back(wr);
    world_pos.push_back(wp);
  }
  raw.source = rig_source::test;
  test_rig t;
  EXPECT_TRUE(build_rig(raw, t.r).ok());
  t.binding.fill(-1);
  for (int b = 0; b < k_bone_count; ++b)
    if (node_of[b] >= 0)
      for (int j = 0; j < t.r.joint_count(); ++j)
        if (t.r.source_index[j] == node_of[b]) t.binding[b] = j;
  return t;
}

// A performer standing with the left knee bent (thigh 20 degrees forward, shin 40 back, foot
// level), hips drifting a few centimetres: frame i of a clip.
proxy_pose drifting_pose(int i, float left_contact, float right_contact) {
  const proxy_skeleton sk = make_proxy_skeleton(1.70f);
  proxy_pose p;
  p[bone::left_upper_leg] = axis_angle({1, 0, 0}, -20.f * k_deg);
  p[bone::left_lower_leg] = axis_angle({1, 0, 0}, 40.f * k_deg);
  p[bone::left_foot] = axis_angle({1, 0, 0}, -20.f * k_deg);
  const float f = static_cast<float>(i);
  p.hips_position = glm::vec3(0.05f * std::sin(f / 10.f),
                              standing_hips_height(sk) - 0.03f - 0.02f * std::sin(f / 7.f),
                              0.04f * std::cos(f / 9.f));
  p.foot_contact = {left_contact, right_contact};
  p.t = f / 30.0;
  return p;
}

struct driven {
  retargeter rt;
  foot_lock lock;
  rig_pose pose;
};

void build_driven(const test_rig& t, driven& d, const foot_lock_options& o = {}) {
  retarget_options ro;
  ro.performer_hips_height = standing_hips_height(make_proxy_skeleton(1.70f));
  ASSERT_TRUE(d.rt.build(t.r, t.binding, ro).ok());
  ASSERT_TRUE(d.lock.build(d.rt, o).ok());
  d.rt.prepare(d.pose);
}

bool all_finite(const rig_pose& p) {
  for (const glm::quat& q : p.local_rotations)
    if (!is_finite(q)) return false;
  return is_finite(p.hips_translation);
}

class FootLockRigs : public ::testing::TestWithParam<float> {};

TEST_P(FootLockRigs, PlantedAnkleStaysOnItsAnchorAndToesAboveTheFloor) {
  const test_rig t = make_leg_rig(GetParam());
  driven d;
  build_driven(t, d);
  ASSERT_TRUE(d.lock.leg_enabled(0));
  ASSERT_TRUE(d.lock.leg_enabled(1));
  EXPECT_EQ(d.lock.warning(), "");
  const float floor = d.rt.floor_height();
  const int ankle = t.binding[idx(bone::left_foot)];
  const int toes[2] = {t.binding[idx(bone::left_toes)], t.binding[idx(bone::right_toes)]};
  const float ankle_rest_y = glm::vec3(t.r.rest_world[ankle][3]).y;
  glm::vec3 anchor(0.f);
  float worst = 0.f, lowest_toe = 1e9f, most_drift = 0.f;
  for (int i = 0; i < 90; ++i) {
    const proxy_pose p = drifting_pose(i, 1.f, 0.f);
    d.rt.apply(p, d.pose);
    rig_pose free = d.pose;
    d.lock.apply(p.foot_contact, d.pose);
    ASSERT_TRUE(all_finite(d.pose));
    const std::vector<glm::vec3> pos = test::posed_positions(t.r, d.pose);
    const std::vector<glm::vec3> free_pos = test::posed_positions(t.r, free);
    if (i == 0) {
      anchor = pos[ankle];
      // Anchored where the free ankle was, at the ankle's standing height.
      EXPECT_NEAR(anchor.x, free_pos[ankle].x, 1e-4f);
      EXPECT_NEAR(anchor.z, free_pos[ankle].z, 1e-4f);
      EXPECT_NEAR(anchor.y, ankle_rest_y, 1e-4f);
    }
    worst = std::max(worst, glm::length(pos[ankle] - anchor));
    most_drift = std::max(most_drift, glm::length(free_pos[ankle] - anchor));
    for (int j : toes) lowest_toe = std::min(lowest_toe, pos[j].y - floor);
  }
  EXPECT_LT(worst, k_mm) << "leg scale " << GetParam();
  EXPECT_GT(most_drift, 0.02f);  // without the lock the foot would have slid
  EXPECT_GE(lowest_toe, -1e-4f);
}

TEST_P(FootLockRigs, BlendsInAndOutWithoutJumps) {
  const test_rig t = make_leg_rig(GetParam());
  driven d;
  build_driven(t, d);
  const int ankle = t.binding[idx(bone::left_foot)];
  glm::vec3 prev(0.f), prev_free(0.f);
  float worst_excess = 0.f;
  for (int i = 0; i < 120; ++i) {
    // Contact rises over 10 frames from frame 20, holds, falls over 10 frames from 70.
    const float c = std::clamp(std::min((i - 20) / 10.f, (80 - i) / 10.f), 0.f, 1.f);
    const proxy_pose p = drifting_pose(i, c, 0.f);
    d.rt.apply(p, d.pose);
    const glm::vec3 free_ankle = test::posed_positions(t.r, d.pose)[ankle];
    d.lock.apply(p.foot_contact, d.pose);
    const glm::vec3 a = test::posed_positions(t.r, d.pose)[ankle];
    if (i > 0) {
      // A step of the locked ankle is at most the free ankle's step plus a tenth of the
      // anchor's distance (one blend step of 10 frames), plus a millimetre.
      const float bound = glm::length(free_ankle - prev_free) +
                          0.1f * glm::length(d.lock.anchor(0) - free_ankle) + k_mm;
      worst_excess = std::max(worst_excess, glm::length(a - prev) - bound);
    }
    prev = a;
    prev_free = free_ankle;
  }
  EXPECT_LT(worst_excess, 0.005f);  // no frame-to-frame jump beyond the blend's own step
}

INSTANTIATE_TEST_SUITE_P(LongerAndShorterLegs, FootLockRigs, ::testing::Values(1.2f, 0.8f));

TEST(FootLock, ToeTipsTheRigKnowsStayAboveTheFloor) {
  // The performer's toes curl 35 degrees down (into the floor); the rig knows where its toes
  // end (a BVH's End Sites). Planted, the toes lie flat with the foot; free, the foot is lifted
  // so the tip stays on the floor. A free foot of a rig that does not know its tips is guarded
  // at the toe joint only: the same pose puts the tip under the floor (not vacuous).
  for (bool tips : {true, false}) {
    SCOPED_TRACE(tips);
    const test_rig t = make_leg_rig(1.f, true, true, 3, true);
    test_rig blind = t;
    if (!tips) blind.r.tips.assign(blind.r.tips.size(), glm::vec3(std::nanf("")));
    for (float contact : {1.f, 0.f}) {
      SCOPED_TRACE(contact);
      driven d;
      build_driven(blind, d);
      const float floor = d.rt.floor_height();
      const int toe = t.binding[idx(bone::left_toes)];
      const glm::vec3 tip_local = t.r.tips[static_cast<std::size_t>(toe)];
      float lowest_tip = 1e9f;
      for (int i = 0; i < 30; ++i) {
        proxy_pose p = drifting_pose(i, contact, 0.f);
        p[bone::left_foot] = axis_angle({1, 0, 0}, 0.f);  // the foot level
        p[bone::left_upper_leg] = identity_quat();
        p[bone::left_lower_leg] = identity_quat();
        p[bone::left_toes] = axis_angle({1, 0, 0}, 35.f * k_deg);
        d.rt.apply(p, d.pose);
        d.lock.apply(p.foot_contact, d.pose);
        ASSERT_TRUE(all_finite(d.pose));
        const glm::vec3 tip =
            glm::vec3(test::posed_matrices(t.r, d.pose)[toe] * glm::vec4(tip_local, 1.f));
        lowest_tip = std::min(lowest_tip, tip.y - floor);
      }
      if (tips || contact > 0.f)
        EXPECT_GE(lowest_tip, -1e-4f);  // planted: the toes lie flat, tips known or not
      else
        EXPECT_LT(lowest_tip, -0.005f);
    }
  }
}

TEST(FootLock, FreeLegsAboveTheFloorAreUntouched) {
  const test_rig t = make_leg_rig(1.f);
  driven d;
  build_driven(t, d);
  proxy_pose p = drifting_pose(0, 0.f, 0.f);
  p.hips_position.y += 0.05f;  // feet in the air
  d.rt.apply(p, d.pose);
  const rig_pose before = d.pose;
  d.lock.apply(p.foot_contact, d.pose);
  for (std::size_t j = 0; j < before.local_rotations.size(); ++j)
    EXPECT_EQ(before.local_rotations[j], d.pose.local_rotations[j]) << j;
  EXPECT_EQ(before.hips_translation, d.pose.hips_translation);
  EXPECT_FALSE(d.lock.locked(0));
  // Non-finite contacts count as 0.
  d.lock.apply({std::nanf(""), -3.f}, d.pose);
  EXPECT_FALSE(d.lock.locked(0));
  EXPECT_FALSE(d.lock.locked(1));
}

TEST(FootLock, UnreachableAnchorLowersTheHips) {
  const test_rig t = make_leg_rig(1.f);
  driven d;
  build_driven(t, d);
  const int ankle = t.binding[idx(bone::left_foot)];
  proxy_pose p = drifting_pose(0, 1.f, 0.f);
  d.rt.apply(p, d.pose);
  d.lock.apply(p.foot_contact, d.pose);
  const glm::vec3 anchor = d.lock.anchor(0);
  // The hips move 25 cm sideways away from the planted foot: straight leg cannot reach.
  p.hips_position.x -= 0.25f;
  d.rt.apply(p, d.pose);
  const rig_pose free = d.pose;
  d.lock.apply(p.foot_contact, d.pose);
  EXPECT_GT(d.lock.last_hips_drop(), 0.f);
  const std::vector<glm::vec3> pos = test::posed_positions(t.r, d.pose);
  const std::vector<glm::vec3> free_pos = test::posed_positions(t.r, free);
  const int hips = t.binding[idx(bone::hips)];
  EXPECT_NEAR(free_pos[hips].y - pos[hips].y, d.lock.last_hips_drop(), 1e-4f);
  EXPECT_LT(glm::length(pos[ankle] - anchor), k_mm);
  // Turned off: no lowering.
  driven off;
  foot_lock_options o;
  o.lower_hips = false;
  build_driven(t, off, o);
  proxy_pose q = drifting_pose(0, 1.f, 0.f);
  off.rt.apply(q, off.pose);
  off.lock.apply(q.foot_contact, off.pose);
  q.hips_position.x -= 0.25f;
  off.rt.apply(q, off.pose);
  const glm::vec3 hips_before = off.pose.hips_translation;
  off.lock.apply(q.foot_contact, off.pose);
  EXPECT_EQ(off.lock.last_hips_drop(), 0.f);
  EXPECT_EQ(hips_before, off.pose.hips_translation);
}

TEST(FootLock, RigWithoutToesOrLowerLegIsLeftAsRetargeted) {
  for (int variant = 0; variant < 2; ++variant) {
    const test_rig t = make_leg_rig(1.f, variant != 0, variant == 0);
    driven d;
    build_driven(t, d);
    EXPECT_FALSE(d.lock.leg_enabled(0));
    EXPECT_FALSE(d.lock.leg_enabled(1));
    EXPECT_NE(d.lock.warning().find(variant == 0 ? "no toes joint" : "no lower leg joint"),
              std::string::npos)
        << d.lock.warning();
    for (int i = 0; i < 10; ++i) {
      const proxy_pose p = drifting_pose(i, 1.f, 1.f);
      d.rt.apply(p, d.pose);
      const rig_pose before = d.pose;
      d.lock.apply(p.foot_contact, d.pose);
      ASSERT_TRUE(all_finite(d.pose));
      for (std::size_t j = 0; j < before.local_rotations.size(); ++j)
        EXPECT_EQ(before.local_rotations[j], d.pose.local_rotations[j]);
    }
  }
}

TEST(FootLock, OptionsAreChecked) {
  foot_lock_options o;
  o.max_hips_drop = 2.f;
  EXPECT_EQ(o.validate().code(), status_code::invalid_argument);
  const test_rig t = make_leg_rig(1.f);
  retargeter rt;
  ASSERT_TRUE(rt.build(t.r, t.binding).ok());
  foot_lock lock;
  EXPECT_FALSE(lock.build(rt, o).ok());
}

TEST(ProxyFootLock, VrmaRoundTripKeepsThePlantedFootStill) {
  std::vector<proxy_pose> frames;
  for (int i = 0; i < 60; ++i) frames.push_back(drifting_pose(i, 1.f, 0.f));
  test::temp_dir dir("foot_lock");
  const std::string path = (dir.path() / "locked.vrma").string();
  clip_output_job job;
  job.path = path;
  job.frames = &frames;
  clip_output_summary s;
  ASSERT_TRUE(job.run(s).ok());
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  ASSERT_EQ(clip.frames.size(), frames.size());
  const proxy_skeleton sk = make_proxy_skeleton();
  std::array<glm::vec3, k_bone_count> joints;
  joint_world_positions(sk, clip.frames[0], joints);
  const glm::vec3 anchor = joints[idx(bone::left_foot)];
  float worst = 0.f, free_worst = 0.f;
  for (std::size_t i = 0; i < clip.frames.size(); ++i) {
    joint_world_positions(sk, clip.frames[i], joints);
    worst = std::max(worst, glm::length(joints[idx(bone::left_foot)] - anchor));
    std::array<glm::vec3, k_bone_count> free_joints;
    joint_world_positions(sk, frames[i], free_joints);
    free_worst = std::max(free_worst, glm::length(free_joints[idx(bone::left_foot)] - anchor));
  }
  EXPECT_LT(worst, k_mm);
  EXPECT_GT(free_worst, 0.02f);
  // Turned off: written as given.
  job.foot_lock.enabled = false;
  ASSERT_TRUE(job.run(s).ok());
  ASSERT_TRUE(read_vrma(path, clip).ok());
  joint_world_positions(sk, clip.frames[30], joints);
  std::array<glm::vec3, k_bone_count> free_joints;
  joint_world_positions(sk, frames[30], free_joints);
  EXPECT_LT(glm::length(joints[idx(bone::left_foot)] - free_joints[idx(bone::left_foot)]), k_mm);
}

}  // namespace
}  // namespace avatarmap
