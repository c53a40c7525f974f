// Tests of the synthetic recordings that the accuracy figures are measured on
// (include/avatarmap/synth/synth_recording.hpp, random_motion.hpp, landmark_synth.hpp's
// random camera and low-visibility bursts): the presets stay in their ranges, measured noise
// matches the requested sigma, bursts take the requested share of time with visibility in
// range, the motion is fast and has non-hinge fingers, and the truth file round-trips.
#include "avatarmap/synth/synth_recording.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/pose_accuracy.hpp"
#include "avatarmap/synth/random_motion.hpp"
#include "support/temp_dir.hpp"

using namespace avatarmap;

namespace {

constexpr double k_pi_d = 3.14159265358979323846;

// Pose landmark indices of each limb, by the person's side (no mirror in these tests).
const std::vector<int> k_limb_points[k_synth_limb_count] = {
    {13, 15, 17, 19, 21}, {14, 16, 18, 20, 22}, {25, 27, 29, 31}, {26, 28, 30, 32}};

// Sample standard deviation of the differences of matching points.
struct deviation {
  double sum_sq = 0.0;
  long n = 0;
  void add(const glm::vec3& a, const glm::vec3& b) {
    const glm::vec3 d = a - b;
    sum_sq += double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z;
    n += 3;
  }
  double sigma() const { return std::sqrt(sum_sq / double(n)); }
};

}  // namespace

TEST(SynthScenario, NamesRoundTripAndDemoIsTheDefault) {
  for (synth_scenario s : {synth_scenario::demo, synth_scenario::clean, synth_scenario::noisy})
    EXPECT_EQ(synth_scenario_from_name(synth_scenario_name(s)), s);
  EXPECT_FALSE(synth_scenario_from_name("Noisy").has_value());
  EXPECT_FALSE(synth_scenario_from_name("").has_value());
  const synth_options d = synth_scenario_options(synth_scenario::demo, 7);
  const synth_options defaults;
  EXPECT_EQ(d.seed, 7u);
  EXPECT_EQ(d.motion, synth_motion::demo);
  EXPECT_FALSE(d.random_camera);
  EXPECT_EQ(d.body_noise_sigma, 0.f);
  EXPECT_EQ(d.low_visibility_fraction, 0.f);
  EXPECT_EQ(d.person_height, defaults.person_height);
}

TEST(SynthScenario, PresetsStayInTheirRanges) {
  float fov_lo = 180.f, fov_hi = 0.f, dist_lo = 100.f, dist_hi = 0.f, off_hi = 0.f;
  for (std::uint32_t seed = 1; seed <= 60; ++seed) {
    for (synth_scenario sc : {synth_scenario::clean, synth_scenario::noisy}) {
      const synth_options o = synth_scenario_options(sc, seed);
      ASSERT_TRUE(o.validate().ok()) << o.validate().message();
      EXPECT_EQ(o.motion, synth_motion::random);
      EXPECT_GE(o.person_height, 1.55f);
      EXPECT_LE(o.person_height, 1.90f);
      const landmark_synth s(o);
      const float fov = s.horizontal_fov_degrees();
      EXPECT_GE(fov, 50.f);
      EXPECT_LE(fov, 90.f);
      EXPECT_NEAR(s.focal_pixels(), 0.5 * 1280 / std::tan(0.5 * fov * k_pi_d / 180), 1e-2);
      const glm::vec3 c = s.camera_position();
      EXPECT_GE(c.z, 1.5f);
      EXPECT_LE(c.z, 4.f);
      EXPECT_GE(c.y, 0.8f * s.skeleton().scale - 1e-5f);
      EXPECT_LE(c.y, 1.5f * s.skeleton().scale + 1e-5f);
      // The origin's image x, as a fraction of the half width from the centre.
      const float off = std::abs(s.project(glm::vec3(0.f, c.y, 0.f), c.z).x - 0.5f) * 2.f;
      EXPECT_LE(off, 0.5f + 1e-4f);
      fov_lo = std::min(fov_lo, fov);
      fov_hi = std::max(fov_hi, fov);
      dist_lo = std::min(dist_lo, c.z);
      dist_hi = std::max(dist_hi, c.z);
      off_hi = std::max(off_hi, off);
      if (sc == synth_scenario::noisy) {
        EXPECT_FLOAT_EQ(o.body_noise_sigma, 0.010f);
        EXPECT_FLOAT_EQ(o.hand_noise_sigma, 0.005f);
        EXPECT_FLOAT_EQ(o.face_noise_sigma, 0.001f);
        EXPECT_FLOAT_EQ(o.low_visibility_fraction, 0.12f);
        EXPECT_FLOAT_EQ(o.low_visibility_min, 0.02f);
        EXPECT_FLOAT_EQ(o.low_visibility_max, 0.3f);
        EXPECT_FLOAT_EQ(o.low_visibility_noise_sigma, 0.03f);
      } else {
        EXPECT_EQ(o.body_noise_sigma, 0.f);
        EXPECT_EQ(o.low_visibility_fraction, 0.f);
      }
    }
  }
  // The draws cover the ranges rather than sitting at one value.
  EXPECT_LT(fov_lo, 56.f);
  EXPECT_GT(fov_hi, 84.f);
  EXPECT_LT(dist_lo, 1.8f);
  EXPECT_GT(dist_hi, 3.7f);
  EXPECT_GT(off_hi, 0.35f);
}

TEST(SynthOptions, NewFieldsAreValidated) {
  auto bad = [](auto change) {
    synth_options o;
    o.random_camera = true;
    change(o);
    return o.validate();
  };
  EXPECT_TRUE(bad([](synth_options&) {}).ok());
  EXPECT_NE(bad([](synth_options& o) { o.fov_min_degrees = 95.f; }).message().find("fov_min"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.distance_min = 0.f; }).message().find("distance_min"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.off_centre_max = 1.5f; }).message().find("off_centre"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.low_visibility_fraction = 0.95f; })
                .message()
                .find("low_visibility_fraction"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.low_visibility_min = 0.5f; })
                .message()
                .find("low_visibility_min"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.low_visibility_noise_sigma = NAN; })
                .message()
                .find("low_visibility_noise_sigma"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.max_wrist_speed = 0.f; }).message().find("wrist"),
            std::string::npos);
  EXPECT_NE(bad([](synth_options& o) { o.finger_side_bend_degrees = 50.f; })
                .message()
                .find("finger_side_bend"),
            std::string::npos);
}

// Noise measured on the generator's 3-D points against a noiseless twin (same camera and
// skeleton: the noise has its own generator, so the twins see the same poses).
TEST(SynthScenario, MeasuredNoiseMatchesTheRequestedSigma) {
  synth_options noisy = synth_scenario_options(synth_scenario::noisy, 101);
  noisy.low_visibility_fraction = 0.f;  // bursts measured below
  synth_options clean = noisy;
  clean.body_noise_sigma = clean.hand_noise_sigma = clean.face_noise_sigma = 0.f;
  landmark_synth a(noisy), b(clean);
  random_motion motion(a.skeleton(), 101);
  deviation body, hands, face;
  landmark_frame fa, fb;
  proxy_pose pose;
  for (int i = 0; i < 400; ++i) {
    motion.pose_at(i / 30.0, pose);
    a.generate(pose, fa);
    b.generate(pose, fb);
    for (int p = 0; p < k_pose_landmark_count; ++p)
      body.add(a.points().pose[p], b.points().pose[p]);
    for (int p = 0; p < k_hand_landmark_count; ++p) {
      hands.add(a.points().left_hand[p], b.points().left_hand[p]);
      hands.add(a.points().right_hand[p], b.points().right_hand[p]);
    }
    for (int p = 0; p < k_face_mesh_iris_count; ++p)
      face.add(a.points().face[p], b.points().face[p]);
  }
  EXPECT_NEAR(body.sigma(), 0.010, 0.0005);
  EXPECT_NEAR(hands.sigma(), 0.005, 0.00025);
  EXPECT_NEAR(face.sigma(), 0.001, 0.00005);
}

// Over a long noisy run: each limb spends about 12 % of the time in bursts of about 1 s, the
// burst's points report visibility in [0.02, 0.3] and carry 30 mm extra noise, the other points
// visibility 1, and the truth's marker says exactly which bones were in a burst.
TEST(SynthScenario, LowVisibilityBurstsHaveTheRequestedShareLengthAndVisibility) {
  const synth_options o = synth_scenario_options(synth_scenario::noisy, 102);
  synth_recording rec(o);
  synth_options twin_options = o;
  twin_options.low_visibility_fraction = 0.f;
  landmark_synth twin(twin_options);  // same noise sequence, no bursts
  const double fps = 30.0;
  const int frames = static_cast<int>(1500 * fps);
  std::array<long, k_synth_limb_count> in{};
  std::array<std::vector<double>, k_synth_limb_count> lengths;
  std::array<int, k_synth_limb_count> run{};
  float vis_lo = 1.f, vis_hi = 0.f;
  deviation burst_noise;
  landmark_frame f, ft;
  proxy_pose truth;
  for (int i = 0; i < frames; ++i) {
    rec.generate(i / fps, truth, f);
    const landmark_synth& s = rec.landmarks();
    for (int l = 0; l < k_synth_limb_count; ++l) {
      const bool b = s.limb_low_visibility(static_cast<synth_limb>(l));
      if (b) {
        ++in[l];
        ++run[l];
      } else if (run[l] > 0) {
        lengths[l].push_back(run[l] / fps);
        run[l] = 0;
      }
      for (int p : k_limb_points[l]) {
        const float v = f.pose[p].visibility;
        if (b) {
          vis_lo = std::min(vis_lo, v);
          vis_hi = std::max(vis_hi, v);
          ASSERT_GE(v, 0.02f);
          ASSERT_LE(v, 0.3f);
          ASSERT_EQ(f.pose_world[p].visibility, v);
        } else {
          ASSERT_EQ(v, 1.f) << "point " << p << " frame " << i;
        }
      }
      if (l < 2) {  // an arm: its hand too
        const auto& hand = l == 0 ? f.left_hand : f.right_hand;
        for (const landmark& h : hand) {
          if (b) {
            ASSERT_GE(h.visibility, 0.02f);
            ASSERT_LE(h.visibility, 0.3f);
          } else {
            ASSERT_EQ(h.visibility, 1.f);
          }
        }
      }
    }
    for (int bi = 0; bi < k_bone_count; ++bi) {
      const int l = synth_limb_of(static_cast<bone>(bi));
      const bool marked = l >= 0 && s.limb_low_visibility(static_cast<synth_limb>(l));
      ASSERT_EQ(truth.confidence[bi], marked ? 0.f : 1.f) << bone_name(static_cast<bone>(bi));
    }
    // Extra noise: the burst's points against the twin's (which lack only the extra noise).
    if (i < 9000) {
      twin.generate(truth, ft);
      for (int l = 0; l < k_synth_limb_count; ++l) {
        if (!s.limb_low_visibility(static_cast<synth_limb>(l))) continue;
        for (int p : k_limb_points[l]) burst_noise.add(s.points().pose[p], twin.points().pose[p]);
      }
    }
  }
  double total = 0.0;
  for (int l = 0; l < k_synth_limb_count; ++l) {
    const double share = double(in[l]) / frames;
    total += share;
    EXPECT_NEAR(share, 0.12, 0.03) << "limb " << l;
    ASSERT_GT(lengths[l].size(), 100u);
    double sum = 0.0;
    for (double len : lengths[l]) {
      sum += len;
      EXPECT_GE(len, 0.6 - 1.0 / fps);
      EXPECT_LE(len, 1.4 + 1.0 / fps);
    }
    EXPECT_NEAR(sum / lengths[l].size(), 1.0, 0.08) << "limb " << l;
  }
  EXPECT_NEAR(total / k_synth_limb_count, 0.12, 0.015);
  EXPECT_LT(vis_lo, 0.04f);
  EXPECT_GT(vis_hi, 0.28f);
  EXPECT_NEAR(burst_noise.sigma(), 0.030, 0.0015);
}

TEST(SynthScenario, BurstsSwapWithTheLabelsWhenMirrored) {
  synth_options o = synth_scenario_options(synth_scenario::noisy, 5);
  o.mirror = true;
  landmark_synth s(o);
  random_motion motion(s.skeleton(), 5);
  landmark_frame f;
  proxy_pose pose;
  int checked = 0;
  for (int i = 0; i < 3000 && checked < 30; ++i) {
    motion.pose_at(i / 30.0, pose);
    s.generate(pose, f);
    if (!s.limb_low_visibility(synth_limb::left_arm) ||
        s.limb_low_visibility(synth_limb::right_arm))
      continue;
    // The person's left arm is reported as the right one.
    EXPECT_LE(f.pose[14].visibility, 0.3f);
    EXPECT_EQ(f.pose[13].visibility, 1.f);
    EXPECT_LE(f.right_hand[0].visibility, 0.3f);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(RandomMotion, IsAPureFunctionOfTime) {
  const proxy_skeleton sk = make_proxy_skeleton(1.8f);
  random_motion a(sk, 11), b(sk, 11), c(sk, 12);
  proxy_pose pa, pb, pc;
  for (int i = 0; i < 300; ++i) a.pose_at(i * 0.05, pa);  // a walked there, b jumps
  b.pose_at(299 * 0.05, pb);
  for (int r = 0; r < k_bone_count; ++r) EXPECT_EQ(pa.rotations[r], pb.rotations[r]);
  EXPECT_EQ(pa.hips_position, pb.hips_position);
  b.pose_at(1.0, pb);  // going back replays
  a.pose_at(1.0, pa);
  for (int r = 0; r < k_bone_count; ++r) EXPECT_EQ(pa.rotations[r], pb.rotations[r]);
  c.pose_at(1.0, pc);
  EXPECT_NE(pa.rotations[idx(bone::left_upper_arm)], pc.rotations[idx(bone::left_upper_arm)]);
  // Feet on the floor, unit rotations.
  EXPECT_NEAR(lowest_foot_point(sk, pa), 0.f, 1e-4f);
  for (const glm::quat& q : pa.rotations) EXPECT_NEAR(glm::length(q), 1.f, 1e-4f);
}

// The hands' world angular speed reaches ~6 rad/s (fast motion) but not much more; finger
// intermediate and distal joints bend sideways (non-hinge) within the +-10 degree range.
TEST(RandomMotion, WristsAreFastAndFingersAreNotHinges) {
  const proxy_skeleton sk = make_proxy_skeleton();
  random_motion m(sk, 3);
  const double dt = 0.005;
  std::array<glm::quat, k_bone_count> prev{}, cur{};
  proxy_pose p;
  std::vector<float> speeds;
  float max_side = 0.f;
  for (int i = 0; i <= static_cast<int>(300 / dt); ++i) {
    m.pose_at(i * dt, p);
    compute_world_rotations(p, cur);
    if (i > 0) {
      for (bone h : {bone::left_hand, bone::right_hand})
        speeds.push_back(angle_between(cur[idx(h)], prev[idx(h)]) / static_cast<float>(dt));
    }
    prev = cur;
    if (i % 20 == 0) {
      // Left fingers point along +X at rest and flex toward -Y: a hinge keeps z = 0.
      for (bone b : {bone::left_index_intermediate, bone::left_middle_distal,
                     bone::left_little_intermediate}) {
        const glm::vec3 d = p[b] * glm::vec3(1.f, 0.f, 0.f);
        max_side = std::max(max_side, std::abs(std::asin(std::min(1.f, std::abs(d.z)))));
      }
    }
  }
  std::sort(speeds.begin(), speeds.end());
  const float top = speeds.back();
  const float p99 = speeds[speeds.size() * 99 / 100];
  EXPECT_GT(top, 5.f);
  EXPECT_LT(top, 6.f * 1.5f);
  EXPECT_GT(p99, 3.f);
  const float deg = max_side * 180.f / static_cast<float>(k_pi_d);
  EXPECT_GT(deg, 6.f);
  EXPECT_LE(deg, 10.5f);
}

TEST(SynthRecording, DemoScenarioReproducesTheDemoMotion) {
  synth_recording rec(synth_scenario_options(synth_scenario::demo, 1));
  landmark_synth plain{synth_options{}};
  landmark_frame a, b;
  proxy_pose truth;
  for (double t : {0.0, 1.3, 7.9}) {
    rec.generate(t, truth, a);
    const proxy_pose demo = demo_motion_pose(t, plain.skeleton());
    plain.generate(demo, b);
    for (int r = 0; r < k_bone_count; ++r) EXPECT_EQ(truth.rotations[r], demo.rotations[r]);
    for (int i = 0; i < k_pose_landmark_count; ++i) EXPECT_EQ(a.pose[i].x, b.pose[i].x);
    for (float c : truth.confidence) EXPECT_EQ(c, 1.f);
  }
}

// The truth written as `avatarmap synth --truth` writes it reads back with its times, rotations
// and low-visibility marker, and measures 0 against itself.
TEST(SynthRecording, TruthFileRoundTrips) {
  avatarmap::test::temp_dir dir("synth_truth");
  const std::string path = dir.file("truth.pose.jsonl");
  synth_recording rec(synth_scenario_options(synth_scenario::noisy, 104));
  std::vector<proxy_pose> written;
  {
    pose_writer w;
    pose_file_header h;
    h.present = true;
    h.fps = 30.0;
    pose_write_options wo;
    wo.write_confidence = true;
    ASSERT_TRUE(w.open(path, h, wo).ok());
    landmark_frame f;
    proxy_pose truth;
    for (int i = 0; i < 300; ++i) {
      rec.generate(i / 30.0, truth, f);
      written.push_back(truth);
      ASSERT_TRUE(w.write(truth).ok());
    }
    ASSERT_TRUE(w.commit().ok());
  }
  pose_reader r;
  ASSERT_TRUE(r.open(path).ok());
  proxy_pose back;
  size_t n = 0;
  long marked = 0;
  while (r.next(back) == read_result::frame) {
    ASSERT_LT(n, written.size());
    const proxy_pose& w = written[n++];
    EXPECT_NEAR(back.t, w.t, 1e-9);
    for (int b = 0; b < k_bone_count; ++b) {
      EXPECT_LT(angle_between(back.rotations[b], w.rotations[b]), 1e-5f);
      EXPECT_EQ(back.confidence[b], w.confidence[b]);
      marked += back.confidence[b] == 0.f;
    }
  }
  EXPECT_EQ(n, written.size());
  EXPECT_GT(marked, 0);  // seed 104 has bursts in its first 10 s
  pose_accuracy acc;
  ASSERT_TRUE(evaluate_pose_files(path, path, acc).ok());
  EXPECT_EQ(acc.frames, 300);
  EXPECT_GT(acc.low_visibility_frames, 0);
  EXPECT_LT(acc.all.direction.max, 0.01);
  EXPECT_LT(acc.all.head.max, 0.01);
}
