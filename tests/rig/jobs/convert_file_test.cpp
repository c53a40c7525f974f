// The convert job (include/avatarmap/jobs/convert_file.hpp): one rule for what a motion file
// is, one reader, one rule for frame times (sorted, counted, warned) for every input and
// every output, the avatar bound only when the output uses it, and every output the bytes
// the steps it stands for write (solve_file_job for landmarks, clip_output_job for the rest).
#include "avatarmap/jobs/convert_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// 12 frames at 30 fps from t = 1 s: the spine bends, the hips move.
std::vector<proxy_pose> in_order() {
  std::vector<proxy_pose> frames(12);
  for (int i = 0; i < 12; ++i) {
    proxy_pose& p = frames[static_cast<std::size_t>(i)];
    p.set_rest();
    p.t = 1.0 + i / 30.0;
    p.hips_position = glm::vec3(0.01f * i, 0.9f, 0.f);
    p.rotations[idx(bone::spine)] = axis_angle(glm::vec3(1, 0, 0), 0.04f * i);
  }
  return frames;
}

void write_poses(const std::string& path, const std::vector<proxy_pose>& frames, double fps) {
  pose_writer w;
  pose_file_header h;
  h.present = true;
  h.fps = fps;
  ASSERT_TRUE(w.open(path, h).ok());
  for (const proxy_pose& p : frames) ASSERT_TRUE(w.write(p).ok());
  ASSERT_TRUE(w.commit().ok());
}

// The in-order frames with frames 3 and 4, and 8 and 9, swapped: two frames out of order.
std::vector<proxy_pose> out_of_order() {
  std::vector<proxy_pose> f = in_order();
  std::swap(f[3], f[4]);
  std::swap(f[8], f[9]);
  return f;
}

void write_landmarks(const std::string& path, int frames) {
  synth_options o;
  o.seed = 3;
  landmark_synth synth(o);
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = o.image_width;
  h.image_height = o.image_height;
  h.fps = 30.0;
  ASSERT_TRUE(writer.open(path, h).ok());
  landmark_frame frame;
  for (int i = 0; i < frames; ++i) {
    const double t = i / 30.0;
    synth.generate(demo_motion_pose(t, synth.skeleton()), frame);
    frame.t = t;
    ASSERT_TRUE(writer.write(frame).ok());
  }
  ASSERT_TRUE(writer.commit().ok());
}

class convert_file : public ::testing::Test {
 protected:
  test::temp_dir dir{"convert_file"};
  std::vector<std::string> warnings;
  convert_file_job job(const std::string& in, const std::string& out, double fps) {
    convert_file_job j;
    j.input = in;
    j.output = dir.file(out);
    j.fps = fps;
    j.warning = [this](const std::string& w) { warnings.push_back(w); };
    return j;
  }
  // What clip_output_job writes of `frames` (the reference for every non-landmark input).
  std::string clip_bytes(const std::vector<proxy_pose>& frames, const std::string& name, double fps,
                         double source_fps) {
    clip_output_job j;
    j.path = dir.file(name);
    j.frames = &frames;
    j.fps = fps;
    j.source_fps = source_fps;
    clip_output_summary s;
    const status st = j.run(s);
    EXPECT_TRUE(st.ok()) << st.message();
    return read_bytes(j.path);
  }
};

TEST(motion_input, the_extension_decides_in_any_case_then_the_content) {
  struct known {
    const char* path;
    motion_input kind;
    const char* stem;
  };
  for (const known& c :
       {known{"a/take.landmarks.jsonl", motion_input::landmarks, "a/take"},
        known{"TAKE.LANDMARKS.JSONL", motion_input::landmarks, "TAKE"},
        known{"x.Pose.Jsonl", motion_input::poses, "x"},
        known{"clip.VRMA", motion_input::vrma, "clip"}, known{"-", motion_input::landmarks, "-"},
        known{"raw.jsonl", motion_input::landmarks, "raw"}}) {
    const motion_input_info* info = nullptr;
    std::string stem;
    const status st = find_motion_input(c.path, info, &stem);
    ASSERT_TRUE(st.ok()) << c.path << ": " << st.message();
    EXPECT_EQ(info->kind, c.kind) << c.path;
    EXPECT_EQ(stem, c.stem) << c.path;
  }
  test::temp_dir dir("motion_input");
  // Names that say nothing: the first bytes do.
  write_poses(dir.file("poses.json"), in_order(), 30.0);
  ASSERT_TRUE(write_vrma(dir.file("clip.glb"), in_order()).ok());
  write_landmarks(dir.file("marks.txt"), 2);
  test::write_text(dir.file("notes.txt"), "{\"format\":\"something else\"}\n");
  const struct {
    const char* name;
    motion_input kind;
  } sniffed[] = {{"poses.json", motion_input::poses},
                 {"clip.glb", motion_input::vrma},
                 {"marks.txt", motion_input::landmarks}};
  for (const auto& c : sniffed) {
    const motion_input_info* info = nullptr;
    std::string stem;
    const status st = find_motion_input(dir.file(c.name), info, &stem);
    ASSERT_TRUE(st.ok()) << c.name << ": " << st.message();
    EXPECT_EQ(info->kind, c.kind) << c.name;
    EXPECT_EQ(stem, dir.file(std::string(c.name).substr(0, std::string(c.name).find('.'))));
  }
  const motion_input_info* info = nullptr;
  status st = find_motion_input(dir.file("notes.txt"), info);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_EQ(st.message(), dir.file("notes.txt") +
                              ": unknown input type (give *.landmarks.jsonl, *.pose.jsonl, "
                              "*.vrma or *.bvh)");
  ASSERT_TRUE(find_motion_input("walk.BVH", info).ok());  // BVH motion: tests/rig/bvh_rig_test
  EXPECT_EQ(info->kind, motion_input::bvh);
  // A FIFO is never opened to look (it could be read only once, and would block here).
  const std::string fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_FALSE(find_motion_input(fifo, info).ok());
}

TEST_F(convert_file, frames_out_of_order_are_sorted_for_every_output_with_one_warning) {
  const std::string in = dir.file("ooo.pose.jsonl");
  write_poses(in, out_of_order(), 30.0);
  // The reference frames: the in-order clip through the same file format, read back by the
  // pose reader (no sorting involved).
  write_poses(dir.file("sorted.pose.jsonl"), in_order(), 30.0);
  std::vector<proxy_pose> sorted;
  {
    pose_reader r;
    ASSERT_TRUE(r.open(dir.file("sorted.pose.jsonl")).ok());
    proxy_pose p;
    while (r.next(p) == read_result::frame) sorted.push_back(p);
    ASSERT_EQ(sorted.size(), 12u);
  }
  for (const std::string ext : {".pose.jsonl", ".vrma", ".bvh"}) {
    for (double fps : {0.0, 30.0}) {
      const std::string out = (fps > 0.0 ? "fps30" : "own") + ext;
      warnings.clear();
      convert_file_summary s;
      const status st = job(in, out, fps).run(s);
      ASSERT_TRUE(st.ok()) << out << ": " << st.message();
      EXPECT_EQ(s.input->kind, motion_input::poses);
      EXPECT_EQ(s.frames_read, 12u);
      EXPECT_EQ(s.out_of_order, 2u);
      EXPECT_DOUBLE_EQ(s.t_first, 1.0);
      EXPECT_DOUBLE_EQ(s.source_fps, 30.0);
      ASSERT_EQ(warnings.size(), 1u) << out;
      EXPECT_EQ(warnings[0], "2 frame(s) of " + in + " were out of time order; sorted by time " +
                                 (fps > 0.0 ? "before resampling" : "before writing"));
      // The bytes clip_output_job writes of the frames in order.
      EXPECT_EQ(read_bytes(dir.file(out)), clip_bytes(sorted, "ref_" + out, fps, 30.0)) << out;
    }
  }
  // In order: no warning, the same bytes.
  warnings.clear();
  convert_file_summary s;
  ASSERT_TRUE(job(dir.file("sorted.pose.jsonl"), "b.pose.jsonl", 0.0).run(s).ok());
  EXPECT_EQ(s.out_of_order, 0u);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(read_bytes(dir.file("b.pose.jsonl")), read_bytes(dir.file("own.pose.jsonl")));
  EXPECT_EQ(read_bytes(dir.file("b.pose.jsonl")), read_bytes(dir.file("sorted.pose.jsonl")));
}

TEST_F(convert_file, a_vrma_in_converts_like_its_frames) {
  const std::string in = dir.file("clip.vrma");
  ASSERT_TRUE(write_vrma(in, in_order()).ok());
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(in, clip).ok());
  convert_file_summary s;
  const status st = job(in, "back.pose.jsonl", 0.0).run(s);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(s.input->kind, motion_input::vrma);
  EXPECT_EQ(s.frames_read, clip.frames.size());
  EXPECT_EQ(s.source_fps, 0.0);
  EXPECT_EQ(read_bytes(dir.file("back.pose.jsonl")),
            clip_bytes(clip.frames, "ref.pose.jsonl", 0.0, 0.0));
  // read_motion is the reader: the same frames.
  motion_clip read;
  ASSERT_TRUE(read_motion(in, nullptr, read).ok());
  ASSERT_EQ(read.frames.size(), clip.frames.size());
  for (std::size_t i = 0; i < read.frames.size(); ++i)
    EXPECT_EQ(read.frames[i].t, clip.frames[i].t);
}

TEST_F(convert_file, landmarks_are_solved_as_the_solve_job_solves_them) {
  const std::string in = dir.file("take.landmarks.jsonl");
  write_landmarks(in, 40);
  // The reference: solve_file_job writing the file itself.
  solve_file_job solve;
  solve.input = in;
  solve.output = dir.file("solved.pose.jsonl");
  solve_file_summary ss;
  ASSERT_TRUE(solve.run(ss).ok());
  convert_file_summary s;
  convert_file_job j = job(in, "converted.pose.jsonl", 0.0);
  const status st = j.run(s);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(s.input->kind, motion_input::landmarks);
  EXPECT_EQ(s.frames_read, 40u);
  EXPECT_EQ(s.solve.frames, 40);
  EXPECT_DOUBLE_EQ(s.source_fps, 30.0);
  EXPECT_EQ(read_bytes(dir.file("converted.pose.jsonl")), read_bytes(solve.output));
  EXPECT_TRUE(warnings.empty());
  // read_motion without a solve job refuses a landmark file.
  motion_clip read;
  const status refused = read_motion(in, nullptr, read);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.code(), status_code::invalid_argument);
  EXPECT_NE(refused.message().find("a landmark file"), std::string::npos);
}

TEST_F(convert_file, the_avatar_is_bound_only_for_outputs_that_use_it) {
  const std::string in = dir.file("in.pose.jsonl");
  write_poses(in, in_order(), 30.0);
  // .vrma and .pose.jsonl do not use the avatar: a missing one is not even opened.
  for (const char* out : {"x.vrma", "x.pose.jsonl"}) {
    convert_file_job j = job(in, out, 30.0);
    j.avatar = dir.file("missing.vrm");
    convert_file_summary s;
    const status st = j.run(s);
    ASSERT_TRUE(st.ok()) << out << ": " << st.message();
    EXPECT_EQ(s.avatar, nullptr);
  }
  // .glb binds it (bind_avatar) before reading the input: a missing avatar fails first.
  convert_file_job j = job(dir.file("missing.pose.jsonl"), "x.glb", 30.0);
  j.avatar = dir.file("missing.vrm");
  convert_file_summary s;
  status st = j.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::io);
  EXPECT_NE(st.message().find("missing.vrm"), std::string::npos);
  ASSERT_NE(s.avatar, nullptr);
  EXPECT_EQ(s.avatar->failed_step, bind_avatar_step::load);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.glb")));
  // The built-in avatar: bound by its VRM humanoid, the rig written.
  const std::string avatar = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(avatar).ok());
  j = job(in, "x.glb", 0.0);
  j.avatar = avatar;
  st = j.run(s);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_NE(s.avatar, nullptr);
  EXPECT_EQ(s.avatar->failed_step, bind_avatar_step::none);
  EXPECT_NE(s.avatar->description.find("VRM 1.0 humanoid"), std::string::npos);
  EXPECT_DOUBLE_EQ(s.output.fps, k_default_rig_fps);  // avatar outputs need a fixed rate
  EXPECT_EQ(s.output.frames_written, 12u);
}

TEST_F(convert_file, validate_names_what_is_wrong_before_any_file_is_read) {
  convert_file_job j = job("missing.pose.jsonl", "x.glb", 0.0);
  status st = j.validate();
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(), ".glb output needs an avatar (the model to animate)");
  j.avatar_name = "--avatar AVATAR";
  EXPECT_EQ(j.validate().message(), ".glb output needs --avatar AVATAR (the model to animate)");
  j = job("missing.pose.jsonl", "x.fbx", 0.0);
  st = j.validate();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("unknown output format"), std::string::npos);
  for (double fps : {-1.0, 1000.5, std::nan("")}) {
    j = job("missing.pose.jsonl", "x.vrma", fps);
    st = j.validate();
    ASSERT_FALSE(st.ok()) << fps;
    EXPECT_EQ(st.code(), status_code::invalid_argument);
    EXPECT_NE(st.message().find("fps"), std::string::npos);
  }
  j = job("missing.pose.jsonl", "x.vrma", 30.0);
  j.solve.threads = 3;
  EXPECT_FALSE(j.validate().ok());
  // Reading fails after validation, with the reader's code; nothing is written.
  j = job(dir.file("missing.pose.jsonl"), "x.vrma", 30.0);
  convert_file_summary s;
  st = j.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::io);
  test::write_text(dir.file("empty.pose.jsonl"), "");
  j = job(dir.file("empty.pose.jsonl"), "x.vrma", 30.0);
  st = j.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(), dir.file("empty.pose.jsonl") + " has no frames");
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.vrma")));
}

}  // namespace
}  // namespace avatarmap
