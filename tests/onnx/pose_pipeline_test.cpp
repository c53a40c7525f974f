// Tests of pose_pipeline.hpp: SSD anchors against MediaPipe's golden anchor files, weighted
// NMS and region-of-interest known answers, and the whole pipeline on pose.jpg against the
// landmarks Google's MediaPipe WASM pose (model complexity 1) gives for it.
//
// Real data: $AVATARMAP_TEST_DATA (the shared data folder) and $AVATARMAP_MODELS (the folder of
// converted models: pose_detection.onnx, pose_landmark_full.onnx); tests needing them skip
// without them. Timings are printed, never asserted.
#define STB_IMAGE_IMPLEMENTATION
#include "avatarmap/capture/pose_pipeline.hpp"

#include <gtest/gtest.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979f;

// ---- anchors -------------------------------------------------------------------------------

// [[x_center, y_center, width, height], ...] from MediaPipe's ssd_anchors_calculator_test.
bool load_golden_anchors(const std::string& name, std::vector<ssd_anchor>& out) {
  const std::string path = test::test_data_path("motion/tfjs-models/" + name);
  std::ifstream f(path);
  if (path.empty() || !f) return false;
  nlohmann::json j = nlohmann::json::parse(f);
  out.clear();
  for (const auto& a : j)
    out.push_back({a[0].get<float>(), a[1].get<float>(), a[2].get<float>(), a[3].get<float>()});
  return true;
}

void expect_anchors_near(const std::vector<ssd_anchor>& got, const std::vector<ssd_anchor>& want) {
  ASSERT_EQ(got.size(), want.size());
  int bad = 0;
  for (size_t i = 0; i < got.size() && bad < 5; ++i) {
    const bool ok = std::fabs(got[i].x_center - want[i].x_center) < 1e-5f &&
                    std::fabs(got[i].y_center - want[i].y_center) < 1e-5f &&
                    std::fabs(got[i].width - want[i].width) < 1e-5f &&
                    std::fabs(got[i].height - want[i].height) < 1e-5f;
    if (!ok) {
      ++bad;
      ADD_FAILURE() << "anchor " << i << ": got " << got[i].x_center << " " << got[i].y_center
                    << " " << got[i].width << " " << got[i].height << ", want " << want[i].x_center
                    << " " << want[i].y_center << " " << want[i].width << " " << want[i].height;
    }
  }
}

TEST(ssd_anchors, pose_detection_count_and_corners) {
  std::vector<ssd_anchor> a;
  ASSERT_TRUE(generate_ssd_anchors(pose_detection_anchor_options(), a));
  // 28x28x2 + 14x14x2 + 7x7x6.
  ASSERT_EQ(a.size(), 2254u);
  EXPECT_FLOAT_EQ(a[0].x_center, 0.5f / 28);
  EXPECT_FLOAT_EQ(a[1].x_center, 0.5f / 28);  // two anchors per cell
  EXPECT_FLOAT_EQ(a[2].x_center, 1.5f / 28);
  EXPECT_FLOAT_EQ(a.back().x_center, 6.5f / 7);
  EXPECT_FLOAT_EQ(a.back().y_center, 6.5f / 7);
  EXPECT_FLOAT_EQ(a.back().width, 1.f);
}

// MediaPipe's "FaceDetectionConfig" test: 256x256, strides 8,16,32,32,32, fixed anchor size.
TEST(ssd_anchors, golden_file_0) {
  std::vector<ssd_anchor> want;
  if (!load_golden_anchors("anchor_golden_file_0.json", want)) GTEST_SKIP() << test::k_no_test_data;
  ssd_anchor_options o;
  o.num_layers = 5;
  o.min_scale = 0.1171875f;
  o.max_scale = 0.75f;
  o.input_width = o.input_height = 256;
  o.strides = {8, 16, 32, 32, 32};
  o.aspect_ratios = {1.0f};
  o.fixed_anchor_size = true;
  std::vector<ssd_anchor> got;
  ASSERT_TRUE(generate_ssd_anchors(o, got));
  expect_anchors_near(got, want);
}

// MediaPipe's "MobileSSDConfig" test: 300x300, six layers, five aspect ratios, reduced lowest
// layer, interpolated scales, sized anchors.
TEST(ssd_anchors, golden_file_1) {
  std::vector<ssd_anchor> want;
  if (!load_golden_anchors("anchor_golden_file_1.json", want)) GTEST_SKIP() << test::k_no_test_data;
  ssd_anchor_options o;
  o.num_layers = 6;
  o.min_scale = 0.2f;
  o.max_scale = 0.95f;
  o.input_width = o.input_height = 300;
  o.strides = {16, 32, 64, 128, 256, 512};
  o.aspect_ratios = {1.0f, 2.0f, 0.5f, 3.0f, 0.3333f};
  o.reduce_boxes_in_lowest_layer = true;
  o.fixed_anchor_size = false;
  std::vector<ssd_anchor> got;
  ASSERT_TRUE(generate_ssd_anchors(o, got));
  expect_anchors_near(got, want);
}

TEST(ssd_anchors, rejects_bad_options) {
  std::vector<ssd_anchor> a;
  ssd_anchor_options o;
  o.strides = {8, 16};
  EXPECT_FALSE(generate_ssd_anchors(o, a));
  EXPECT_TRUE(a.empty());
  o = ssd_anchor_options{};
  o.aspect_ratios.clear();
  EXPECT_FALSE(generate_ssd_anchors(o, a));
  o = ssd_anchor_options{};
  o.input_width = 0;
  EXPECT_FALSE(generate_ssd_anchors(o, a));
}

// ---- decoding and NMS ----------------------------------------------------------------------

TEST(decode_detections, known_answer) {
  detection_decode_options o;
  o.num_boxes = 2;
  ssd_anchor anchors[2] = {{0.25f, 0.5f, 1.f, 1.f}, {0.75f, 0.5f, 1.f, 1.f}};
  float boxes[24] = {};
  // Box 0: centre offset (22.4, -44.8) px of 224, size 112 x 56, keypoint 0 at +(0, 22.4).
  boxes[0] = 22.4f;
  boxes[1] = -44.8f;
  boxes[2] = 112.f;
  boxes[3] = 56.f;
  boxes[4] = 0.f;
  boxes[5] = 22.4f;
  float scores[2] = {2.f, -2.f};  // sigmoid: 0.881, 0.119 (dropped)
  std::vector<detection> out;
  ASSERT_EQ(decode_detections(boxes, scores, anchors, o, out), 1);
  const detection& d = out[0];
  EXPECT_NEAR(d.score, 1.f / (1.f + std::exp(-2.f)), 1e-6f);
  EXPECT_NEAR(d.xmin, 0.35f - 0.25f, 1e-6f);
  EXPECT_NEAR(d.ymin, 0.3f - 0.125f, 1e-6f);
  EXPECT_NEAR(d.width, 0.5f, 1e-6f);
  EXPECT_NEAR(d.height, 0.25f, 1e-6f);
  EXPECT_EQ(d.keypoint_count, 4);
  EXPECT_NEAR(d.keypoints[0], 0.25f, 1e-6f);
  EXPECT_NEAR(d.keypoints[1], 0.6f, 1e-6f);
  // Score clipping: a huge logit is clipped to 100 before the sigmoid, never NaN.
  scores[1] = 1e30f;
  ASSERT_EQ(decode_detections(boxes, scores, anchors, o, out), 2);
  EXPECT_EQ(out[1].score, 1.f);
}

detection box(float score, float x, float y, float w, float h, float kx, float ky) {
  detection d;
  d.score = score;
  d.xmin = x;
  d.ymin = y;
  d.width = w;
  d.height = h;
  d.keypoint_count = 1;
  d.keypoints[0] = kx;
  d.keypoints[1] = ky;
  return d;
}

TEST(weighted_nms, iou_known_answers) {
  const detection a = box(1, 0, 0, 2, 2, 0, 0);
  EXPECT_FLOAT_EQ(detection_iou(a, box(1, 1, 1, 2, 2, 0, 0)), 1.f / 7.f);
  EXPECT_FLOAT_EQ(detection_iou(a, box(1, 2, 0, 2, 2, 0, 0)), 0.f);  // touching
  EXPECT_FLOAT_EQ(detection_iou(a, a), 1.f);
}

TEST(weighted_nms, averages_overlapping_group_by_score) {
  std::vector<detection> in = {
      box(0.6f, 0.1f, 0.1f, 0.4f, 0.4f, 0.3f, 0.3f),      // overlaps the best (IoU 0.6)
      box(0.9f, 0.0f, 0.0f, 0.5f, 0.5f, 0.2f, 0.2f),      // best
      box(0.8f, 0.6f, 0.6f, 0.3f, 0.3f, 0.7f, 0.7f),      // separate
      box(0.55f, 0.4f, 0.4f, 0.1f, 0.1f, 0.45f, 0.45f)};  // IoU 0.04 with the best: kept
  std::vector<detection> out;
  std::vector<int> scratch;
  ASSERT_EQ(weighted_non_max_suppression(in, 0.3f, 0, out, scratch), 3);
  // Group {0.9, 0.6}: total 1.5.
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  EXPECT_NEAR(out[0].xmin, (0.9f * 0.f + 0.6f * 0.1f) / 1.5f, 1e-6f);
  EXPECT_NEAR(out[0].xmin + out[0].width, (0.9f * 0.5f + 0.6f * 0.5f) / 1.5f, 1e-6f);
  EXPECT_NEAR(out[0].keypoints[0], (0.9f * 0.2f + 0.6f * 0.3f) / 1.5f, 1e-6f);
  EXPECT_FLOAT_EQ(out[1].score, 0.8f);
  EXPECT_FLOAT_EQ(out[1].xmin, 0.6f);
  EXPECT_FLOAT_EQ(out[2].score, 0.55f);
  EXPECT_FLOAT_EQ(out[2].keypoints[0], 0.45f);
  // A limit keeps the best only.
  ASSERT_EQ(weighted_non_max_suppression(in, 0.3f, 1, out, scratch), 1);
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  // Empty in, empty out.
  ASSERT_EQ(weighted_non_max_suppression({}, 0.3f, 0, out, scratch), 0);
}

// ---- regions of interest -------------------------------------------------------------------

TEST(roi, upright_body_on_square_image) {
  // Hip centre (0.5, 0.6), scale point straight above at distance 0.2: side 0.4 * 1.25.
  const normalized_rect r = roi_from_alignment_points(0.5f, 0.6f, 0.5f, 0.4f, 100, 100);
  EXPECT_FLOAT_EQ(r.x_center, 0.5f);
  EXPECT_FLOAT_EQ(r.y_center, 0.6f);
  EXPECT_NEAR(r.width, 0.5f, 1e-6f);
  EXPECT_NEAR(r.height, 0.5f, 1e-6f);
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
}

TEST(roi, rotation_and_square_long_on_wide_image) {
  // 200 x 100 image; the scale point 20 px to the right of the centre: the body lies on its
  // side, head to the right, so the region turns by +90 degrees (clockwise on screen).
  const normalized_rect r = roi_from_alignment_points(0.5f, 0.5f, 0.6f, 0.5f, 200, 100);
  EXPECT_NEAR(r.rotation, k_pi / 2, 1e-6f);  // 90 - atan2(0, +x) = +90 degrees
  // 40 px square -> 50 px after scaling: 0.25 of the width, 0.5 of the height.
  EXPECT_NEAR(r.width, 0.25f, 1e-6f);
  EXPECT_NEAR(r.height, 0.5f, 1e-6f);
  // Scale point below the centre (head down): 180 degrees, normalised into [-pi, pi).
  const normalized_rect d = roi_from_alignment_points(0.5f, 0.5f, 0.5f, 0.7f, 200, 100);
  EXPECT_NEAR(std::fabs(d.rotation), k_pi, 1e-5f);
  // Up and to the left at 45 degrees: rotation -45 degrees.
  const normalized_rect l = roi_from_alignment_points(0.5f, 0.5f, 0.45f, 0.4f, 200, 100);
  EXPECT_NEAR(l.rotation, -k_pi / 4, 1e-6f);
}

TEST(roi, normalize_radians_range) {
  EXPECT_NEAR(normalize_radians(3 * k_pi / 2), -k_pi / 2, 1e-6f);
  EXPECT_NEAR(normalize_radians(-3 * k_pi / 2), k_pi / 2, 1e-6f);
  EXPECT_NEAR(normalize_radians(0.5f), 0.5f, 1e-7f);
}

TEST(roi, detection_uses_keypoints_0_and_1) {
  detection d;
  d.keypoint_count = 4;
  d.keypoints = {0.5f, 0.6f, 0.5f, 0.4f, 0.f, 0.f, 0.f, 0.f};
  const normalized_rect r = pose_detection_to_roi(d, 100, 100);
  EXPECT_NEAR(r.width, 0.5f, 1e-6f);
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
}

// ---- end to end ----------------------------------------------------------------------------

// $AVATARMAP_MODELS is the model cache (scripts/prepare_capture.sh puts the ONNX conversions
// in its onnx/ folder) or directly a folder of .onnx files.
std::string models_dir() {
  const char* m = std::getenv("AVATARMAP_MODELS");
  if (m == nullptr || *m == '\0') return "";
  const std::string sub = std::string(m) + "/onnx";
  if (std::ifstream(sub + "/pose_detection.onnx").good()) return sub;
  return m;
}

struct loaded_image {
  std::vector<unsigned char> pixels;
  int width = 0, height = 0;
  image_view view() const { return {pixels.data(), width, height, width * 3, pixel_format::rgb8}; }
};

bool load_image(const std::string& path, loaded_image& out) {
  int c = 0;
  unsigned char* p = stbi_load(path.c_str(), &out.width, &out.height, &c, 3);
  if (!p) return false;
  out.pixels.assign(p, p + static_cast<size_t>(out.width) * out.height * 3);
  stbi_image_free(p);
  return true;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

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

TEST(pose_pipeline, pose_jpg_vs_mediapipe_wasm_full) {
  const std::string models = models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
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
