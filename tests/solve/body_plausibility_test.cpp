// Bodies that are not followed (solve/body_plausibility.hpp; docs/solver.md): the hysteresis on
// its own, and the solver on real landmarks: Google's reference squat (a full body: never
// held), the same squat cropped to its upper body (a webcam's framing: the lower body held,
// the arms still follow), and a forearm close-up captured from asl_hand.25fps.mp4 (a body
// found where there is none: held; the fingers still move as before). Skipped without
// AVATARMAP_TEST_DATA.
#include "avatarmap/solve/body_plausibility.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

body_verdict verdict(std::uint32_t doubts) {
  body_verdict v;
  v.has_body = true;
  v.doubts = doubts;
  return v;
}

TEST(BodyHold, FirstFrameDecidesThenAFewFramesInARowChangeIt) {
  body_hold h;
  double t = 0.0;
  auto next = [&](std::uint32_t doubts) { return h.update(verdict(doubts), t += 1.0 / 30); };
  EXPECT_EQ(next(0), body_follow::all);
  // Two implausible frames are not enough; the third in a row holds.
  EXPECT_EQ(next(body_doubt_legs_above_hips), body_follow::all);
  EXPECT_EQ(next(body_doubt_legs_above_hips), body_follow::all);
  EXPECT_EQ(next(0), body_follow::all);  // the run is broken
  for (int i = 0; i < body_hold::k_enter_frames - 1; ++i)
    EXPECT_EQ(next(body_doubt_legs_above_hips), body_follow::all);
  EXPECT_EQ(next(body_doubt_torso_too_large), body_follow::limbs_off);
  // Frames without a body change nothing.
  EXPECT_EQ(h.update(body_verdict{}, t += 1.0 / 30), body_follow::limbs_off);
  // The legs alone unseen asks for less doubt: a run of 8 frames.
  for (int i = 0; i < body_hold::k_leave_frames - 1; ++i)
    EXPECT_EQ(next(body_doubt_lower_body_unseen), body_follow::limbs_off);
  EXPECT_EQ(next(body_doubt_lower_body_unseen), body_follow::upper_body);
  for (int i = 0; i < body_hold::k_leave_frames - 1; ++i)
    EXPECT_EQ(next(0), body_follow::upper_body);
  EXPECT_EQ(next(0), body_follow::all);
  // Legs unseen for less than 1.5 s (an occlusion the filters bridge): still followed; for
  // longer (the framing): held.
  const double start = t + 1.0 / 30;
  while (t + 1.0 / 30 - start < body_hold::k_unseen_enter_seconds - 1e-6)
    EXPECT_EQ(next(body_doubt_lower_body_unseen), body_follow::all) << t - start;
  EXPECT_EQ(next(body_doubt_lower_body_unseen), body_follow::upper_body);
  // The first frame with a body decides at once, whatever the doubt.
  body_hold fresh;
  EXPECT_EQ(fresh.update(body_verdict{}, 0.0), body_follow::all);
  EXPECT_EQ(fresh.update(verdict(body_doubt_lower_body_unseen), 0.1), body_follow::upper_body);
}

// Google's reference squat: 65 frames of a 720x1280 video at 5 fps.
constexpr float k_width = 720.f, k_height = 1280.f;
bool load_squats(std::vector<landmark_frame>& frames) {
  const std::string img = test::test_data_path("motion/tfjs-models/pose_squats.full.json");
  const std::string wld = test::test_data_path("motion/tfjs-models/pose_squats_3d.full.json");
  if (img.empty()) return false;
  std::ifstream fi(img), fw(wld);
  const nlohmann::json ji = nlohmann::json::parse(fi), jw = nlohmann::json::parse(fw);
  frames.resize(ji.size());
  for (size_t i = 0; i < ji.size(); ++i) {
    landmark_frame& f = frames[i];
    f.t = double(i) / 5.0;
    for (int k = 0; k < 33; ++k) {
      f.pose[k] = landmark{ji[i][k][0].get<float>() / k_width, ji[i][k][1].get<float>() / k_height,
                           ji[i][k][2].get<float>() / k_width, 1.f, 1.f};
      f.pose_world[k] = landmark{jw[i][k][0].get<float>(), jw[i][k][1].get<float>(),
                                 jw[i][k][2].get<float>(), 1.f, 1.f};
    }
    f.set(frame_part::pose, true);
    f.set(frame_part::pose_world, true);
  }
  return true;
}

const bone k_legs[] = {bone::hips,           bone::left_upper_leg,  bone::right_upper_leg,
                       bone::left_lower_leg, bone::right_lower_leg, bone::left_foot,
                       bone::right_foot};

struct take_figures {
  float hips_min = 1e9f, hips_max = -1e9f;
  float leg_change = 0.f;  // largest rotation of a leg bone (or the hips) from its first frame
  std::vector<proxy_pose> poses;
};

take_figures solve_take(const std::vector<landmark_frame>& frames, const solver_options& o,
                        body_hold_stats* stats = nullptr) {
  frame_solver solver(o);
  take_figures r;
  proxy_pose out;
  for (const landmark_frame& f : frames) {
    solver.solve(f, out);
    r.poses.push_back(out);
    r.hips_min = std::min(r.hips_min, out.hips_position.y);
    r.hips_max = std::max(r.hips_max, out.hips_position.y);
    for (bone b : k_legs)
      r.leg_change = std::max(
          r.leg_change, angle_between(out.rotations[idx(b)], r.poses[0].rotations[idx(b)]) / k_deg);
  }
  if (stats) *stats = solver.hold_stats();
  return r;
}

TEST(BodyPlausibility, AFullBodySquatIsNeverHeld) {
  std::vector<landmark_frame> frames;
  if (!load_squats(frames)) GTEST_SKIP() << test::k_no_test_data;
  for (size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(judge_body(frames[i], k_width, k_height).doubts, 0u) << "frame " << i;
  solver_options o;
  o.image_width = k_width;
  o.image_height = k_height;
  body_hold_stats stats;
  const take_figures r = solve_take(frames, o, &stats);
  std::printf("[figures] squat: held %ld of %ld frames; hips height %.3f..%.3f m\n",
              stats.held_frames, stats.frames, r.hips_min, r.hips_max);
  EXPECT_EQ(stats.frames, long(frames.size()));
  EXPECT_EQ(stats.held_frames, 0);
  EXPECT_GE(r.hips_max - r.hips_min, 0.25f);  // the squat still lowers the hips
}

// `fit_body`: the body fitted to the image (the default) in both takes; without it the
// cropped take's arms are the uncropped take's exactly (the rule changes nothing above the
// hips); with it they move a few degrees, the fit's root being found from the shoulders alone.
void upper_body_crop(bool fit_body, float max_arm_difference_degrees) {
  std::vector<landmark_frame> frames;
  if (!load_squats(frames)) GTEST_SKIP() << test::k_no_test_data;
  // A webcam's framing: the image cropped at 90 % of the highest the hips come over the take,
  // so the hips and legs are always below it. Points below the crop are not visible (as the
  // estimator reports points it places outside the image); image y renormalised.
  float hip_top = 1.f;
  for (const landmark_frame& f : frames)
    hip_top = std::min(hip_top, 0.5f * (f.pose[23].y + f.pose[24].y));
  const float crop = 0.9f * hip_top;
  std::vector<landmark_frame> cropped = frames;
  for (landmark_frame& f : cropped)
    for (int k = 0; k < 33; ++k) {
      if (f.pose[k].y > crop) {
        f.pose[k].visibility = f.pose[k].presence = 0.f;
        f.pose_world[k].visibility = f.pose_world[k].presence = 0.f;
      }
      f.pose[k].y /= crop;
    }
  solver_options o;
  o.image_width = k_width;
  o.image_height = k_height * crop;
  body_hold_stats stats;
  const take_figures held = solve_take(cropped, o, &stats);
  o.fit_body_to_image = fit_body;
  solver_options full_o;
  full_o.image_width = k_width;
  full_o.image_height = k_height;
  full_o.fit_body_to_image = fit_body;
  const take_figures full = solve_take(frames, full_o);
  // The upper arms' directions (local to the upper chest) cropped against uncropped, on the
  // frames where the arm (shoulder, elbow, wrist) is inside the crop, and how far they move.
  float arm_diff = 0.f, arm_move = 0.f;
  int arm_frames = 0;
  for (size_t i = 0; i < frames.size(); ++i)
    for (int side = 0; side < 2; ++side) {
      const int sh = side == 0 ? 11 : 12, el = sh + 2, wr = sh + 4;
      auto inside = [&](size_t k) {
        return std::max({frames[k].pose[sh].y, frames[k].pose[el].y, frames[k].pose[wr].y}) <= crop;
      };
      // Inside on this frame and the one before (the confidence gate blends a bone found
      // again in over 0.15 s: a frame at 5 fps).
      if (i == 0 || !inside(i) || !inside(i - 1)) continue;
      const int b = idx(side == 0 ? bone::left_upper_arm : bone::right_upper_arm);
      // The arm's direction (a straight arm's twist is not observable).
      const glm::vec3 rest = bone_rest_direction(static_cast<bone>(b));
      auto dir = [&](const proxy_pose& p) { return p.rotations[b] * rest; };
      auto angle = [](const glm::vec3& u, const glm::vec3& v) {
        return std::acos(std::clamp(glm::dot(u, v), -1.f, 1.f));
      };
      arm_diff += angle(dir(held.poses[i]), dir(full.poses[i]));
      arm_move = std::max(arm_move, angle(dir(held.poses[i]), dir(held.poses[0])));
      ++arm_frames;
    }
  ASSERT_GT(arm_frames, 15);
  arm_diff /= arm_frames * k_deg;
  arm_move /= k_deg;
  std::printf(
      "[figures] upper-body crop at y %.2f, body fit %s: held %ld of %ld frames; hips height range "
      "%.2f cm, "
      "leg-bone change %.2f deg; upper arms in the crop (%d arm frames): %.1f deg mean from the "
      "uncropped take's, moving %.1f deg\n",
      crop, fit_body ? "on" : "off", stats.held_frames, stats.frames,
      100.f * (held.hips_max - held.hips_min), held.leg_change, arm_frames, arm_diff, arm_move);
  EXPECT_EQ(stats.held_frames, long(frames.size()));
  EXPECT_EQ(stats.limbs_off_frames, 0);  // the torso is a person's: only the legs are held
  EXPECT_LT(held.hips_max - held.hips_min, 1e-4f);
  EXPECT_LT(held.leg_change, 0.01f);
  EXPECT_LT(arm_diff, max_arm_difference_degrees);
  EXPECT_GT(arm_move, 20.f);
}

TEST(BodyPlausibility, AnUpperBodyCropHoldsTheLegsAndTheArmsStillFollow) {
  upper_body_crop(true, 12.f);
}

TEST(BodyPlausibility, AnUpperBodyCropLeavesTheArmsAsTheyWereWithoutTheBodyFit) {
  upper_body_crop(false, 0.05f);
}

// The forearm close-up: `avatarmap capture asl_hand.25fps.mp4 --hands -o asl_hand.landmarks.jsonl`
// (Google's reference landmarks beside the video are the hand's only), in the data folder or in
// $AVATARMAP_CAPTURES.
std::string asl_capture() {
  for (const std::string& p :
       {test::test_data_path("motion/tfjs-models/asl_hand.landmarks.jsonl"),
        std::string(std::getenv("AVATARMAP_CAPTURES") ? std::getenv("AVATARMAP_CAPTURES") : "")})
    if (!p.empty()) {
      const std::string path = p.size() > 6 && p.compare(p.size() - 6, 6, ".jsonl") == 0
                                   ? p
                                   : p + "/asl_hand.landmarks.jsonl";
      if (std::ifstream(path).good()) return path;
    }
  return {};
}

TEST(BodyPlausibility, AForearmCloseUpHoldsTheLowerBodyAndTheFingersStillMove) {
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  const std::string path = asl_capture();
  if (path.empty())
    GTEST_SKIP() << "no capture of asl_hand.25fps.mp4: run `avatarmap capture "
                    "motion/tfjs-models/asl_hand.25fps.mp4 --hands -o asl_hand.landmarks.jsonl` "
                    "into the data folder or $AVATARMAP_CAPTURES";
  landmark_reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  std::vector<landmark_frame> frames;
  landmark_frame f;
  while (reader.next(f) == read_result::frame) frames.push_back(f);
  ASSERT_GT(frames.size(), 200u);
  solver_options o;
  o.image_width = float(reader.header().image_width);
  o.image_height = float(reader.header().image_height);
  body_hold_stats stats;
  const take_figures held = solve_take(frames, o, &stats);
  solver_options off = o;
  off.lower_body_rest = body_rest::off;
  const take_figures followed = solve_take(frames, off);
  // The fingers: every finger bone is local to its parent in the hand, so holding the body
  // changes none of them; and they move over the take.
  float finger_diff = 0.f, finger_move = 0.f;
  for (size_t i = 0; i < frames.size(); ++i)
    for (int b = idx(bone::left_thumb_metacarpal); b <= idx(bone::right_little_distal); ++b) {
      finger_diff = std::max(
          finger_diff, angle_between(held.poses[i].rotations[b], followed.poses[i].rotations[b]));
      finger_move = std::max(finger_move,
                             angle_between(held.poses[i].rotations[b], held.poses[0].rotations[b]));
    }
  std::printf(
      "[figures] asl_hand: held %ld of %ld frames with a body (legs above the hips %ld, bone "
      "lengths %ld, lower body not seen %ld); hips height range %.2f cm (followed: %.1f cm, "
      "%.1f..%.1f), leg-bone change %.2f deg (followed: %.1f deg); fingers move %.1f deg, "
      "%.4f deg from the followed take's\n",
      stats.held_frames, stats.frames, stats.doubt_frames[0], stats.doubt_frames[2],
      stats.doubt_frames[3], 100.f * (held.hips_max - held.hips_min),
      100.f * (followed.hips_max - followed.hips_min), 100.f * followed.hips_min,
      100.f * followed.hips_max, held.leg_change, followed.leg_change, finger_move / k_deg,
      finger_diff / k_deg);
  EXPECT_GT(stats.frames, 200);
  EXPECT_EQ(stats.held_frames, stats.frames);
  EXPECT_LT(held.hips_max - held.hips_min, 1e-4f);
  EXPECT_NEAR(held.hips_max, o.rest_hips_height, 1e-4f);
  EXPECT_LT(held.leg_change, 0.01f);
  // What the rule is for: followed, the avatar falls over.
  EXPECT_GT(followed.hips_max - followed.hips_min, 0.2f);
  EXPECT_GT(followed.leg_change, 90.f);
  EXPECT_GT(finger_move / k_deg, 30.f);
  EXPECT_LT(finger_diff / k_deg, 0.01f);
}

}  // namespace
}  // namespace avatarmap
