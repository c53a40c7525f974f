// A real face at rest reads ~0 (docs/expressions.md, "Figures on real video"): pose_squats.mp4
// (65 frames at 5 frames/s, a person squatting, the face about 50 px between the outer eye
// corners, glasses) captured with the face models, then solved by the file job with its
// defaults (the face calibrated over the whole take). The person's face rests throughout: the
// measured shapes' median must be near 0, their 0.9 quantile low, and their frame-to-frame
// change small (no flicker).
// Needs $AVATARMAP_MODELS and $AVATARMAP_TEST_DATA; skips without them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <string>
#include <vector>

#include "avatarmap/capture/capture_file.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/solve/face_expressions.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

float quantile(std::vector<float> v, float q) {
  const std::size_t at = std::min(v.size() - 1, static_cast<std::size_t>(q * float(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
  return v[at];
}

// Standard deviation of the frame-to-frame change.
float jitter(const std::vector<float>& v) {
  double s = 0.0, s2 = 0.0;
  for (std::size_t i = 1; i < v.size(); ++i) {
    const double d = v[i] - v[i - 1];
    s += d;
    s2 += d * d;
  }
  const double n = double(v.size() - 1);
  return static_cast<float>(std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n))));
}

TEST(face_rest, pose_squats_face_reads_near_zero_at_rest) {
  if (test::models_dir().empty())
    GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  const std::string video = test::test_data_path("motion/tfjs-models/pose_squats.mp4");
  if (video.empty() || !fs::exists(video)) GTEST_SKIP() << test::k_no_test_data;
  const fs::path dir =
      fs::temp_directory_path() / ("avatarmap_face_rest_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  capture_file_job capture;
  capture.input = video;
  capture.output = (dir / "squats.landmarks.jsonl").string();
  capture.options.source = test::models_dir();
  capture.options.face = true;
  capture_file_summary cs;
  const status captured = capture.run(cs);
  ASSERT_TRUE(captured.ok()) << captured.message();

  solve_file_job solve;
  solve.input = capture.output;
  std::vector<std::array<float, k_blendshape_count>> shapes;
  solve.sink = [&](const proxy_pose& p) {
    shapes.push_back(p.blendshapes);
    return status{};
  };
  solve_file_summary ss;
  const status solved = solve.run(ss);
  fs::remove_all(dir);
  ASSERT_TRUE(solved.ok()) << solved.message();
  ASSERT_EQ(shapes.size(), 65u);
  ASSERT_GT(ss.face_iris_frames, 50);

  // Every shape the solver measures: the mesh's (k_mesh_blendshapes) and the eyes' looks (the
  // irises' rest is the take's most frequent gaze, docs/expressions.md).
  std::vector<blendshape> measured(std::begin(k_mesh_blendshapes), std::end(k_mesh_blendshapes));
  for (int b = idx(blendshape::eye_look_down_left); b <= idx(blendshape::eye_look_up_right); ++b)
    measured.push_back(static_cast<blendshape>(b));
  for (blendshape b : measured) {
    std::vector<float> v;
    for (const auto& s : shapes) v.push_back(s[idx(b)]);
    const float m = quantile(v, 0.5f), p90 = quantile(v, 0.9f), j = jitter(v);
    std::printf("[figures] pose_squats at rest %-18s median %.3f p90 %.3f jitter %.3f\n",
                std::string(blendshape_name(b)).c_str(), m, p90, j);
    EXPECT_LT(m, 0.1f) << blendshape_name(b);
    EXPECT_LT(p90, 0.3f) << blendshape_name(b);
    EXPECT_LT(j, 0.06f) << blendshape_name(b);
  }
}

}  // namespace
}  // namespace avatarmap
