// Several people in one landmark file (jobs/people.hpp, docs/file-formats.md "Version 2"): the
// output names, the runs planned for a file, and the solve job reading one person's lines: a
// person's poses out of a file of two are bit for bit those of a file of that person alone, the
// root measured from where the file's first person was first seen.
#include "avatarmap/jobs/people.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;

// Frames of one synthetic person (its own seed and place), 40 frames.
std::vector<landmark_frame> person_frames(std::uint32_t seed, float x) {
  synth_options o;
  o.seed = seed;
  landmark_synth synth(o);
  std::vector<landmark_frame> out(40);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double t = static_cast<double>(i) / k_fps;
    proxy_pose p = demo_motion_pose(t + seed, synth.skeleton());
    p.hips_position.x += x;
    synth.generate(p, out[i]);
    out[i].t = t;
  }
  return out;
}

void write(const std::string& path, int version,
           const std::vector<std::pair<int, const std::vector<landmark_frame>*>>& people) {
  landmark_file_header h;
  h.version = version;
  h.image_width = 1280;
  h.image_height = 720;
  h.fps = k_fps;
  landmark_writer w;
  ASSERT_TRUE(w.open(path, h).ok());
  for (std::size_t i = 0; i < people.front().second->size(); ++i)
    for (const auto& [id, frames] : people) {
      landmark_frame f = (*frames)[i];
      f.person = id;
      ASSERT_TRUE(w.write(f).ok());
    }
  ASSERT_TRUE(w.commit().ok());
}

std::vector<proxy_pose> solve(const std::string& input, int person, status* out_status = nullptr) {
  solve_file_job job;
  job.input = input;
  job.person = person;
  std::vector<proxy_pose> got;
  job.sink = [&got](const proxy_pose& p) {
    got.push_back(p);
    return status{};
  };
  solve_file_summary s;
  const status st = job.run(s);
  if (out_status != nullptr)
    *out_status = st;
  else
    EXPECT_TRUE(st.ok()) << st.message();
  return got;
}

TEST(people, output_names_carry_the_person_before_the_extension) {
  EXPECT_EQ(person_output_path("take.glb", 0), "take.p0.glb");
  EXPECT_EQ(person_output_path("dir.v2/take.vrma", 12), "dir.v2/take.p12.vrma");
  EXPECT_EQ(person_output_path("take.pose.jsonl", 3), "take.p3.pose.jsonl");
  EXPECT_EQ(person_output_path("a/b.landmarks.jsonl", 1), "a/b.p1.landmarks.jsonl");
  EXPECT_EQ(person_output_path("take", 2), "take.p2");
  EXPECT_EQ(person_output_path("dir.v2/take", 2), "dir.v2/take.p2");
  EXPECT_EQ(person_output_path(".pose.jsonl", 2), ".pose.p2.jsonl");
}

// Each person of a file of two is solved as alone, its root measured from where the file's
// first person was first seen: the two stand apart as the synthetic scene placed them.
TEST(people, a_persons_poses_from_a_file_of_two_are_those_of_that_person_alone) {
  test::temp_dir dir{"people"};
  const std::vector<landmark_frame> a = person_frames(3, -0.5f), b = person_frames(4, 0.6f);
  const std::string two = dir.file("two.landmarks.jsonl"), only_a = dir.file("a.landmarks.jsonl"),
                    only_b = dir.file("b.landmarks.jsonl");
  write(two, 2, {{0, &a}, {7, &b}});
  write(only_a, 1, {{0, &a}});
  write(only_b, 2, {{7, &b}});  // one person, version 2

  const std::vector<proxy_pose> want_a = solve(only_a, -1), want_b = solve(only_b, -1);
  ASSERT_EQ(want_a.size(), 40u);
  ASSERT_EQ(want_b.size(), 40u);
  const std::vector<proxy_pose> got_a = solve(two, 0), got_b = solve(two, 7);
  ASSERT_EQ(got_a.size(), 40u);
  ASSERT_EQ(got_b.size(), 40u);
  const glm::vec3 shift = got_b[0].hips_position - want_b[0].hips_position;
  for (std::size_t i = 0; i < 40; ++i) {
    EXPECT_EQ(got_a[i].rotations, want_a[i].rotations) << i;
    EXPECT_EQ(got_a[i].hips_position, want_a[i].hips_position) << i;
    EXPECT_EQ(got_a[i].blendshapes, want_a[i].blendshapes) << i;
    EXPECT_EQ(got_b[i].rotations, want_b[i].rotations) << i;
    // b's root: b alone's, moved on the ground by one constant.
    EXPECT_NEAR(got_b[i].hips_position.x - want_b[i].hips_position.x, shift.x, 1e-5f) << i;
    EXPECT_EQ(got_b[i].hips_position.y, want_b[i].hips_position.y) << i;
    EXPECT_NEAR(got_b[i].hips_position.z - want_b[i].hips_position.z, shift.z, 1e-5f) << i;
  }
  // The constant is where b first stood from where a did, as the scene placed them: hips 0.6 m
  // and -0.5 m to the side, plus each one's own motion at its first frame.
  synth_options so;
  const float truth_x =
      (0.6f + demo_motion_pose(4.0, landmark_synth(so).skeleton()).hips_position.x) -
      (-0.5f + demo_motion_pose(3.0, landmark_synth(so).skeleton()).hips_position.x);
  std::printf("b stands %.3f m beside a (the scene: %.3f m); %.3f m apart in depth\n", shift.x,
              truth_x, shift.z);
  EXPECT_NEAR(shift.x, truth_x, 0.05f);
  EXPECT_LT(std::abs(shift.z), 0.3f);
  // The two people are not the same poses (the test would pass on one person's lines twice).
  EXPECT_NE(got_a[20].rotations, got_b[20].rotations);

  // Without a person, a file of two is refused, naming its people.
  status st;
  EXPECT_TRUE(solve(two, -1, &st).empty());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("has 2 people (0, 7)"), std::string::npos) << st.message();

  // The runs planned: one per person with its own output; one person asked for, or a file
  // of one, keeps the name; an absent person and shared standard output are refused.
  std::vector<person_run> runs;
  ASSERT_TRUE(plan_person_runs(two, -1, "out.glb", runs).ok());
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].person, 0);
  EXPECT_EQ(runs[0].output, "out.p0.glb");
  EXPECT_EQ(runs[1].person, 7);
  EXPECT_EQ(runs[1].output, "out.p7.glb");
  ASSERT_TRUE(plan_person_runs(two, 7, "out.glb", runs).ok());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].output, "out.glb");
  ASSERT_TRUE(plan_person_runs(only_a, -1, "out.glb", runs).ok());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].person, 0);
  EXPECT_EQ(runs[0].output, "out.glb");
  ASSERT_TRUE(plan_person_runs(only_b, -1, "-", runs).ok());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].person, 7);
  st = plan_person_runs(two, 3, "out.glb", runs);
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("no person 3 (its people: 0, 7)"), std::string::npos) << st.message();
  st = plan_person_runs(two, -1, "-", runs);
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  // A path that is no regular file (absent, a pipe) is read once by the job, which reports
  // what it finds there.
  ASSERT_TRUE(plan_person_runs(dir.file("absent.landmarks.jsonl"), -1, "o.glb", runs).ok());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].person, -1);
}

}  // namespace
}  // namespace avatarmap
