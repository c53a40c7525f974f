// Accuracy of solved poses against the synthetic ground truth. See
// include/avatarmap/synth/pose_accuracy.hpp.
#include "avatarmap/synth/pose_accuracy.hpp"

#include <cmath>
#include <cstdio>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/pose_file.hpp"

namespace avatarmap {

namespace {

constexpr double k_rad_to_deg = 180.0 / 3.14159265358979323846;
// Truth confidence below this marks a low-visibility bone (synth_recording writes 0 or 1).
constexpr float k_low_visibility_marker = 0.5f;

bool usable(const glm::quat& q) {
  if (!is_finite(q)) return false;
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return n > 1e-12f && std::isfinite(n);
}

// Angle between two directions in degrees, by atan2 (exact near 0 and 180, unlike acos).
double angle_degrees(const glm::vec3& a, const glm::vec3& b) {
  const double c = glm::length(glm::cross(a, b));
  const double d = glm::dot(a, b);
  return std::atan2(c, d) * k_rad_to_deg;
}

}  // namespace

accuracy_group bone_accuracy_group(bone b) {
  switch (b) {
    case bone::hips:
    case bone::spine:
    case bone::chest:
    case bone::upper_chest:
    case bone::neck:
      return accuracy_group::torso;
    case bone::head:
    case bone::left_eye:
    case bone::right_eye:
    case bone::jaw:
      return accuracy_group::head;
    case bone::left_upper_leg:
    case bone::left_lower_leg:
    case bone::left_foot:
    case bone::left_toes:
    case bone::right_upper_leg:
    case bone::right_lower_leg:
    case bone::right_foot:
    case bone::right_toes:
      return accuracy_group::legs;
    case bone::left_shoulder:
    case bone::left_upper_arm:
    case bone::left_lower_arm:
    case bone::left_hand:
    case bone::right_shoulder:
    case bone::right_upper_arm:
    case bone::right_lower_arm:
    case bone::right_hand:
      return accuracy_group::arms;
    default:
      return accuracy_group::fingers;
  }
}

const char* accuracy_group_name(accuracy_group g) {
  constexpr const char* k_names[k_accuracy_group_count] = {"torso", "arms", "legs", "fingers",
                                                           "head"};
  return k_names[static_cast<int>(g)];
}

void accumulate_pose_accuracy(const proxy_pose& truth, const proxy_pose& solved,
                              pose_accuracy& acc) {
  std::array<glm::quat, k_bone_count> wt, ws;
  compute_world_rotations(truth, wt);
  // A bad solved rotation poisons its descendants' world rotations: mark them all.
  std::array<bool, k_bone_count> bad{};
  proxy_pose s = solved;
  for (int b = 0; b < k_bone_count; ++b) {
    const int p = bone_parent(b);
    bad[b] = !usable(solved.rotations[b]) || (p != k_no_parent && bad[p]);
    s.rotations[b] =
        usable(solved.rotations[b]) ? glm::normalize(solved.rotations[b]) : identity_quat();
  }
  compute_world_rotations(s, ws);

  bool low_frame = false;
  for (int b = 0; b < k_bone_count; ++b)
    if (truth.confidence[b] < k_low_visibility_marker) low_frame = true;
  ++acc.frames;
  if (low_frame) ++acc.low_visibility_frames;

  auto add = [&](accuracy_figures& f, int g, double deg) {
    f.direction.add(deg);
    f.groups[g].add(deg);
  };
  for (int b = 0; b < k_bone_count; ++b) {
    const accuracy_group g = bone_accuracy_group(static_cast<bone>(b));
    if (g == accuracy_group::head) continue;
    const glm::vec3 rest = bone_rest_direction(static_cast<bone>(b));
    const double deg = bad[b] ? 180.0 : angle_degrees(wt[b] * rest, glm::normalize(ws[b]) * rest);
    add(acc.all, static_cast<int>(g), deg);
    acc.bones[b].add(deg);
    if (low_frame) add(acc.low_visibility, static_cast<int>(g), deg);
    if (truth.confidence[b] < k_low_visibility_marker) acc.marked.add(deg);
  }
  const int h = idx(bone::head);
  const double head =
      bad[h] ? 180.0 : rotation_angle(glm::normalize(glm::inverse(ws[h]) * wt[h])) * k_rad_to_deg;
  acc.all.head.add(head);
  acc.all.head_histogram.add(head);
  acc.bones[h].add(head);
  if (low_frame) {
    acc.low_visibility.head.add(head);
    acc.low_visibility.head_histogram.add(head);
  }

  face_accuracy& fa = acc.face;
  for (int side = 0; side < 2; ++side) {
    const expression one = side == 0 ? expression::blink_left : expression::blink_right;
    fa.blink.add((solved[expression::blink] + solved[one]) -
                 (truth[expression::blink] + truth[one]));
    const bone eye = side == 0 ? bone::left_eye : bone::right_eye;
    const glm::quat qs = solved[eye], qt = truth[eye];
    const bool eye_bad = !(glm::dot(qs, qs) > 1e-12f) || !std::isfinite(glm::dot(qs, qs));
    const glm::vec3 fwd(0.f, 0.f, 1.f);
    const double g =
        eye_bad ? 180.0 : angle_degrees(glm::normalize(qt) * fwd, glm::normalize(qs) * fwd);
    fa.gaze.add(g);
    fa.gaze_histogram.add(g);
  }
  fa.jaw_open.add(solved[blendshape::jaw_open] - truth[blendshape::jaw_open]);
  for (int v = 0; v < 5; ++v)
    fa.visemes[v].add(solved.expressions[idx(expression::aa) + v] -
                      truth.expressions[idx(expression::aa) + v]);
  for (int i = 0; i < k_blendshape_count; ++i) {
    fa.shapes[i].add(solved.blendshapes[i] - truth.blendshapes[i]);
    if (truth.blendshapes[i] >= 0.2f)
      fa.shapes_active[i].add(solved.blendshapes[i] - truth.blendshapes[i]);
  }
}

status evaluate_pose_files(const std::string& truth_path, const std::string& solved_path,
                           pose_accuracy& out, const pose_accuracy_options& options) {
  out = pose_accuracy{};
  if (!(options.time_tolerance >= 0.0) || !std::isfinite(options.time_tolerance))
    return status::error("pose_accuracy_options.time_tolerance must be finite and >= 0 seconds");
  pose_reader truth, solved;
  status st = truth.open(truth_path);
  if (!st.ok()) return st;
  st = solved.open(solved_path);
  if (!st.ok()) return st;

  proxy_pose t, s;
  bool have_s = false, s_done = false;
  double last_t = -INFINITY, last_s = -INFINITY;
  long unmatched = 0;
  double first_unmatched = 0.0;
  // Reads the next solved frame; false at the end or on an error (st set).
  auto next_solved = [&]() {
    const read_result r = solved.next(s);
    if (r == read_result::error) {
      st = status::error(solved.error());
      return false;
    }
    if (r == read_result::end) {
      s_done = true;
      return false;
    }
    if (!(s.t > last_s)) {
      char msg[160];
      std::snprintf(msg, sizeof msg, ":%ld: time %.6g s is not after the previous frame's",
                    solved.line(), s.t);
      st = status::error(solved_path + msg + " (eval-pose needs increasing times)");
      return false;
    }
    last_s = s.t;
    return true;
  };
  for (;;) {
    const read_result r = truth.next(t);
    if (r == read_result::error) return status::error(truth.error());
    if (r == read_result::end) break;
    if (!(t.t > last_t)) {
      char msg[160];
      std::snprintf(msg, sizeof msg, ":%ld: time %.6g s is not after the previous frame's",
                    truth.line(), t.t);
      return status::error(truth_path + msg + " (eval-pose needs increasing times)");
    }
    last_t = t.t;
    // Skip solved frames before this truth frame's window.
    while (!s_done && (!have_s || s.t < t.t - options.time_tolerance)) {
      have_s = next_solved();
      if (!st.ok()) return st;
    }
    if (have_s && std::abs(s.t - t.t) <= options.time_tolerance) {
      accumulate_pose_accuracy(t, s, out);
    } else {
      if (unmatched == 0) first_unmatched = t.t;
      ++unmatched;
    }
  }
  if (out.frames == 0 && unmatched == 0)
    return status::error(truth_path + ": no frames (eval-pose needs the truth poses)");
  if (unmatched > 0) {
    char msg[200];
    std::snprintf(msg, sizeof msg,
                  "%ld of %ld frames of the truth have no frame at the same time (within %.3g ms) "
                  "in ",
                  unmatched, unmatched + out.frames, options.time_tolerance * 1e3);
    char first[96];
    std::snprintf(first, sizeof first, " (the first at t = %.6g s)", first_unmatched);
    return status::error(std::string(msg) + solved_path + first +
                         "; solve the landmarks made with the truth, without --fps");
  }
  return {};
}

status measure_pose_jitter(const std::string& path, pose_jitter& out) {
  out = pose_jitter{};
  pose_reader reader;
  if (status st = reader.open(path); !st.ok()) return st;
  // The world directions of the last three frames (a ring) and their times.
  std::array<std::array<glm::dvec3, k_bone_count>, 3> dirs{};
  std::array<double, 3> times{};
  std::array<double, k_direction_group_count> sum{};
  std::array<long, k_direction_group_count> count{};
  std::array<double, k_bone_count> bone_sum{};
  proxy_pose p;
  std::array<glm::quat, k_bone_count> world;
  for (;;) {
    const read_result r = reader.next(p);
    if (r == read_result::error) return status::error(reader.error());
    if (r == read_result::end) break;
    if (out.frames > 0 && !(p.t > times[(out.frames - 1) % 3])) {
      char msg[160];
      std::snprintf(msg, sizeof msg, ":%ld: time %.6g s is not after the previous frame's",
                    reader.line(), p.t);
      return status::error(path + msg + " (eval-pose --jitter needs increasing times)");
    }
    for (int b = 0; b < k_bone_count; ++b)
      if (!usable(p.rotations[b])) p.rotations[b] = identity_quat();
    compute_world_rotations(p, world);
    const int k = static_cast<int>(out.frames % 3);
    times[k] = p.t;
    for (int b = 0; b < k_bone_count; ++b)
      dirs[k][b] = glm::normalize(
          glm::dvec3(glm::normalize(world[b]) * bone_rest_direction(static_cast<bone>(b))));
    ++out.frames;
    if (out.frames < 3) continue;
    const int k0 = static_cast<int>((out.frames - 3) % 3),
              k1 = static_cast<int>((out.frames - 2) % 3);
    const double dt0 = times[k1] - times[k0], dt1 = times[k] - times[k1];
    for (int b = 0; b < k_bone_count; ++b) {
      const accuracy_group g = bone_accuracy_group(static_cast<bone>(b));
      if (g == accuracy_group::head) continue;
      const glm::dvec3 a = ((dirs[k][b] - dirs[k1][b]) / dt1 - (dirs[k1][b] - dirs[k0][b]) / dt0) /
                           (0.5 * (dt0 + dt1));
      const double deg = glm::length(a) * k_rad_to_deg;
      sum[static_cast<int>(g)] += deg * deg;
      bone_sum[b] += deg * deg;
      ++count[static_cast<int>(g)];
    }
  }
  if (out.frames < 3)
    return status::error(path + ": fewer than three frames (jitter needs at least three)");
  double all = 0.0;
  long n = 0;
  for (int g = 0; g < k_direction_group_count; ++g) {
    out.groups[g] = count[g] > 0 ? std::sqrt(sum[g] / static_cast<double>(count[g])) : 0.0;
    all += sum[g];
    n += count[g];
  }
  out.rms = n > 0 ? std::sqrt(all / static_cast<double>(n)) : 0.0;
  for (int b = 0; b < k_bone_count; ++b)
    out.bones[b] = std::sqrt(bone_sum[b] / static_cast<double>(out.frames - 2));
  return {};
}

}  // namespace avatarmap
