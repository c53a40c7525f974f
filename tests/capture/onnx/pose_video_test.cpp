// The body pipeline in video (tracking + smoothing) mode on pose_squats.mp4 against Google's
// reference landmarks for it (tfjs-models' pose_squats.full.json: 2-D pixels, and
// pose_squats_3d.full.json: world metres), with the tolerances tfjs-models' own tests use
// (expected_from_tests.json: EPSILON_VIDEO 31 px, EPSILON_VIDEO_WORLD 0.24 m).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "avatarmap/capture/pose_pipeline.hpp"
#include "avatarmap/media/video_source.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

nlohmann::json load_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

struct video_errors {
  std::vector<double> point_px;  // per point, Euclidean, pixels
  double max_coord_px = 0.0;     // largest |dx| or |dy|
  int coords_over = 0;           // coordinates over the image epsilon
  int coords = 0;
  double max_world_m = 0.0;  // largest |d| of a world coordinate
  int frames = 0;
  int found = 0;
  // Frames 32-64 only: those the int8 models were not calibrated on (scripts/calibrate_int8.sh).
  double held_out_max_coord_px = 0.0;
  int held_out_coords_over = 0;
  double held_out_max_world_m = 0.0;
};

// `clock_fps` > 0: frame i is given the time i / clock_fps instead of the video's own (5 fps).
video_errors run_squats(pose_smoothing smoothing, double eps_px, double clock_fps = 0.0,
                        model_precision precision = model_precision::float32) {
  video_errors e;
  const std::string dir = test::test_data_path("motion/tfjs-models");
  const nlohmann::json ref = load_json(dir + "/pose_squats.full.json");
  const nlohmann::json ref3 = load_json(dir + "/pose_squats_3d.full.json");
  pose_pipeline_options o;
  o.models_dir = test::models_dir();
  o.smoothing = smoothing;
  o.precision = precision;
  std::unique_ptr<pose_pipeline> p;
  const status s = pose_pipeline::create(o, p);
  EXPECT_TRUE(s.ok()) << s.message();
  if (!s.ok()) return e;
  video_source src;
  EXPECT_TRUE(src.open(dir + "/pose_squats.mp4").ok());
  image_view img;
  double t = 0.0;
  landmark_frame f;
  while (src.next(img, t) == read_result::frame) {
    const size_t i = static_cast<size_t>(e.frames++);
    if (i >= ref.size()) break;
    f.clear();
    if (clock_fps > 0.0) t = static_cast<double>(i) / clock_fps;
    f.t = t;
    if (p->process(img, f) != pose_result::found) continue;
    ++e.found;
    for (int j = 0; j < k_pose_landmark_count; ++j) {
      const double dx = f.pose[j].x * img.width - ref[i][j][0].get<double>();
      const double dy = f.pose[j].y * img.height - ref[i][j][1].get<double>();
      e.point_px.push_back(std::hypot(dx, dy));
      for (double d : {std::fabs(dx), std::fabs(dy)}) {
        e.max_coord_px = std::max(e.max_coord_px, d);
        e.coords_over += d > eps_px;
        ++e.coords;
        if (i >= 32) {
          e.held_out_max_coord_px = std::max(e.held_out_max_coord_px, d);
          e.held_out_coords_over += d > eps_px;
        }
      }
      const landmark& w = f.pose_world[j];
      for (int k = 0; k < 3; ++k) {
        const double v = k == 0 ? w.x : k == 1 ? w.y : w.z;
        e.max_world_m = std::max(e.max_world_m, std::fabs(v - ref3[i][j][k].get<double>()));
        if (i >= 32)
          e.held_out_max_world_m =
              std::max(e.held_out_max_world_m, std::fabs(v - ref3[i][j][k].get<double>()));
      }
    }
  }
  return e;
}

// tfjs-models' video tolerances (expected_from_tests.json): EPSILON_VIDEO pixels, and
// EPSILON_VIDEO_WORLD metres.
std::pair<double, double> video_tolerances() {
  const nlohmann::json eps =
      load_json(test::test_data_path("motion/tfjs-models/expected_from_tests.json"));
  return {eps["pose-detection::EPSILON_VIDEO"].get<double>(),
          eps["pose-detection::EPSILON_VIDEO_WORLD"].get<double>()};
}

TEST(pose_video, squats_vs_mediapipe_reference) {
  if (test::models_dir().empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set";
  if (test::test_data_path("motion/tfjs-models/pose_squats.mp4").empty() ||
      !video_source_available())
    GTEST_SKIP() << "AVATARMAP_TEST_DATA is not set or no FFmpeg";
  const auto [eps_px, eps_world] = video_tolerances();
  const char* names[] = {"velocity filter", "One Euro", "unsmoothed"};
  for (pose_smoothing mode :
       {pose_smoothing::velocity, pose_smoothing::one_euro, pose_smoothing::none}) {
    const video_errors e = run_squats(mode, eps_px);
    ASSERT_EQ(e.frames, 65);
    EXPECT_EQ(e.found, 65) << "the person is in every frame";
    std::vector<double> v = e.point_px;
    std::sort(v.begin(), v.end());
    double mean = 0.0;
    for (double x : v) mean += x;
    mean /= std::max<size_t>(1, v.size());
    const double p95 = v.empty() ? 0.0 : v[v.size() * 95 / 100];
    std::printf(
        "[figures] pose_squats.mp4 %s: mean %.2f px, p95 %.1f px, max coordinate %.1f px, "
        "%d of %d coordinates (%.2f%%) over %.0f px; world max %.3f m\n",
        names[static_cast<int>(mode)], mean, p95, e.max_coord_px, e.coords_over, e.coords,
        100.0 * e.coords_over / std::max(1, e.coords), eps_px, e.max_world_m);
    // tfjs-models asserts every coordinate within EPSILON_VIDEO; we miss it on a handful of
    // fast-moving hand points (docs/capture.md), so this asserts the share, the mean and a
    // bound on the worst; tighter for the default, tfjs's own smoothing.
    EXPECT_LT(mean, 10.0);
    EXPECT_LE(e.coords_over, e.coords / 200) << "at most 0.5% of coordinates over epsilon";
    EXPECT_LT(e.max_coord_px, 2 * eps_px);
    EXPECT_LE(e.max_world_m, eps_world);
    if (mode == pose_smoothing::velocity) {
      EXPECT_LE(e.coords_over, e.coords / 500) << "at most 0.2% of coordinates over epsilon";
      EXPECT_LT(e.max_coord_px, 1.25 * eps_px);
    }
  }
}

// tfjs-models' own video test feeds this 5 fps video to MediaPipe with time stamps 33.3 ms
// apart (its simulatedInterval: a 30 fps clock), and MediaPipe's current pose graph smooths
// with One Euro filters. Under those conditions our pipeline meets the test's own tolerance
// on every coordinate: the misses above come from the clock, not from the models or the crops.
void check_squats_on_the_references_clock(model_precision precision) {
  if (test::models_dir().empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set";
  if (test::test_data_path("motion/tfjs-models/pose_squats.mp4").empty() ||
      !video_source_available())
    GTEST_SKIP() << "AVATARMAP_TEST_DATA is not set or no FFmpeg";
  if (!std::ifstream(test::models_dir() + "/" + model_file_name("pose_landmark_full", precision))
           .good())
    GTEST_SKIP() << "no int8 models (scripts/prepare_capture.sh builds them)";
  const auto [eps_px, eps_world] = video_tolerances();
  const video_errors e = run_squats(pose_smoothing::one_euro, eps_px, 1000.0 / 33.3333, precision);
  ASSERT_EQ(e.frames, 65);
  double mean = 0.0;
  for (double x : e.point_px) mean += x;
  mean /= std::max<size_t>(1, e.point_px.size());
  std::printf(
      "[figures] pose_squats.mp4 %s One Euro on a 30 fps clock: mean %.2f px, max coordinate "
      "%.1f px, %d of %d coordinates over %.0f px; world max %.3f m; frames 32-64: max "
      "coordinate %.1f px, %d over, world max %.3f m\n",
      precision == model_precision::int8 ? "int8" : "float", mean, e.max_coord_px, e.coords_over,
      e.coords, eps_px, e.max_world_m, e.held_out_max_coord_px, e.held_out_coords_over,
      e.held_out_max_world_m);
  EXPECT_EQ(e.coords_over, 0);
  EXPECT_LE(e.max_coord_px, eps_px);
  EXPECT_LE(e.max_world_m, eps_world);
}

TEST(pose_video, squats_on_the_references_clock_meet_every_tolerance) {
  check_squats_on_the_references_clock(model_precision::float32);
}

// The int8 models (docs/capture.md "int8 models") hold the same tolerances.
TEST(pose_video, squats_on_the_references_clock_meet_every_tolerance_int8) {
  check_squats_on_the_references_clock(model_precision::int8);
}

}  // namespace
}  // namespace avatarmap
