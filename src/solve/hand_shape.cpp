// A hand's landmarks fitted to the shape of that hand. See include/avatarmap/solve/hand_shape.hpp.
#include "avatarmap/solve/hand_shape.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/core/rotation.hpp"
#include "solve/solve_geometry.hpp"

namespace avatarmap {
namespace {

// Palm slots (indices into hand_shape::k_palm) of the points that give the palm its axes.
constexpr int k_slot_wrist = 0, k_slot_index = 2, k_slot_middle = 3, k_slot_pinky = 5;
// Gauss-Newton steps of the palm's rotation, from a start within a few degrees: it converges
// quadratically on exact points and by ~10x a step under 5 mm of noise; done below 1e-7 rad
// (0.01 micrometres on a palm).
constexpr int k_align_steps = 8;
constexpr double k_align_done = 1e-7;
// Block coordinate descent sweeps of a finger's three segments: from the observed directions,
// 3 sweeps reach what 6 do (tuning seeds: noisy overall 4.62 degrees either way; 2 give 4.63).
constexpr int k_finger_sweeps = 3;
// A frame whose palm strays by more than this times the learnt noise's deviation, or by more
// than k_stray_floor_m per coordinate when the noise is smaller, is not learnt from.
constexpr double k_stray_factor = 4.0;
constexpr double k_stray_floor_m = 0.003;
constexpr int k_strays_to_restart = 30;
// How far an observed segment's length may be from the learnt one: the fit is taken whole
// within k_full_off x the learnt length or k_full_sd standard deviations of the length's noise
// (sqrt(2) sigma: two ends), whichever is more, not at all beyond k_none_off x the length or
// k_none_sd deviations (a failed depth estimate, a segment seen end-on), linearly between.
constexpr float k_full_off = 0.3f, k_none_off = 0.5f;
constexpr float k_full_sd = 3.f, k_none_sd = 5.f;
// The palm's residual has 3 x 6 coordinates less 6 degrees of freedom of the rigid motion.
constexpr double k_palm_dof = 3.0 * hand_shape::k_palm_points - 6.0;

bool finite(const glm::vec3& v) { return std::isfinite(v.x + v.y + v.z); }

// How much of the fit a finger takes for an observed segment of length l whose learnt length
// is len, with a length noise of sd (see k_full_off): a finger does not snap between fitted
// and observed.
float segment_weight(float l, float len, float sd) {
  if (!(len > 0.f) || !(l > 0.f)) return 0.f;
  const float off = std::fabs(l - len);
  const float full = std::max(k_full_off * len, k_full_sd * sd);
  const float none = std::max(k_none_off * len, k_none_sd * sd);
  if (off <= full) return 1.f;
  if (off >= none) return 0.f;
  return (none - off) / (none - full);
}

// The palm's own axes (as solve_hands measures the hand): X from the wrist to the middle
// knuckle, Z toward the index side.
glm::quat palm_frame(const glm::vec3* p) {
  return solve_detail::frame_from_axes<solve_detail::k_px, solve_detail::k_pz>(
      normalize_or(p[k_slot_middle] - p[k_slot_wrist], solve_detail::k_x),
      p[k_slot_index] - p[k_slot_pinky]);
}

}  // namespace

glm::quat hand_shape::align(const palm_points& observed, float* residual) const {
  // Start: the rotation between the two palms' own axes; then Gauss-Newton on
  // sum |R a_i - b_i|^2 with R <- exp(w) R, J w = sum (R a_i) x b_i,
  // J = sum (|q|^2 I - q q^T), q = R a_i; in double (a few microns matter on a 2 cm bone).
  glm::dquat r(palm_frame(observed.data()) * glm::conjugate(palm_frame(palm_.data())));
  for (int step = 0; step < k_align_steps; ++step) {
    glm::dvec3 g(0.0);
    glm::dmat3 j(0.0);
    for (int i = 0; i < k_palm_points; ++i) {
      const glm::dvec3 q = r * glm::dvec3(palm_[i]);
      g += glm::cross(q, glm::dvec3(observed[i]));
      const double qq = glm::dot(q, q);
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) j[c][k] += (c == k ? qq : 0.0) - q[c] * q[k];
    }
    if (!(std::fabs(glm::determinant(j)) > 1e-30)) break;
    const glm::dvec3 w = glm::inverse(j) * g;
    const double angle = glm::length(w);
    if (!(angle > 1e-12)) break;
    // exp(w) to first order, normalised: the iteration's fixed point (g = 0) is the same.
    r = glm::normalize(glm::dquat(1.0, 0.5 * w.x, 0.5 * w.y, 0.5 * w.z) * r);
    if (angle < k_align_done) break;
  }
  double sum = 0.0;
  for (int i = 0; i < k_palm_points; ++i) {
    const glm::dvec3 d = r * glm::dvec3(palm_[i]) - glm::dvec3(observed[i]);
    sum += glm::dot(d, d);
  }
  *residual = static_cast<float>(sum);
  return glm::quat(r);
}

bool hand_shape::centred_palm(const points& p, palm_points& b, glm::vec3& centre) {
  for (const glm::vec3& v : p)
    if (!finite(v)) return false;
  centre = glm::vec3(0.f);
  for (int i = 0; i < k_palm_points; ++i) centre += p[k_palm[i]];
  centre /= float(k_palm_points);
  for (int i = 0; i < k_palm_points; ++i) b[i] = p[k_palm[i]] - centre;
  return true;
}

void hand_shape::learn(const points& p, float confidence) {
  if (!(confidence >= k_learn_above)) return;
  palm_points b;
  glm::vec3 centre;
  if (!centred_palm(p, b, centre)) return;
  float residual = 0.f;
  const glm::quat r = frames_ > 0 ? align(b, &residual) : glm::quat(1.f, 0.f, 0.f, 0.f);
  learn_aligned(p, confidence, b, r, residual);
}

void hand_shape::fit(points& p, float confidence) const {
  if (!ready()) return;
  palm_points b;
  glm::vec3 centre;
  if (!centred_palm(p, b, centre)) return;
  float residual = 0.f;
  const glm::quat r = align(b, &residual);
  if (confidence >= k_learn_above && strays(residual)) return;  // not this hand: as observed
  fit_aligned(p, centre, r);
}

bool hand_shape::strays(float residual) const {
  const double var = residual / k_palm_dof;
  const double limit =
      std::max(k_stray_factor * k_stray_factor * noise_var_, k_stray_floor_m * k_stray_floor_m);
  return !(var <= limit);
}

void hand_shape::fit_and_learn(points& p, float confidence) {
  palm_points b;
  glm::vec3 centre;
  if (!centred_palm(p, b, centre)) return;
  const bool learning = confidence >= k_learn_above;
  if (!ready() && !learning) return;
  // One alignment serves both: the fit with the shape learnt so far, then learning from the
  // observed points (copied: the fit moves them).
  float residual = 0.f;
  const glm::quat r = frames_ > 0 ? align(b, &residual) : glm::quat(1.f, 0.f, 0.f, 0.f);
  const bool fitting = ready() && !(learning && strays(residual));
  if (!learning) {
    if (fitting) fit_aligned(p, centre, r);
    return;
  }
  const points observed = p;
  if (fitting) fit_aligned(p, centre, r);
  learn_aligned(observed, confidence, b, r, residual);
}

void hand_shape::learn_aligned(const points& p, float confidence, const palm_points& b,
                               const glm::quat& r, float residual) {
  if (!(confidence >= k_learn_above)) return;
  std::array<float, k_segments> len_sq;
  for (int f = 0; f < 5; ++f) {
    const int base = finger_base_landmark(f);
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 d = p[base + k + 1] - p[base + k];
      len_sq[3 * f + k] = glm::dot(d, d);
    }
  }
  if (frames_ == 0) {
    palm_ = b;
    length_sq_ = len_sq;
    frames_ = 1;
    return;
  }
  const double var = residual / k_palm_dof;
  if (frames_ >= k_min_frames && strays(residual)) {
    if (++strays_ >= k_strays_to_restart) {
      reset();
      learn_aligned(p, confidence, b, r, 0.f);  // the first frame of the new shape
    }
    return;
  }
  strays_ = 0;
  const float w = 1.f / float(std::min(frames_ + 1, k_horizon_frames));
  const glm::quat inv = glm::conjugate(r);
  for (int i = 0; i < k_palm_points; ++i) palm_[i] += w * (inv * b[i] - palm_[i]);
  for (int s = 0; s < k_segments; ++s) length_sq_[s] += w * (len_sq[s] - length_sq_[s]);
  // The noise from the second frame on (the first one is the shape itself).
  const double wn = 1.0 / double(std::min(frames_, k_horizon_frames));
  noise_var_ += wn * (var - noise_var_);
  ++frames_;
}

void hand_shape::fit_aligned(points& p, const glm::vec3& centre, const glm::quat& r) const {
  for (int i = 0; i < k_palm_points; ++i) p[k_palm[i]] = centre + r * palm_[i];

  // Per finger, from its fitted root: the observed joints o, the learnt lengths, the directions
  // d (from the observed segments) and the joints they give.
  constexpr int k_fingers = 5;
  const float length_sd = 1.41421356f * noise_sigma();
  glm::vec3 o[k_fingers][3], d[k_fingers][3], joint[k_fingers][3];
  float len[k_fingers][3], weight[k_fingers];
  for (int f = 0; f < k_fingers; ++f) {
    const int base = finger_base_landmark(f);
    glm::vec3 from = p[base];  // fitted
    weight[f] = 1.f;
    for (int k = 0; k < 3; ++k) {
      len[f][k] = segment_length(3 * f + k);
      o[f][k] = p[base + k + 1];
      const glm::vec3 seg = o[f][k] - from;
      const float l = glm::length(seg);
      weight[f] = std::min(weight[f], segment_weight(l, len[f][k], length_sd));
      d[f][k] = weight[f] > 0.f ? seg / l : glm::vec3(1.f, 0.f, 0.f);
      joint[f][k] = (k == 0 ? p[base] : joint[f][k - 1]) + len[f][k] * d[f][k];
      from = o[f][k];
    }
  }
  // Least squares over each finger's three directions: joint j = root + sum_{m <= j} len_m d_m.
  // With the others fixed, the best d_k is the direction of sum_{j >= k} (o_j - joint_j) +
  // (3 - k) len_k d_k, the observed joints' pull on segment k. The fingers are independent and
  // stepped side by side (their square roots overlap); the joints follow each change.
  for (int sweep = 0; sweep < k_finger_sweeps; ++sweep) {
    for (int k = 0; k < 3; ++k) {
      for (int f = 0; f < k_fingers; ++f) {
        glm::vec3 pull = float(3 - k) * len[f][k] * d[f][k];
        for (int j = k; j < 3; ++j) pull += o[f][j] - joint[f][j];
        const float l2 = glm::dot(pull, pull);
        if (!(l2 > 0.f)) continue;
        const glm::vec3 nd = pull / std::sqrt(l2);
        const glm::vec3 shift = len[f][k] * (nd - d[f][k]);
        d[f][k] = nd;
        for (int j = k; j < 3; ++j) joint[f][j] += shift;
      }
    }
  }
  for (int f = 0; f < k_fingers; ++f) {
    if (!(weight[f] > 0.f)) continue;  // kept as observed
    const int base = finger_base_landmark(f);
    for (int k = 0; k < 3; ++k) p[base + k + 1] = o[f][k] + weight[f] * (joint[f][k] - o[f][k]);
  }
}

float hand_shape::noise_sigma() const {
  return frames_ >= 2 ? static_cast<float>(std::sqrt(noise_var_)) : 0.f;
}

float hand_shape::segment_length(int s) const {
  if (s < 0 || s >= k_segments || frames_ == 0) return 0.f;
  const double l2 = length_sq_[s];
  // Each end carries noise_var per coordinate: |observed|^2 = length^2 + 6 noise_var.
  return static_cast<float>(std::sqrt(std::max(l2 - 6.0 * noise_var_, 0.25 * l2)));
}

}  // namespace avatarmap
