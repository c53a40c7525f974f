// The onnx estimator on two lanes gives the same landmarks as on one: estimate() (the hands
// and face of a frame side by side) and estimate_pipelined() (the body of the next frame
// beside them) against plain one-thread estimate(), frame by frame and bit for bit, on
// pose_squats.mp4 with body, hands and face tracked. Every model runs on one ORT thread in
// all three, so the arithmetic is the same; only the order of the work differs.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/media/video_source.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

std::unique_ptr<estimator> make_estimator(int threads, int lanes) {
  estimator_options o;
  o.source = test::models_dir();
  o.threads = threads;
  o.lanes = lanes;
  o.hands = o.face = true;
  std::unique_ptr<estimator> e;
  const status s = create_estimator("onnx", o, e);
  EXPECT_TRUE(s.ok()) << s.message();
  return e;
}

// Bit-for-bit equality of two frames' parts (the landmarks' floats, not within a tolerance).
::testing::AssertionResult same_frame(const landmark_frame& a, const landmark_frame& b) {
  if (a.parts != b.parts) return ::testing::AssertionFailure() << "different parts";
  if (a.face_count != b.face_count) return ::testing::AssertionFailure() << "face count";
  auto same = [](const auto& x, const auto& y, int n) {
    return std::memcmp(x.data(), y.data(), sizeof(x[0]) * static_cast<size_t>(n)) == 0;
  };
  const bool eq = same(a.pose, b.pose, k_pose_landmark_count) &&
                  same(a.pose_world, b.pose_world, k_pose_landmark_count) &&
                  (!a.has(frame_part::left_hand) ||
                   (same(a.left_hand, b.left_hand, k_hand_landmark_count) &&
                    same(a.left_hand_world, b.left_hand_world, k_hand_landmark_count))) &&
                  (!a.has(frame_part::right_hand) ||
                   (same(a.right_hand, b.right_hand, k_hand_landmark_count) &&
                    same(a.right_hand_world, b.right_hand_world, k_hand_landmark_count))) &&
                  same(a.face, b.face, a.face_count);
  if (!eq) return ::testing::AssertionFailure() << "different landmarks";
  return ::testing::AssertionSuccess();
}

TEST(two_lanes_estimator, same_landmarks_as_one_lane) {
  if (test::models_dir().empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg";
  auto one = make_estimator(1, 1);
  auto side_by_side = make_estimator(2, 2);
  auto pipelined = make_estimator(2, 2);
  ASSERT_TRUE(one && side_by_side && pipelined);
  EXPECT_EQ(one->pipeline_delay(), 0);
  ASSERT_EQ(pipelined->pipeline_delay(), 1);

  video_source src;
  ASSERT_TRUE(src.open(test::test_data_path("motion/tfjs-models/pose_squats.mp4")).ok());
  // The pipelined estimator reads a frame's pixels until that frame comes back: two buffers.
  std::vector<std::uint8_t> pixels[2];
  estimate_args args[2];
  landmark_frame want, got, late;
  std::vector<landmark_frame> expected;
  int frames = 0, hands = 0, faces = 0, compared = 0;
  image_view v;
  double t = 0;
  while (src.next(v, t) == read_result::frame && frames < 40) {
    const int k = frames % 2;
    const size_t row = static_cast<size_t>(v.width) * 3;
    pixels[k].resize(row * static_cast<size_t>(v.height));
    for (int y = 0; y < v.height; ++y)
      std::memcpy(pixels[k].data() + row * y, v.data + static_cast<size_t>(v.stride_bytes) * y,
                  row);
    args[k].image = {pixels[k].data(), v.width, v.height, static_cast<int>(row), v.format};
    args[k].t = t;
    ASSERT_TRUE(one->estimate(args[k], want).ok());
    ASSERT_TRUE(side_by_side->estimate(args[k], got).ok());
    EXPECT_TRUE(same_frame(want, got)) << "estimate() on two lanes, frame " << frames;
    expected.push_back(want);
    hands += want.has(frame_part::left_hand) + want.has(frame_part::right_hand);
    faces += want.has(frame_part::face);
    bool ready = false;
    ASSERT_TRUE(pipelined->estimate_pipelined(&args[k], late, ready).ok());
    EXPECT_EQ(ready, frames > 0) << "one frame late";
    if (ready) {
      EXPECT_EQ(late.t, expected[static_cast<size_t>(compared)].t);
      EXPECT_TRUE(same_frame(expected[static_cast<size_t>(compared)], late))
          << "estimate_pipelined(), frame " << compared;
      ++compared;
    }
    ++frames;
  }
  bool ready = false;
  ASSERT_TRUE(pipelined->estimate_pipelined(nullptr, late, ready).ok());  // drain
  ASSERT_TRUE(ready);
  EXPECT_TRUE(same_frame(expected.back(), late)) << "the last frame";
  ++compared;
  ASSERT_TRUE(pipelined->estimate_pipelined(nullptr, late, ready).ok());
  EXPECT_FALSE(ready) << "nothing left after draining";
  EXPECT_EQ(compared, frames);
  // The comparison covered every part.
  EXPECT_EQ(frames, 40);
  EXPECT_GT(hands, 20);
  EXPECT_EQ(faces, frames);
}

}  // namespace
}  // namespace avatarmap
