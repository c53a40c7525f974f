// Upper-body / webcam-like framings (motion/upper_body/*.png: the body's region runs past the
// image's edges) against Google's MediaPipe web solutions in static-image mode
// (golden/upper_body_<image>_<pose|hands|face>.json; see the data README). Each part runs
// the graph its golden was made with: pose (full), Hands (palm detector, full, 2 hands), Face
// Mesh (whole-image face detector); then the whole capture (the "onnx" estimator: hands and
// face from the body, as Holistic) on the same images. Tolerances are tfjs-models' own
// (expected_from_tests.json), as in the single-image tests of each pipeline.
//
// Real data: $AVATARMAP_TEST_DATA and $AVATARMAP_MODELS; skipped without them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/pose_pipeline.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using test::load_image;
using test::loaded_image;
using test::models_dir;

#define UPPER_SKIP_WITHOUT_DATA()                                                            \
  do {                                                                                       \
    if (models_dir().empty())                                                                \
      GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";            \
    if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;                 \
    if (!std::ifstream(test::test_data_path("golden/upper_body_portrait_pose.json")).good()) \
      GTEST_SKIP() << "golden/upper_body_* is not in $AVATARMAP_TEST_DATA";                  \
  } while (0)

nlohmann::json load_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

const char* const k_images[] = {"pose_upper55", "pose_upper40", "portrait", "squats_upper"};

bool load_upper(const std::string& name, loaded_image& img) {
  return load_image(test::test_data_path("motion/upper_body/" + name + ".png"), img);
}

std::string golden_path(const std::string& name, const char* part) {
  return test::test_data_path("golden/upper_body_" + name + "_" + part + ".json");
}

struct tolerances {
  double pose_px, pose_world_m, hand_px, hand_world_m, face_px;
};

tolerances load_tolerances() {
  const nlohmann::json e =
      load_json(test::test_data_path("motion/tfjs-models/expected_from_tests.json"));
  return {e["pose-detection::EPSILON_IMAGE"].get<double>(),
          e["pose-detection::EPSILON_IMAGE_WORLD"].get<double>(),
          e["hand-pose-detection::EPSILON_IMAGE"].get<double>(),
          e["hand-pose-detection::EPSILON_VIDEO_WORLD"].get<double>(),
          e["face-landmarks-detection::EPSILON_IMAGE"].get<double>()};
}

// ---- pose ------------------------------------------------------------------------------------

// Errors of the 33 pose points against a golden, split by where the golden point lies: inside
// the image or outside it (legs cut off by the frame, low visibility).
struct pose_errors {
  int in_count = 0;
  double in_mean = 0, in_max = 0;
  double out_mean = 0, out_max = 0;
  double world_max = 0;  // per point, 3D distance, all 33
  double visibility_max = 0;
};

pose_errors compare_pose(const landmark_frame& f, const nlohmann::json& g, int w, int h) {
  pose_errors e;
  int out_count = 0;
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    const auto& p = g["landmarks_px"][i];
    const auto& q = g["world"][i];
    const double gx = p[0].get<double>(), gy = p[1].get<double>();
    const double d = std::hypot(f.pose[i].x * w - gx, f.pose[i].y * h - gy);
    if (gx >= 0 && gx <= w && gy >= 0 && gy <= h) {
      ++e.in_count;
      e.in_mean += d;
      e.in_max = std::max(e.in_max, d);
    } else {
      ++out_count;
      e.out_mean += d;
      e.out_max = std::max(e.out_max, d);
    }
    e.world_max =
        std::max(e.world_max, std::sqrt(std::pow(f.pose_world[i].x - q[0].get<double>(), 2) +
                                        std::pow(f.pose_world[i].y - q[1].get<double>(), 2) +
                                        std::pow(f.pose_world[i].z - q[2].get<double>(), 2)));
    e.visibility_max =
        std::max(e.visibility_max, std::fabs(f.pose[i].visibility - p[3].get<double>()));
  }
  if (e.in_count > 0) e.in_mean /= e.in_count;
  if (out_count > 0) e.out_mean /= out_count;
  return e;
}

std::unique_ptr<pose_pipeline> make_pose(crop_sampling sampling) {
  pose_pipeline_options o;
  o.models_dir = models_dir();
  o.complexity = pose_model_complexity::full;
  o.static_images = true;
  o.sampling = sampling;
  std::unique_ptr<pose_pipeline> p;
  const status s = pose_pipeline::create(o, p);
  EXPECT_TRUE(s.ok()) << s.message();
  return p;
}

// Tolerances of the pose checks. In-frame points: tfjs's EPSILON_IMAGE, except on the portrait
// (below). Points outside the frame (the legs: MediaPipe gives them visibility < 0.3 and no
// image evidence, so both models extrapolate from the torso): 2 x EPSILON_IMAGE.
// portrait.png: the body's region is 2400 px on an 820 x 1024 image (the legs run 900 px below
// it), so one tensor pixel is 9.4 image pixels and a one-pixel difference in the region moves
// the arms by several pixels. Its in-frame points get EPSILON_VIDEO's 31 px (what tfjs allows
// for a region it does not control: tracking), the mean EPSILON_IMAGE.
TEST(upper_body, pose_vs_mediapipe) {
  UPPER_SKIP_WITHOUT_DATA();
  const tolerances tol = load_tolerances();
  auto p = make_pose(crop_sampling::gl);
  ASSERT_NE(p, nullptr);
  for (const std::string name : k_images) {
    SCOPED_TRACE(name);
    loaded_image img;
    ASSERT_TRUE(load_upper(name, img));
    const nlohmann::json g = load_json(golden_path(name, "pose"));
    ASSERT_EQ(g["w"].get<int>(), img.width);
    ASSERT_EQ(g["h"].get<int>(), img.height);
    landmark_frame f;
    const pose_result r = p->process(img.view(), f);
    ASSERT_NE(r, pose_result::error) << p->last_error();
    if (g["landmarks_px"].empty()) {
      // pose_upper40: the top of the hair only; MediaPipe finds nobody, nor must we.
      std::printf("[figures] %s pose: MediaPipe none, ours %s\n", name.c_str(),
                  r == pose_result::found ? "found" : "none");
      EXPECT_EQ(r, pose_result::not_found);
      EXPECT_FALSE(f.has(frame_part::pose));
      continue;
    }
    ASSERT_EQ(r, pose_result::found);
    const normalized_rect roi = p->last_roi();
    const pose_errors e = compare_pose(f, g, img.width, img.height);
    std::printf(
        "[figures] %s pose: region %.0f px at (%.0f, %.0f); %d in-frame points mean %.2f px, max "
        "%.2f px; %d outside mean %.2f px, max %.2f px; world max %.3f m; visibility max "
        "diff %.3f\n",
        name.c_str(), roi.width * img.width, roi.x_center * img.width, roi.y_center * img.height,
        e.in_count, e.in_mean, e.in_max, k_pose_landmark_count - e.in_count, e.out_mean, e.out_max,
        e.world_max, e.visibility_max);
    const bool huge_region = name == "portrait";
    EXPECT_LT(e.in_max, huge_region ? 31.0 : tol.pose_px);
    EXPECT_LT(e.in_mean, huge_region ? tol.pose_px : tol.pose_px / 2);
    EXPECT_LT(e.out_max, 2 * tol.pose_px);
    EXPECT_LT(e.world_max, tol.pose_world_m);
    EXPECT_LT(e.visibility_max, 0.1);
  }
}

// ---- hands -----------------------------------------------------------------------------------

struct hand_errors {
  double mean_px = 0, max_px = 0, world_max_m = 0;
};

hand_errors compare_hand(const std::array<landmark, k_hand_landmark_count>& image,
                         const std::array<landmark, k_hand_landmark_count>& world,
                         const nlohmann::json& g_px, const nlohmann::json& g_world, int w, int h) {
  hand_errors e;
  for (int i = 0; i < k_hand_landmark_count; ++i) {
    const double d = std::hypot(image[i].x * w - g_px[i][0].get<double>(),
                                image[i].y * h - g_px[i][1].get<double>());
    e.mean_px += d / k_hand_landmark_count;
    e.max_px = std::max(e.max_px, d);
    e.world_max_m = std::max({e.world_max_m, std::fabs(world[i].x - g_world[i][0].get<double>()),
                              std::fabs(world[i].y - g_world[i][1].get<double>()),
                              std::fabs(world[i].z - g_world[i][2].get<double>())});
  }
  return e;
}

double wrist_gap(const std::array<landmark, k_hand_landmark_count>& image, const nlohmann::json& g,
                 int w, int h) {
  return std::hypot(image[0].x * w - g[0][0].get<double>(), image[0].y * h - g[0][1].get<double>());
}

// MediaPipe Hands' graph: the palm detector on the whole image, 2 hands, static images.
// Each golden hand must be found (nearest wrist) within EPSILON_IMAGE (max) and a quarter of
// it (mean), world points within EPSILON_VIDEO_WORLD, with MediaPipe's handedness label.
// pose_upper55: MediaPipe reports one hand (the person's right, x ~ 300 px). We find it, and
// also the person's left hand: its palm scores 0.77 (threshold 0.5) and the landmark model's
// presence is 0.55, just over MediaPipe's 0.5, so a last-digit difference decides whether it
// counts. That extra hand is allowed, only with a presence under 0.6.
TEST(upper_body, hands_vs_mediapipe) {
  UPPER_SKIP_WITHOUT_DATA();
  const tolerances tol = load_tolerances();
  hand_pipeline_options o;
  o.models_dir = models_dir();
  o.static_images = true;
  o.roi_source = hand_roi_source::palm;
  o.sampling = crop_sampling::gl;
  std::unique_ptr<hand_pipeline> p;
  const status s = hand_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  int checked = 0;
  for (const std::string name : k_images) {
    const std::string gp = golden_path(name, "hands");
    if (!std::ifstream(gp).good()) continue;  // pose_upper40 has no hands golden
    SCOPED_TRACE(name);
    loaded_image img;
    ASSERT_TRUE(load_upper(name, img));
    const nlohmann::json g = load_json(gp);
    landmark_frame f;
    ASSERT_NE(p->process(img.view(), nullptr, f), hand_result::error) << p->last_error();
    const size_t n = g["hands_px"].size();
    std::vector<bool> used(p->hand_count(), false);
    for (size_t k = 0; k < n; ++k) {
      int best = -1;
      double bd = 1e30;
      for (int i = 0; i < p->hand_count(); ++i) {
        const double d = wrist_gap(p->hand(i).image, g["hands_px"][k], img.width, img.height);
        if (d < bd) bd = d, best = i;
      }
      ASSERT_GE(best, 0) << "golden hand " << k << " not found";
      used[best] = true;
      const hand_observation& h = p->hand(best);
      const hand_errors e = compare_hand(h.image, h.world, g["hands_px"][k], g["hands_world_m"][k],
                                         img.width, img.height);
      const auto& gh = g["handedness"][k];
      const bool golden_left = gh["label"].get<std::string>() == "Left";
      std::printf(
          "[figures] %s hand %zu: mean %.2f px, max %.2f px, world max %.4f m; presence %.3f; "
          "\"Left\" score %.3f (MediaPipe: %s %.3f)\n",
          name.c_str(), k, e.mean_px, e.max_px, e.world_max_m, h.presence, h.handedness_score,
          gh["label"].get<std::string>().c_str(), gh["score"].get<double>());
      EXPECT_LT(e.max_px, tol.hand_px);
      EXPECT_LT(e.mean_px, tol.hand_px / 4);
      EXPECT_LT(e.world_max_m, tol.hand_world_m);
      EXPECT_EQ(h.handedness_score >= 0.5f, golden_left) << "handedness label differs";
      ++checked;
    }
    for (int i = 0; i < p->hand_count(); ++i) {
      if (used[i]) continue;
      std::printf(
          "[figures] %s: one more hand than MediaPipe, wrist (%.0f, %.0f) px, presence %.3f\n",
          name.c_str(), p->hand(i).image[0].x * img.width, p->hand(i).image[0].y * img.height,
          p->hand(i).presence);
      EXPECT_EQ(name, "pose_upper55");
      EXPECT_LT(p->hand(i).presence, 0.6f);
    }
  }
  EXPECT_EQ(checked, 4);  // pose_upper55 1, portrait 1, squats_upper 2
}

// ---- face ------------------------------------------------------------------------------------

struct face_errors {
  double mean = 0, median = 0, p95 = 0, max = 0;
};

face_errors compare_face(const landmark_frame& f, const nlohmann::json& g, int w, int h) {
  std::vector<double> d;
  for (int i = 0; i < f.face_count; ++i)  // all 478 (with the 468-point model: the first 468)
    d.push_back(std::hypot(f.face[i].x * w - g[i][0].get<double>(),
                           f.face[i].y * h - g[i][1].get<double>()));
  face_errors e;
  for (double v : d) e.mean += v / d.size();
  std::sort(d.begin(), d.end());
  e.median = d[d.size() / 2];
  e.p95 = d[static_cast<size_t>(std::ceil(0.95 * d.size())) - 1];
  e.max = d.back();
  return e;
}

// MediaPipe Face Mesh's graph: the short-range detector on the whole image. With the attention
// model (the default, the golden's own network: refineLandmarks) every one of the 478 points,
// irises included, must be within EPSILON_IMAGE and the mean within a tenth of it (measured:
// max 0.21 / 0.18 px, mean 0.06 / 0.04 px on portrait / squats_upper). Without its file the
// pipeline falls back to the 468-point model, a different network: then the bounds of
// face_pipeline_test's 468-point check (mean and median within EPSILON_IMAGE, p95 1.5x, max
// 2x). pose_upper55: the face is too small for the short-range detector; MediaPipe finds none
// and neither must we.
TEST(upper_body, face_vs_mediapipe) {
  UPPER_SKIP_WITHOUT_DATA();
  const tolerances tol = load_tolerances();
  face_pipeline_options o;
  o.models_dir = models_dir();
  o.static_images = true;
  o.roi_source = face_roi_source::detector;
  o.sampling = crop_sampling::gl;
  std::unique_ptr<face_pipeline> p;
  const status s = face_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  int checked = 0;
  for (const std::string name : k_images) {
    const std::string gp = golden_path(name, "face");
    if (!std::ifstream(gp).good()) continue;
    SCOPED_TRACE(name);
    loaded_image img;
    ASSERT_TRUE(load_upper(name, img));
    const nlohmann::json g = load_json(gp);
    landmark_frame f;
    const face_result r = p->process(img.view(), nullptr, f);
    ASSERT_NE(r, face_result::error) << p->last_error();
    ++checked;
    if (g["faces_px"].empty()) {
      std::printf("[figures] %s face: MediaPipe none, ours %s\n", name.c_str(),
                  r == face_result::found ? "found" : "none");
      EXPECT_EQ(r, face_result::not_found);
      continue;
    }
    ASSERT_EQ(r, face_result::found);
    ASSERT_EQ(g["faces_px"][0].size(), 478u);
    const face_errors e = compare_face(f, g["faces_px"][0], img.width, img.height);
    std::printf("[figures] %s face (%d points): mean %.2f, median %.2f, p95 %.2f, max %.2f px\n",
                name.c_str(), f.face_count, e.mean, e.median, e.p95, e.max);
    if (p->mesh_model() == face_mesh_model::attention) {
      EXPECT_EQ(f.face_count, k_face_mesh_iris_count);
      EXPECT_LT(e.max, tol.face_px);
      EXPECT_LT(e.mean, 0.1 * tol.face_px);
    } else {
      std::printf("[figures] %s\n", p->note().c_str());
      EXPECT_LT(e.mean, tol.face_px);
      EXPECT_LT(e.median, tol.face_px);
      EXPECT_LT(e.p95, 1.5 * tol.face_px);
      EXPECT_LT(e.max, 2 * tol.face_px);
    }
  }
  EXPECT_EQ(checked, 3);
}

// ---- the whole capture -----------------------------------------------------------------------

// The "onnx" estimator, static images, body + hands + face, as `avatarmap capture --hands
// --face` runs. The body is the pose graph above (same bounds). Hands and face are looked for
// in the body's regions (MediaPipe Holistic), not by the whole-image detectors that made the
// goldens, so they run on other regions:
//  - face: the detector inside the body's face region, the mesh on Holistic's keypoint region
//    (x2 of the detection's keypoint box, not x1.5 of its box): measured mean 2.0 / 2.3 px,
//    max 5.5 / 10.0 px on portrait / squats_upper. Bounds: mean EPSILON_IMAGE, max 3x.
//  - hands: Holistic's region from the pose wrist, index and pinky (x2.7, sized for its
//    hand_recrop model, not converted), then one run on the landmarks' own region. Where that
//    works (pose_upper55, squats_upper's right hand) tfjs's image bounds hold, and the world
//    points within 2x EPSILON_VIDEO_WORLD (measured 0.017 m: another region). Two known gaps,
//    printed and not asserted: squats_upper's left hand lies across the bottom edge and the loose
//    region gives presence 0.26 (not found; the palm detector finds it to 0.27 px); portrait's
//    hand is folded and the pose's finger points spread, so the region is 425 px for a 150 px
//    hand and the one refinement lands 18 px (mean) off MediaPipe's (more runs converge: 5
//    runs halve it; video tracking does that over frames).
TEST(upper_body, whole_capture_vs_mediapipe) {
  UPPER_SKIP_WITHOUT_DATA();
  const tolerances tol = load_tolerances();
  estimator_options eo;
  eo.source = models_dir();
  eo.static_images = true;
  eo.hands = true;
  eo.face = true;
  std::unique_ptr<estimator> est;
  const status s = create_estimator("onnx", eo, est);
  ASSERT_TRUE(s.ok()) << s.message();
  for (const std::string name : k_images) {
    SCOPED_TRACE(name);
    loaded_image img;
    ASSERT_TRUE(load_upper(name, img));
    landmark_frame f;
    estimate_args a;
    a.image = img.view();
    ASSERT_TRUE(est->estimate(a, f).ok());
    const nlohmann::json gpose = load_json(golden_path(name, "pose"));
    if (gpose["landmarks_px"].empty()) {
      EXPECT_FALSE(f.has(frame_part::pose));
      EXPECT_FALSE(f.has(frame_part::face));
      std::printf("[figures] %s capture: no body, %s hand, %s face\n", name.c_str(),
                  f.has(frame_part::left_hand) || f.has(frame_part::right_hand) ? "a" : "no",
                  f.has(frame_part::face) ? "a" : "no");
      continue;
    }
    ASSERT_TRUE(f.has(frame_part::pose));
    const pose_errors pe = compare_pose(f, gpose, img.width, img.height);
    const bool huge_region = name == "portrait";
    EXPECT_LT(pe.in_max, huge_region ? 31.0 : tol.pose_px);

    std::string hands_line;
    const std::string gh = golden_path(name, "hands");
    if (std::ifstream(gh).good()) {
      const nlohmann::json g = load_json(gh);
      for (size_t k = 0; k < g["hands_px"].size(); ++k) {
        // The golden hand's side on this raw image: the nearer of our two hands.
        const bool have_l = f.has(frame_part::left_hand), have_r = f.has(frame_part::right_hand);
        const double dl =
            have_l ? wrist_gap(f.left_hand, g["hands_px"][k], img.width, img.height) : 1e30;
        const double dr =
            have_r ? wrist_gap(f.right_hand, g["hands_px"][k], img.width, img.height) : 1e30;
        char buf[160];
        const bool known_gap = (name == "squats_upper" && k == 1) || (name == "portrait" && k == 0);
        if (!have_l && !have_r) {
          std::snprintf(buf, sizeof buf, " hand %zu not found;", k);
          if (!known_gap) ADD_FAILURE() << "golden hand " << k << " not found";
        } else {
          const bool left = dl < dr;
          const hand_errors e = compare_hand(
              left ? f.left_hand : f.right_hand, left ? f.left_hand_world : f.right_hand_world,
              g["hands_px"][k], g["hands_world_m"][k], img.width, img.height);
          const bool far = e.max_px >= tol.hand_px;  // another hand, or a known gap
          std::snprintf(buf, sizeof buf, " hand %zu %s mean %.2f max %.2f px;", k,
                        far && known_gap ? "(known gap)" : "", e.mean_px, e.max_px);
          if (!known_gap) {
            EXPECT_LT(e.max_px, tol.hand_px) << "hand " << k;
            EXPECT_LT(e.mean_px, tol.hand_px / 4) << "hand " << k;
            EXPECT_LT(e.world_max_m, 2 * tol.hand_world_m) << "hand " << k;
          }
        }
        hands_line += buf;
      }
    }
    std::string face_line = " no face golden";
    const std::string gf = golden_path(name, "face");
    if (std::ifstream(gf).good()) {
      const nlohmann::json g = load_json(gf);
      if (g["faces_px"].empty()) {
        // MediaPipe's whole-image detector misses this small face; the body's face region
        // gives the detector a close-up, so the capture may find it. Reported, not compared.
        face_line = f.has(frame_part::face) ? " face found (MediaPipe Face Mesh: none)"
                                            : " no face (as MediaPipe)";
      } else {
        ASSERT_TRUE(f.has(frame_part::face));
        const face_errors e = compare_face(f, g["faces_px"][0], img.width, img.height);
        char buf[120];
        std::snprintf(buf, sizeof buf, " face mean %.2f p95 %.2f max %.2f px", e.mean, e.p95,
                      e.max);
        face_line = buf;
        EXPECT_LT(e.mean, tol.face_px);
        EXPECT_LT(e.max, 3 * tol.face_px);
      }
    }
    std::printf("[figures] %s capture: body in-frame mean %.2f max %.2f px;%s%s\n", name.c_str(),
                pe.in_mean, pe.in_max, hands_line.c_str(), face_line.c_str());
  }
}

// ---- the crop convention ---------------------------------------------------------------------

// The goldens come from MediaPipe's web graphs, whose crops are its OpenGL converter's. With the
// CPU converter's sampling (crop_sampling::opencv) the same pipelines disagree more: printed for
// docs/capture.md, and the two clearest cases asserted (see the numbers there).
TEST(upper_body, cpu_sampling_disagrees_more) {
  UPPER_SKIP_WITHOUT_DATA();
  double hand_gl = 0, hand_cpu = 0;
  for (crop_sampling sampling : {crop_sampling::gl, crop_sampling::opencv}) {
    const char* label = sampling == crop_sampling::gl ? "gl" : "opencv";
    auto pose = make_pose(sampling);
    ASSERT_NE(pose, nullptr);
    hand_pipeline_options ho;
    ho.models_dir = models_dir();
    ho.static_images = true;
    ho.roi_source = hand_roi_source::palm;
    ho.sampling = sampling;
    std::unique_ptr<hand_pipeline> hands;
    ASSERT_TRUE(hand_pipeline::create(ho, hands).ok());
    face_pipeline_options fo;
    fo.models_dir = models_dir();
    fo.static_images = true;
    fo.roi_source = face_roi_source::detector;
    fo.sampling = sampling;
    std::unique_ptr<face_pipeline> face;
    ASSERT_TRUE(face_pipeline::create(fo, face).ok());
    for (const std::string name : {"pose_upper55", "portrait", "squats_upper"}) {
      loaded_image img;
      ASSERT_TRUE(load_upper(name, img));
      landmark_frame f;
      ASSERT_EQ(pose->process(img.view(), f), pose_result::found);
      const pose_errors pe =
          compare_pose(f, load_json(golden_path(name, "pose")), img.width, img.height);
      ASSERT_NE(hands->process(img.view(), nullptr, f), hand_result::error);
      const nlohmann::json gh = load_json(golden_path(name, "hands"));
      double hand_mean = 0;  // over the golden hands, each against our nearest
      for (size_t k = 0; k < gh["hands_px"].size(); ++k) {
        double best = 1e30;
        for (int i = 0; i < hands->hand_count(); ++i) {
          const hand_observation& h = hands->hand(i);
          best = std::min(best, compare_hand(h.image, h.world, gh["hands_px"][k],
                                             gh["hands_world_m"][k], img.width, img.height)
                                    .mean_px);
        }
        hand_mean += best / gh["hands_px"].size();
      }
      (sampling == crop_sampling::gl ? hand_gl : hand_cpu) += hand_mean;
      const nlohmann::json gf = load_json(golden_path(name, "face"));
      std::string face_line = "none";
      if (!gf["faces_px"].empty()) {
        char buf[96];
        if (face->process(img.view(), nullptr, f) == face_result::found)
          std::snprintf(buf, sizeof buf, "mean %.2f px",
                        compare_face(f, gf["faces_px"][0], img.width, img.height).mean);
        else
          std::snprintf(
              buf, sizeof buf, "none (%s, mesh presence %.3f)",
              face->last_ran_detector() && face->last_acquisition() == face_acquisition::none
                  ? "no detection"
                  : "mesh rejected",
              face->last_presence());
        face_line = buf;
      }
      std::printf(
          "[figures] sampling %-6s %-12s body in-frame mean %.2f max %.2f px, outside mean "
          "%.2f px, world max %.3f m; hands mean %.2f px; face %s\n",
          label, name.c_str(), pe.in_mean, pe.in_max, pe.out_mean, pe.world_max, hand_mean,
          face_line.c_str());
    }
  }
  // pose_upper55's one golden hand is found only with the OpenGL sampling (the CPU sampling's
  // palm detector keeps the other hand), and the others agree several times better.
  EXPECT_LT(hand_gl * 4, hand_cpu);
}

}  // namespace
}  // namespace avatarmap
