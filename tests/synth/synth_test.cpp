// Tests of the synthetic ground truth (include/avatarmap/synth/*): rest geometry, FK against
// an independent Eigen implementation, output spaces, noise, mirror, expressions.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"

using namespace avatarmap;

namespace {

constexpr float k_eps = 1e-5f;

// |a x b| / (|a||b|): 0 when parallel (either sign).
float sin_between(const glm::vec3& a, const glm::vec3& b) {
  return glm::length(glm::cross(a, b)) / (glm::length(a) * glm::length(b));
}
// Cosine of the angle between a and b.
float cos_between(const glm::vec3& a, const glm::vec3& b) {
  return glm::dot(a, b) / (glm::length(a) * glm::length(b));
}
glm::vec3 v3(const landmark& l) { return glm::vec3(l.x, l.y, l.z); }

int primary_child(int b) {
  switch (static_cast<bone>(b)) {
    case bone::upper_chest:
      return idx(bone::neck);
    case bone::hips:
      return idx(bone::spine);
    case bone::head:
      return -1;  // leaf: its length reaches the top of the head
    case bone::left_hand:
      return idx(bone::left_middle_proximal);
    case bone::right_hand:
      return idx(bone::right_middle_proximal);
    default:
      break;
  }
  for (int c = b + 1; c < k_bone_count; ++c)
    if (bone_parent(c) == b) return c;
  return -1;  // leaf
}

synth_options all_parts() {
  synth_options o;
  o.face = synth_face::mesh_478;
  return o;
}

}  // namespace

TEST(SynthSkeleton, PrimaryChildrenLieAlongRestDirections) {
  for (float height : {1.70f, 1.55f, 1.92f}) {
    proxy_skeleton s = make_proxy_skeleton(height);
    EXPECT_FLOAT_EQ(s.scale, height / 1.70f);
    for (int b = 0; b < k_bone_count; ++b) {
      EXPECT_GT(s.lengths[b], 0.f) << bone_name(static_cast<bone>(b));
      int c = primary_child(b);
      if (c < 0) continue;
      glm::vec3 expect = s.lengths[b] * bone_rest_direction(static_cast<bone>(b));
      EXPECT_NEAR(glm::length(s.offsets[c] - expect), 0.f, k_eps)
          << bone_name(static_cast<bone>(b));
    }
    // Upper legs sit exactly +-0.09 s beside the hips joint.
    EXPECT_EQ(s.offsets[idx(bone::left_upper_leg)], glm::vec3(0.09f * s.scale, 0.f, 0.f));
    EXPECT_EQ(s.offsets[idx(bone::right_upper_leg)], glm::vec3(-0.09f * s.scale, 0.f, 0.f));
    // Left/right symmetry.
    for (int b = 0; b < k_bone_count; ++b) {
      int m = idx(mirror_bone(static_cast<bone>(b)));
      EXPECT_EQ(s.offsets[m], mirror_x(s.offsets[b]));
      EXPECT_EQ(s.lengths[m], s.lengths[b]);
    }
  }
}

TEST(SynthSkeleton, StandingHeightAndGrounding) {
  proxy_skeleton s = make_proxy_skeleton(1.70f);
  float h = standing_hips_height(s);
  EXPECT_NEAR(h, 0.89f, 0.01f);
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.3f, 5.f, -1.f);
  ground_pose(s, rest);
  EXPECT_NEAR(rest.hips_position.y, h, 1e-5f);
  proxy_fk fk;
  compute_proxy_fk(s, rest, fk);
  // The top of the head is the person's height.
  EXPECT_NEAR(fk.tips[idx(bone::head)].y, 1.70f, 0.005f);
  EXPECT_NEAR(standing_hips_height(make_proxy_skeleton(1.9f)), h * 1.9f / 1.7f, 1e-4f);
}

TEST(SynthFk, MatchesIndependentEigenFk) {
  proxy_skeleton s = make_proxy_skeleton(1.76f);
  std::mt19937 rng(7);
  for (int n = 0; n < 50; ++n) {
    proxy_pose p = random_pose(rng);
    std::array<Eigen::Quaternionf, k_bone_count> world;
    std::array<Eigen::Vector3f, k_bone_count> joints;
    for (int b = 0; b < k_bone_count; ++b) {
      const glm::quat& q = p.rotations[b];
      Eigen::Quaternionf local(q.w, q.x, q.y, q.z);
      Eigen::Vector3f off(s.offsets[b].x, s.offsets[b].y, s.offsets[b].z);
      int parent = bone_parent(b);
      if (parent < 0) {
        world[b] = local;
        joints[b] = Eigen::Vector3f(p.hips_position.x, p.hips_position.y, p.hips_position.z);
      } else {
        world[b] = world[parent] * local;
        joints[b] = joints[parent] + world[parent].toRotationMatrix() * off;
      }
    }
    std::array<glm::vec3, k_bone_count> mine;
    joint_world_positions(s, p, mine);
    proxy_fk fk;
    compute_proxy_fk(s, p, fk);
    for (int b = 0; b < k_bone_count; ++b) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(mine[b][k], joints[b][k], 1e-5f);
        EXPECT_NEAR(fk.joints[b][k], joints[b][k], 1e-5f);
      }
      glm::vec3 r = bone_rest_direction(static_cast<bone>(b)) * s.lengths[b];
      Eigen::Vector3f tip =
          joints[b] + world[b].toRotationMatrix() * Eigen::Vector3f(r.x, r.y, r.z);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(fk.tips[b][k], tip[k], 1e-5f);
    }
    // The generator's landmarks are these joints.
    landmark_synth gen(s, all_parts());
    landmark_frame f;
    gen.generate(p, f);
    const auto& P = gen.points().pose;
    const bone body[18] = {bone::left_upper_arm,
                           bone::right_upper_arm,
                           bone::left_lower_arm,
                           bone::right_lower_arm,
                           bone::left_hand,
                           bone::right_hand,
                           bone::left_little_proximal,
                           bone::right_little_proximal,
                           bone::left_index_proximal,
                           bone::right_index_proximal,
                           bone::left_thumb_proximal,
                           bone::right_thumb_proximal,
                           bone::left_upper_leg,
                           bone::right_upper_leg,
                           bone::left_lower_leg,
                           bone::right_lower_leg,
                           bone::left_foot,
                           bone::right_foot};
    for (int i = 0; i < 18; ++i)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(P[11 + i][k], joints[idx(body[i])][k], 1e-5f);
    Eigen::Vector3f heel =
        joints[idx(bone::left_foot)] + world[idx(bone::left_foot)].toRotationMatrix() *
                                           Eigen::Vector3f(0.f, -0.07f, -0.06f) * s.scale;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(P[29][k], heel[k], 1e-5f);
    const auto& H = gen.points().right_hand;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(H[0][k], joints[idx(bone::right_hand)][k], 1e-5f);
      EXPECT_NEAR(H[1][k], joints[idx(bone::right_thumb_metacarpal)][k], 1e-5f);
      EXPECT_NEAR(H[10][k], joints[idx(bone::right_middle_intermediate)][k], 1e-5f);
      EXPECT_NEAR(H[20][k], fk.tips[idx(bone::right_little_distal)][k], 1e-5f);
    }
  }
}

TEST(Synth, RestPoseRelations) {
  const float height = 1.80f;
  synth_options o = all_parts();
  o.person_height = height;
  landmark_synth gen(o);
  const float s = gen.skeleton().scale;
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f, standing_hips_height(gen.skeleton()), 0.f);
  landmark_frame f;
  gen.generate(rest, f);
  const synth_points& pts = gen.points();
  const glm::vec3 X(1.f, 0.f, 0.f), Y(0.f, 1.f, 0.f), Z(0.f, 0.f, 1.f);
  const auto& P = pts.pose;
  // Pose face points.
  EXPECT_LT(sin_between(P[7] - P[8], X), k_eps);
  EXPECT_GT(cos_between(P[7] - P[8], X), 0.f);
  glm::vec3 eyes = 0.5f * (P[2] + P[5]), mouth = 0.5f * (P[9] + P[10]);
  EXPECT_LT(sin_between(eyes - mouth, Y), k_eps);
  EXPECT_GT((eyes - mouth).y, 0.f);
  EXPECT_LT(P[7].z, P[2].z - 0.05f * s);  // ears clearly behind the eyes
  EXPECT_GT(P[1].x, P[4].x);              // left eye on +X
  // Hands.
  for (const auto* H : {&pts.left_hand, &pts.right_hand}) {
    glm::vec3 mid = (*H)[9] - (*H)[0];
    EXPECT_LT(sin_between(mid, X), k_eps);
    glm::vec3 across = (*H)[5] - (*H)[17];
    EXPECT_LT(sin_between(across, Z), k_eps);
    EXPECT_GT(across.z, 0.f);
  }
  EXPECT_GT((pts.left_hand[9] - pts.left_hand[0]).x, 0.f);
  EXPECT_LT((pts.right_hand[9] - pts.right_hand[0]).x, 0.f);
  // Face mesh.
  const auto& F = pts.face;
  EXPECT_LT(sin_between(F[454] - F[234], X), k_eps);
  EXPECT_GT((F[454] - F[234]).x, 0.f);
  EXPECT_LT(sin_between(F[263] - F[130], X), k_eps);
  EXPECT_GT((F[263] - F[130]).x, 0.f);
  EXPECT_LT(sin_between(F[10] - F[152], Y), k_eps);
  EXPECT_GT((F[10] - F[152]).y, 0.f);
  const float w = 0.03f * s;
  EXPECT_NEAR(glm::length(F[130] - F[133]), w, 1e-5f);
  EXPECT_NEAR(glm::length(F[263] - F[362]), w, 1e-5f);
  EXPECT_NEAR(glm::length(F[291] - F[61]), 0.05f * s, 1e-5f);
  EXPECT_NEAR(glm::length(F[454] - F[234]), 0.14f * s, 1e-5f);
  EXPECT_NEAR(F[13].y - F[14].y, 0.f, 1e-5f);  // mouth closed
  // Lids on an arc: 0.85, 1 and 0.9 of the middle gap 0.22 w (outer -> inner).
  const int up[6] = {160, 159, 158, 387, 386, 385}, lo[6] = {144, 145, 153, 373, 374, 380};
  const float arc[3] = {0.85f, 1.f, 0.9f};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(F[up[i]].y - F[lo[i]].y, arc[i % 3] * 0.22f * w, 1e-5f);
    float line = i < 3 ? F[133].y : F[362].y;
    EXPECT_NEAR(F[up[i]].y - line, line - F[lo[i]].y, 1e-5f);
  }
  EXPECT_NEAR(F[105].y - F[159].y, 0.012f * s, 1e-5f);
  EXPECT_NEAR(F[334].y - F[386].y, 0.012f * s, 1e-5f);
  // Irises.
  for (auto [c, inner, outer] : {std::array<int, 3>{468, 133, 130}, {473, 362, 263}}) {
    glm::vec3 expect = F[inner] + 0.5f * (F[outer] - F[inner]);
    EXPECT_NEAR(F[c].x, expect.x, 1e-5f);
    EXPECT_NEAR(F[c].y - expect.y, 0.02f * w, 1e-5f);
    for (int r = 1; r <= 4; ++r) EXPECT_NEAR(glm::length(F[c + r] - F[c]), 0.0058f * s, 1e-5f);
  }
  // The template function agrees with the generated rest face (head joint + offset).
  glm::vec3 t10 = face_template_point(10, s);
  EXPECT_NEAR(glm::length(pts.head_joint + t10 - F[10]), 0.f, 1e-5f);
  for (const glm::vec3& p : F) EXPECT_TRUE(is_finite(p));
}

TEST(Synth, ElbowBelowShoulderAfterArmDown) {
  landmark_synth gen(all_parts());
  proxy_pose p;
  p[bone::left_upper_arm] = axis_angle(glm::vec3(0.f, 0.f, 1.f), -0.5f * k_pi);
  landmark_frame f;
  gen.generate(p, f);
  ASSERT_TRUE(f.has(frame_part::pose_world));
  glm::vec3 sh = v3(f.pose_world[11]), el = v3(f.pose_world[13]);
  // MediaPipe world: y down.
  EXPECT_NEAR(el.y - sh.y, 0.28f, 1e-4f);
  EXPECT_NEAR(el.x, sh.x, 1e-5f);
  EXPECT_NEAR(el.z, sh.z, 1e-5f);
  // And in the image: below (larger y) and horizontally aligned.
  EXPECT_GT(f.pose[13].y, f.pose[11].y);
  EXPECT_NEAR(f.pose[13].x, f.pose[11].x, 1e-3f);
  // A non-mirrored camera puts the person's left at larger x.
  EXPECT_GT(f.pose[11].x, f.pose[12].x);
}

TEST(Synth, OutputSpacesAndOrigins) {
  synth_options o = all_parts();
  o.body_noise_sigma = 0.01f;
  o.hand_noise_sigma = 0.005f;
  landmark_synth gen(o);
  std::mt19937 rng(3);
  landmark_frame f;
  for (int n = 0; n < 20; ++n) {
    proxy_pose p = random_pose(rng);
    gen.generate(p, f);
    EXPECT_EQ(f.parts, (1u << k_frame_part_count) - 1u);
    glm::vec3 mid = 0.5f * (v3(f.pose_world[23]) + v3(f.pose_world[24]));
    EXPECT_NEAR(glm::length(mid), 0.f, 1e-5f);
    // World = VRM with y, z negated, relative to the hip midpoint.
    const auto& P = gen.points().pose;
    glm::vec3 d = P[15] - 0.5f * (P[23] + P[24]);
    EXPECT_NEAR(f.pose_world[15].x, d.x, 1e-5f);
    EXPECT_NEAR(f.pose_world[15].y, -d.y, 1e-5f);
    EXPECT_NEAR(f.pose_world[15].z, -d.z, 1e-5f);
    for (const auto* W : {&f.left_hand_world, &f.right_hand_world}) {
      glm::vec3 c(0.f);
      for (int i : {0, 5, 9, 13, 17}) c += v3((*W)[i]);
      EXPECT_NEAR(glm::length(c / 5.f), 0.f, 1e-5f);
    }
    // Hand image z is relative to the wrist.
    EXPECT_NEAR(f.left_hand[0].z, 0.f, 1e-5f);
    for (const landmark& l : f.pose) EXPECT_EQ(l.visibility, 1.f);
    for (int i = 0; i < f.face_count; ++i) EXPECT_TRUE(std::isfinite(f.face[i].x));
  }
}

TEST(Synth, Projection) {
  synth_options o = all_parts();
  o.image_width = 1000;
  o.image_height = 500;
  o.horizontal_fov_degrees = 90.f;
  o.camera_position = glm::vec3(0.2f, 1.2f, 4.f);
  o.camera_y_scales_with_height = false;
  landmark_synth gen(o);
  EXPECT_NEAR(gen.focal_pixels(), 500.f, 1e-3f);
  glm::vec3 on_axis = gen.project(glm::vec3(0.2f, 1.2f, 0.5f), 3.5f);
  EXPECT_NEAR(on_axis.x, 0.5f, 1e-6f);
  EXPECT_NEAR(on_axis.y, 0.5f, 1e-6f);
  EXPECT_NEAR(on_axis.z, 0.f, 1e-6f);
  // 1 m right and 0.5 m up at 2 m depth: u = 500 + 500 * 1 / 2, v = 250 - 500 * 0.5 / 2.
  glm::vec3 q = gen.project(glm::vec3(1.2f, 1.7f, 2.f), 2.f);
  EXPECT_NEAR(q.x, 750.f / 1000.f, 1e-6f);
  EXPECT_NEAR(q.y, 125.f / 500.f, 1e-6f);
  // Depth 2.5 m against z_ref 2 m: (0.5) * 500 / (2 * 1000).
  glm::vec3 r = gen.project(glm::vec3(0.2f, 1.2f, 1.5f), 2.f);
  EXPECT_NEAR(r.z, 0.125f, 1e-6f);
  // Default camera: 1.0 * s high; hip midpoint z = 0 in the pose image.
  landmark_synth def(all_parts());
  EXPECT_NEAR(def.camera_position().y, 1.f, 1e-6f);
  proxy_pose p;
  landmark_frame f;
  def.generate(p, f);
  EXPECT_NEAR(0.5f * (f.pose[23].z + f.pose[24].z), 0.f, 1e-6f);
  EXPECT_NEAR(0.5f * (f.pose[23].x + f.pose[24].x), 0.5f, 1e-6f);
}

TEST(Synth, NoiseHasRequestedSigma) {
  synth_options o = all_parts();
  o.body_noise_sigma = 0.02f;
  o.hand_noise_sigma = 0.004f;
  o.face_noise_sigma = 0.003f;
  o.seed = 42;
  landmark_synth noisy(o);
  landmark_synth clean(all_parts());
  proxy_pose p;
  landmark_frame f, g;
  clean.generate(p, g);
  const int n = 4000;
  double body = 0.0, hand = 0.0, face = 0.0, mean = 0.0;
  for (int i = 0; i < n; ++i) {
    noisy.generate(p, f);
    // Differences of two points cancel the origin's noise: variance 2 sigma^2 per axis.
    glm::vec3 db = (v3(f.pose_world[11]) - v3(f.pose_world[12])) -
                   (v3(g.pose_world[11]) - v3(g.pose_world[12]));
    glm::vec3 dh = (v3(f.left_hand_world[4]) - v3(f.left_hand_world[8])) -
                   (v3(g.left_hand_world[4]) - v3(g.left_hand_world[8]));
    float dx = noisy.points().face[1].x - clean.points().face[1].x;
    mean += db.x;
    body += glm::dot(db, db) / 6.0;
    hand += glm::dot(dh, dh) / 6.0;
    face += dx * dx;
  }
  EXPECT_NEAR(std::sqrt(body / n), 0.02, 0.02 * 0.04);
  EXPECT_NEAR(std::sqrt(hand / n), 0.004, 0.004 * 0.04);
  EXPECT_NEAR(std::sqrt(face / n), 0.003, 0.003 * 0.05);
  EXPECT_NEAR(mean / n, 0.0, 0.02 * 1.414 * 4.0 / std::sqrt(double(n)));
  // Same seed, same sequence.
  landmark_synth again(o);
  landmark_frame h;
  noisy.reseed(42);
  noisy.generate(p, f);
  again.generate(p, h);
  EXPECT_EQ(f.pose[5].x, h.pose[5].x);
  EXPECT_EQ(f.face[300].y, h.face[300].y);
}

TEST(Synth, MirrorSwapsSidesAndFlipsX) {
  synth_options o = all_parts();
  o.camera_position.x = 0.15f;  // the mirror also mirrors an off-axis camera
  landmark_synth plain(o);
  o.mirror = true;
  landmark_synth mirrored(o);
  std::mt19937 rng(11);
  landmark_frame a, b;
  for (int n = 0; n < 10; ++n) {
    proxy_pose p = random_pose(rng);
    p[expression::blink_left] = 0.7f;
    plain.generate(p, a);
    mirrored.generate(p, b);
    for (int i = 0; i < k_pose_landmark_count; ++i) {
      int m = pose_mirror_index(i);
      EXPECT_NEAR(b.pose[i].x, 1.f - a.pose[m].x, 1e-5f) << i;
      EXPECT_NEAR(b.pose[i].y, a.pose[m].y, 1e-5f) << i;
      EXPECT_NEAR(b.pose[i].z, a.pose[m].z, 1e-5f) << i;
      EXPECT_NEAR(b.pose_world[i].x, -a.pose_world[m].x, 1e-5f) << i;
      EXPECT_NEAR(b.pose_world[i].y, a.pose_world[m].y, 1e-5f) << i;
    }
    for (int i = 0; i < k_hand_landmark_count; ++i) {
      EXPECT_NEAR(b.left_hand[i].x, 1.f - a.right_hand[i].x, 1e-5f);
      EXPECT_NEAR(b.right_hand_world[i].x, -a.left_hand_world[i].x, 1e-5f);
      EXPECT_NEAR(b.right_hand_world[i].z, a.left_hand_world[i].z, 1e-5f);
    }
    for (auto [l, r] : {std::array<int, 2>{263, 130},
                        {362, 133},
                        {386, 159},
                        {374, 145},
                        {454, 234},
                        {473, 468},
                        {291, 61}}) {
      EXPECT_NEAR(b.face[l].x, 1.f - a.face[r].x, 1e-5f) << l;
      EXPECT_NEAR(b.face[l].y, a.face[r].y, 1e-5f) << l;
    }
  }
}

TEST(Synth, FaceCounts) {
  synth_options o = all_parts();
  proxy_pose p;
  landmark_frame f;
  o.face = synth_face::mesh_468;
  landmark_synth(o).generate(p, f);
  EXPECT_TRUE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, 468);
  o.face = synth_face::mesh_478;
  landmark_synth(o).generate(p, f);
  EXPECT_EQ(f.face_count, 478);
  o.face = synth_face::none;
  o.hands_image = false;
  o.pose_world = false;
  landmark_synth(o).generate(p, f);
  EXPECT_FALSE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, 0);
  EXPECT_TRUE(f.has(frame_part::pose));
  EXPECT_FALSE(f.has(frame_part::pose_world));
  EXPECT_FALSE(f.has(frame_part::left_hand));
  EXPECT_TRUE(f.has(frame_part::left_hand_world));
}

TEST(Synth, BlendshapesDriveTheFace) {
  landmark_synth gen(all_parts());
  const float s = gen.skeleton().scale, w = 0.03f * s;
  proxy_pose p;
  // A turned head: measure along the head's axes.
  p[bone::head] = axis_angle(glm::normalize(glm::vec3(0.3f, 1.f, 0.2f)), 0.6f);
  p[blendshape::eye_blink_left] = 1.f;
  p[blendshape::eye_blink_right] = 0.5f;
  p[blendshape::jaw_open] = 0.5f;
  p[blendshape::brow_outer_up_left] = 1.f;
  p[blendshape::brow_down_right] = 1.f;
  p[blendshape::mouth_smile_left] = 1.f;
  const float yaw = 0.3f, pitch = 0.2f;
  glm::quat eye =
      axis_angle(glm::vec3(0.f, 1.f, 0.f), yaw) * axis_angle(glm::vec3(1.f, 0.f, 0.f), pitch);
  p[bone::left_eye] = eye;
  landmark_frame f;
  gen.generate(p, f);
  std::array<glm::quat, k_bone_count> world;
  compute_world_rotations(p, world);
  const glm::quat head = world[idx(bone::head)];
  const glm::vec3 up = head * glm::vec3(0.f, 1.f, 0.f), lat = head * glm::vec3(1.f, 0.f, 0.f);
  const auto& F = gen.points().face;
  const glm::vec3 o = gen.points().head_joint;
  auto rest = [&](int i) { return o + head * face_template_point(i, s); };
  // The population face (synth_face_shape{}): lids 0.22 w apart in the middle, shut at 0.09
  // of that; the upper lid makes 80 % of the change.
  EXPECT_NEAR(glm::dot(F[386] - F[374], up), 0.22f * 0.09f * w, 1e-5f);
  EXPECT_NEAR(glm::dot(F[159] - F[145], up), 0.22f * w * (1.f - 0.91f * 0.5f), 1e-5f);
  EXPECT_NEAR(glm::dot(F[386] - rest(386), up), -0.8f * 0.22f * 0.91f * w, 1e-5f);
  // The lower inner lip drops 29 mm at jawOpen 1; the corners follow half; the left corner
  // rises 9 mm for its smile and moves out by 0.6 of that.
  const float drop = 0.029f * s * 0.5f;
  EXPECT_NEAR(glm::dot(F[13] - F[14], up), drop, 1e-5f);
  EXPECT_NEAR(glm::dot(F[291] - rest(291), up), 0.009f * s - 0.5f * drop, 1e-5f);
  EXPECT_NEAR(glm::dot(F[291] - rest(291), lat), 0.6f * 0.009f * s, 1e-5f);
  EXPECT_NEAR(glm::dot(F[61] - rest(61), up), -0.5f * drop, 1e-5f);
  // Brows: the left outer end rises 7.5 mm, its middle half of that; the right brow lowers
  // 5 mm in the middle.
  EXPECT_NEAR(glm::dot(F[300] - rest(300), up), 0.0075f * s, 1e-5f);
  EXPECT_NEAR(glm::dot(F[334] - rest(334), up), 0.5f * 0.0075f * s, 1e-5f);
  EXPECT_NEAR(glm::dot(F[105] - rest(105), up), -0.005f * s, 1e-5f);
  // Left iris moved toward +X and down (positive pitch turns the gaze down); right one not.
  glm::vec3 dl = F[473] - rest(473);
  EXPECT_NEAR(glm::dot(dl, lat), 0.012f * s * std::sin(yaw), 1e-5f);
  EXPECT_NEAR(glm::dot(dl, up), -0.012f * s * std::sin(pitch), 1e-5f);
  EXPECT_NEAR(glm::length(F[468] - rest(468)), 0.f, 1e-5f);
  // Pose mouth corners follow the mouth.
  EXPECT_NEAR(glm::length(gen.points().pose[9] - F[291]), 0.f, 1e-6f);

  // A pose with expressions only draws their blendshapes (blendshapes_from_expressions): aa
  // opens the jaw fully.
  proxy_pose q;
  q[bone::head] = p[bone::head];
  q[expression::aa] = 1.f;
  gen.generate(q, f);
  EXPECT_NEAR(glm::dot(gen.points().face[13] - gen.points().face[14], up), 0.029f * s, 1e-5f);
}

TEST(Synth, FaceVariationDrawsEachSeedItsOwnFace) {
  synth_options o = all_parts();
  o.face_variation = true;
  o.seed = 3;
  const synth_face_shape a = landmark_synth(o).face_shape();
  o.seed = 4;
  const synth_face_shape b = landmark_synth(o).face_shape();
  EXPECT_NE(a.eye_open[0], b.eye_open[0]);
  for (const synth_face_shape& f : {a, b}) {
    EXPECT_GE(f.eye_open[0], 0.17f * 0.95f);
    EXPECT_LE(f.eye_open[0], 0.28f * 1.05f);
    EXPECT_GE(f.jaw_drop, 0.027f);
    EXPECT_LE(f.jaw_drop, 0.031f);
  }
  o.face_variation = false;
  EXPECT_EQ(landmark_synth(o).face_shape().eye_open[0], 0.22f);
}

TEST(RandomPose, FingersFlexTowardThePalmOnBothHands) {
  proxy_skeleton s = make_proxy_skeleton();
  std::mt19937 rng(5);
  random_pose_limits lim;
  for (int n = 0; n < 100; ++n) {
    proxy_pose p = random_pose(rng, lim);
    for (const glm::quat& q : p.rotations) EXPECT_NEAR(glm::length(q), 1.f, 1e-5f);
    // Keep only the finger rotations: the flexed tips then lie below the palm (-Y).
    proxy_pose hands;
    for (int b = idx(bone::left_index_proximal); b < k_bone_count; ++b) {
      if (b == idx(bone::right_thumb_metacarpal) || b == idx(bone::right_thumb_proximal) ||
          b == idx(bone::right_thumb_distal))
        continue;
      hands.rotations[b] = p.rotations[b];
    }
    proxy_fk fk;
    compute_proxy_fk(s, hands, fk);
    // Flexion in [0, 110] degrees: each intermediate joint lies at or below its knuckle.
    for (bone prox : {bone::left_index_proximal, bone::right_ring_proximal,
                      bone::left_little_proximal, bone::right_middle_proximal})
      EXPECT_LE(fk.joints[idx(prox) + 1].y, fk.joints[idx(prox)].y + 1e-6f);
  }
  // A single flexion: left and right tips go down by the same amount.
  proxy_pose p;
  p[bone::left_index_proximal] = axis_angle(glm::vec3(0.f, 0.f, -1.f), 1.f);
  p[bone::right_index_proximal] = mirror_x(p[bone::left_index_proximal]);
  proxy_fk fk;
  compute_proxy_fk(s, p, fk);
  glm::vec3 l = fk.tips[idx(bone::left_index_distal)], r = fk.tips[idx(bone::right_index_distal)];
  EXPECT_LT(l.y, fk.joints[idx(bone::left_hand)].y - 0.03f);
  EXPECT_NEAR(l.y, r.y, 1e-5f);
  EXPECT_NEAR(l.x, -r.x, 1e-5f);
}

TEST(DemoMotion, FeetOnTheFloorHipsLowerAndLoops) {
  proxy_skeleton s = make_proxy_skeleton();
  float standing = standing_hips_height(s);
  proxy_pose a = demo_motion_pose(0.0), squat = demo_motion_pose(1.0), b = demo_motion_pose(10.0);
  EXPECT_NEAR(a.hips_position.y, standing, 1e-3f);
  EXPECT_LT(squat.hips_position.y, standing - 0.15f);
  EXPECT_NEAR(lowest_foot_point(s, squat), 0.f, 1e-5f);
  proxy_fk sq;
  compute_proxy_fk(s, squat, sq);  // feet stay flat: heel and toe tip on the floor
  EXPECT_NEAR(sq.heels[0].y, 0.f, 1e-3f);
  EXPECT_NEAR(sq.tips[idx(bone::right_toes)].y, 0.f, 1e-3f);
  EXPECT_GT(sq.joints[idx(bone::left_lower_leg)].z,
            sq.joints[idx(bone::left_foot)].z);  // knees forward
  for (int i = 0; i < k_bone_count; ++i)
    EXPECT_LT(angle_between(a.rotations[i], b.rotations[i]), 1e-3f);
  landmark_synth gen(all_parts());
  landmark_frame f;
  for (double t = 0.0; t < 10.0; t += 0.1) {
    proxy_pose p = demo_motion_pose(t);
    EXPECT_NEAR(lowest_foot_point(s, p), 0.f, 1e-5f);
    gen.generate(p, f);
    for (const landmark& l : f.pose) EXPECT_TRUE(std::isfinite(l.x) && std::isfinite(l.z));
    for (float e : p.expressions) EXPECT_TRUE(e >= 0.f && e <= 1.f);
  }
  // Waving: right wrist above the right elbow, both above the shoulder.
  proxy_fk fk;
  compute_proxy_fk(s, demo_motion_pose(6.0), fk);
  EXPECT_GT(fk.joints[idx(bone::right_hand)].y, fk.joints[idx(bone::right_upper_arm)].y);
}

TEST(Synth, OptionsValidate) {
  synth_options o;
  EXPECT_TRUE(o.validate().ok());
  o.image_width = 0;
  EXPECT_FALSE(o.validate().ok());
  o = synth_options{};
  o.face_noise_sigma = -1.f;
  EXPECT_NE(o.validate().message().find("noise_sigma"), std::string::npos);
}
