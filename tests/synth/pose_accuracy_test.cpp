// Known-answer tests of the accuracy measure (include/avatarmap/synth/pose_accuracy.hpp):
// identical poses give 0, a known rotation of one bone gives its angle, twist is not a
// direction error, the groups partition the bones, low-visibility frames are counted from the
// truth's marker, and the file comparison matches frames by time.
#include "avatarmap/synth/pose_accuracy.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

using namespace avatarmap;

namespace {

constexpr float k_deg = 3.14159265f / 180.f;

proxy_pose sample_pose(unsigned seed) {
  std::mt19937 rng(seed);
  proxy_pose p = random_pose(rng);
  p.confidence.fill(1.f);
  return p;
}

// Group by name, independently of the switch in pose_accuracy.cpp.
accuracy_group group_by_name(std::string_view n) {
  for (const char* f : {"Thumb", "Index", "Middle", "Ring", "Little"})
    if (n.find(f) != std::string_view::npos) return accuracy_group::fingers;
  for (const char* l : {"Leg", "Foot", "Toes"})
    if (n.find(l) != std::string_view::npos) return accuracy_group::legs;
  for (const char* a : {"Shoulder", "Arm", "Hand"})
    if (n.find(a) != std::string_view::npos) return accuracy_group::arms;
  if (n == "head" || n == "jaw" || n.find("Eye") != std::string_view::npos)
    return accuracy_group::head;
  return accuracy_group::torso;
}

void write_poses(const std::string& path, const std::vector<proxy_pose>& poses) {
  pose_writer w;
  pose_file_header h;
  h.present = true;
  pose_write_options o;
  o.write_confidence = true;
  ASSERT_TRUE(w.open(path, h, o).ok());
  for (const proxy_pose& p : poses) ASSERT_TRUE(w.write(p).ok());
  ASSERT_TRUE(w.commit().ok());
}

}  // namespace

TEST(PoseAccuracy, GroupsPartitionTheBones) {
  int counts[k_accuracy_group_count] = {};
  for (int b = 0; b < k_bone_count; ++b) {
    const bone bb = static_cast<bone>(b);
    EXPECT_EQ(bone_accuracy_group(bb), group_by_name(bone_name(bb))) << bone_name(bb);
    ++counts[static_cast<int>(bone_accuracy_group(bb))];
  }
  EXPECT_EQ(counts[static_cast<int>(accuracy_group::torso)], 5);
  EXPECT_EQ(counts[static_cast<int>(accuracy_group::arms)], 8);
  EXPECT_EQ(counts[static_cast<int>(accuracy_group::legs)], 8);
  EXPECT_EQ(counts[static_cast<int>(accuracy_group::fingers)], 30);
  EXPECT_EQ(counts[static_cast<int>(accuracy_group::head)], 4);
  EXPECT_STREQ(accuracy_group_name(accuracy_group::fingers), "fingers");

  // One frame: every measured bone is counted once, in its group and in the overall figure.
  pose_accuracy acc;
  const proxy_pose p = sample_pose(1);
  accumulate_pose_accuracy(p, p, acc);
  long sum = 0;
  for (int g = 0; g < k_direction_group_count; ++g) {
    EXPECT_EQ(acc.all.groups[g].count, counts[g]);
    sum += acc.all.groups[g].count;
  }
  EXPECT_EQ(acc.all.direction.count, sum);
  EXPECT_EQ(sum, k_bone_count - 4);
  EXPECT_EQ(acc.all.head.count, 1);
}

TEST(PoseAccuracy, IdenticalPosesGiveZero) {
  pose_accuracy acc;
  for (unsigned s = 1; s <= 20; ++s) {
    const proxy_pose p = sample_pose(s);
    proxy_pose q = p;
    for (glm::quat& r : q.rotations) r = -r;       // the other cover: the same rotations
    q.hips_position += glm::vec3(3.f, 0.f, -2.f);  // not measured
    accumulate_pose_accuracy(p, q, acc);
  }
  EXPECT_EQ(acc.frames, 20);
  EXPECT_EQ(acc.low_visibility_frames, 0);
  EXPECT_LT(acc.all.direction.max, 1e-3);
  EXPECT_LT(acc.all.head.max, 1e-3);
  EXPECT_EQ(acc.marked.count, 0);
}

TEST(PoseAccuracy, OneRotatedLeafGivesItsAngle) {
  const proxy_pose truth = sample_pose(3);
  proxy_pose solved = truth;
  // Left distal bones point along +X at rest: a 30 degree turn about their local Z moves the
  // direction by exactly 30 degrees, and no other bone.
  solved[bone::left_index_distal] =
      solved[bone::left_index_distal] * axis_angle(glm::vec3(0.f, 0.f, 1.f), 30.f * k_deg);
  pose_accuracy acc;
  accumulate_pose_accuracy(truth, solved, acc);
  EXPECT_NEAR(acc.all.direction.max, 30.0, 1e-3);
  const int fingers = static_cast<int>(accuracy_group::fingers);
  EXPECT_NEAR(acc.all.groups[fingers].mean(), 30.0 / 30.0, 1e-4);
  EXPECT_NEAR(acc.all.direction.mean(), 30.0 / 51.0, 1e-4);
  EXPECT_NEAR(acc.all.groups[static_cast<int>(accuracy_group::arms)].max, 0.0, 1e-3);
  EXPECT_NEAR(acc.all.head.max, 0.0, 1e-3);
}

TEST(PoseAccuracy, TwistIsNoDirectionErrorAndAParentMovesItsChildren) {
  const proxy_pose truth = sample_pose(4);
  // A 40 degree twist of the left lower leg about its own rest direction, undone at the foot:
  // every bone's world direction is unchanged, so the measure is 0 although a rotation differs.
  const glm::vec3 shin = bone_rest_direction(bone::left_lower_leg);
  const glm::quat twist = axis_angle(shin, 40.f * k_deg);
  proxy_pose twisted = truth;
  twisted[bone::left_lower_leg] = truth[bone::left_lower_leg] * twist;
  twisted[bone::left_foot] = glm::inverse(twist) * truth[bone::left_foot];
  pose_accuracy acc;
  accumulate_pose_accuracy(truth, twisted, acc);
  EXPECT_LT(acc.all.direction.max, 1e-3);

  // Not undone at the foot: the shin is still exact, the foot (rest direction not along the
  // shin) swings around it, so the legs' error is positive and the shin's sample is 0.
  proxy_pose swung = truth;
  swung[bone::left_lower_leg] = truth[bone::left_lower_leg] * twist;
  pose_accuracy moved;
  accumulate_pose_accuracy(truth, swung, moved);
  EXPECT_GT(moved.all.groups[static_cast<int>(accuracy_group::legs)].max, 5.0);
  // Foot and toes moved, the other 6 leg samples did not: at most 2 non-zero samples, each at
  // most 40 degrees.
  EXPECT_LE(moved.all.groups[static_cast<int>(accuracy_group::legs)].sum, 2 * 40.0 + 1e-3);

  // A head turned by 20 degrees: head error 20, no direction error.
  proxy_pose turned = truth;
  turned[bone::head] = turned[bone::head] * axis_angle(glm::vec3(0.f, 1.f, 0.f), 20.f * k_deg);
  pose_accuracy head;
  accumulate_pose_accuracy(truth, turned, head);
  EXPECT_NEAR(head.all.head.mean(), 20.0, 1e-3);
  EXPECT_NEAR(head.all.direction.max, 0.0, 1e-3);
}

TEST(PoseAccuracy, LowVisibilityComesFromTheTruthMarker) {
  proxy_pose truth = sample_pose(5);
  proxy_pose solved = truth;
  solved[bone::left_hand] =
      solved[bone::left_hand] * axis_angle(glm::vec3(0.f, 0.f, 1.f), 10.f * k_deg);
  pose_accuracy acc;
  accumulate_pose_accuracy(truth, solved, acc);  // a visible frame
  for (bone b : {bone::left_upper_arm, bone::left_lower_arm, bone::left_hand})
    truth.confidence[idx(b)] = 0.f;
  accumulate_pose_accuracy(truth, solved, acc);  // a low-visibility frame
  EXPECT_EQ(acc.frames, 2);
  EXPECT_EQ(acc.low_visibility_frames, 1);
  EXPECT_EQ(acc.low_visibility.direction.count, 51);
  EXPECT_EQ(acc.low_visibility.head.count, 1);
  EXPECT_EQ(acc.marked.count, 3);
  // The hand turned 10 degrees about its local Z (perpendicular to its +X rest direction);
  // upper and lower arm are exact: marked mean 10 / 3.
  EXPECT_NEAR(acc.marked.mean(), 10.0 / 3.0, 1e-3);
  EXPECT_NEAR(acc.low_visibility.groups[static_cast<int>(accuracy_group::arms)].max, 10.0, 1e-3);
}

TEST(PoseAccuracy, FilesAreMatchedByTime) {
  avatarmap::test::temp_dir dir("pose_accuracy");
  std::vector<proxy_pose> truth, solved;
  for (int i = 0; i < 10; ++i) {
    proxy_pose p = sample_pose(10 + i);
    p.t = i / 30.0;
    truth.push_back(p);
    proxy_pose s = p;
    s[bone::left_index_distal] =
        s[bone::left_index_distal] * axis_angle(glm::vec3(0.f, 0.f, 1.f), 12.f * k_deg);
    solved.push_back(s);
  }
  // Solved frames between the truth frames are ignored.
  std::vector<proxy_pose> with_extra;
  for (const proxy_pose& s : solved) {
    with_extra.push_back(s);
    proxy_pose mid = sample_pose(99);
    mid.t = s.t + 0.5 / 30.0;
    with_extra.push_back(mid);
  }
  write_poses(dir.file("truth.pose.jsonl"), truth);
  write_poses(dir.file("solved.pose.jsonl"), with_extra);
  pose_accuracy acc;
  status st = evaluate_pose_files(dir.file("truth.pose.jsonl"), dir.file("solved.pose.jsonl"), acc);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(acc.frames, 10);
  EXPECT_NEAR(acc.all.direction.max, 12.0, 1e-3);
  EXPECT_NEAR(acc.all.direction.mean(), 12.0 / 51.0, 1e-3);

  // A missing frame is an error that counts them; the others are still measured.
  std::vector<proxy_pose> gap = solved;
  gap.erase(gap.begin() + 4);
  write_poses(dir.file("gap.pose.jsonl"), gap);
  st = evaluate_pose_files(dir.file("truth.pose.jsonl"), dir.file("gap.pose.jsonl"), acc);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("1 of 10 frames"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("gap.pose.jsonl"), std::string::npos) << st.message();
  EXPECT_EQ(acc.frames, 9);

  // Times going back are an error naming the file.
  std::vector<proxy_pose> back = solved;
  std::swap(back[2], back[3]);
  write_poses(dir.file("back.pose.jsonl"), back);
  st = evaluate_pose_files(dir.file("truth.pose.jsonl"), dir.file("back.pose.jsonl"), acc);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("back.pose.jsonl"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("not after"), std::string::npos) << st.message();

  // An empty truth, and a missing file.
  write_poses(dir.file("empty.pose.jsonl"), {});
  st = evaluate_pose_files(dir.file("empty.pose.jsonl"), dir.file("solved.pose.jsonl"), acc);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("no frames"), std::string::npos) << st.message();
  st = evaluate_pose_files(dir.file("absent.pose.jsonl"), dir.file("solved.pose.jsonl"), acc);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("absent.pose.jsonl"), std::string::npos) << st.message();
}

// A bone turning at a constant rate w about an axis across it: its direction's acceleration is
// the centripetal w^2 (radians per second squared); bones that do not move give 0.
TEST(PoseJitter, ConstantTurnGivesTheCentripetalAcceleration) {
  avatarmap::test::temp_dir dir("pose_jitter");
  const double w = 2.0, dt = 0.01;
  std::vector<proxy_pose> poses;
  for (int i = 0; i < 200; ++i) {
    proxy_pose p;
    p.set_rest();
    p.t = i * dt;
    p[bone::left_upper_arm] = axis_angle(glm::vec3(0.f, 0.f, 1.f), static_cast<float>(w * p.t));
    poses.push_back(p);
  }
  const std::string path = dir.file("turn.pose.jsonl");
  write_poses(path, poses);
  pose_jitter j;
  ASSERT_TRUE(measure_pose_jitter(path, j).ok());
  EXPECT_EQ(j.frames, 200);
  // The upper arm, lower arm and hand of the left arm move rigidly (their rest directions lie
  // across the z axis); the shoulders and the right arm stay: 3 of the arms group's 8 bones.
  const double deg = w * w * 180.0 / 3.14159265358979323846;
  EXPECT_NEAR(j.groups[static_cast<int>(accuracy_group::arms)], deg * std::sqrt(3.0 / 8.0),
              deg * 1e-3);
  EXPECT_NEAR(j.groups[static_cast<int>(accuracy_group::legs)], 0.0, 1e-6);
  EXPECT_NEAR(j.groups[static_cast<int>(accuracy_group::torso)], 0.0, 1e-6);
  // Per bone: each moving bone of the left arm has the whole w^2; the rest 0.
  for (bone b : {bone::left_upper_arm, bone::left_lower_arm, bone::left_hand})
    EXPECT_NEAR(j.bones[idx(b)], deg, deg * 1e-3) << bone_name(b);
  for (bone b : {bone::right_upper_arm, bone::left_shoulder, bone::hips, bone::left_upper_leg})
    EXPECT_NEAR(j.bones[idx(b)], 0.0, 1e-6) << bone_name(b);
}

TEST(PoseJitter, RefusesShortFilesAndTimesGoingBack) {
  avatarmap::test::temp_dir dir("pose_jitter");
  std::vector<proxy_pose> poses(2);
  poses[0].set_rest();
  poses[1].set_rest();
  poses[1].t = 0.1;
  const std::string path = dir.file("short.pose.jsonl");
  write_poses(path, poses);
  pose_jitter j;
  const status st = measure_pose_jitter(path, j);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("fewer than three frames"), std::string::npos) << st.message();
  poses.push_back(poses[0]);  // t = 0 after t = 0.1
  write_poses(path, poses);
  const status back = measure_pose_jitter(path, j);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.message().find("not after the previous frame"), std::string::npos)
      << back.message();
}
