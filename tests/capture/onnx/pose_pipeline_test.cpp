// Tests of pose_pipeline.hpp: the whole pipeline on pose.jpg against the landmarks Google's
// MediaPipe WASM pose (model complexity 1) gives for it (the geometry is tested in
// tests/capture/detection_test.cpp).
//
// Real data: $AVATARMAP_TEST_DATA (the shared data folder) and $AVATARMAP_MODELS (the folder of
// converted models: pose_detection.onnx, pose_landmark_full.onnx); tests needing them skip
// without them. Timings are printed, never asserted.
#include "avatarmap/capture/pose_pipeline.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using test::load_image;
using test::loaded_image;
using test::median;
using test::models_dir;

constexpr float k_pi = 3.14159265358979f;

// ---- end to end ----------------------------------------------------------------------------

TEST(pose_pipeline, create_reports_missing_models) {
  pose_pipeline_options o;
  o.models_dir = "/nonexistent";
  std::unique_ptr<pose_pipeline> p;
  status s = pose_pipeline::create(o, p);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("pose_detection.onnx"), std::string::npos) << s.message();
  o.intra_op_threads = 0;
  EXPECT_FALSE(pose_pipeline::create(o, p).ok());
}

// A corrupt model: the message names it, whichever of the two sessions (created side by side
// on two threads) refused it.
TEST(pose_pipeline, create_names_a_corrupt_model) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("avatarmap_pose_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "pose_detection.onnx", std::ios::binary) << "not an onnx model";
  std::ofstream(dir / "pose_landmark_full.onnx", std::ios::binary) << "not one either";
  pose_pipeline_options o;
  o.models_dir = dir.string();
  std::unique_ptr<pose_pipeline> p;
  status s = pose_pipeline::create(o, p);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("pose_detection.onnx"), std::string::npos) << s.message();
  const std::string good = test::models_dir() + "/pose_detection.onnx";
  if (!test::models_dir().empty() && std::ifstream(good).good()) {
    // A good detector and a corrupt landmark model: the message names the latter.
    fs::copy_file(good, dir / "pose_detection.onnx", fs::copy_options::overwrite_existing);
    s = pose_pipeline::create(o, p);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find("pose_landmark_full.onnx"), std::string::npos) << s.message();
  }
  fs::remove_all(dir);
}

// pose.jpg against the golden with the float models or their int8 versions (which must hold
// the same tolerances; docs/capture.md "int8 models").
void check_pose_jpg(model_precision precision) {
  const std::string models = models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  if (!std::ifstream(models + "/" + model_file_name("pose_landmark_full", precision)).good())
    GTEST_SKIP() << "no int8 models (scripts/prepare_capture.sh builds them)";
  loaded_image img;
  ASSERT_TRUE(load_image(test::test_data_path("motion/tfjs-models/pose.jpg"), img));
  std::ifstream gf(test::test_data_path("golden/pose_jpg_full.json"));
  ASSERT_TRUE(gf.good());
  const nlohmann::json golden = nlohmann::json::parse(gf);
  ASSERT_EQ(golden["w"].get<int>(), img.width);
  ASSERT_EQ(golden["h"].get<int>(), img.height);
  std::ifstream ef(test::test_data_path("motion/tfjs-models/expected_from_tests.json"));
  const nlohmann::json tfjs = nlohmann::json::parse(ef);
  const double eps_image = tfjs["pose-detection::EPSILON_IMAGE"].get<double>();        // px
  const double eps_world = tfjs["pose-detection::EPSILON_IMAGE_WORLD"].get<double>();  // m

  pose_pipeline_options o;
  o.models_dir = models;
  o.complexity = pose_model_complexity::full;
  o.precision = precision;
  std::unique_ptr<pose_pipeline> p;
  status s = pose_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();

  landmark_frame f;
  ASSERT_EQ(p->process(img.view(), f), pose_result::found) << p->last_error();
  EXPECT_TRUE(p->last_ran_detector());
  EXPECT_TRUE(f.has(frame_part::pose));
  EXPECT_TRUE(f.has(frame_part::pose_world));
  const normalized_rect roi0 = p->last_roi();
  std::printf(
      "detector roi: centre (%.1f, %.1f) px, size %.1f x %.1f px, rotation %.2f deg; "
      "presence %.4f\n",
      roi0.x_center * img.width, roi0.y_center * img.height, roi0.width * img.width,
      roi0.height * img.height, roi0.rotation * 180 / k_pi, p->last_presence());

  auto compare = [&](const char* label, double& out_mean, double& out_max, double& out_world_max) {
    double sum = 0, mx = 0, wmx = 0, wsum = 0;
    int worst = 0;
    for (int i = 0; i < k_pose_landmark_count; ++i) {
      const auto& g = golden["landmarks_px"][i];
      const double dx = f.pose[i].x * img.width - g[0].get<double>();
      const double dy = f.pose[i].y * img.height - g[1].get<double>();
      const double e = std::hypot(dx, dy);
      sum += e;
      if (e > mx) {
        mx = e;
        worst = i;
      }
      const auto& w = golden["world"][i];
      const double we = std::sqrt(std::pow(f.pose_world[i].x - w[0].get<double>(), 2) +
                                  std::pow(f.pose_world[i].y - w[1].get<double>(), 2) +
                                  std::pow(f.pose_world[i].z - w[2].get<double>(), 2));
      wsum += we;
      wmx = std::max(wmx, we);
    }
    out_mean = sum / k_pose_landmark_count;
    out_max = mx;
    out_world_max = wmx;
    std::printf(
        "%s: image error mean %.2f px, max %.2f px (landmark %d); world error mean "
        "%.4f m, max %.4f m\n",
        label, out_mean, out_max, worst, wsum / k_pose_landmark_count, wmx);
  };
  double mean0, max0, wmax0;
  compare("frame 1 (detector roi)", mean0, max0, wmax0);

  // Second frame: tracked from the auxiliary points of the first, as MediaPipe's video mode
  // would (the golden is a static image; MediaPipe's static mode also runs the landmark
  // model on the detector's region, so frame 1 is the comparable one).
  ASSERT_EQ(p->process(img.view(), f), pose_result::found) << p->last_error();
  EXPECT_FALSE(p->last_ran_detector());
  const normalized_rect roi1 = p->last_roi();
  std::printf("tracked roi:  centre (%.1f, %.1f) px, size %.1f x %.1f px, rotation %.2f deg\n",
              roi1.x_center * img.width, roi1.y_center * img.height, roi1.width * img.width,
              roi1.height * img.height, roi1.rotation * 180 / k_pi);
  double mean1, max1, wmax1;
  compare("frame 2 (tracked roi)", mean1, max1, wmax1);

  // tfjs's own tolerances for this image (EPSILON_IMAGE px, EPSILON_IMAGE_WORLD m) hold with
  // MediaPipe's heatmap refinement; a model converted without its heatmap output loses it
  // (measured: max 15 px on frame 1, mean 4.7 px), so it gets twice the image tolerance.
  const double image_tolerance = p->refines_from_heatmap() ? eps_image : 2 * eps_image;
  std::printf("heatmap refinement: %s; tolerance %.0f px, %.2f m\n",
              p->refines_from_heatmap() ? "yes" : "no (heatmap output dropped)", image_tolerance,
              eps_world);
  EXPECT_LT(max0, image_tolerance);
  EXPECT_LT(wmax0, eps_world);
  EXPECT_LT(max1, image_tolerance);
  EXPECT_LT(wmax1, eps_world);
  EXPECT_LT(mean0, eps_image / 2);
  EXPECT_LT(mean1, eps_image / 2);
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    EXPECT_GE(f.pose[i].visibility, 0.f);
    EXPECT_LE(f.pose[i].visibility, 1.f);
    EXPECT_EQ(f.pose_world[i].visibility, f.pose[i].visibility);
  }
  // The world origin is the hip centre.
  EXPECT_NEAR((f.pose_world[23].x + f.pose_world[24].x) * 0.5f, 0.f, 0.02f);
  EXPECT_NEAR((f.pose_world[23].y + f.pose_world[24].y) * 0.5f, 0.f, 0.02f);
}

TEST(pose_pipeline, pose_jpg_vs_mediapipe_wasm_full) { check_pose_jpg(model_precision::float32); }
TEST(pose_pipeline, pose_jpg_vs_mediapipe_wasm_full_int8) { check_pose_jpg(model_precision::int8); }

TEST(pose_pipeline, latency) {
  const std::string models = models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  loaded_image img;
  ASSERT_TRUE(load_image(test::test_data_path("motion/tfjs-models/pose.jpg"), img));
  for (int threads : {1, 2}) {
    for (pose_model_complexity c :
         {pose_model_complexity::lite, pose_model_complexity::full, pose_model_complexity::heavy}) {
      pose_pipeline_options o;
      o.models_dir = models;
      o.complexity = c;
      o.intra_op_threads = threads;
      o.static_images = true;  // the detector runs on every frame
      std::unique_ptr<pose_pipeline> p;
      if (!pose_pipeline::create(o, p).ok()) continue;  // that complexity is not converted
      landmark_frame f;
      std::vector<double> det, det_inf, lm, lm_inf;
      const int runs = c == pose_model_complexity::heavy ? 10 : 30;
      for (int i = 0; i < runs + 3; ++i) {
        ASSERT_EQ(p->process(img.view(), f), pose_result::found);
        if (i < 3) continue;  // warm-up
        const pose_timings& t = p->last_timings();
        det.push_back(t.detector_ms);
        det_inf.push_back(t.detector_inference_ms);
        lm.push_back(t.landmark_ms);
        lm_inf.push_back(t.landmark_inference_ms);
      }
      static const char* names[] = {"lite", "full", "heavy"};
      std::printf(
          "threads %d, landmark %-5s: detector %.2f ms (inference %.2f), landmark %.2f "
          "ms (inference %.2f); medians of %d\n",
          threads, names[static_cast<int>(c)], median(det), median(det_inf), median(lm),
          median(lm_inf), runs);
    }
  }
}

}  // namespace
}  // namespace avatarmap
