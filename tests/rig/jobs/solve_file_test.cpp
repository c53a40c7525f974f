// The landmarks-file -> poses job (include/avatarmap/jobs/solve_file.hpp): on a synthetic
// recording it must give exactly what frame_solver + pose_filter give frame by frame, resample
// on the bounded grid, and fail cleanly (naming the field, file or line) on bad input.
#include "avatarmap/jobs/solve_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;

// Writes `frames` frames of the scripted demo motion (with a little noise, so that the filters
// have work to do) as a *.landmarks.jsonl with an image-size header.
void write_synthetic(const std::string& path, int frames, bool header = true) {
  synth_options o;
  o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma = 0.002f;
  o.seed = 7;
  ASSERT_TRUE(o.validate().ok());
  landmark_synth synth(o);
  landmark_writer writer;
  landmark_file_header h;
  if (header) {
    h.present = true;
    h.image_width = o.image_width;
    h.image_height = o.image_height;
    h.fps = k_fps;
  }
  ASSERT_TRUE(writer.open(path, h).ok());
  landmark_frame frame;
  for (int i = 0; i < frames; ++i) {
    const double t = 1.0 + i / k_fps;
    synth.generate(demo_motion_pose(t, synth.skeleton()), frame);
    frame.t = t;
    ASSERT_TRUE(writer.write(frame).ok());
  }
  ASSERT_TRUE(writer.commit().ok());
}

// The job's first pass (src/rig/jobs/solve_file.cpp): the face calibrated over the whole file
// (docs/expressions.md, "Calibration over a take"), whatever the filter.
void calibrate_face(frame_solver& solver, const std::string& path) {
  if (!solver.options().parts.face) return;
  landmark_reader reader;
  EXPECT_TRUE(reader.open(path).ok());
  landmark_frame frame;
  solver.begin_face_take();
  while (reader.next(frame) == read_result::frame) solver.add_face_take(frame);
  solver.end_face_take();
}

// The job's warm-up with the offline filter (src/rig/jobs/solve_file.cpp): the solver learns
// the camera from the file's first 300 frames, forgets the view and learns it again with the
// field of view known, then starts the take from the beginning with all of it known and held.
void warm_up(frame_solver& solver, const std::string& path) {
  landmark_reader reader;
  EXPECT_TRUE(reader.open(path).ok());
  std::vector<landmark_frame> frames;
  landmark_frame frame;
  while (frames.size() < 300 && reader.next(frame) == read_result::frame) frames.push_back(frame);
  proxy_pose scratch;
  for (const landmark_frame& f : frames) solver.solve(f, scratch);
  solver.restart_take(false);
  for (const landmark_frame& f : frames) solver.solve(f, scratch);
  solver.restart_take(true);
  solver.hold_view();
}

// The reference: the file read back with landmark_reader, solved and filtered frame by frame,
// then the contact stage (time/foot_contacts.hpp) as the job runs it.
std::vector<proxy_pose> reference_poses(const std::string& path, const solver_options& options,
                                        const pose_filter_options& filter_options,
                                        const pose_filter_channels& channels = {},
                                        const foot_contact_options& contact_options = {}) {
  std::vector<proxy_pose> out;
  landmark_reader reader;
  EXPECT_TRUE(reader.open(path).ok());
  frame_solver solver(options);  // the live and no filters: no warm-up, as live
  calibrate_face(solver, path);
  pose_filter filter(filter_options);
  foot_contact_stage contacts(contact_options, false);  // causal: one pose in, one out
  landmark_frame frame;
  proxy_pose raw, filtered, contacted;
  while (reader.next(frame) == read_result::frame) {
    solver.solve(frame, raw);
    filter.apply(raw, filtered);
    if (!channels.position) filtered.hips_position = raw.hips_position;
    if (!channels.rotations) filtered.rotations = raw.rotations;
    if (!channels.expressions) filtered.expressions = raw.expressions;
    if (contacts.push(filtered, contacted)) out.push_back(contacted);
  }
  while (contacts.flush(contacted)) out.push_back(contacted);
  return out;
}

solver_options synth_camera() {
  solver_options o;
  o.image_width = 1280.f;
  o.image_height = 720.f;
  return o;
}

// The reference of the default (offline) filter: solved frame by frame with the confidence
// gate opened (thresholds 0, as the job does for the offline filter), then streamed through
// offline_smoother.
std::vector<proxy_pose> reference_offline_poses(const std::string& path, solver_options options,
                                                const offline_smoother_options& smooth = {}) {
  options.confidence.lost_below = 0.f;
  options.confidence.found_above = 0.f;
  options.confidence.regain_seconds = 0.f;
  landmark_reader reader;
  EXPECT_TRUE(reader.open(path).ok());
  frame_solver solver(options);
  // The face is calibrated after the warm-up, through the field of view it learnt.
  warm_up(solver, path);
  calibrate_face(solver, path);
  offline_smoother smoother(smooth);
  foot_contact_stage contacts(foot_contact_options{}, true);  // both-sided, as for files
  // As the warm-up's end does (pose_stream::restart_take).
  contacts.set_leg_length(solver.performer_leg_length());
  landmark_frame frame;
  proxy_pose raw, smoothed, contacted;
  std::vector<proxy_pose> out;
  while (reader.next(frame) == read_result::frame) {
    solver.solve(frame, raw);
    smoother.push(raw);
    while (smoother.pop(smoothed))
      if (contacts.push(smoothed, contacted)) out.push_back(contacted);
  }
  smoother.finish();
  while (smoother.pop(smoothed))
    if (contacts.push(smoothed, contacted)) out.push_back(contacted);
  while (contacts.flush(contacted)) out.push_back(contacted);
  return out;
}

void expect_same_poses(const std::vector<proxy_pose>& got, const std::vector<proxy_pose>& want,
                       float tolerance) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t f = 0; f < got.size(); ++f) {
    EXPECT_NEAR(got[f].t, want[f].t, 1e-9) << "frame " << f;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(got[f].hips_position[c], want[f].hips_position[c], tolerance) << "frame " << f;
    for (int b = 0; b < k_bone_count; ++b)
      for (int c = 0; c < 4; ++c)
        ASSERT_NEAR(got[f].rotations[b][c], want[f].rotations[b][c], tolerance)
            << "frame " << f << " bone " << bone_name(static_cast<bone>(b));
    for (int e = 0; e < k_expression_count; ++e)
      EXPECT_NEAR(got[f].expressions[e], want[f].expressions[e], tolerance) << "frame " << f;
  }
}

// Runs `job` with a sink that collects every pose; the run must succeed.
std::vector<proxy_pose> run_collecting(solve_file_job& job) {
  std::vector<proxy_pose> got;
  job.sink = [&got](const proxy_pose& p) {
    got.push_back(p);
    return status{};
  };
  solve_file_summary s;
  const status st = job.run(s);
  EXPECT_TRUE(st.ok()) << st.message();
  return got;
}

class solve_file : public ::testing::Test {
 protected:
  test::temp_dir dir{"solve_file"};
  std::string input = dir.file("in.landmarks.jsonl");
  void SetUp() override { write_synthetic(input, 60); }
};

TEST_F(solve_file, sink_gets_exactly_the_frame_by_frame_poses_with_either_thread_count) {
  // The default filter is the offline one.
  const std::vector<proxy_pose> want = reference_offline_poses(input, synth_camera());
  ASSERT_EQ(want.size(), 60u);
  for (int threads : {1, 2}) {
    solve_file_job job;
    job.input = input;
    job.threads = threads;
    std::vector<proxy_pose> got;
    job.sink = [&got](const proxy_pose& p) {
      got.push_back(p);
      return status{};
    };
    solve_file_summary s;
    const status st = job.run(s);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(s.frames, 60);
    EXPECT_EQ(s.poses_written, 60);
    EXPECT_EQ(st.code(), status_code::ok);
    EXPECT_FALSE(s.image_size_assumed);  // the header's 1280x720
    EXPECT_EQ(s.image_width, 1280.f);
    EXPECT_DOUBLE_EQ(s.t_first, 1.0);
    EXPECT_NEAR(s.t_last, 1.0 + 59 / k_fps, 1e-9);
    EXPECT_EQ(s.part_frames[static_cast<int>(frame_part::face)], 60);
    expect_same_poses(got, want, 0.f);  // the same code on the same frames: bit for bit
  }
}

TEST_F(solve_file, a_source_of_the_files_frames_gives_the_same_poses_as_the_file) {
  std::vector<landmark_frame> frames;
  {
    landmark_reader reader;
    ASSERT_TRUE(reader.open(input).ok());
    landmark_frame f;
    while (reader.next(f) == read_result::frame) frames.push_back(f);
  }
  ASSERT_EQ(frames.size(), 60u);
  for (pose_filter_mode mode :
       {pose_filter_mode::offline, pose_filter_mode::live, pose_filter_mode::none}) {
    solve_file_job from_file;
    from_file.input = input;
    from_file.filter_mode = mode;
    const std::vector<proxy_pose> want = run_collecting(from_file);
    solve_file_job from_source;
    from_source.filter_mode = mode;
    from_source.image_width = 1280.f;  // no header: the file's size given
    from_source.image_height = 720.f;
    std::size_t next = 0;
    from_source.source = [&](landmark_frame& out, bool& end) {
      end = next == frames.size();
      if (!end) out = frames[next++];
      return status{};
    };
    expect_same_poses(run_collecting(from_source), want, 0.f);
  }
}

TEST(solve_file_inputs, a_source_error_ends_the_run_as_an_argument_error) {
  solve_file_job job;
  int calls = 0;
  job.source = [&calls](landmark_frame& out, bool&) {
    out.clear();
    out.t = calls;
    return ++calls == 3 ? status::error("frame 2 is bad") : status{};
  };
  int poses = 0;
  job.sink = [&poses](const proxy_pose&) {
    ++poses;
    return status{};
  };
  job.filter_mode = pose_filter_mode::none;
  solve_file_summary s;
  const status st = job.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(), "frame 2 is bad");
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_EQ(poses, 2);
  solve_file_job none;
  none.sink = job.sink;
  EXPECT_NE(none.validate().message().find("or a source"), std::string::npos);
}

TEST_F(solve_file, written_file_reads_back_as_the_same_poses) {
  const std::string out = dir.file("out.pose.jsonl");
  solve_file_job job;
  job.input = input;
  job.output = out;
  solve_file_summary s;
  ASSERT_TRUE(job.run(s).ok());
  pose_reader reader;
  ASSERT_TRUE(reader.open(out).ok());
  EXPECT_DOUBLE_EQ(reader.header().fps, k_fps);  // the input's header fps
  std::vector<proxy_pose> got;
  proxy_pose p;
  while (reader.next(p) == read_result::frame) got.push_back(p);
  // Text round trip: the writer prints ~7 significant digits.
  expect_same_poses(got, reference_offline_poses(input, synth_camera()), 2e-6f);
}

TEST_F(solve_file, filter_options_and_channels_are_those_of_the_reference) {
  pose_filter_options f;
  f.rotation.min_cutoff = 0.5f;
  pose_filter_channels c;
  c.position = false;
  solve_file_job job;
  job.input = input;
  job.filter_mode = pose_filter_mode::live;  // the live path is exactly pose_filter's
  job.filter = f;
  job.filter_channels = c;
  // The root following planted feet moves the hips with the (filtered) legs: off here, so
  // the position channel alone decides the hips.
  foot_contact_options no_root;
  no_root.root_follows_contacts = false;
  job.foot_contacts = no_root;
  std::vector<proxy_pose> got;
  job.sink = [&got](const proxy_pose& p) {
    got.push_back(p);
    return status{};
  };
  solve_file_summary s;
  ASSERT_TRUE(job.run(s).ok());
  const std::vector<proxy_pose> want = reference_poses(input, synth_camera(), f, c, no_root);
  expect_same_poses(got, want, 0.f);
  // And they differ from the unfiltered solve (the channels matter).
  pose_filter_options off;
  off.enabled = false;
  const std::vector<proxy_pose> raw = reference_poses(input, synth_camera(), off, {}, no_root);
  float rotation_gap = 0.f;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    EXPECT_EQ(got[i].hips_position, raw[i].hips_position);  // position filtering is off
    for (int b = 0; b < k_bone_count; ++b)
      rotation_gap = std::max(rotation_gap,
                              glm::length(glm::vec4(got[i].rotations[b].x, got[i].rotations[b].y,
                                                    got[i].rotations[b].z, got[i].rotations[b].w) -
                                          glm::vec4(raw[i].rotations[b].x, raw[i].rotations[b].y,
                                                    raw[i].rotations[b].z, raw[i].rotations[b].w)));
  }
  EXPECT_GT(rotation_gap, 1e-3f);
}

TEST_F(solve_file, output_fps_writes_the_bounded_grid) {
  solve_file_job job;
  job.input = input;
  job.output_fps = 60.0;
  std::vector<double> times;
  job.sink = [&times](const proxy_pose& p) {
    times.push_back(p.t);
    return status{};
  };
  solve_file_summary s;
  ASSERT_TRUE(job.run(s).ok());
  // 59 / 30 s at 60 fps: t = 1 + j / 60 for j = 0..118.
  ASSERT_EQ(times.size(), 119u);
  EXPECT_EQ(s.poses_written, 119);
  for (std::size_t j = 0; j < times.size(); ++j) EXPECT_NEAR(times[j], 1.0 + j / 60.0, 1e-9);
}

TEST(solve_file_times, a_frame_going_back_is_skipped_with_a_warning_when_resampling) {
  test::temp_dir dir{"solve_file_back"};
  const std::string in = dir.file("back.landmarks.jsonl");
  test::write_text(in, "{\"t\":5}\n{\"t\":5.1}\n{\"t\":1}\n");
  solve_file_job job;
  job.input = in;
  job.output_fps = 60.0;
  job.output_fps_name = "--fps";
  std::vector<std::string> warnings;
  job.warning = [&warnings](const std::string& w) { warnings.push_back(w); };
  long poses = 0;
  job.sink = [&poses](const proxy_pose&) {
    ++poses;
    return status{};
  };
  solve_file_summary s;
  ASSERT_TRUE(job.run(s).ok());
  EXPECT_EQ(s.out_of_order, 1);
  EXPECT_EQ(poses, 7);  // 5.0 .. 5.1 s at 60 fps
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("frame 2 (t = 1.000 s) is earlier than the frame before it"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("--fps needs times in order"), std::string::npos) << warnings[0];
  EXPECT_TRUE(s.image_size_assumed);  // no header, no size given
}

TEST(solve_file_times, a_span_beyond_a_day_fails_as_an_argument_and_leaves_the_output) {
  test::temp_dir dir{"solve_file_gap"};
  const std::string in = dir.file("gap.landmarks.jsonl");
  const std::string out = dir.file("gap.pose.jsonl");
  test::write_text(in, "{\"t\":0}\n{\"t\":1000000}\n");
  test::write_text(out, "precious");
  solve_file_job job;
  job.input = in;
  job.output = out;
  job.output_fps = 60.0;
  solve_file_summary s;
  const status st = job.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("gap.landmarks.jsonl: frame 1"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("output_fps resamples at most 86400 s"), std::string::npos)
      << st.message();
  EXPECT_EQ(test::read_text(out), "precious");
}

TEST(solve_file_lines, a_bad_line_fails_naming_it_or_is_skipped_and_counted) {
  test::temp_dir dir{"solve_file_bad"};
  const std::string in = dir.file("bad.landmarks.jsonl");
  const std::string out = dir.file("bad.pose.jsonl");
  test::write_text(in, "{\"t\":0}\n{\"t\": [oops\n{\"t\":0.1}\n");
  for (int threads : {1, 2}) {
    std::filesystem::remove(out);
    solve_file_job job;
    job.input = in;
    job.output = out;
    job.threads = threads;
    solve_file_summary s;
    status st = job.run(s);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.code(), status_code::parse);
    EXPECT_NE(st.message().find("bad.landmarks.jsonl:2"), std::string::npos) << st.message();
    EXPECT_TRUE(test::read_text(out).empty());  // never created

    job.skip_bad_lines = true;
    std::vector<std::string> warnings;
    job.warning = [&warnings](const std::string& w) { warnings.push_back(w); };
    st = job.run(s);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(s.bad_lines, 1);
    EXPECT_EQ(s.frames, 2);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].rfind("skipped ", 0), 0u) << warnings[0];
  }
}

TEST(solve_file_long, many_frames_in_batches_give_the_frame_by_frame_poses_and_errors) {
  // Ten times the frames the parsing thread's ring holds and several MiB of output (the
  // writer's buffer is written out several times), with malformed lines in the middle: both
  // thread counts give exactly the frame-by-frame poses, skip the same lines, and stop at the
  // same first one.
  test::temp_dir dir{"solve_file_long"};
  const std::string clean = dir.file("clean.landmarks.jsonl");
  const std::string in = dir.file("in.landmarks.jsonl");
  write_synthetic(clean, 700);
  std::string text = test::read_text(clean), damaged;
  std::size_t line = 0, start = 0;
  for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1) {
    damaged.append(text, start, end + 1 - start);
    if (++line == 101 || line == 334 || line == 651) damaged += "{\"t\": [oops\n";
  }
  test::write_text(in, damaged);
  const std::vector<proxy_pose> want = reference_offline_poses(clean, synth_camera());
  ASSERT_EQ(want.size(), 700u);
  for (int threads : {1, 2}) {
    const std::string out = dir.file("out" + std::to_string(threads) + ".pose.jsonl");
    solve_file_job job;
    job.input = in;
    job.output = out;
    job.threads = threads;
    solve_file_summary s;
    status st = job.run(s);  // stops at the first bad line
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.code(), status_code::parse);
    EXPECT_NE(st.message().find("in.landmarks.jsonl:102"), std::string::npos) << st.message();
    EXPECT_FALSE(std::filesystem::exists(out));

    job.skip_bad_lines = true;
    st = job.run(s);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(s.bad_lines, 3);
    EXPECT_EQ(s.frames, 700);
    pose_reader reader;
    ASSERT_TRUE(reader.open(out).ok());
    std::vector<proxy_pose> written;
    proxy_pose p;
    while (reader.next(p) == read_result::frame) written.push_back(p);
    expect_same_poses(written, want, 2e-6f);  // the text round trip

    job.output.clear();
    std::vector<proxy_pose> got;
    job.sink = [&got](const proxy_pose& q) {
      got.push_back(q);
      return status{};
    };
    st = job.run(s);
    ASSERT_TRUE(st.ok()) << st.message();
    expect_same_poses(got, want, 0.f);  // bit for bit
  }
}

TEST(solve_file_inputs, a_missing_input_is_an_input_error) {
  test::temp_dir dir{"solve_file_missing"};
  solve_file_job job;
  job.input = dir.file("none.landmarks.jsonl");
  job.output = dir.file("none.pose.jsonl");
  solve_file_summary s;
  const status st = job.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::io);
  EXPECT_NE(st.message().find("none.landmarks.jsonl"), std::string::npos) << st.message();
}

TEST(solve_file_inputs, a_sink_error_ends_the_run_as_an_output_error) {
  test::temp_dir dir{"solve_file_sink"};
  const std::string in = dir.file("in.landmarks.jsonl");
  write_synthetic(in, 5);
  solve_file_job job;
  job.input = in;
  int calls = 0;
  job.sink = [&calls](const proxy_pose&) {
    return ++calls == 3 ? status::io_error("sink full") : status{};
  };
  solve_file_summary s;
  const status st = job.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(), "sink full");
  EXPECT_EQ(st.code(), status_code::io);  // the sink's own code
  EXPECT_EQ(calls, 3);
}

// validate() breaks one field at a time; each message names the field.
TEST(solve_file_validate, names_each_broken_field) {
  auto good = [] {
    solve_file_job j;
    j.input = "in.landmarks.jsonl";
    j.output = "out.pose.jsonl";
    return j;
  };
  ASSERT_TRUE(good().validate().ok());
  struct breaking {
    void (*change)(solve_file_job&);
    const char* words;
  };
  const breaking cases[] = {
      {[](solve_file_job& j) { j.input.clear(); }, "input"},
      {[](solve_file_job& j) { j.output.clear(); }, "output"},
      {[](solve_file_job& j) { j.threads = 3; }, "threads"},
      {[](solve_file_job& j) { j.output_fps = -1.0; }, "output_fps"},
      {[](solve_file_job& j) { j.output_fps = 1001.0; }, "output_fps"},
      {[](solve_file_job& j) { j.output_fps = NAN; }, "output_fps"},
      {[](solve_file_job& j) { j.image_width = 640.f; }, "image_width"},
      {[](solve_file_job& j) { j.options.horizontal_fov_degrees = 500.f; },
       "horizontal_fov_degrees"},
      {[](solve_file_job& j) { j.filter.rotation.min_cutoff = 0.f; }, "rotation.min_cutoff"},
      {[](solve_file_job& j) { j.filter.position.beta = INFINITY; }, "position.beta"},
      {[](solve_file_job& j) { j.filter.expression.d_cutoff = -1.f; }, "expression.d_cutoff"},
      {[](solve_file_job& j) { j.offline.finger_sigma_seconds = 0.f; },
       "offline_smoother_options.finger_sigma_seconds"},
      {[](solve_file_job& j) { j.filter_mode = static_cast<pose_filter_mode>(7); }, "filter_mode"},
  };
  for (const breaking& c : cases) {
    solve_file_job j = good();
    c.change(j);
    const status st = j.validate();
    ASSERT_FALSE(st.ok()) << c.words;
    EXPECT_NE(st.message().find(c.words), std::string::npos) << st.message();
    solve_file_summary s;
    const status run = j.run(s);
    EXPECT_FALSE(run.ok());
    EXPECT_EQ(run.code(), status_code::invalid_argument) << c.words;
  }
  // A sink replaces the output.
  solve_file_job j = good();
  j.output.clear();
  j.sink = [](const proxy_pose&) { return status{}; };
  EXPECT_TRUE(j.validate().ok());
}

TEST_F(solve_file, offline_strength_and_none_are_honoured) {
  auto solve_with = [&](pose_filter_mode mode, float strength) {
    solve_file_job job;
    job.input = input;
    job.filter_mode = mode;
    job.offline.strength = strength;
    return run_collecting(job);
  };
  offline_smoother_options twice;
  twice.strength = 2.f;
  expect_same_poses(solve_with(pose_filter_mode::offline, 2.f),
                    reference_offline_poses(input, synth_camera(), twice), 0.f);
  pose_filter_options off;
  off.enabled = false;
  expect_same_poses(solve_with(pose_filter_mode::none, 1.f),
                    reference_poses(input, synth_camera(), off), 0.f);
}

TEST(solve_file_offline, a_hand_found_again_is_its_measurement_at_once) {
  // The left hand is lost for half a second and found again curled further. With the offline filter
  // the smoother decides what was observed, so the solver's gate is open (thresholds 0) and a
  // bone found again is its measurement at once: no blend in from the rotation held through
  // the gap (the causal gate's regain blend is for live streams). Strength 0: gaps filled,
  // nothing smoothed, so the frames after the gap are the solver's own output.
  test::temp_dir dir{"solve_file_regain"};
  const std::string path = dir.file("in.landmarks.jsonl");
  synth_options o;
  o.seed = 7;
  landmark_synth synth(o);
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = o.image_width;
  h.image_height = o.image_height;
  h.fps = k_fps;
  ASSERT_TRUE(writer.open(path, h).ok());
  landmark_frame frame;
  for (int i = 0; i < 60; ++i) {
    const double t = 5.0 + i / k_fps;  // the left hand's finger curls (5-9 s)
    synth.generate(demo_motion_pose(t, synth.skeleton()), frame);
    frame.t = t;
    if (i >= 30 && i < 45) {
      frame.set(frame_part::left_hand, false);
      frame.set(frame_part::left_hand_world, false);
    }
    ASSERT_TRUE(writer.write(frame).ok());
  }
  ASSERT_TRUE(writer.commit().ok());

  solve_file_job job;
  job.input = path;
  job.filter_mode = pose_filter_mode::offline;
  job.offline.strength = 0.f;
  const std::vector<proxy_pose> got = run_collecting(job);
  ASSERT_EQ(got.size(), 60u);
  offline_smoother_options fill_only;
  fill_only.strength = 0.f;
  expect_same_poses(got, reference_offline_poses(path, synth_camera(), fill_only), 0.f);
  // With the regain blend the hand after the gap would start from the held rotation.
  solver_options blended = synth_camera();
  blended.confidence.lost_below = 0.f;
  blended.confidence.found_above = 0.f;
  frame_solver solver(blended);
  warm_up(solver, path);
  landmark_reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  proxy_pose p;
  // A finger: the hand bone itself is still placed by the body's hand points in the gap.
  const int finger = idx(bone::left_index_intermediate);
  for (int i = 0; reader.next(frame) == read_result::frame; ++i) {
    solver.solve(frame, p);
    if (i == 45) EXPECT_GT(angle_between(p.rotations[finger], got[45].rotations[finger]), 0.05f);
  }
}

TEST_F(solve_file, resampling_runs_after_the_offline_filter) {
  // --fps resamples the smoothed poses: at 60 fps every second pose falls on a frame time
  // (1 + k / 30 s), where it is that frame's smoothed pose.
  solve_file_job job;
  job.input = input;
  job.output_fps = 60.0;
  std::vector<proxy_pose> got;
  job.sink = [&got](const proxy_pose& p) {
    got.push_back(p);
    return status{};
  };
  solve_file_summary s;
  ASSERT_TRUE(job.run(s).ok());
  const std::vector<proxy_pose> smoothed = reference_offline_poses(input, synth_camera());
  ASSERT_EQ(got.size(), 2 * smoothed.size() - 1);
  std::vector<proxy_pose> on_frames;
  for (std::size_t j = 0; j < got.size(); j += 2) on_frames.push_back(got[j]);
  expect_same_poses(on_frames, smoothed, 1e-5f);
}

}  // namespace
}  // namespace avatarmap
