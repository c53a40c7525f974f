// hand_shape: a hand's landmarks fitted to its learnt shape (a rigid palm, fingers of constant
// length). The hands here are built in this file: a palm of six points, three segments per
// finger turned by random bends, the whole hand turned and moved at random; the palm's best
// rigid fit is checked against Eigen's SVD (Kabsch), an independent method.
#include "avatarmap/solve/hand_shape.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>

#include "avatarmap/solve/frame_solver.hpp"

namespace avatarmap {
namespace {

using points = hand_shape::points;

// A hand in its own axes: the palm, and per finger three segment lengths (metres).
struct hand_model {
  // Wrist, thumb CMC (toward the palm's side, -Y), index to pinky knuckles (an arch).
  std::array<glm::vec3, 6> palm = {
      glm::vec3(0.f, 0.f, 0.f),           glm::vec3(0.02f, -0.025f, 0.025f),
      glm::vec3(0.085f, 0.f, 0.025f),     glm::vec3(0.09f, 0.004f, 0.003f),
      glm::vec3(0.085f, 0.001f, -0.017f), glm::vec3(0.075f, -0.008f, -0.035f)};
  float length[5][3] = {{0.040f, 0.032f, 0.028f},
                        {0.042f, 0.025f, 0.021f},
                        {0.046f, 0.029f, 0.023f},
                        {0.043f, 0.027f, 0.022f},
                        {0.034f, 0.020f, 0.019f}};
};

glm::quat random_rotation(std::mt19937& rng, float max_angle) {
  std::normal_distribution<float> n(0.f, 1.f);
  std::uniform_real_distribution<float> u(0.f, max_angle);
  glm::vec3 axis(n(rng), n(rng), n(rng));
  return glm::angleAxis(u(rng), glm::normalize(axis));
}

// The 21 points of the model turned by `hand`, at `at`, with random finger bends (curls up to
// 90 degrees a joint, sideways bends up to 15).
points pose_hand(const hand_model& m, const glm::quat& hand, const glm::vec3& at,
                 std::mt19937& rng) {
  std::uniform_real_distribution<float> curl(-0.2f, 1.57f), side(-0.26f, 0.26f);
  points p{};
  for (int i = 0; i < 6; ++i) p[hand_shape::k_palm[i]] = at + hand * m.palm[i];
  for (int f = 0; f < 5; ++f) {
    const int base = finger_base_landmark(f);
    // From the wrist through the finger's root (the thumb's CMC or the knuckle, palm slot f+1).
    glm::vec3 joint = m.palm[f + 1];
    glm::vec3 dir = glm::normalize(joint - m.palm[0]);
    for (int k = 0; k < 3; ++k) {
      const glm::quat bend = glm::angleAxis(curl(rng), glm::vec3(0.f, 0.f, 1.f)) *
                             glm::angleAxis(side(rng), glm::vec3(0.f, 1.f, 0.f));
      dir = glm::normalize(bend * dir);
      joint += m.length[f][k] * dir;
      p[base + k + 1] = at + hand * joint;
    }
  }
  return p;
}

points add_noise(points p, float sigma, std::mt19937& rng) {
  std::normal_distribution<float> n(0.f, sigma);
  for (glm::vec3& v : p) v += glm::vec3(n(rng), n(rng), n(rng));
  return p;
}

// Learns `frames` exact poses of m (random turns and finger bends, at the origin).
void learn_exact(hand_shape& s, const hand_model& m, std::mt19937& rng, int frames) {
  for (int i = 0; i < frames; ++i)
    s.learn(pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.f), rng), 1.f);
}

double mean_sq_error(const points& a, const points& b) {
  double s = 0;
  for (int i = 0; i < k_hand_landmark_count; ++i) s += glm::dot(a[i] - b[i], a[i] - b[i]);
  return s / k_hand_landmark_count;
}

// atan2 of |a x b| and a . b in double: exact near 0, where acos of a rounded cosine is not.
double angle_deg(const glm::vec3& a, const glm::vec3& b) {
  const glm::dvec3 x(a), y(b);
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y)) * 180.0 / 3.14159265358979;
}

// Mean angle of the 15 finger segments against the truth's.
double finger_error_deg(const points& p, const points& truth) {
  double s = 0;
  for (int f = 0; f < 5; ++f) {
    const int base = finger_base_landmark(f);
    for (int k = 0; k < 3; ++k)
      s += angle_deg(p[base + k + 1] - p[base + k], truth[base + k + 1] - truth[base + k]);
  }
  return s / 15.0;
}

TEST(HandShape, NothingMovesBeforeTheShapeIsKnown) {
  hand_model m;
  std::mt19937 rng(1);
  hand_shape s;
  for (int i = 0; i < hand_shape::k_min_frames - 1; ++i) {
    const points p =
        add_noise(pose_hand(m, random_rotation(rng, 3.f), glm::vec3(0.1f), rng), 0.005f, rng);
    s.learn(p, 1.f);
    points q = p;
    s.fit(q);
    EXPECT_EQ(q, p);
  }
  EXPECT_FALSE(s.ready());
}

TEST(HandShape, ExactLandmarksStayExactlyWhereTheyAre) {
  hand_model m;
  std::mt19937 rng(2);
  hand_shape s;
  for (int i = 0; i < 60; ++i) {
    const points p = pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.3f, -0.1f, 2.f), rng);
    s.learn(p, 1.f);
    points q = p;
    s.fit(q);
    if (i < hand_shape::k_min_frames) continue;
    ASSERT_TRUE(s.ready());
    for (int j = 0; j < k_hand_landmark_count; ++j)
      EXPECT_LT(glm::length(q[j] - p[j]), 2e-5f) << "frame " << i << " point " << j;
    EXPECT_LT(finger_error_deg(q, p), 0.01);
  }
  EXPECT_LT(s.noise_sigma(), 1e-5f);
  for (int f = 0; f < 5; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.segment_length(3 * f + k), m.length[f][k], 1e-5f);
}

TEST(HandShape, LearnsLengthsAndNoiseUnderNoise) {
  hand_model m;
  std::mt19937 rng(3);
  hand_shape s;
  const float sigma = 0.005f;
  for (int i = 0; i < 600; ++i)
    s.learn(add_noise(pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.f), rng), sigma, rng),
            1.f);
  // The learnt noise: how far the palm strays from its rigid shape.
  EXPECT_NEAR(s.noise_sigma(), sigma, 0.0006f);
  // Lengths without the noise's share: raw observed lengths would be ~sqrt(L^2 + 6 sigma^2),
  // 3-9 mm too long on these segments.
  for (int f = 0; f < 5; ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(s.segment_length(3 * f + k), m.length[f][k], 0.0015f) << f << " " << k;
}

TEST(HandShape, FittedPointsAreNearerTheTruth) {
  hand_model m;
  std::mt19937 rng(4);
  hand_shape s;
  double raw_sq = 0, fit_sq = 0, raw_deg = 0, fit_deg = 0;
  int n = 0;
  for (int i = 0; i < 800; ++i) {
    const points truth = pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.2f), rng);
    const points p = add_noise(truth, 0.005f, rng);
    s.learn(p, 1.f);
    if (i < 200) continue;  // the shape learnt
    points q = p;
    s.fit(q);
    raw_sq += mean_sq_error(p, truth);
    fit_sq += mean_sq_error(q, truth);
    raw_deg += finger_error_deg(p, truth);
    fit_deg += finger_error_deg(q, truth);
    ++n;
  }
  // The fit removes the noise the shape does not allow: 6 of the palm's 18 coordinates and one
  // of each segment's 3 are left, so a good share of the points' error goes.
  EXPECT_LT(fit_sq, 0.7 * raw_sq);
  EXPECT_LT(fit_deg, 0.9 * raw_deg) << raw_deg / n << " -> " << fit_deg / n << " degrees";
}

// The palm's fit against Kabsch by SVD: the rotation and translation that carry the (known,
// exact) palm onto noisy points in the least-squares sense.
TEST(HandShape, PalmFitIsTheLeastSquaresRigidMotion) {
  hand_model m;
  std::mt19937 rng(5);
  hand_shape s;
  learn_exact(s, m, rng, 20);
  for (int trial = 0; trial < 50; ++trial) {
    const points truth =
        pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(-0.4f, 0.2f, 1.f), rng);
    points q = add_noise(truth, 0.0015f, rng);  // within the 3 mm a learnt exact palm allows
    Eigen::Matrix<double, 3, 6> a, b;
    for (int i = 0; i < 6; ++i) {
      a.col(i) = Eigen::Vector3d(m.palm[i].x, m.palm[i].y, m.palm[i].z);
      const glm::vec3& o = q[hand_shape::k_palm[i]];
      b.col(i) = Eigen::Vector3d(o.x, o.y, o.z);
    }
    const Eigen::Vector3d ca = a.rowwise().mean(), cb = b.rowwise().mean();
    const Eigen::Matrix3d h = (a.colwise() - ca) * (b.colwise() - cb).transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
    const Eigen::Matrix3d r = svd.matrixV() * d * svd.matrixU().transpose();
    s.fit(q);
    for (int i = 0; i < 6; ++i) {
      const Eigen::Vector3d want = r * (a.col(i) - ca) + cb;
      const glm::vec3& got = q[hand_shape::k_palm[i]];
      EXPECT_NEAR(got.x, want.x(), 2e-5);
      EXPECT_NEAR(got.y, want.y(), 2e-5);
      EXPECT_NEAR(got.z, want.z(), 2e-5);
    }
  }
}

TEST(HandShape, AFingerSeenFarFromItsLengthKeepsItsPoints) {
  hand_model m;
  std::mt19937 rng(6);
  hand_shape s;
  learn_exact(s, m, rng, 20);
  points p = pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.f), rng);
  // The middle finger's distal segment seen end-on: a fifth of its length.
  const int tip = finger_base_landmark(2) + 3;
  p[tip] = p[tip - 1] + 0.2f * (p[tip] - p[tip - 1]);
  points q = p;
  s.fit(q);
  for (int k = 1; k <= 3; ++k) EXPECT_EQ(q[tip - 3 + k], p[tip - 3 + k]);
  // The other fingers still fitted (exact here, so unchanged up to rounding).
  EXPECT_LT(glm::length(q[8] - p[8]), 2e-5f);
}

TEST(HandShape, BadFramesAreNotLearntAndAnotherHandRestarts) {
  hand_model m;
  std::mt19937 rng(7);
  hand_shape s;
  learn_exact(s, m, rng, 20);
  EXPECT_EQ(s.frames(), 20);
  points p = pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.f), rng);
  s.learn(p, 0.3f);  // barely seen
  points nan = p;
  nan[7].y = std::nanf("");
  s.learn(nan, 1.f);
  EXPECT_EQ(s.frames(), 20);
  points q = nan;
  s.fit(q);  // a non-finite point: left alone
  EXPECT_TRUE(std::isnan(q[7].y));
  EXPECT_EQ(q[0], nan[0]);
  // A mirrored detection of the same hand (handedness swapped): no rotation carries the palm
  // (not flat: the thumb's CMC sits 2.5 cm toward the palm's side) onto it, so it is left as
  // observed and not learnt from.
  points mirrored = pose_hand(m, random_rotation(rng, 3.14f), glm::vec3(0.f), rng);
  for (glm::vec3& v : mirrored) v.x = -v.x;
  points left_alone = mirrored;
  s.fit(left_alone);
  EXPECT_EQ(left_alone, mirrored);
  s.fit_and_learn(left_alone, 1.f);
  EXPECT_EQ(left_alone, mirrored);
  EXPECT_EQ(s.frames(), 20);
  // Barely seen (a burst's poor points), the same points are fitted: the shape is what it has.
  s.fit(left_alone, 0.2f);
  EXPECT_NE(left_alone, mirrored);
  // Another, larger hand: its palm strays; after 30 such frames the shape starts afresh.
  hand_model big;
  for (glm::vec3& v : big.palm) v *= 1.3f;
  for (auto& f : big.length)
    for (float& l : f) l *= 1.3f;
  learn_exact(s, big, rng, 28);  // the mirrored frame above was the first stray
  EXPECT_EQ(s.frames(), 20);
  learn_exact(s, big, rng, 1);
  EXPECT_EQ(s.frames(), 1);
  learn_exact(s, big, rng, 20);
  EXPECT_NEAR(s.segment_length(0), big.length[0][0], 1e-5f);
}

TEST(HandShape, TheSolverUsesItOnlyWhenAsked) {
  solver_options on, off;
  off.fit_hand_shape = false;
  frame_solver a(on), b(off);
  EXPECT_TRUE(a.options().fit_hand_shape);
  hand_model m;
  std::mt19937 rng(8);
  landmark_frame f;
  proxy_pose pa, pb;
  for (int i = 0; i < 30; ++i) {
    f.clear();
    f.t = i / 30.0;
    const points p =
        add_noise(pose_hand(m, glm::angleAxis(0.3f, glm::vec3(0.f, 1.f, 0.f)), glm::vec3(0.f), rng),
                  0.004f, rng);
    for (int j = 0; j < k_hand_landmark_count; ++j)
      f.left_hand_world[j] = landmark{p[j].x, p[j].y, p[j].z, 1.f, 1.f};
    f.set(frame_part::left_hand_world, true);
    a.solve(f, pa);
    b.solve(f, pb);
  }
  EXPECT_EQ(a.learnt_hand(0).frames(), 30);  // not mirrored: the person's left is the avatar's
  EXPECT_EQ(b.learnt_hand(0).frames(), 0);
  // Noisy points: the fitted fingers differ from the raw ones.
  bool differs = false;
  for (int bi = idx(bone::left_thumb_metacarpal); bi < k_bone_count; ++bi)
    differs = differs || pa.rotations[bi] != pb.rotations[bi];
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace avatarmap
