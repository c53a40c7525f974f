// live_filter_eval: lag against jitter of the live (causal) filter, for one setting of its
// rotation parameters; tools/eval/live_filter.sh sweeps settings and prints the table of
// docs/smoothing.md ("Live: lag against jitter").
//
// Usage: live_filter_eval [SETTING] [--fps N] [--clean L T]... [--noisy L T]...
//                         [--video NAME L]... [--keep PREFIX] [--header]
// SETTING (the rotation filter; the hips and expression filters keep pose_filter's defaults):
//   --none                no filter at all (the solver's output)
//   --min-cutoff HZ --beta B --d-cutoff HZ   (default: pose_filter_options' rotation)
//   --speed output|input  one_euro_speed (default: pose_filter_options')
//   --predict K           one_euro_quat_options::prediction (0..1)
//   --max-predict S       one_euro_quat_options::max_prediction_seconds
//   --predict-from filtered|input   one_euro_quat_options::velocity
//   --legacy              the defaults before issue 9 (1.5 Hz, beta 0.5, d 1 Hz, output speed)
// Figures, one row (--header: only the header line of the same columns):
//   lag1/lag3/lag6   ms by which the filter alone trails a bone turning at a constant 1, 3 and
//                    6 rad/s at --fps (default 30), after 3 s of turning (the mean over 1 s);
//                    negative = ahead. err3: the angle it trails by at 3 rad/s, degrees.
//   over3            degrees the output runs past a bone that turned at 3 rad/s and stopped.
//   chain3           ms the whole live chain trails at 3 rad/s: a synthetic upper arm swinging
//                    round at shoulder height (exact landmarks) -> the capture's landmark
//                    smoothing of pose points (as pose_pipeline sets it up: velocity filter on
//                    the image points, MediaPipe's One Euro 0.1 Hz / beta 40 on the world
//                    points) -> frame_solver -> the filter, measured against the solver on the
//                    raw landmarks; chain3raw: the same without the capture's smoothing (the
//                    C API's per-frame path on raw landmarks).
//   still            jitter (eval-pose --jitter, deg/s^2) of a still body with the noisy
//                    scenario's landmark noise (10 mm body, 5 mm hands, 1 mm face; 3 poses,
//                    10 s each at --fps), through solver + filter; still_cap: with the
//                    capture's smoothing of the pose points in front.
//   NAME             jitter of `solve --filter live` with this setting on landmark file L
//                    (real video captured by `avatarmap capture`), per --video; --keep PREFIX
//                    leaves the poses in PREFIX + NAME + ".pose.jsonl".
//   clean/noisy      mean bone-direction error (degrees) of the same solve against the truth T
//                    (`avatarmap synth --scenario clean|noisy --truth T`), over the files given.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "avatarmap/capture/landmark_smoothing.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/pose_accuracy.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace am = avatarmap;

namespace {

struct setting {
  bool none = false;
  am::pose_filter_options filter;
};

// The capture's smoothing of the body points in video mode, as pose_pipeline.cpp sets it up
// with its default pose_smoothing::velocity (the auxiliary points only steer the crop).
struct capture_smoothing {
  am::landmark_smoother image{am::mediapipe_velocity_params{5, 10.f}};
  am::landmark_smoother world{am::mediapipe_one_euro_params{0.1f, 40.f, 1.f, true}};
  am::visibility_smoother visibility{0.1f};
  void apply(am::landmark_frame& f, int width, int height) {
    if (!f.has(am::frame_part::pose)) return;
    image.apply(f.t, f.pose.data(), am::k_pose_landmark_count, true, width, height);
    visibility.apply(f.pose.data(), am::k_pose_landmark_count);
    world.apply(f.t, f.pose_world.data(), am::k_pose_landmark_count, false, 0, 0);
  }
};

// Signed angle (radians) of rotation `d` about the unit axis `axis`.
float signed_angle_about(const glm::quat& d, const glm::vec3& axis) {
  glm::quat q = d;
  if (q.w < 0.f) q = -q;
  return 2.f * std::atan2(glm::dot(glm::vec3(q.x, q.y, q.z), axis), q.w);
}

// The filter alone: a bone turning about Y at `omega` rad/s from a tilted start; `stop_at` > 0
// stops the turn there. Returns the mean signed trail (radians, positive = behind) over
// [t_from, t_to] and the largest lead (radians) after the stop.
struct ramp_result {
  double trail = 0.0;
  double lead_after_stop = 0.0;
};
ramp_result filter_ramp(const setting& s, double fps, float omega, double t_from, double t_to,
                        double stop_at) {
  am::pose_filter f(s.filter);
  am::proxy_pose in, out;
  const glm::vec3 axis(0.f, 1.f, 0.f);
  const glm::quat base = am::axis_angle(glm::normalize(glm::vec3(1.f, 0.f, 1.f)), 0.7f);
  const am::bone b = am::bone::left_upper_arm;
  ramp_result r;
  long n = 0;
  const long frames = std::lround(t_to * fps);
  for (long i = 0; i <= frames; ++i) {
    const double t = static_cast<double>(i) / fps;
    const double turn = stop_at > 0.0 && t > stop_at ? stop_at : t;
    in.t = t;
    in[b] = am::axis_angle(axis, omega * static_cast<float>(turn)) * base;
    if (s.none)
      out = in;
    else
      f.apply(in, out);
    const float behind = -signed_angle_about(out[b] * glm::conjugate(in[b]), axis);
    if (t >= t_from && (stop_at <= 0.0 || t <= stop_at)) {
      r.trail += behind;
      ++n;
    }
    if (stop_at > 0.0 && t > stop_at)
      r.lead_after_stop = std::max(r.lead_after_stop, -double(behind));
  }
  if (n > 0) r.trail /= static_cast<double>(n);
  return r;
}

// The whole chain: the default synthetic person (fixed camera) with the left upper arm at
// shoulder height swinging round the vertical at `omega`; the world direction of the left upper
// arm from the solver (+ capture smoothing) (+ filter) against the solver's on raw landmarks.
// Mean signed trail in radians over [1 s, 4 s].
double chain_trail(const setting& s, double fps, float omega, bool smooth_capture) {
  am::synth_options so;
  am::landmark_synth synth(so);
  am::solver_options sv;
  sv.image_width = static_cast<float>(so.image_width);
  sv.image_height = static_cast<float>(so.image_height);
  am::frame_solver raw_solver(sv), solver(sv);
  am::pose_filter f(s.filter);
  capture_smoothing cap;
  auto frame = std::make_unique<am::landmark_frame>();
  am::proxy_pose truth, reference, solved, out;
  std::array<glm::quat, am::k_bone_count> world_ref{}, world_out{};
  const am::bone b = am::bone::left_upper_arm;
  const glm::vec3 rest_dir = am::bone_rest_direction(b);
  double sum = 0.0;
  long n = 0;
  for (long i = 0; i <= std::lround(4.0 * fps); ++i) {
    const double t = static_cast<double>(i) / fps;
    truth.set_rest();
    truth.t = t;
    truth[b] = am::axis_angle(glm::vec3(0.f, 1.f, 0.f), omega * static_cast<float>(t));
    synth.generate(truth, *frame);
    raw_solver.solve(*frame, reference);
    if (smooth_capture) cap.apply(*frame, so.image_width, so.image_height);
    solver.solve(*frame, solved);
    if (s.none)
      out = solved;
    else
      f.apply(solved, out);
    am::compute_world_rotations(reference, world_ref);
    am::compute_world_rotations(out, world_out);
    const glm::vec3 u = world_ref[am::idx(b)] * rest_dir, v = world_out[am::idx(b)] * rest_dir;
    // Signed angle from the reference to the output in the horizontal plane.
    const float a = std::atan2(u.z * v.x - u.x * v.z, u.x * v.x + u.z * v.z);
    if (t >= 1.0) {
      sum += -a;
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

std::string temp_path(const char* name) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && *dir ? dir : "/tmp") + "/live_filter_eval_" + std::to_string(getpid()) +
         "_" + name;
}

// Jitter of a still, noisy body through solver (+ capture smoothing) + filter: three poses.
double still_jitter(const setting& s, double fps, bool smooth_capture) {
  double sum2 = 0.0;
  long count = 0;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    am::synth_options so = am::synth_scenario_options(am::synth_scenario::noisy, seed);
    so.low_visibility_fraction = 0.f;
    am::landmark_synth synth(so);
    std::mt19937 rng(seed);
    am::proxy_pose pose = am::random_pose(rng);
    am::solver_options sv;
    sv.image_width = static_cast<float>(so.image_width);
    sv.image_height = static_cast<float>(so.image_height);
    am::frame_solver solver(sv);
    am::pose_filter f(s.filter);
    capture_smoothing cap;
    auto frame = std::make_unique<am::landmark_frame>();
    am::proxy_pose solved, out;
    const std::string path = temp_path("still.pose.jsonl");
    am::pose_writer w;
    am::pose_file_header h;
    h.fps = fps;
    if (!w.open(path, h).ok()) return NAN;
    for (long i = 0; i < std::lround(10.0 * fps); ++i) {
      pose.t = static_cast<double>(i) / fps;
      synth.generate(pose, *frame);
      if (smooth_capture) cap.apply(*frame, so.image_width, so.image_height);
      solver.solve(*frame, solved);
      if (s.none)
        out = solved;
      else
        f.apply(solved, out);
      if (!w.write(out).ok()) return NAN;
    }
    if (!w.commit().ok()) return NAN;
    am::pose_jitter j;
    const am::status st = am::measure_pose_jitter(path, j);
    std::remove(path.c_str());
    if (!st.ok()) return NAN;
    sum2 += j.rms * j.rms * static_cast<double>(j.frames - 2);
    count += j.frames - 2;
  }
  return std::sqrt(sum2 / static_cast<double>(count));
}

// `solve --filter live` (or none) with this setting, into a temporary pose file.
bool solve_file(const setting& s, const std::string& in, const std::string& out) {
  am::solve_file_job job;
  job.input = in;
  job.output = out;
  job.filter_mode = s.none ? am::pose_filter_mode::none : am::pose_filter_mode::live;
  job.filter = s.filter;
  am::solve_file_summary summary;
  const am::status st = job.run(summary);
  if (!st.ok()) std::fprintf(stderr, "live_filter_eval: %s\n", st.message().c_str());
  return st.ok();
}

// `keep`: where to leave the solved poses (empty: a temporary file, removed).
double file_jitter(const setting& s, const std::string& landmarks, const std::string& keep) {
  const std::string path = keep.empty() ? temp_path("video.pose.jsonl") : keep;
  if (!solve_file(s, landmarks, path)) return NAN;
  am::pose_jitter j;
  const am::status st = am::measure_pose_jitter(path, j);
  if (keep.empty()) std::remove(path.c_str());
  return st.ok() ? j.rms : NAN;
}

double file_error(const setting& s, const std::string& landmarks, const std::string& truth) {
  const std::string path = temp_path("synth.pose.jsonl");
  if (!solve_file(s, landmarks, path)) return NAN;
  am::pose_accuracy acc;
  const am::status st = am::evaluate_pose_files(truth, path, acc);
  std::remove(path.c_str());
  if (!st.ok()) std::fprintf(stderr, "live_filter_eval: %s\n", st.message().c_str());
  return st.ok() ? acc.all.direction.mean() : NAN;
}

constexpr double k_deg = 180.0 / 3.14159265358979323846;

}  // namespace

int main(int argc, char** argv) {
  setting s;
  double fps = 30.0;
  bool header = false;
  std::string keep;
  std::vector<std::pair<std::string, std::string>> clean, noisy, videos;
  am::one_euro_params& r = s.filter.rotation;
  am::one_euro_quat_options& q = s.filter.rotation_options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](int k = 1) -> const char* {
      if (i + k >= argc) {
        std::fprintf(stderr, "live_filter_eval: %s needs %d value(s)\n", a.c_str(), k);
        std::exit(2);
      }
      return argv[i + k];
    };
    if (a == "--none") {
      s.none = true;
    } else if (a == "--legacy") {
      r = {1.5f, 0.5f, 1.0f};
      q = am::one_euro_quat_options{};
      q.speed = am::one_euro_speed::output_change;
      q.prediction = 0.f;
    } else if (a == "--min-cutoff") {
      r.min_cutoff = std::strtof(value(), nullptr), ++i;
    } else if (a == "--beta") {
      r.beta = std::strtof(value(), nullptr), ++i;
    } else if (a == "--d-cutoff") {
      r.d_cutoff = std::strtof(value(), nullptr), ++i;
    } else if (a == "--speed") {
      const std::string v = value();
      ++i;
      if (v != "output" && v != "input") {
        std::fprintf(stderr, "live_filter_eval: --speed is output or input\n");
        return 2;
      }
      q.speed =
          v == "input" ? am::one_euro_speed::input_velocity : am::one_euro_speed::output_change;
    } else if (a == "--predict") {
      q.prediction = std::strtof(value(), nullptr), ++i;
    } else if (a == "--predict-from") {
      const std::string v = value();
      ++i;
      if (v != "filtered" && v != "input") {
        std::fprintf(stderr, "live_filter_eval: --predict-from is filtered or input\n");
        return 2;
      }
      q.velocity = v == "input" ? am::one_euro_velocity::input : am::one_euro_velocity::filtered;
    } else if (a == "--max-predict") {
      q.max_prediction_seconds = std::strtof(value(), nullptr), ++i;
    } else if (a == "--fps") {
      fps = std::strtod(value(), nullptr), ++i;
    } else if (a == "--clean" || a == "--noisy") {
      (a == "--clean" ? clean : noisy).emplace_back(value(1), value(2));
      i += 2;
    } else if (a == "--video") {
      videos.emplace_back(value(1), value(2));
      i += 2;
    } else if (a == "--keep") {
      keep = value(), ++i;
    } else if (a == "--header") {
      header = true;
    } else {
      std::fprintf(stderr, "live_filter_eval: unknown argument '%s' (see the file's comment)\n",
                   a.c_str());
      return 2;
    }
  }
  if (!(fps > 1.0 && fps <= 1000.0) || !(r.min_cutoff > 0.f) || !(r.beta >= 0.f) ||
      !(r.d_cutoff > 0.f)) {
    std::fprintf(stderr, "live_filter_eval: fps in (1, 1000], cutoffs > 0, beta >= 0\n");
    return 2;
  }
  if (header) {
    std::printf("%6s %6s %6s %6s %6s %6s %7s %9s %7s %9s", "lag1", "lag3", "lag6", "err3", "over3",
                "chain3", "chain3r", "still", "still_c", "");
    for (const auto& v : videos) std::printf(" %9s", v.first.c_str());
    if (!clean.empty()) std::printf(" %6s", "clean");
    if (!noisy.empty()) std::printf(" %6s", "noisy");
    std::printf("\n");
    return 0;
  }
  const double lag1 = filter_ramp(s, fps, 1.f, 3.0, 4.0, 0.0).trail / 1.0;
  const double trail3 = filter_ramp(s, fps, 3.f, 3.0, 4.0, 0.0).trail;
  const double lag6 = filter_ramp(s, fps, 6.f, 3.0, 4.0, 0.0).trail / 6.0;
  const double over3 = filter_ramp(s, fps, 3.f, 1.0, 4.0, 2.0).lead_after_stop;
  const double chain3 = chain_trail(s, fps, 3.f, true) / 3.0;
  const double chain3raw = chain_trail(s, fps, 3.f, false) / 3.0;
  std::printf("%6.1f %6.1f %6.1f %6.2f %6.2f %6.1f %7.1f %9.0f %7.0f %9s", lag1 * 1e3,
              trail3 / 3.0 * 1e3, lag6 * 1e3, trail3 * k_deg, over3 * k_deg, chain3 * 1e3,
              chain3raw * 1e3, still_jitter(s, fps, false), still_jitter(s, fps, true), "");
  for (const auto& v : videos)
    std::printf(" %9.0f",
                file_jitter(s, v.second, keep.empty() ? keep : keep + v.first + ".pose.jsonl"));
  auto mean_error = [&](const std::vector<std::pair<std::string, std::string>>& files) {
    double sum = 0.0;
    for (const auto& f : files) sum += file_error(s, f.first, f.second);
    return sum / static_cast<double>(files.size());
  };
  if (!clean.empty()) std::printf(" %6.2f", mean_error(clean));
  if (!noisy.empty()) std::printf(" %6.2f", mean_error(noisy));
  std::printf("\n");
  return 0;
}
