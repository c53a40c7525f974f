// Tests of face_pipeline.hpp end to end (the geometry is tested in
// tests/capture/face_geometry_test.cpp):
//  - portrait.jpg against Google's MediaPipe Face Mesh (WASM, refine_landmarks = 1, static
//    image mode: golden/portrait_facemesh.json, 478 points) and against the face detector
//    keypoints tfjs-models' own tests expect (expected_from_tests.json);
//  - pose_squats.mp4 with the body pipeline's face points as the hint;
//  - bad input; latency (printed, never asserted).
//
// Real data: $AVATARMAP_TEST_DATA (the shared data folder) and $AVATARMAP_MODELS (the folder of
// converted models: face_detection_short_range.onnx, face_landmark.onnx, pose_*.onnx); tests
// needing them skip without them.
#include "avatarmap/capture/face_pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/capture/pose_pipeline.hpp"
#include "avatarmap/media/video_source.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using test::load_image;
using test::loaded_image;
using test::median;
using test::models_dir;

constexpr float k_pi = 3.14159265358979f;

// Contours of MediaPipe's face mesh connection sets (FACEMESH_RIGHT_EYE, FACEMESH_LEFT_EYE,
// FACEMESH_LIPS): the regions the attention model refines.
constexpr int k_right_eye[] = {33,  7,   163, 144, 145, 153, 154, 155,
                               133, 246, 161, 160, 159, 158, 157, 173};
constexpr int k_left_eye[] = {263, 249, 390, 373, 374, 380, 381, 382,
                              362, 466, 388, 387, 386, 385, 384, 398};
constexpr int k_lips[] = {61,  146, 91,  181, 84,  17,  314, 405, 321, 375, 291, 185, 40,  39,
                          37,  0,   267, 269, 270, 409, 78,  95,  88,  178, 87,  14,  317, 402,
                          318, 324, 308, 191, 80,  81,  82,  13,  312, 311, 310, 415};

#define REQUIRE_MODELS_AND_DATA()                                                 \
  do {                                                                            \
    if (models_dir().empty())                                                     \
      GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)"; \
    if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;      \
  } while (0)

struct error_stats {
  double mean = 0, median = 0, p95 = 0, max = 0;
  int worst = -1;
};

error_stats stats_of(const std::vector<double>& e, const std::vector<int>& index) {
  error_stats s;
  if (e.empty()) return s;
  std::vector<double> v = e;
  for (size_t i = 0; i < e.size(); ++i) {
    s.mean += e[i];
    if (e[i] > s.max) {
      s.max = e[i];
      s.worst = index[i];
    }
  }
  s.mean /= static_cast<double>(e.size());
  std::sort(v.begin(), v.end());
  s.median = v[v.size() / 2];
  s.p95 = v[std::min(v.size() - 1, static_cast<size_t>(std::ceil(0.95 * v.size())) - 1)];
  return s;
}

nlohmann::json load_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// ---- bad input -----------------------------------------------------------------------------

TEST(face_pipeline, create_reports_missing_models_and_bad_options) {
  face_pipeline_options o;
  o.models_dir = "/nonexistent";
  std::unique_ptr<face_pipeline> p;
  status s = face_pipeline::create(o, p);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("face_detection_short_range.onnx"), std::string::npos) << s.message();
  EXPECT_EQ(p, nullptr);
  for (int k = 0; k < 4; ++k) {
    face_pipeline_options b;
    b.models_dir = models_dir();
    if (k == 0) b.intra_op_threads = 0;
    if (k == 1) b.min_detection_score = 1.f;
    if (k == 2) b.nms_iou_threshold = 0.f;
    if (k == 3) b.pose_region_scale = -1.f;
    EXPECT_FALSE(face_pipeline::create(b, p).ok()) << k;
  }
}

TEST(face_pipeline, create_names_a_corrupt_model) {
  const std::string models = models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() /
      ("avatarmap_face_corrupt_" +
       std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  fs::create_directories(dir);
  fs::copy_file(models + "/face_detection_short_range.onnx",
                dir / "face_detection_short_range.onnx");
  {
    std::ofstream bad(dir / "face_landmark.onnx", std::ios::binary);
    bad << "this is not an ONNX model";
  }
  face_pipeline_options o;
  o.models_dir = dir.string();
  std::unique_ptr<face_pipeline> p;
  const status s = face_pipeline::create(o, p);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("face_landmark.onnx"), std::string::npos) << s.message();
  std::printf("corrupt model: %s\n", s.message().c_str());
  // A model with the wrong shapes (the detector in the mesh's place) is refused too.
  fs::remove(dir / "face_landmark.onnx");
  fs::copy_file(models + "/face_detection_short_range.onnx", dir / "face_landmark.onnx");
  const status s2 = face_pipeline::create(o, p);
  EXPECT_FALSE(s2.ok());
  EXPECT_NE(s2.message().find("face_landmark.onnx"), std::string::npos) << s2.message();
  std::printf("wrong model: %s\n", s2.message().c_str());
  fs::remove_all(dir);
}

TEST(face_pipeline, empty_black_and_bodiless_images) {
  const std::string models = models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  face_pipeline_options o;
  o.models_dir = models;
  std::unique_ptr<face_pipeline> p;
  status s = face_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  landmark_frame f;
  f.set(frame_part::face, true);  // stale: must be cleared
  f.face_count = 468;
  EXPECT_EQ(p->process(image_view{}, nullptr, f), face_result::error);
  EXPECT_FALSE(p->last_error().empty());
  EXPECT_FALSE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, 0);

  std::vector<unsigned char> black(640 * 480 * 3, 0);
  const image_view img{black.data(), 640, 480, 640 * 3, pixel_format::rgb8};
  EXPECT_EQ(p->process(img, nullptr, f), face_result::not_found);
  EXPECT_TRUE(p->last_ran_detector());
  EXPECT_EQ(p->last_acquisition(), face_acquisition::none);
  EXPECT_FALSE(f.has(frame_part::face));
  EXPECT_FALSE(p->tracking());

  // A body whose face points lie on the black image: the detector searches their region.
  landmark_frame body;
  for (int i = 0; i < k_pose_landmark_count; ++i)
    body.pose[i] = {0.5f + 0.01f * (i % 5), 0.3f + 0.01f * (i % 3), 0.f, 1.f, 1.f};
  body.set(frame_part::pose, true);
  EXPECT_EQ(p->process(img, &body, f), face_result::not_found);
  EXPECT_TRUE(p->last_ran_detector());
  const normalized_rect& sr = p->last_search_region();
  EXPECT_LT(sr.width, 0.5f);  // not the whole image

  // roi_source::pose without a body: nothing to search, nothing run.
  o.roi_source = face_roi_source::pose;
  ASSERT_TRUE(face_pipeline::create(o, p).ok());
  EXPECT_EQ(p->process(img, nullptr, f), face_result::not_found);
  EXPECT_FALSE(p->last_ran_detector());
  // Non-finite face points are treated as no body.
  body.pose[3].x = std::nanf("");
  EXPECT_EQ(p->process(img, &body, f), face_result::not_found);
  EXPECT_FALSE(p->last_ran_detector());
}

// ---- portrait.jpg against Google's face mesh -----------------------------------------------

// portrait.jpg against the golden, float or int8 models (docs/capture.md "int8 models"), with
// the attention model (478 points) or the plain mesh (468).
void check_portrait(model_precision precision, face_mesh_model model) {
  REQUIRE_MODELS_AND_DATA();
  if (!test::has_model("face_landmark", precision))
    GTEST_SKIP() << "no int8 models (scripts/prepare_capture.sh builds them)";
  const bool attention = model == face_mesh_model::attention;
  if (attention && !test::has_model("face_landmark_with_attention", model_precision::float32))
    GTEST_SKIP() << "no face_landmark_with_attention.onnx (scripts/prepare_capture.sh converts it)";
  loaded_image img;
  ASSERT_TRUE(load_image(test::test_data_path("motion/tfjs-models/portrait.jpg"), img));
  const nlohmann::json golden = load_json(test::test_data_path("golden/portrait_facemesh.json"));
  ASSERT_EQ(golden["w"].get<int>(), img.width);
  ASSERT_EQ(golden["h"].get<int>(), img.height);
  const nlohmann::json& g = golden["faces_px"][0];
  ASSERT_EQ(g.size(), 478u);
  const nlohmann::json tfjs =
      load_json(test::test_data_path("motion/tfjs-models/expected_from_tests.json"));
  const double eps_mesh = tfjs["face-landmarks-detection::EPSILON_IMAGE"].get<double>();  // px
  const double eps_det = tfjs["face-detection::EPSILON_IMAGE"].get<double>();             // px

  face_pipeline_options o;
  o.models_dir = models_dir();
  o.roi_source = face_roi_source::detector;
  o.precision = precision;
  o.model = model;
  std::unique_ptr<face_pipeline> p;
  const status s = face_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(p->mesh_model(), model);
  EXPECT_TRUE(p->note().empty()) << p->note();
  const int n = attention ? k_face_mesh_iris_count : k_face_mesh_count;
  EXPECT_EQ(p->mesh_points(), n);
  landmark_frame f;
  ASSERT_EQ(p->process(img.view(), nullptr, f), face_result::found) << p->last_error();
  EXPECT_TRUE(p->last_ran_detector());
  EXPECT_EQ(p->last_acquisition(), face_acquisition::detector_image);
  EXPECT_TRUE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, n);
  EXPECT_GT(p->last_presence(), 0.9f);

  // The detector against tfjs-models' short-range expectations (their EPSILON_IMAGE). Those
  // agree with the CPU converter's sampling (1.6 px); the OpenGL one (the default, which the
  // mesh golden below was made with) moves the keypoints by up to 9 px, inside the 10 px but
  // not by a margin worth asserting: checked with crop_sampling::opencv.
  face_pipeline_options oc = o;
  oc.sampling = crop_sampling::opencv;
  std::unique_ptr<face_pipeline> cpu;
  ASSERT_TRUE(face_pipeline::create(oc, cpu).ok());
  landmark_frame fc;
  ASSERT_EQ(cpu->process(img.view(), nullptr, fc), face_result::found) << cpu->last_error();
  const detection& d = cpu->last_detection();
  const nlohmann::json& kp = tfjs["face-detection::SHORT_RANGE_EXPECTED_FACE_KEY_POINTS"];
  double det_max = 0;
  for (int k = 0; k < 6; ++k) {
    det_max = std::max(det_max, std::fabs(d.keypoints[2 * k] * img.width - kp[k][0].get<double>()));
    det_max =
        std::max(det_max, std::fabs(d.keypoints[2 * k + 1] * img.height - kp[k][1].get<double>()));
  }
  const nlohmann::json& box = tfjs["face-detection::SHORT_RANGE_EXPECTED_BOX"];
  const double box_err =
      std::max({std::fabs(d.xmin * img.width - box["xMin"].get<double>()),
                std::fabs((d.xmin + d.width) * img.width - box["xMax"].get<double>()),
                std::fabs(d.ymin * img.height - box["yMin"].get<double>()),
                std::fabs((d.ymin + d.height) * img.height - box["yMax"].get<double>())});
  std::printf("detector vs tfjs: keypoints max %.2f px, box max %.2f px (EPSILON_IMAGE %.0f)\n",
              det_max, box_err, eps_det);
  EXPECT_LT(det_max, eps_det);
  EXPECT_LT(box_err, eps_det);
  const normalized_rect r = p->last_roi();
  std::printf(
      "roi: centre (%.1f, %.1f) px, size %.1f x %.1f px, rotation %.2f deg; presence %.4f\n",
      r.x_center * img.width, r.y_center * img.height, r.width * img.width, r.height * img.height,
      r.rotation * 180 / k_pi, p->last_presence());

  auto compare = [&](const char* label, const landmark_frame& fr, auto&& indices) {
    std::vector<double> e;
    std::vector<int> idx;
    double sdx = 0, sdy = 0;
    for (int i : indices) {
      sdx += fr.face[i].x * img.width - g[i][0].get<double>();
      sdy += fr.face[i].y * img.height - g[i][1].get<double>();
      e.push_back(std::hypot(fr.face[i].x * img.width - g[i][0].get<double>(),
                             fr.face[i].y * img.height - g[i][1].get<double>()));
      idx.push_back(i);
    }
    const error_stats st = stats_of(e, idx);
    std::printf(
        "%-22s %3zu pts: mean %.2f, median %.2f, p95 %.2f, max %.2f px (point %d); mean "
        "offset (%.2f, %.2f) px\n",
        label, e.size(), st.mean, st.median, st.p95, st.max, st.worst, sdx / e.size(),
        sdy / e.size());
    return st;
  };
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  std::vector<int> irises;
  for (int i = k_face_mesh_count; i < n; ++i) irises.push_back(i);
  std::vector<int> eyes(std::begin(k_right_eye), std::end(k_right_eye));
  eyes.insert(eyes.end(), std::begin(k_left_eye), std::end(k_left_eye));
  const std::vector<int> lips(std::begin(k_lips), std::end(k_lips));
  std::vector<int> rest;
  for (int i = 0; i < k_face_mesh_count; ++i)
    if (std::find(eyes.begin(), eyes.end(), i) == eyes.end() &&
        std::find(lips.begin(), lips.end(), i) == lips.end())
      rest.push_back(i);
  // Face size for scale: outer eye corners and forehead-chin in the golden.
  const double eye_span = std::hypot(g[263][0].get<double>() - g[33][0].get<double>(),
                                     g[263][1].get<double>() - g[33][1].get<double>());
  const double face_h = std::hypot(g[152][0].get<double>() - g[10][0].get<double>(),
                                   g[152][1].get<double>() - g[10][1].get<double>());
  std::printf("golden face: eye corners %.1f px apart, forehead-chin %.1f px\n", eye_span, face_h);
  std::printf("model: %s\n", attention ? "face_landmark_with_attention" : "face_landmark");
  const error_stats st_all = compare(attention ? "frame 1, all 478" : "frame 1, all 468", f, all);
  const error_stats st_eyes = compare("frame 1, eye contours", f, eyes);
  const error_stats st_lips = compare("frame 1, lips", f, lips);
  const error_stats st_rest = compare("frame 1, other points", f, rest);
  const error_stats st_iris = attention ? compare("frame 1, irises", f, irises) : error_stats{};

  // Frame 2 is tracked from frame 1's mesh (MediaPipe's video mode would do the same).
  landmark_frame f2;
  ASSERT_EQ(p->process(img.view(), nullptr, f2), face_result::found);
  EXPECT_FALSE(p->last_ran_detector());
  EXPECT_EQ(p->last_acquisition(), face_acquisition::tracked);
  const error_stats st_tracked = compare("frame 2 (tracked), all", f2, all);

  if (attention) {
    // The same network as the golden's (MediaPipe Face Mesh with refine_landmarks, static image
    // mode: the detector's region): tfjs-models assert every keypoint of that model within
    // EPSILON_IMAGE (5 px) of what it gave. So do we, for all 478 points, irises included.
    // Measured (ORT 1.29, x86-64): max 0.30 px, mean 0.07 px -- the same network on the same
    // crop; the mean bound (10% of the epsilon) catches a wrong crop or refinement that the max
    // would let through. Frame 2 runs on the region tracked from frame 1's mesh, which the
    // golden (static images) never used: measured max 5.3 px, mean 1.3 px; bounds as the 468-point
    // model's tracked frame below.
    EXPECT_LT(st_all.max, eps_mesh);
    EXPECT_LT(st_iris.max, eps_mesh);
    EXPECT_LT(st_all.mean, 0.1 * eps_mesh);
    EXPECT_LT(st_iris.mean, 0.1 * eps_mesh);
    EXPECT_LT(st_tracked.mean, eps_mesh);
    EXPECT_LT(st_tracked.p95, 1.5 * eps_mesh);
    EXPECT_LT(st_tracked.max, 2 * eps_mesh);
    // Irises in their eyes: each centre inside the box of its eye's contour, the right eye's
    // (mesh point 33 side) at 468, the left's at 473; depth = the contour's mean depth.
    for (const auto& [first, contour] : {std::pair<int, const int*>{468, k_right_eye},
                                         std::pair<int, const int*>{473, k_left_eye}}) {
      float x0 = 1, x1 = 0, y0 = 1, y1 = 0, z = 0;
      for (int k = 0; k < 16; ++k) {
        const landmark& q = f.face[contour[k]];
        x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y);
        y1 = std::max(y1, q.y), z += q.z / 16;
      }
      for (int k = 0; k < 5; ++k) EXPECT_NEAR(f.face[first + k].z, z, 1e-6f);
      EXPECT_GT(f.face[first].x, x0);
      EXPECT_LT(f.face[first].x, x1);
      EXPECT_GT(f.face[first].y, y0);
      EXPECT_LT(f.face[first].y, y1);
    }
  } else {
    // Tolerance. tfjs-models assert their attention-model keypoints within EPSILON_IMAGE (5 px)
    // of what that same model gave. Ours come from the non-attention mesh, a different network,
    // measured against the attention model's points on a face about 200 x 250 px (eye corners
    // ~120 px apart). Measured (ORT 1.30, x86-64): mean 3.2 px with a common offset of about
    // (2.0, 1.6) px over the non-refined points, while the eye contours the attention model
    // refines agree to 1.2 px -- the crop geometry matches; the offset is the networks'. Bounds:
    // the epsilon for the typical point (mean, median, and each refined region's mean), 1.5x for
    // the 95th percentile, 2x (8% of the eye span) for the worst point; the eyes at half of it.
    EXPECT_LT(st_all.mean, eps_mesh);
    EXPECT_LT(st_all.median, eps_mesh);
    EXPECT_LT(st_all.p95, 1.5 * eps_mesh);
    EXPECT_LT(st_all.max, 2 * eps_mesh);
    EXPECT_LT(st_rest.mean, eps_mesh);
    EXPECT_LT(st_eyes.mean, 0.5 * eps_mesh);
    EXPECT_LT(st_eyes.max, eps_mesh);
    EXPECT_LT(st_lips.mean, eps_mesh);
    EXPECT_LT(st_tracked.mean, eps_mesh);
    EXPECT_LT(st_tracked.p95, 1.5 * eps_mesh);
    EXPECT_LT(st_tracked.max, 2 * eps_mesh);
  }
  // z: same scale as x (image widths), the nose tip in front of the ears.
  EXPECT_LT(f.face[1].z, f.face[234].z);
  EXPECT_LT(f.face[1].z, f.face[454].z);
}

TEST(face_pipeline, portrait_vs_mediapipe_face_mesh) {
  check_portrait(model_precision::float32, face_mesh_model::attention);
}
TEST(face_pipeline, portrait_vs_mediapipe_face_mesh_int8) {
  check_portrait(model_precision::int8, face_mesh_model::attention);
}
TEST(face_pipeline, portrait_vs_mediapipe_face_mesh_468) {
  check_portrait(model_precision::float32, face_mesh_model::mesh);
}
TEST(face_pipeline, portrait_vs_mediapipe_face_mesh_468_int8) {
  check_portrait(model_precision::int8, face_mesh_model::mesh);
}

// A models folder without the attention model: the 468-point mesh, with a one-line note.
TEST(face_pipeline, falls_back_to_468_without_the_attention_model) {
  REQUIRE_MODELS_AND_DATA();
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "avatarmap_face_fallback";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* name : {"face_detection_short_range.onnx", "face_landmark.onnx"})
    fs::copy_file(fs::path(models_dir()) / name, dir / name);
  face_pipeline_options o;
  o.models_dir = dir.string();
  o.roi_source = face_roi_source::detector;
  std::unique_ptr<face_pipeline> p;
  const status s = face_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(p->mesh_model(), face_mesh_model::mesh);
  EXPECT_EQ(p->mesh_points(), k_face_mesh_count);
  EXPECT_NE(p->note().find("face_landmark_with_attention"), std::string::npos) << p->note();
  EXPECT_EQ(p->note().find('\n'), std::string::npos);
  loaded_image img;
  ASSERT_TRUE(load_image(test::test_data_path("motion/tfjs-models/portrait.jpg"), img));
  landmark_frame f;
  ASSERT_EQ(p->process(img.view(), nullptr, f), face_result::found) << p->last_error();
  EXPECT_EQ(f.face_count, k_face_mesh_count);
  // Neither model at all is still an error naming the file, never a crash.
  fs::remove(dir / "face_landmark.onnx");
  const status s2 = face_pipeline::create(o, p);
  EXPECT_FALSE(s2.ok());
  EXPECT_NE(s2.message().find("face_landmark.onnx"), std::string::npos) << s2.message();
  fs::remove_all(dir);
}

// ---- video with the body's face points as the hint -----------------------------------------

struct video_run {
  int frames = 0, found = 0, detector_runs = 0, region_runs = 0;
  // Per frame with a face: the larger of the two eyes' distances between the mesh's eye
  // centre (mean of its corners) and an eye point of a body model, in pixels and as a
  // fraction of that body model's eye distance. "ref": Google's BlazePose landmarks for the
  // video (tfjs-models' pose_squats.full.json); "ours": our pose pipeline's.
  std::vector<double> ref_px, ref_rel, ours_px, ours_rel;
  std::vector<double> face_ms;
};

double p95(std::vector<double> v) {
  if (v.empty()) return 1e9;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(std::ceil(0.95 * v.size())) - 1)];
}

// Eye error of the mesh in `f` against eye points r (right) and l (left), pixels.
void eye_error(const landmark_frame& f, int w, int h, const double r[2], const double l[2],
               std::vector<double>& out_px, std::vector<double>& out_rel) {
  const double mr[2] = {(f.face[33].x + f.face[133].x) * 0.5 * w,
                        (f.face[33].y + f.face[133].y) * 0.5 * h};
  const double ml[2] = {(f.face[263].x + f.face[362].x) * 0.5 * w,
                        (f.face[263].y + f.face[362].y) * 0.5 * h};
  const double span = std::hypot(l[0] - r[0], l[1] - r[1]);
  const double e =
      std::max(std::hypot(mr[0] - r[0], mr[1] - r[1]), std::hypot(ml[0] - l[0], ml[1] - l[1]));
  out_px.push_back(e);
  out_rel.push_back(e / std::max(span, 1.0));
}

video_run run_squats(face_roi_source source, bool follow_body_motion) {
  video_run v;
  const std::string dir = test::test_data_path("motion/tfjs-models");
  const nlohmann::json ref = load_json(dir + "/pose_squats.full.json");
  pose_pipeline_options po;
  po.models_dir = models_dir();
  std::unique_ptr<pose_pipeline> pose;
  status s = pose_pipeline::create(po, pose);
  EXPECT_TRUE(s.ok()) << s.message();
  face_pipeline_options fo;
  fo.models_dir = models_dir();
  fo.roi_source = source;
  fo.follow_body_motion = follow_body_motion;
  std::unique_ptr<face_pipeline> face;
  s = face_pipeline::create(fo, face);
  EXPECT_TRUE(s.ok()) << s.message();
  if (!pose || !face) return v;
  video_source src;
  EXPECT_TRUE(src.open(dir + "/pose_squats.mp4").ok());
  image_view img;
  double t = 0.0;
  landmark_frame f;
  while (src.next(img, t) == read_result::frame) {
    const size_t i = static_cast<size_t>(v.frames++);
    f.clear();
    const bool has_body = pose->process(img, f) == pose_result::found;
    if (face->process(img, has_body ? &f : nullptr, f) == face_result::found) ++v.found;
    const face_timings& ft = face->last_timings();
    v.face_ms.push_back(ft.detector_ms + ft.mesh_ms);
    if (face->last_ran_detector()) ++v.detector_runs;
    if (face->last_acquisition() == face_acquisition::detector_region) ++v.region_runs;
    if (!f.has(frame_part::face)) continue;
    if (i < ref.size()) {
      const double r[2] = {ref[i][5][0].get<double>(), ref[i][5][1].get<double>()};
      const double l[2] = {ref[i][2][0].get<double>(), ref[i][2][1].get<double>()};
      eye_error(f, img.width, img.height, r, l, v.ref_px, v.ref_rel);
    }
    if (has_body) {
      const double r[2] = {f.pose[5].x * img.width, f.pose[5].y * img.height};
      const double l[2] = {f.pose[2].x * img.width, f.pose[2].y * img.height};
      eye_error(f, img.width, img.height, r, l, v.ours_px, v.ours_rel);
    }
  }
  return v;
}

void print_run(const char* label, const video_run& v) {
  if (v.found == 0) {
    std::printf("squats, %s: face in 0 of %d frames; detector ran %d times\n", label, v.frames,
                v.detector_runs);
    return;
  }
  std::printf(
      "squats, %s: face in %d of %d frames (%.1f%%); detector ran %d times (%d in the body's "
      "region); face stage median %.2f ms\n"
      "  mesh eye centres vs Google's pose eyes: median %.2f px, p95 %.2f px; median %.3f, p95 "
      "%.3f of the eye distance\n"
      "  mesh eye centres vs our pose eyes:      median %.2f px, p95 %.2f px; median %.3f, p95 "
      "%.3f of the eye distance\n",
      label, v.found, v.frames, 100.0 * v.found / std::max(v.frames, 1), v.detector_runs,
      v.region_runs, median(v.face_ms), median(v.ref_px), p95(v.ref_px), median(v.ref_rel),
      p95(v.ref_rel), median(v.ours_px), p95(v.ours_px), median(v.ours_rel), p95(v.ours_rel));
}

TEST(face_pipeline, squats_video_with_body_hint) {
  REQUIRE_MODELS_AND_DATA();
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg";
  const video_run a = run_squats(face_roi_source::automatic, true);
  ASSERT_GT(a.frames, 0);
  print_run("roi from the body, following its motion", a);
  EXPECT_GT(static_cast<double>(a.found) / a.frames, 0.9);
  // Tracking: the detector runs to acquire only.
  EXPECT_LT(a.detector_runs, a.frames / 4);
  EXPECT_EQ(a.detector_runs, a.region_runs);
  // Two independent networks (BlazePose's eye points vs the mesh's eye corners) must agree
  // on where the eyes are. The face is small (eyes ~25 px apart, each ~10 px wide) and the
  // head moves up to ~50 px between frames. Against our own pose (same decoded frames, no
  // smoothing): a quarter of the eye distance typically, 3/4 of it for the 95th percentile
  // (measured 0.20 and 0.54). Google's reference was recorded with its smoothing filter on,
  // which lags on the fast rises (up to ~25 px behind both of our models): it gets tfjs's own
  // video tolerance for this clip, EPSILON_VIDEO, for every frame.
  EXPECT_LT(median(a.ours_rel), 0.25);
  EXPECT_LT(p95(a.ours_rel), 0.75);
  const nlohmann::json tfjs =
      load_json(test::test_data_path("motion/tfjs-models/expected_from_tests.json"));
  const double eps_video = tfjs["pose-detection::EPSILON_VIDEO"].get<double>();
  const double ref_max = *std::max_element(a.ref_px.begin(), a.ref_px.end());
  std::printf("  largest distance to Google's pose eyes %.2f px (EPSILON_VIDEO %.0f px)\n", ref_max,
              eps_video);
  EXPECT_LT(ref_max, eps_video);

  // For the record: MediaPipe's plain tracking (no body motion), and the whole-image
  // short-range detector (faces within ~2 m; this one is small in a full-body frame).
  print_run("roi from the body, plain tracking", run_squats(face_roi_source::automatic, false));
  print_run("whole-image detector only", run_squats(face_roi_source::detector, true));
}

// ---- latency (printed, never asserted) ------------------------------------------------------

// Per-frame cost of the face stage with each mesh model (printed for docs/capture-face.md,
// never asserted): detector + mesh on every frame, then tracking frames (mesh only), the two
// models' frames interleaved so that both see the same machine load.
TEST(face_pipeline, latency) {
  REQUIRE_MODELS_AND_DATA();
  loaded_image img;
  ASSERT_TRUE(load_image(test::test_data_path("motion/tfjs-models/portrait.jpg"), img));
  const face_mesh_model models[] = {face_mesh_model::mesh, face_mesh_model::attention};
  for (int threads : {1, 2}) {
    std::unique_ptr<face_pipeline> still[2], tracked[2];
    for (int k = 0; k < 2; ++k) {
      face_pipeline_options o;
      o.models_dir = models_dir();
      o.roi_source = face_roi_source::detector;
      o.intra_op_threads = threads;
      o.model = models[k];
      o.static_images = true;  // detector + mesh on every frame
      ASSERT_TRUE(face_pipeline::create(o, still[k]).ok());
      o.static_images = false;  // the whole process() call per frame, the detector not running
      ASSERT_TRUE(face_pipeline::create(o, tracked[k]).ok());
    }
    std::vector<double> det[2], det_inf[2], mesh[2], mesh_inf[2], track[2];
    const int runs = 40;
    landmark_frame f;
    for (int i = 0; i < runs + 3; ++i) {
      for (int k = 0; k < 2; ++k) {
        ASSERT_EQ(still[k]->process(img.view(), nullptr, f), face_result::found);
        const auto t0 = std::chrono::steady_clock::now();
        ASSERT_EQ(tracked[k]->process(img.view(), nullptr, f), face_result::found);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        if (i < 3) continue;
        const face_timings& t = still[k]->last_timings();
        det[k].push_back(t.detector_ms);
        det_inf[k].push_back(t.detector_inference_ms);
        mesh[k].push_back(t.mesh_ms);
        mesh_inf[k].push_back(t.mesh_inference_ms);
        EXPECT_FALSE(tracked[k]->last_ran_detector());
        track[k].push_back(ms);
      }
    }
    for (int k = 0; k < 2; ++k)
      std::printf(
          "threads %d, %s (%d points): detector %.2f ms (inference %.2f), mesh %.2f ms "
          "(inference %.2f), tracking frame %.2f ms; medians of %d\n",
          threads, k ? "attention" : "mesh", still[k]->mesh_points(), median(det[k]),
          median(det_inf[k]), median(mesh[k]), median(mesh_inf[k]), median(track[k]), runs);
  }
}

}  // namespace
}  // namespace avatarmap
