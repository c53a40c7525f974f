// The world benchmark: landmarks from motion capture (jobs/mocap_synth.hpp) and the scorer
// (jobs/world_score.hpp), against known answers worked out by hand on a small BVH written
// here, and on the CMU clips when AVATARMAP_TEST_DATA is set.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/jobs/mocap_synth.hpp"
#include "avatarmap/jobs/world_score.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using mp = mocap_point;

// A standing performer (metres, Y up, facing +Z, left at +X) whose left arm swings about Z;
// the feet never move. 60 frames at 30 fps. `with_legs` false leaves the legs out.
std::string small_bvh(bool with_legs = true, const char* bad_value = nullptr) {
  std::ostringstream s;
  auto leg = [&](const char* side, float x) {
    s << "JOINT " << side << "UpLeg\n{\nOFFSET " << x << " -0.05 0\nCHANNELS 3 Zrotation Xrotation "
      << "Yrotation\nJOINT " << side << "Leg\n{\nOFFSET 0 -0.45 0\nCHANNELS 3 Zrotation Xrotation "
      << "Yrotation\nJOINT " << side << "Foot\n{\nOFFSET 0 -0.42 0\nCHANNELS 3 Zrotation "
      << "Xrotation Yrotation\nJOINT " << side << "ToeBase\n{\nOFFSET 0 -0.06 0.12\nCHANNELS 3 "
      << "Zrotation Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 0 0.05\n}\n}\n}\n}\n}\n";
  };
  auto arm = [&](const char* side, float x) {
    s << "JOINT " << side << "Arm\n{\nOFFSET " << x << " 0 0\nCHANNELS 3 Zrotation Xrotation "
      << "Yrotation\nJOINT " << side << "ForeArm\n{\nOFFSET " << (x > 0 ? 0.28 : -0.28)
      << " 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nJOINT " << side << "Hand\n{\nOFFSET "
      << (x > 0 ? 0.25 : -0.25) << " 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\n"
      << "OFFSET " << (x > 0 ? 0.08 : -0.08) << " 0 0\n}\n}\n}\n}\n";
  };
  s << "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition "
       "Zrotation Xrotation Yrotation\n";
  if (with_legs) {
    leg("Left", 0.1f);
    leg("Right", -0.1f);
  }
  s << "JOINT Spine\n{\nOFFSET 0 0.1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
       "JOINT Neck\n{\nOFFSET 0 0.4 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  arm("Left", 0.18f);
  arm("Right", -0.18f);
  s << "JOINT Head\n{\nOFFSET 0 0.1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\n"
       "OFFSET 0 0.2 0\n}\n}\n}\n}\n}\n";
  const int joints = with_legs ? 17 : 9;  // after the root
  s << "MOTION\nFrames: 60\nFrame Time: 0.0333333333\n";
  for (int f = 0; f < 60; ++f) {
    s << "0 1 0 0 0 0";
    for (int j = 0; j < joints; ++j) {
      // The left arm (after Spine, Neck) swings: 30 degrees * sin(2 pi t) about Z.
      const int left_arm = with_legs ? 10 : 2;
      if (j == left_arm)
        s << " " << 30.0 * std::sin(2 * 3.14159265358979 * f / 30.0) << " 0 0";
      else if (bad_value && f == 7 && j == 0)
        s << " " << bad_value << " 0 0";
      else
        s << " 0 0 0";
    }
    s << "\n";
  }
  return s.str();
}

mocap_camera_setup front_camera(float pitch = 0.f, float roll = 0.f) {
  mocap_camera_setup c;
  c.height = 0.93f;  // the hip sockets' height (0.95) above the floor (0.02): level with the hips
  c.distance = 3.f;
  c.lateral = 0.f;
  c.pitch_degrees = pitch;
  c.roll_degrees = roll;
  c.fov_degrees = 60.f;
  return c;
}

TEST(world_benchmark, take_points_from_the_bvh) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  EXPECT_EQ(take.frame_count(), 60);
  // Frame 0 is the rest pose with the root at (0, 1, 0) (rest(): the root at its OFFSET, 0).
  const mocap_frame& r = take.frame(0);
  EXPECT_NEAR(take.rest()[mp::hip_mid].y, -0.05f, 1e-6f);
  // By hand: hip sockets at (+-0.1, 0.95, 0), ankles at 0.08, toe tip at (0.1, 0.02, 0.17).
  EXPECT_NEAR(r[mp::hip_mid].y, 0.95f, 1e-6f);
  EXPECT_NEAR(r[mp::left_hip].x, 0.1f, 1e-6f);
  EXPECT_NEAR(r[mp::left_ankle].y, 0.08f, 1e-6f);
  EXPECT_NEAR(r[mp::left_toe_tip].z, 0.17f, 1e-6f);
  EXPECT_NEAR(r[mp::left_toe_tip].y, 0.02f, 1e-6f);
  // Heel: at the toe tip's level, a quarter of |ankle -> toe tip| behind the ankle.
  EXPECT_NEAR(r[mp::left_heel].y, 0.02f, 1e-6f);
  EXPECT_NEAR(r[mp::left_heel].z, -0.25f * std::sqrt(0.06f * 0.06f + 0.17f * 0.17f), 1e-6f);
  EXPECT_NEAR(r[mp::left_shoulder].x, 0.18f, 1e-6f);
  EXPECT_NEAR(r[mp::left_hand_tip].x, 0.79f, 1e-6f);
  EXPECT_NEAR(r[mp::head_top].y, 1.8f, 1e-6f);
  EXPECT_NEAR(take.floor_y(), 0.02f, 1e-6f);
  EXPECT_NEAR(take.rest_height(), 1.78f, 1e-5f);
  // Frame 7: the left arm turned by 30 sin(2 pi 7/30) degrees about Z at the shoulder.
  const float a = 30.f * std::sin(2.f * 3.14159265f * 7.f / 30.f) * 3.14159265f / 180.f;
  const mocap_frame& f = take.frame(7);
  EXPECT_NEAR(f[mp::left_elbow].x, 0.18f + 0.28f * std::cos(a), 1e-5f);
  EXPECT_NEAR(f[mp::left_elbow].y, 1.5f + 0.28f * std::sin(a), 1e-5f);
}

TEST(world_benchmark, camera_axis_projects_to_the_image_centre) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  for (float pitch : {-25.f, 0.f, 15.f})
    for (float roll : {-8.f, 0.f, 5.f}) {
      const mocap_camera cam = place_mocap_camera(take, front_camera(pitch, roll));
      const glm::vec3 on_axis = cam.position + cam.world_from_camera * glm::vec3(0.f, 0.f, 3.f);
      const glm::vec2 uv = cam.project(cam.to_camera(on_axis));
      EXPECT_NEAR(uv.x, 0.5f, 1e-5f);
      EXPECT_NEAR(uv.y, 0.5f, 1e-5f);
    }
  // A level camera at the hips' height, 3 m in front: it stands at (0, 0.95, 3).
  const mocap_camera cam = place_mocap_camera(take, front_camera());
  EXPECT_NEAR(cam.position.x, 0.f, 1e-5f);
  EXPECT_NEAR(cam.position.y, 0.95f, 1e-5f);
  EXPECT_NEAR(cam.position.z, 3.f, 1e-5f);
  // 60 degrees horizontal on 1280 pixels: focal 640 / tan 30.
  EXPECT_NEAR(cam.focal_pixels(), 640.f / std::tan(3.14159265f / 6.f), 1e-3f);
}

TEST(world_benchmark, drawn_cameras_stay_in_their_ranges) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  for (unsigned seed = 0; seed < 200; ++seed) {
    mocap_camera_setup setup;
    setup.seed = seed;
    const mocap_camera c = place_mocap_camera(take, setup);
    EXPECT_GE(c.height, 0.5f);
    EXPECT_LE(c.height, 2.f);
    EXPECT_GE(c.distance, 2.5f);
    EXPECT_LE(c.distance, 5.f);
    EXPECT_GE(c.lateral, -1.f);
    EXPECT_LE(c.lateral, 1.f);
    EXPECT_GE(c.horizontal_fov_degrees, 40.f);
    EXPECT_LE(c.horizontal_fov_degrees, 90.f);
    EXPECT_GE(c.pitch_degrees, -30.f);
    EXPECT_LE(c.pitch_degrees, 20.f);
    EXPECT_GE(c.roll_degrees, -8.f);
    EXPECT_LE(c.roll_degrees, 8.f);
    // The camera stands where it says: height above the floor, distance + lateral from the
    // mean hips (the performer faces +Z, left +X).
    EXPECT_NEAR(c.position.y, take.floor_y() + c.height, 1e-5f);
    EXPECT_NEAR(c.position.z, c.distance, 1e-5f);
    EXPECT_NEAR(c.position.x, c.lateral, 1e-5f);
    // Fixing one option leaves the other draws as they were.
    setup.fov_degrees = 55.f;
    const mocap_camera d = place_mocap_camera(take, setup);
    EXPECT_EQ(d.horizontal_fov_degrees, 55.f);
    EXPECT_EQ(d.height, c.height);
    EXPECT_EQ(d.roll_degrees, c.roll_degrees);
  }
}

TEST(world_benchmark, clean_world_points_are_the_joints_in_camera_axes) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  const mocap_camera cam = place_mocap_camera(take, front_camera());
  mocap_landmark_synth synth(take, cam, mocap_synth_options::preset(mocap_scenario::clean, 1));
  EXPECT_EQ(synth.lean_degrees(), 0.f);
  landmark_frame lf;
  const double t = 7.0 / 30.0;
  synth.generate(t, lf);
  const mocap_frame& f = take.frame(7);
  // The camera faces the performer (looking along -Z): camera x = world +X (the performer's
  // left at image right), y = -Y, z = -Z. So a world point is (dX, -dY, -dZ) from the hips.
  const struct {
    int landmark;
    mp point;
  } pairs[] = {{11, mp::left_shoulder}, {13, mp::left_elbow},  {16, mp::right_wrist},
               {23, mp::left_hip},      {26, mp::right_knee},  {27, mp::left_ankle},
               {30, mp::right_heel},    {31, mp::left_toe_tip}};
  for (const auto& p : pairs) {
    const glm::vec3 d = f[p.point] - f[mp::hip_mid];
    const landmark& w = lf.pose_world[p.landmark];
    EXPECT_NEAR(w.x, d.x, 1e-4f) << p.landmark;
    EXPECT_NEAR(w.y, -d.y, 1e-4f) << p.landmark;
    EXPECT_NEAR(w.z, -d.z, 1e-4f) << p.landmark;
  }
  // The performer's left hip is at image right; the hips at the image centre's height.
  EXPECT_GT(lf.pose[23].x, 0.5f);
  EXPECT_LT(lf.pose[24].x, 0.5f);
  EXPECT_NEAR(0.5f * (lf.pose[23].y + lf.pose[24].y), 0.5f, 1e-5f);
}

TEST(world_benchmark, pitch_and_roll_turn_the_right_way) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  const auto clean = mocap_synth_options::preset(mocap_scenario::clean, 1);
  landmark_frame level, up, down, rolled;
  mocap_landmark_synth(take, place_mocap_camera(take, front_camera()), clean).generate(0, level);
  mocap_landmark_synth(take, place_mocap_camera(take, front_camera(10.f)), clean).generate(0, up);
  mocap_landmark_synth(take, place_mocap_camera(take, front_camera(-10.f)), clean)
      .generate(0, down);
  mocap_landmark_synth(take, place_mocap_camera(take, front_camera(0.f, 10.f)), clean)
      .generate(0, rolled);
  for (const landmark_frame* f : {&level, &up, &down, &rolled})
    EXPECT_LT(f->pose[11].y, f->pose[23].y);  // the shoulder above the hip in every image
  // A camera pitched up sees the hips lower in the image; pitched down, higher.
  EXPECT_GT(up.pose[23].y, level.pose[23].y);
  EXPECT_LT(down.pose[23].y, level.pose[23].y);
  // Positive roll turns the camera's x toward its y: the image-right side rises.
  EXPECT_NEAR(level.pose[23].y, level.pose[24].y, 1e-6f);
  EXPECT_LT(rolled.pose[23].y, rolled.pose[24].y);
}

TEST(world_benchmark, world_points_lean_toward_the_camera) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  const mocap_camera cam = place_mocap_camera(take, front_camera());
  auto o = mocap_synth_options::preset(mocap_scenario::clean, 1);
  o.lean_degrees = 20.f;
  landmark_frame clean, leaned;
  mocap_landmark_synth(take, cam, mocap_synth_options::preset(mocap_scenario::clean, 1))
      .generate(0, clean);
  mocap_landmark_synth(take, cam, o).generate(0, leaned);
  // The shoulders' midpoint (on the camera's y-z plane here) turns by the whole lean.
  auto mid = [](const landmark_frame& f) {
    return 0.5f * glm::vec3(f.pose_world[11].x + f.pose_world[12].x,
                            f.pose_world[11].y + f.pose_world[12].y,
                            f.pose_world[11].z + f.pose_world[12].z);
  };
  const glm::vec3 a = mid(clean), b = mid(leaned);
  EXPECT_NEAR(std::acos(glm::dot(glm::normalize(a), glm::normalize(b))) * 180.f / 3.14159265f, 20.f,
              1e-3f);
  EXPECT_LT(b.z, a.z);  // closer to the camera
  // The image points do not lean.
  EXPECT_FLOAT_EQ(clean.pose[11].y, leaned.pose[11].y);
  // The preset draws the lean in 10..25 degrees.
  for (unsigned seed = 1; seed < 20; ++seed) {
    mocap_landmark_synth s(take, cam, mocap_synth_options::preset(mocap_scenario::blazepose, seed));
    EXPECT_GE(s.lean_degrees(), 10.f);
    EXPECT_LE(s.lean_degrees(), 25.f);
  }
}

world_take take_as_solved(const mocap_take& take) {
  world_take w;
  for (int i = 0; i < take.frame_count(); ++i) {
    w.t.push_back(i * take.frame_time());
    w.frames.push_back(take.frame(i));
  }
  return w;
}

TEST(world_benchmark, scorer_known_answers) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  world_scores s;
  // The same file, read as a solved BVH: zero everywhere.
  world_take same;
  ASSERT_TRUE(read_world_take_bvh(path, 1.f, same).ok());
  ASSERT_TRUE(score_world(take, same, {}, s).ok());
  EXPECT_EQ(s.frames, 60);
  EXPECT_GT(s.planted, 0);
  EXPECT_NEAR(s.mpjpe_mm, 0, 1e-3);
  EXPECT_NEAR(s.pa_mpjpe_mm, 0, 1e-3);
  EXPECT_NEAR(s.lean_deg, 0, 1e-3);
  EXPECT_NEAR(s.accel_mm, 0, 1e-3);
  EXPECT_NEAR(s.root_cm, 0, 1e-4);
  EXPECT_NEAR(s.skate_cm_s, 0, 1e-4);
  EXPECT_NEAR(s.truth_skate_cm_s, 0, 1e-4);
  EXPECT_NEAR(s.penetration_cm, 0, 1e-6);
  EXPECT_NEAR(s.lowest_toe_cm, 2.0, 1e-4);
  // Shifted by 10 cm (and turned 90 degrees about Y): hips-relative figures and the aligned
  // root are still zero.
  world_take moved = take_as_solved(take);
  for (mocap_frame& f : moved.frames)
    for (glm::vec3& p : f.p) p = glm::vec3(p.z, p.y, -p.x) + glm::vec3(0.1f, 0.f, 0.f);
  ASSERT_TRUE(score_world(take, moved, {}, s).ok());
  EXPECT_NEAR(s.mpjpe_mm, 0, 1e-3);
  EXPECT_NEAR(s.root_cm, 0, 1e-4);
  // Scaled by 1.1 about the hips: Procrustes removes it, MPJPE does not.
  world_take scaled = take_as_solved(take);
  for (mocap_frame& f : scaled.frames) {
    const glm::vec3 h = f[mp::hip_mid];
    for (glm::vec3& p : f.p) p = h + 1.1f * (p - h);
  }
  ASSERT_TRUE(score_world(take, scaled, {}, s).ok());
  EXPECT_NEAR(s.pa_mpjpe_mm, 0, 1e-2);
  EXPECT_GT(s.mpjpe_mm, 10);
  // The whole body sliding at 10 cm/s along X while the truth's feet are planted: skate 10.
  world_take sliding = take_as_solved(take);
  for (std::size_t i = 0; i < sliding.frames.size(); ++i)
    for (glm::vec3& p : sliding.frames[i].p) p.x += 0.1f * static_cast<float>(sliding.t[i]);
  ASSERT_TRUE(score_world(take, sliding, {}, s).ok());
  EXPECT_NEAR(s.skate_cm_s, 10.0, 1e-3);
  EXPECT_NEAR(s.mpjpe_mm, 0, 1e-3);
  // Sunk 3 cm: toe tips and heels (0.02 above Y = 0) are 1 cm under the floor.
  world_take sunk = take_as_solved(take);
  for (mocap_frame& f : sunk.frames)
    for (glm::vec3& p : f.p) p.y -= 0.03f;
  world_score_options feet;
  feet.feet_only = true;
  ASSERT_TRUE(score_world(take, sunk, feet, s).ok());
  EXPECT_NEAR(s.penetration_cm, 1.0, 1e-3);
  EXPECT_NEAR(s.lowest_toe_cm, -1.0, 1e-3);
}

TEST(world_benchmark, proxy_poses_at_rest_match_the_truth_rest) {
  test::temp_dir dir("world");
  const std::string path = dir.file("small.bvh");
  test::write_text(path, small_bvh());
  mocap_take take;
  ASSERT_TRUE(take.load(path, 1.f).ok());
  const proxy_skeleton sk = proxy_skeleton_like(take);
  proxy_pose rest;
  rest.hips_position = take.rest()[mp::hip_mid];
  proxy_fk fk;
  compute_proxy_fk(sk, rest, fk);
  const glm::vec3 h = rest.hips_position;
  // The truth's rest has arms along X and straight legs: the proxy's T-pose, so the joints meet.
  auto near = [&](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-4f; };
  EXPECT_TRUE(near(fk.joints[idx(bone::left_upper_leg)], take.rest()[mp::left_hip]));
  EXPECT_TRUE(near(fk.joints[idx(bone::left_foot)], take.rest()[mp::left_ankle]));
  EXPECT_TRUE(near(fk.joints[idx(bone::neck)], take.rest()[mp::neck]));
  EXPECT_TRUE(near(fk.joints[idx(bone::head)], take.rest()[mp::head]));
  EXPECT_TRUE(near(fk.joints[idx(bone::left_upper_arm)], take.rest()[mp::left_shoulder]));
  EXPECT_TRUE(near(fk.joints[idx(bone::right_hand)], take.rest()[mp::right_wrist]));
  EXPECT_TRUE(near(fk.joints[idx(bone::hips)], h));
}

TEST(world_benchmark, bad_input_is_a_clear_error) {
  test::temp_dir dir("world");
  mocap_take take;
  status st = take.load(dir.file("missing.bvh"), 1.f);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("missing.bvh"), std::string::npos);
  const std::string legless = dir.file("legless.bvh");
  test::write_text(legless, small_bvh(false));
  st = take.load(legless, 1.f);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("hip"), std::string::npos) << st.message();
  const std::string nan = dir.file("nan.bvh");
  test::write_text(nan, small_bvh(true, "nan"));
  st = take.load(nan, 1.f);
  EXPECT_FALSE(st.ok());
  EXPECT_FALSE(take.load(dir.file("x.bvh"), 0.f).ok());
  // Fewer than 3 frames in the truth's span.
  const std::string good = dir.file("small.bvh");
  test::write_text(good, small_bvh());
  ASSERT_TRUE(take.load(good, 1.f).ok());
  world_take late = take_as_solved(take);
  for (double& t : late.t) t += 100.0;
  world_scores s;
  EXPECT_FALSE(score_world(take, late, {}, s).ok());
  // A non-finite solved frame is skipped, not scored.
  world_take holes = take_as_solved(take);
  holes.frames[5].p[idx(mp::left_knee)].x = NAN;
  ASSERT_TRUE(score_world(take, holes, {}, s).ok());
  EXPECT_EQ(s.frames, 59);
  EXPECT_TRUE(std::isfinite(s.mpjpe_mm));
}

TEST(world_benchmark, cmu_clips) {
  const std::string dir = test::test_data_path("motion/cmu-bvh");
  if (dir.empty()) GTEST_SKIP() << test::k_no_test_data;
  test::temp_dir tmp("world");
  for (const char* name : {"131_01.bvh", "131_02.bvh", "131_03.bvh"}) {
    mocap_take take;
    ASSERT_TRUE(take.load(dir + "/" + name, k_cmu_units_to_metres).ok()) << name;
    // The skeleton (ankle joints to the head's end site, plus the feet) of subject 131.
    EXPECT_GT(take.rest_height(), 1.3f) << name;
    EXPECT_LT(take.rest_height(), 2.0f) << name;
    // A clean take written and read back: world points are the joints within 1e-4 m.
    mocap_synth_job job;
    job.take = &take;
    job.camera = place_mocap_camera(take, mocap_camera_setup{});
    job.options = mocap_synth_options::preset(mocap_scenario::clean, 1);
    job.output = tmp.file("clean.landmarks.jsonl");
    mocap_synth_summary sum;
    ASSERT_TRUE(job.run(sum).ok());
    const long frames = sum.frames;
    EXPECT_EQ(frames, static_cast<long>(std::floor(take.duration() * 30 + 1e-6)) + 1);
    landmark_reader r;
    ASSERT_TRUE(r.open(job.output).ok());
    landmark_frame lf;
    long k = 0;
    double worst = 0;
    while (r.next(lf) == read_result::frame) {
      mocap_frame f;
      take.sample(lf.t, f);
      std::array<glm::vec3, 33> w;
      mocap_landmark_synth::clean_world(f, job.camera, w);
      const glm::vec3 knee =
          job.camera.to_camera(f[mp::left_knee]) - job.camera.to_camera(f[mp::hip_mid]);
      worst = std::max<double>(
          worst, glm::length(knee - glm::vec3(lf.pose_world[25].x, lf.pose_world[25].y,
                                              lf.pose_world[25].z)));
      ++k;
    }
    EXPECT_EQ(k, frames);
    EXPECT_LT(worst, 1e-4) << name;
    // The truth scored against itself through the pose-free path: zero.
    world_scores s;
    ASSERT_TRUE(score_world(take, take_as_solved(take), {}, s).ok());
    EXPECT_NEAR(s.mpjpe_mm, 0, 1e-3);
    EXPECT_NEAR(s.skate_cm_s, s.truth_skate_cm_s, 1e-9);
    EXPECT_GT(s.planted, 100) << name;  // the feet are planted a good part of the take
  }
}

}  // namespace
}  // namespace avatarmap
