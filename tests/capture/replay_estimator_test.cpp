#include "avatarmap/capture/replay_estimator.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder per test, removed afterwards.
using test::read_text;
using test::temp_dir;
using test::write_text;

// A frame with every part; point values depend on `i` so frames can be told apart.
landmark_frame full_frame(int i, double t) {
  landmark_frame f;
  f.t = t;
  auto fill = [&](landmark* p, int n, float base) {
    for (int k = 0; k < n; ++k) p[k] = landmark{base + 0.01f * k + i, 0.5f, -0.1f, 0.9f, 0.8f};
  };
  fill(f.pose.data(), k_pose_landmark_count, 0.1f);
  fill(f.pose_world.data(), k_pose_landmark_count, 0.2f);
  fill(f.left_hand.data(), k_hand_landmark_count, 0.3f);
  fill(f.left_hand_world.data(), k_hand_landmark_count, 0.4f);
  fill(f.right_hand.data(), k_hand_landmark_count, 0.5f);
  fill(f.right_hand_world.data(), k_hand_landmark_count, 0.6f);
  fill(f.face.data(), k_face_mesh_iris_count, 0.7f);
  f.face_count = k_face_mesh_iris_count;
  for (int p = 0; p < k_frame_part_count; ++p) f.set(static_cast<frame_part>(p), true);
  return f;
}

const double k_times[] = {0.25, 0.5, 1.125};  // deliberately not index / fps

// Writes a 3-frame recording (30 fps header, times from k_times) and returns its path.
std::string write_recording(const temp_dir& dir) {
  const std::string path = dir.file("rec.landmarks.jsonl");
  landmark_writer w;
  landmark_file_header h;
  h.image_width = 640;
  h.image_height = 480;
  h.fps = 30.0;
  EXPECT_TRUE(w.open(path, h).ok());
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(w.write(full_frame(i, k_times[i])).ok());
  EXPECT_TRUE(w.commit().ok());
  return path;
}

std::unique_ptr<estimator> make_replay(const std::string& path) {
  estimator_options o;
  o.source = path;
  std::unique_ptr<estimator> e;
  status s = create_estimator("replay", o, e);
  EXPECT_TRUE(s.ok()) << s.message();
  return e;
}

TEST(replay_estimator, returns_frames_in_order_with_their_own_time) {
  temp_dir dir;
  std::unique_ptr<estimator> e = make_replay(write_recording(dir));
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->name(), "replay");
  landmark_frame f;
  for (int i = 0; i < 3; ++i) {
    estimate_args args;
    args.t = 100.0 + i;  // ignored by replay
    status s = e->estimate(args, f);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_DOUBLE_EQ(f.t, k_times[i]);
    const landmark_frame want = full_frame(i, k_times[i]);
    EXPECT_EQ(f.parts, want.parts);
    EXPECT_EQ(f.face_count, k_face_mesh_iris_count);
    EXPECT_FLOAT_EQ(f.pose[0].x, want.pose[0].x);
    EXPECT_FLOAT_EQ(f.right_hand_world[20].x, want.right_hand_world[20].x);
    EXPECT_FLOAT_EQ(f.face[477].x, want.face[477].x);
  }
}

TEST(replay_estimator, header_is_exposed) {
  temp_dir dir;
  std::unique_ptr<replay_estimator> r;
  ASSERT_TRUE(replay_estimator::open(write_recording(dir), r).ok());
  EXPECT_TRUE(r->header().present);
  EXPECT_EQ(r->header().image_width, 640);
  EXPECT_EQ(r->header().image_height, 480);
  EXPECT_DOUBLE_EQ(r->header().fps, 30.0);
  EXPECT_FALSE(r->finished());
}

TEST(replay_estimator, parts_not_asked_for_are_removed) {
  temp_dir dir;
  std::unique_ptr<estimator> e = make_replay(write_recording(dir));
  ASSERT_NE(e, nullptr);
  landmark_frame f;

  estimate_args no_body;
  no_body.body = false;
  ASSERT_TRUE(e->estimate(no_body, f).ok());
  EXPECT_FALSE(f.has(frame_part::pose));
  EXPECT_FALSE(f.has(frame_part::pose_world));
  EXPECT_TRUE(f.has(frame_part::left_hand));
  EXPECT_TRUE(f.has(frame_part::right_hand_world));
  EXPECT_TRUE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, k_face_mesh_iris_count);

  estimate_args no_hands;
  no_hands.hands = false;
  ASSERT_TRUE(e->estimate(no_hands, f).ok());
  EXPECT_TRUE(f.has(frame_part::pose));
  EXPECT_TRUE(f.has(frame_part::pose_world));
  EXPECT_FALSE(f.has(frame_part::left_hand));
  EXPECT_FALSE(f.has(frame_part::left_hand_world));
  EXPECT_FALSE(f.has(frame_part::right_hand));
  EXPECT_FALSE(f.has(frame_part::right_hand_world));
  EXPECT_TRUE(f.has(frame_part::face));

  estimate_args no_face;
  no_face.face = false;
  ASSERT_TRUE(e->estimate(no_face, f).ok());
  EXPECT_TRUE(f.has(frame_part::pose));
  EXPECT_TRUE(f.has(frame_part::left_hand));
  EXPECT_FALSE(f.has(frame_part::face));
  EXPECT_EQ(f.face_count, 0);
  EXPECT_DOUBLE_EQ(f.t, k_times[2]);
}

TEST(replay_estimator, end_of_recording_is_an_error_that_stays) {
  temp_dir dir;
  std::unique_ptr<replay_estimator> r;
  ASSERT_TRUE(replay_estimator::open(write_recording(dir), r).ok());
  landmark_frame f;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(r->estimate({}, f).ok());
  EXPECT_FALSE(r->finished());
  for (int k = 0; k < 3; ++k) {
    f.parts = 1;  // must be cleared
    status s = r->estimate({}, f);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find("end of recording"), std::string::npos) << s.message();
    EXPECT_TRUE(r->finished());
  }
}

TEST(replay_estimator, end_clears_the_output_frame) {
  temp_dir dir;
  std::unique_ptr<replay_estimator> r;
  ASSERT_TRUE(replay_estimator::open(write_recording(dir), r).ok());
  landmark_frame f;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(r->estimate({}, f).ok());
  EXPECT_FALSE(r->estimate({}, f).ok());
  EXPECT_EQ(f.parts, 0u);
}

TEST(replay_estimator, unknown_backend_lists_the_available_ones) {
  std::unique_ptr<estimator> e;
  estimator_options o;
  o.source = "whatever.landmarks.jsonl";
  status s = create_estimator("onnx-nope", o, e);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(e, nullptr);
  EXPECT_NE(s.message().find("onnx-nope"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("replay"), std::string::npos) << s.message();
}

TEST(replay_estimator, missing_source_is_an_error) {
  std::unique_ptr<estimator> e;
  status s = create_estimator("replay", estimator_options{}, e);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(e, nullptr);
  EXPECT_FALSE(s.message().empty());

  temp_dir dir;
  estimator_options o;
  o.source = dir.file("does-not-exist.landmarks.jsonl");
  s = create_estimator("replay", o, e);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(e, nullptr);
  EXPECT_NE(s.message().find("does-not-exist.landmarks.jsonl"), std::string::npos) << s.message();
}

TEST(replay_estimator, malformed_line_names_file_and_line_and_replay_goes_on) {
  temp_dir dir;
  const std::string good = write_recording(dir);
  // Header on line 1, frames on lines 2..4: break line 3 (the second frame).
  std::istringstream in(read_text(good));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 4u);
  lines[2] = "{\"t\": 0.5, \"pose\": [[1, 2]";
  const std::string bad = dir.file("bad.landmarks.jsonl");
  {
    std::ofstream out(bad, std::ios::binary);
    for (const std::string& l : lines) out << l << '\n';
  }

  std::unique_ptr<estimator> e = make_replay(bad);
  ASSERT_NE(e, nullptr);
  landmark_frame f;
  ASSERT_TRUE(e->estimate({}, f).ok());
  EXPECT_DOUBLE_EQ(f.t, k_times[0]);
  status s = e->estimate({}, f);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("bad.landmarks.jsonl:3:"), std::string::npos) << s.message();
  EXPECT_EQ(s.message().find("end of recording"), std::string::npos) << s.message();
  s = e->estimate({}, f);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_DOUBLE_EQ(f.t, k_times[2]);
  s = e->estimate({}, f);
  EXPECT_NE(s.message().find("end of recording"), std::string::npos) << s.message();
}

TEST(replay_estimator, backend_table_lists_replay_with_a_description) {
  estimator_backend_list list = estimator_backends();
  ASSERT_GE(list.count, 1);
  ASSERT_NE(list.items, nullptr);
  bool found = false;
  for (int i = 0; i < list.count; ++i) {
    EXPECT_FALSE(list.items[i].name.empty());
    EXPECT_FALSE(list.items[i].description.empty());
    EXPECT_NE(list.items[i].create, nullptr);
    if (list.items[i].name == "replay") found = true;
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace avatarmap
