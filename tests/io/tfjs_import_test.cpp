// Real data: the tfjs-models BlazePose squat recording (65 frames, 720 x 1280 video, 5 fps).
#include "avatarmap/io/tfjs_import.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

// Size of pose_squats.mp4 (from its 'tkhd' box) and its frame rate (mdhd timescale 10240,
// every sample 2048 ticks long).
constexpr int k_squat_width = 720;
constexpr int k_squat_height = 1280;
constexpr double k_squat_fps = 5.0;

nlohmann::json load(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::string temp_file(const char* name) {
  return ::testing::TempDir() + name + std::to_string(::getpid()) + ".landmarks.jsonl";
}

struct squat_data {
  std::string image_path, world_path;
  nlohmann::json image, world;
};

bool load_squats(squat_data& d) {
  if (test::test_data_dir().empty()) return false;
  d.image_path = test::test_data_path("motion/tfjs-models/pose_squats.full.json");
  d.world_path = test::test_data_path("motion/tfjs-models/pose_squats_3d.full.json");
  d.image = load(d.image_path);
  d.world = load(d.world_path);
  return true;
}

TEST(tfjs_data, squats_written_with_landmark_writer_read_back_equal) {
  squat_data d;
  if (!load_squats(d)) GTEST_SKIP() << test::k_no_test_data;
  ASSERT_EQ(d.image.size(), d.world.size());
  ASSERT_GT(d.image.size(), 0u);
  const std::string path = temp_file("squats_writer");
  landmark_file_header h;
  h.image_width = k_squat_width;
  h.image_height = k_squat_height;
  h.fps = k_squat_fps;
  std::vector<landmark_frame> written(d.image.size());
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, h).ok());
    for (std::size_t i = 0; i < d.image.size(); ++i) {
      landmark_frame& f = written[i];
      f.clear();
      f.t = static_cast<double>(i) / k_squat_fps;
      f.set(frame_part::pose, true);
      f.set(frame_part::pose_world, true);
      ASSERT_EQ(d.image[i].size(), 33u);
      for (int k = 0; k < 33; ++k) {
        const auto& p = d.image[i][static_cast<std::size_t>(k)];
        const auto& q = d.world[i][static_cast<std::size_t>(k)];
        f.pose[k] = {static_cast<float>(p[0].get<double>() / k_squat_width),
                     static_cast<float>(p[1].get<double>() / k_squat_height),
                     static_cast<float>(p[2].get<double>() / k_squat_width), 1.f, 1.f};
        f.pose_world[k] = {q[0].get<float>(), q[1].get<float>(), q[2].get<float>(), 1.f, 1.f};
      }
      ASSERT_TRUE(w.write(f).ok());
    }
    ASSERT_TRUE(w.commit().ok());
  }
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_EQ(r.header().image_width, k_squat_width);
  landmark_frame f;
  for (auto& e : written) {
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(f.t, e.t);
    for (int k = 0; k < 33; ++k) {
      EXPECT_EQ(f.pose[k].x, e.pose[k].x);
      EXPECT_EQ(f.pose[k].y, e.pose[k].y);
      EXPECT_EQ(f.pose[k].z, e.pose[k].z);
      EXPECT_EQ(f.pose_world[k].x, e.pose_world[k].x);
      EXPECT_EQ(f.pose_world[k].y, e.pose_world[k].y);
      EXPECT_EQ(f.pose_world[k].z, e.pose_world[k].z);
    }
  }
  EXPECT_EQ(r.next(f), read_result::end);
  std::remove(path.c_str());
}

TEST(tfjs_data, import_tfjs_pose_converts_the_squats) {
  squat_data d;
  if (!load_squats(d)) GTEST_SKIP() << test::k_no_test_data;
  const std::string path = temp_file("squats_import");
  status s = import_tfjs_pose(d.image_path, d.world_path, k_squat_width, k_squat_height,
                              k_squat_fps, path);
  ASSERT_TRUE(s.ok()) << s.message();
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_TRUE(r.header().present);
  EXPECT_EQ(r.header().image_width, k_squat_width);
  EXPECT_EQ(r.header().image_height, k_squat_height);
  EXPECT_EQ(r.header().fps, k_squat_fps);
  landmark_frame f;
  std::size_t n = 0;
  while (r.next(f) == read_result::frame) {
    ASSERT_LT(n, d.image.size());
    EXPECT_DOUBLE_EQ(f.t, n / k_squat_fps);
    EXPECT_TRUE(f.has(frame_part::pose));
    EXPECT_TRUE(f.has(frame_part::pose_world));
    for (int k = 0; k < 33; ++k) {
      const auto& p = d.image[n][static_cast<std::size_t>(k)];
      EXPECT_NEAR(f.pose[k].x, p[0].get<double>() / k_squat_width, 1e-6);
      EXPECT_NEAR(f.pose[k].y, p[1].get<double>() / k_squat_height, 1e-6);
      EXPECT_NEAR(f.pose[k].z, p[2].get<double>() / k_squat_width, 1e-6);
      EXPECT_NEAR(f.pose_world[k].y, d.world[n][static_cast<std::size_t>(k)][1].get<double>(),
                  1e-6);
      EXPECT_EQ(f.pose[k].visibility, 1.f);
      // Image points of a person in the frame lie (roughly) inside the image.
      EXPECT_GT(f.pose[k].y, -0.2f);
      EXPECT_LT(f.pose[k].y, 1.2f);
    }
    ++n;
  }
  EXPECT_TRUE(r.error().empty()) << r.error();
  EXPECT_EQ(n, d.image.size());
  std::remove(path.c_str());
}

TEST(tfjs_data, import_tfjs_hand_converts_the_asl_recording) {
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  const std::string image_path = test::test_data_path("motion/tfjs-models/asl_hand.full.json");
  const std::string world_path = test::test_data_path("motion/tfjs-models/asl_hand_3d.full.json");
  const nlohmann::json image = load(image_path), world = load(world_path);
  const std::string path = temp_file("asl_import");
  const int w = 620, h = 1080;
  // A hand file read as a pose says what to do.
  status bad = import_tfjs_pose(image_path, world_path, w, h, 25.0, path);
  EXPECT_NE(bad.message().find("expected an array of 33 points, got an array of 21"),
            std::string::npos)
      << bad.message();
  status s = import_tfjs_hand(image_path, world_path, w, h, 25.0, false, path);
  ASSERT_TRUE(s.ok()) << s.message();
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  landmark_frame f;
  std::size_t n = 0;
  while (r.next(f) == read_result::frame) {
    ASSERT_LT(n, image.size());
    EXPECT_DOUBLE_EQ(f.t, n / 25.0);
    EXPECT_TRUE(f.has(frame_part::right_hand));
    EXPECT_TRUE(f.has(frame_part::right_hand_world));
    EXPECT_FALSE(f.has(frame_part::left_hand));
    EXPECT_FALSE(f.has(frame_part::pose));
    for (int k = 0; k < 21; ++k) {
      const auto& p = image[n][static_cast<std::size_t>(k)];
      const auto& q = world[n][static_cast<std::size_t>(k)];
      EXPECT_NEAR(f.right_hand[k].x, p[0].get<double>() / w, 1e-6);
      EXPECT_NEAR(f.right_hand[k].y, p[1].get<double>() / h, 1e-6);
      EXPECT_NEAR(f.right_hand[k].z, p[2].get<double>() / w, 1e-6);
      EXPECT_NEAR(f.right_hand_world[k].x, q[0].get<double>(), 1e-6);
      EXPECT_NEAR(f.right_hand_world[k].z, q[2].get<double>(), 1e-6);
    }
    ++n;
  }
  EXPECT_EQ(n, image.size());
  std::remove(path.c_str());
}

TEST(tfjs_import, rejects_bad_arguments_and_files) {
  const std::string out = temp_file("bad_import");
  EXPECT_FALSE(import_tfjs_pose("a", "b", 0, 10, 5, out).ok());
  EXPECT_FALSE(import_tfjs_pose("a", "b", 10, 10, 0, out).ok());
  status s = import_tfjs_pose("/nonexistent.json", "/nonexistent.json", 10, 10, 5, out);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent.json"), std::string::npos);
  const std::string bad = temp_file("bad_json");
  std::ofstream(bad) << "[[[1,2,3]]]";
  s = import_tfjs_pose(bad, bad, 10, 10, 5, out);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("frame 0: expected an array of 33 points"), std::string::npos)
      << s.message();
  // Messages in our words, never nlohmann's ("[json.exception.out_of_range.406] ...").
  auto message_for = [&](const std::string& text) {
    std::ofstream(bad, std::ios::trunc | std::ios::binary) << text;
    const status st = import_tfjs_pose(bad, bad, 10, 10, 5, out);
    EXPECT_FALSE(st.ok()) << text.substr(0, 40);
    EXPECT_EQ(st.message().find("json.exception"), std::string::npos) << st.message();
    return st.message();
  };
  EXPECT_NE(message_for("[[[1e400,0,0]]]")
                .find(": invalid JSON at line 1, column 4: the number "
                      "1e400 is too large"),
            std::string::npos)
      << message_for("[[[1e400,0,0]]]");
  EXPECT_NE(message_for("[[[1,2,3]],\n [").find("invalid JSON at line 2"), std::string::npos);
  EXPECT_NE(message_for(std::string(100000, '[')).find("JSON nests deeper than 128 levels"),
            std::string::npos);
  EXPECT_NE(message_for("{\"frames\":[]}")
                .find("expected a JSON array of frames (tfjs-models "
                      "test format), got an object"),
            std::string::npos);
  EXPECT_NE(message_for("[[1,2,3]]")
                .find("frame 0: expected an array of 33 points, got an array "
                      "of 3"),
            std::string::npos);
  // The frame rate: positive and finite, and large enough for the last frame's time.
  std::ofstream(bad, std::ios::trunc) << "[[],[]]";
  s = import_tfjs_pose(bad, bad, 10, 10, std::numeric_limits<double>::infinity(), out);
  EXPECT_NE(s.message().find("fps must be a positive finite number"), std::string::npos)
      << s.message();
  s = import_tfjs_pose(bad, bad, 10, 10, 1e-310, out);
  EXPECT_NE(s.message().find("is too small"), std::string::npos) << s.message();
  std::remove(bad.c_str());
  std::ifstream check(out);
  EXPECT_FALSE(check.good());  // nothing written on failure
}

}  // namespace
}  // namespace avatarmap
