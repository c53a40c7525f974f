// Stage 1c of the solver: the body in the world. See solve_fit.hpp.
#include "solve/solve_fit.hpp"

#include <algorithm>
#include <cmath>

#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {
namespace {

using pl = pose_landmark;

// Least confidence of a point the fit puts on its ray (else it keeps its world offset).
constexpr float k_min_confidence = 0.5f;
// Fewest confident torso and leg points for the root (three unknowns, two equations each).
constexpr int k_min_root_points = 4;
// Nearest plausible camera (metres to the hip midpoint).
constexpr double k_min_depth = 0.3;
// BlazePose's world points lean toward the camera (12-29 degrees measured on rendered mocap,
// docs/solver.md). Each frame's lean is the turn about the camera's x axis that best puts the
// world points onto the image (searched over +-35 degrees, every 10, refined to ~0.6); the
// take's lean is their running mean with a prior of no lean worth k_lean_prior_frames.
constexpr float k_lean_search = 35.f * 3.14159265f / 180.f;
constexpr float k_lean_coarse = 10.f * 3.14159265f / 180.f;
constexpr float k_lean_fine = 0.6f * 3.14159265f / 180.f;
constexpr double k_lean_prior_frames = 1.0;
// Field-of-view fits (focal length free) that must have told the lean before theirs is used.
constexpr double k_focal_lean_frames = 5.0;
// Every k_lean_every-th frame is searched, until k_lean_max_frames frames have told the lean.
constexpr long k_lean_every = 3;
constexpr double k_lean_max_frames = 600.0;
// A leg is straight (a standing frame, evidence of the vertical) when thigh and shin point
// within ~12 degrees of each other.
constexpr float k_straight_leg_cos = 0.978f;
// Most height difference between the ankles (metres) of a standing frame.
constexpr float k_standing_feet_step = 0.04f;
// Weight of the level-camera prior, in frames of evidence.
constexpr double k_gravity_prior_frames = 30.0;
// A frame's vertical counts only when it is within this angle of the current estimate's
// (larger: a lying or jumping body, not evidence of gravity).
constexpr float k_gravity_gate_cos = 0.8f;  // ~37 degrees

// The floor's plane (the feet's resting points over the take) decides the vertical once it
// has this many points spread at least k_floor_min_spread (metres, standard deviation) in its
// narrower direction: a walk, not feet standing in one place.
constexpr double k_floor_min_points = 30.0;
constexpr double k_floor_min_spread = 0.15;
// ... or, along one line only (a straight walk), at least this far (standard deviation).
constexpr double k_floor_min_line = 0.3;
// Feet higher than this above the floor are in the air (a jump): the hips rise by the rest.
constexpr double k_jump_min_height = 0.04;
// Share of each grounded frame's floor height taken into the running floor (~1 s memory at
// 30 frames/s: a camera that slowly changes its height is followed).
constexpr double k_floor_rate = 0.05;
// Feet above the floor for longer than this are not in a jump (a hop's flight is ~0.3-0.5 s).
constexpr double k_max_airborne_seconds = 0.8;

// The segment fit's uncertainties (metres): of a learnt length against this frame's image
// (image noise and the person's own give), and of the world points' depth once their lean is
// undone. Their ratio sets where the image's foreshortening overrules the world's depth.
constexpr float k_sigma_length = 0.05f;
constexpr float k_sigma_world = 0.04f;
// Newton steps of the fit along a ray, from the best starting depth.
constexpr int k_newton_steps = 3;

inline float conf(const landmark& l) { return landmark_confidence(l); }
inline glm::vec3 pos(const landmark& l) { return glm::vec3(l.x, l.y, l.z); }

struct frame_view {
  const landmark_frame* in;
  float cx, cy, width, height, focal;
  glm::vec3 ray(int i) const {  // camera axes, z = 1
    const landmark& p = in->pose[i];
    return glm::vec3((p.x * width - cx) / focal, (p.y * height - cy) / focal, 1.f);
  }
  float c(int i) const { return std::min(conf(in->pose[i]), conf(in->pose_world[i])); }
};

// The point on `ray` (z = 1 scaled) that best agrees with both the segment's learnt length
// from the fitted parent `a` and the world points' target `a + world_dir`: it minimises
//   (|P - a| - length)^2 / k_sigma_length^2 + |P - Q|^2 / k_sigma_world^2
// over P on the ray (Q: the ray's point nearest the world's target). Where the segment turns
// in depth its foreshortening pins the depth; seen side-on (perpendicular to its ray) the
// length says little and the world's depth decides; the world points choose between the two
// depths a length allows.
glm::vec3 on_ray(const glm::vec3& ray, const glm::vec3& a, float length,
                 const glm::vec3& world_dir) {
  const float rr = glm::dot(ray, ray), qb = glm::dot(ray, a), qc = glm::dot(a, a) - length * length;
  const glm::vec3 target = a + world_dir;
  const float s_world = glm::dot(target, ray) / rr;
  const float inv_l2 = 1.f / (k_sigma_length * k_sigma_length);
  const float inv_w2 = rr / (k_sigma_world * k_sigma_world);
  // `dist`: |s ray - a|, which the Newton step at an accepted s reuses (no second sqrt).
  auto cost = [&](float s, float& dist) {
    dist = glm::length(ray * s - a);
    const float d = dist - length;
    const float e = s - s_world;
    return d * d * inv_l2 + e * e * inv_w2;
  };
  // The cost's minima lie near the depths the length allows (the two roots of
  // |s ray - a| = length, or the ray's closest point when there are none) or near the world's
  // depth: start from the best of them, then a few Newton steps.
  float best_dist = 0.f;
  float best_s = s_world, best = cost(s_world, best_dist);
  auto consider = [&](float s) {
    float dist;
    const float c = cost(s, dist);
    if (c < best) {
      best = c;
      best_s = s;
      best_dist = dist;
    }
  };
  const float disc = qb * qb - rr * qc;
  if (disc > 0.f) {
    const float root = std::sqrt(disc);
    consider((qb - root) / rr);
    consider((qb + root) / rr);
  } else {
    consider(qb / rr);
  }
  float s = best_s;
  float d = best_dist;  // |s ray - a|
  for (int it = 0; it < k_newton_steps; ++it) {
    if (!(d > 1e-6f)) break;
    const float d1 = (s * rr - qb) / d, d2 = (rr - d1 * d1) / d;
    const float g1 = 2.f * inv_l2 * (d - length) * d1 + 2.f * inv_w2 * (s - s_world);
    const float g2 = 2.f * inv_l2 * (d1 * d1 + (d - length) * d2) + 2.f * inv_w2;
    if (!(g2 > 0.f)) break;
    const float next = s - g1 / g2;
    float next_dist;
    const float c = cost(next, next_dist);
    if (!(c <= best)) break;
    best = c;
    s = next;
    d = next_dist;
  }
  return ray * s;
}

glm::vec3 rotate_x(const glm::vec3& v, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  return glm::vec3(v.x, v.y * c - v.z * s, v.y * s + v.z * c);
}

// Rotation taking `up` (unit, camera axes) to (0, -1, 0): the shortest arc.
glm::mat3 gravity_rotation(const glm::vec3& up) {
  const glm::vec3 target(0.f, -1.f, 0.f);
  const glm::vec3 axis = glm::cross(up, target);
  const float s = glm::length(axis), c = glm::dot(up, target);
  if (s < 1e-6f) return glm::mat3(1.f);
  const glm::vec3 k = axis / s;
  const glm::mat3 kx(0.f, k.z, -k.y, -k.z, 0.f, k.x, k.y, -k.x, 0.f);  // column-major
  return glm::mat3(1.f) + s * kx + (1.f - c) * (kx * kx);
}

void learn_lengths(const frame_view& v, body_lengths& L) {
  const auto& w = v.in->pose_world;
  auto add = [&](int s, int a, int b, float scale = 1.f) {
    if (std::min(v.c(a), v.c(b)) < k_min_confidence) return;
    const float d = glm::length(pos(w[a]) - pos(w[b])) * scale;
    if (!std::isfinite(d) || d <= 0.f) return;
    L.sum[s] += d;
    L.frames[s] += 1.0;
  };
  add(body_lengths::hip_half, idx(pl::left_hip), idx(pl::right_hip), 0.5f);
  add(body_lengths::shoulder_half, idx(pl::left_shoulder), idx(pl::right_shoulder), 0.5f);
  for (int side = 0; side < 2; ++side) {
    const int o = side;  // left = even offset 0, right = 1 (pose indices alternate)
    add(body_lengths::upper_arm, idx(pl::left_shoulder) + o, idx(pl::left_elbow) + o);
    add(body_lengths::forearm, idx(pl::left_elbow) + o, idx(pl::left_wrist) + o);
    add(body_lengths::thigh, idx(pl::left_hip) + o, idx(pl::left_knee) + o);
    add(body_lengths::shin, idx(pl::left_knee) + o, idx(pl::left_ankle) + o);
    add(body_lengths::foot, idx(pl::left_ankle) + o, idx(pl::left_foot_index) + o);
  }
  const int torso[4] = {idx(pl::left_hip), idx(pl::right_hip), idx(pl::left_shoulder),
                        idx(pl::right_shoulder)};
  for (int i : torso)
    if (v.c(i) < k_min_confidence) return;
  const glm::vec3 hm = 0.5f * (pos(w[torso[0]]) + pos(w[torso[1]]));
  const glm::vec3 sm = 0.5f * (pos(w[torso[2]]) + pos(w[torso[3]]));
  const float d = glm::length(sm - hm);
  if (std::isfinite(d) && d > 0.f) {
    L.sum[body_lengths::torso] += d;
    L.frames[body_lengths::torso] += 1.0;
  }
}

// Hip midpoint in camera axes from the pinhole equations of the confident torso and leg
// points, the world points `w` turned by `lean` about the camera's x axis first:
// du (Z + wz) = f (X + wx), dv (Z + wz) = f (Y + wy), linear in (X, Y, Z). `rss`: the
// reprojection residual's sum of squares (pixels^2).
bool fit_root(const frame_view& v, const std::array<glm::vec3, k_pose_landmark_count>& w,
              float lean, glm::vec3& out, double& rss) {
  static constexpr int k_points[] = {11, 12, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32};
  double n[3][3] = {}, r[3] = {};
  int count = 0;
  for (int i : k_points) {
    if (v.c(i) < k_min_confidence) continue;
    const glm::vec3 p = rotate_x(w[i], lean);
    const glm::vec3 ray = v.ray(i);
    // Rows [-1, 0, u] and [0, -1, v] (u, v = ray x, y): -X + u Z = wx - u wz.
    const double rows[2][4] = {{-1.0, 0.0, ray.x, double(p.x) - ray.x * double(p.z)},
                               {0.0, -1.0, ray.y, double(p.y) - ray.y * double(p.z)}};
    for (const auto& q : rows) {
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) n[a][b] += q[a] * q[b];
        r[a] += q[a] * q[3];
      }
    }
    ++count;
  }
  if (count < k_min_root_points) return false;
  // 3x3 solve by Cramer's rule (the system is small and well conditioned when it passes).
  auto det3 = [](double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det3(n);
  if (!(std::fabs(d) > 1e-12)) return false;
  double x[3];
  for (int c = 0; c < 3; ++c) {
    double m[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) m[a][b] = b == c ? r[a] : n[a][b];
    x[c] = det3(m) / d;
  }
  if (!(x[2] > k_min_depth) || !std::isfinite(x[0]) || !std::isfinite(x[1])) return false;
  out = glm::vec3(float(x[0]), float(x[1]), float(x[2]));
  rss = 0.0;
  for (int i : k_points) {
    if (v.c(i) < k_min_confidence) continue;
    const glm::vec3 p = out + rotate_x(w[i], lean);
    const glm::vec3 ray = v.ray(i);
    const double du = (p.x / p.z - ray.x) * v.focal, dv = (p.y / p.z - ray.y) * v.focal;
    rss += du * du + dv * dv;
  }
  return std::isfinite(rss);
}

// The lean about the camera's x axis that best turns the world points onto the image (coarse
// to fine over +-k_lean_search), or false when no fit.
bool best_lean(const frame_view& v, const std::array<glm::vec3, k_pose_landmark_count>& w,
               float& lean) {
  glm::vec3 root;
  double best = 0.0, rss = 0.0;
  bool found = false;
  auto consider = [&](float a) {
    if (!fit_root(v, w, a, root, rss)) return;
    if (!found || rss < best) {
      best = rss;
      lean = a;
      found = true;
    }
  };
  for (float a = -k_lean_search; a <= k_lean_search + 1e-4f; a += k_lean_coarse) consider(a);
  if (!found) return false;
  for (float step = 0.5f * k_lean_coarse; step >= k_lean_fine; step *= 0.5f) {
    const float centre = lean;
    consider(centre - step);
    consider(centre + step);
  }
  // A minimum at the search's edge is no estimate.
  return std::fabs(lean) < k_lean_search - 0.5f * k_lean_coarse;
}

}  // namespace

void camera_gravity::add_floor_point(const glm::dvec3& p) {
  floor_m1 += p;
  floor_m2 += glm::outerProduct(p, p);
  floor_n += 1.0;
}

glm::vec3 camera_gravity::up() const {
  glm::vec3 n;
  return floor_normal(n) ? n : glm::vec3(glm::normalize(up_sum));
}

bool camera_gravity::floor_normal(glm::vec3& out) const {
  const glm::dvec3 legs = glm::normalize(up_sum);
  if (floor_n < k_floor_min_points) return false;
  // The floor's normal: the least-spread direction of the feet's resting points (inverse
  // iteration from the legs' vertical), trusted when the points spread over the floor in
  // both its directions and it agrees with the legs.
  const glm::dvec3 mean = floor_m1 / floor_n;
  const glm::dmat3 c = floor_m2 / floor_n - glm::outerProduct(mean, mean);
  const glm::dmat3 inv = glm::inverse(c + glm::dmat3(1e-6));
  glm::dvec3 n = legs;
  for (int it = 0; it < 8; ++it) n = glm::normalize(inv * n);
  if (glm::dot(n, legs) < 0.0) n = -n;
  const glm::dvec3 u = glm::normalize(
      glm::cross(n, std::fabs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  const glm::dvec3 w = glm::cross(n, u);
  const double a = glm::dot(u, c * u), b = glm::dot(u, c * w), d = glm::dot(w, c * w);
  const double root = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  const double lambda1 = 0.5 * (a + d) + root, lambda2 = 0.5 * (a + d) - root;
  if (!(lambda2 > k_floor_min_spread * k_floor_min_spread)) {
    // A walk along one line (toward the camera, or across): the line is level, which decides
    // the tilt about the other horizontal axis; the tilt about the line stays the legs'.
    if (!(lambda1 > k_floor_min_line * k_floor_min_line)) return false;
    // The line's direction: the floor's eigenvector of lambda1 in the (u, w) plane.
    const double angle = 0.5 * std::atan2(2.0 * b, a - d);
    const glm::dvec3 line = glm::normalize(std::cos(angle) * u + std::sin(angle) * w);
    n = legs - glm::dot(legs, line) * line;
    if (!(glm::length(n) > 1e-6)) return false;
    n = glm::normalize(n);
  }
  if (!(glm::dot(n, legs) > k_gravity_gate_cos) || !std::isfinite(n.x + n.y + n.z)) return false;
  out = glm::vec3(n);
  return true;
}

float camera_gravity::pitch_degrees() const {
  const glm::dvec3 u = glm::dvec3(up());
  return float(std::atan2(-u.z, -u.y) * 180.0 / 3.14159265358979);
}

float camera_gravity::roll_degrees() const {
  const glm::dvec3 u = glm::dvec3(up());
  return float(std::asin(std::clamp(u.x, -1.0, 1.0)) * 180.0 / 3.14159265358979);
}

bool fit_body(const landmark_frame& in, float width, float height, float focal, bool learn,
              body_lengths& lengths, camera_gravity& gravity, body_fit& out) {
  out.valid = false;
  if (!in.has(frame_part::pose) || !in.has(frame_part::pose_world) || !(width > 0.f) ||
      !(height > 0.f) || !(focal > 0.f))
    return false;
  const frame_view v{&in, 0.5f * width, 0.5f * height, width, height, focal};
  // A held view (frame_solver::hold_view) learns nothing more of the camera or the performer;
  // the floor's level is still followed.
  const bool learn_view = learn && !gravity.view_held;
  if (learn_view) learn_lengths(v, lengths);
  // The world points, then the take's lean undone.
  std::array<glm::vec3, k_pose_landmark_count> w;
  for (int i = 0; i < k_pose_landmark_count; ++i) w[i] = pos(in.pose_world[i]);
  float lean = 0.f;
  // The lean changes little over a take: a sample of frames tells it (docs/solver.md), the
  // search's cost stays off most frames.
  // Each frame tells once (the file warm-up solves its frames again).
  const bool fresh = in.t > gravity.lean_t_last;
  if (learn && fresh) gravity.lean_t_last = in.t;
  const bool sample = learn_view && fresh && gravity.lean_frames < k_lean_max_frames &&
                      (gravity.lean_tick++ % k_lean_every) == 0;
  if (sample && best_lean(v, w, lean)) {
    gravity.lean_sum += lean;
    gravity.lean_frames += 1.0;
  }
  const float take_lean =
      gravity.focal_lean_frames >= k_focal_lean_frames
          ? float(gravity.focal_lean_sum / gravity.focal_lean_frames)
          : float(gravity.lean_sum / (gravity.lean_frames + k_lean_prior_frames));
  for (auto& p : w) p = rotate_x(p, take_lean);
  glm::vec3 hips;
  double rss = 0.0;
  if (!fit_root(v, w, 0.f, hips, rss)) return false;

  std::array<glm::vec3, k_pose_landmark_count> cam;  // camera axes, metres
  // Joint `child` on its ray at segment `seg`'s length from the fitted `parent_cam`; a point
  // not confident enough (or a length not learnt yet) keeps its world offset.
  auto fit = [&](const glm::vec3& w_parent, const glm::vec3& parent_cam, int child, int seg) {
    const float len = lengths.get(seg);
    const glm::vec3 world_dir = w[child] - w_parent;
    cam[child] = len > 0.f && v.c(child) >= k_min_confidence
                     ? on_ray(v.ray(child), parent_cam, len, world_dir)
                     : parent_cam + world_dir;
  };
  auto hang = [&](int anchor, int point) { cam[point] = cam[anchor] + w[point] - w[anchor]; };

  // Torso: the shoulder line's midpoint on its ray at the torso's length from the hips, the
  // side chosen by the world's direction with BlazePose's lean toward the camera undone.
  const int lh = idx(pl::left_hip), rh = idx(pl::right_hip);
  const int ls = idx(pl::left_shoulder), rs = idx(pl::right_shoulder);
  const glm::vec3 w_hm = 0.5f * (w[lh] + w[rh]);
  const glm::vec3 w_sm = 0.5f * (w[ls] + w[rs]);
  const glm::vec3 hm = hips;  // the world points' origin is the hip midpoint
  glm::vec3 sm = hips + w_sm;
  const float torso_len = lengths.get(body_lengths::torso);
  if (torso_len > 0.f &&
      std::min(std::min(v.c(ls), v.c(rs)), std::min(v.c(lh), v.c(rh))) >= k_min_confidence) {
    const glm::vec3 ray = 0.5f * (v.ray(ls) + v.ray(rs));
    sm = on_ray(ray / ray.z, hm, torso_len, w_sm - w_hm);
  }
  for (int side = 0; side < 2; ++side) {
    const int hip = lh + side, sh = ls + side;
    fit(w_hm, hm, hip, body_lengths::hip_half);
    fit(w_sm, sm, sh, body_lengths::shoulder_half);
    const int el = idx(pl::left_elbow) + side, wr = idx(pl::left_wrist) + side;
    const int kn = idx(pl::left_knee) + side, an = idx(pl::left_ankle) + side;
    const int toe = idx(pl::left_foot_index) + side;
    fit(w[sh], cam[sh], el, body_lengths::upper_arm);
    fit(w[el], cam[el], wr, body_lengths::forearm);
    fit(w[hip], cam[hip], kn, body_lengths::thigh);
    fit(w[kn], cam[kn], an, body_lengths::shin);
    fit(w[an], cam[an], toe, body_lengths::foot);
    hang(an, idx(pl::left_heel) + side);
    for (int h = idx(pl::left_pinky) + side; h <= idx(pl::right_thumb); h += 2) hang(wr, h);
  }
  // Face points hang on the shoulder line's midpoint.
  for (int i = 0; i <= idx(pl::mouth_right); ++i) cam[i] = sm + w[i] - w_sm;

  // Gravity: the standing body's vertical (ankles' midpoint to the hips) in frames whose legs
  // are both straight, confident and parallel, the feet on one level (standing: not a leg
  // swung out, not a body tipping over on one foot). Each frame tells once.
  if (learn_view && fresh) {
    bool standing = true;
    glm::vec3 leg_dir[2];
    for (int side = 0; side < 2 && standing; ++side) {
      const int hip = lh + side, kn = idx(pl::left_knee) + side, an = idx(pl::left_ankle) + side;
      if (std::min(std::min(v.c(hip), v.c(kn)), v.c(an)) < k_min_confidence) standing = false;
      const glm::vec3 thigh = cam[kn] - cam[hip], shin = cam[an] - cam[kn];
      const float lt = glm::length(thigh), lsh = glm::length(shin);
      if (!(lt > 0.f && lsh > 0.f) || glm::dot(thigh, shin) < k_straight_leg_cos * lt * lsh)
        standing = false;
      leg_dir[side] = glm::normalize(cam[hip] - cam[an]);
    }
    const glm::vec3 current = glm::vec3(glm::normalize(gravity.up_sum));
    const float feet_step =
        std::fabs(glm::dot(cam[idx(pl::left_ankle)] - cam[idx(pl::right_ankle)], current));
    if (standing && glm::dot(leg_dir[0], leg_dir[1]) >= k_straight_leg_cos &&
        feet_step <= k_standing_feet_step) {
      const glm::vec3 ankles = 0.5f * (cam[idx(pl::left_ankle)] + cam[idx(pl::right_ankle)]);
      const glm::vec3 axis = glm::normalize(hm - ankles);
      if (glm::dot(axis, current) >= k_gravity_gate_cos) {
        if (gravity.weight == 0.0) gravity.up_sum *= k_gravity_prior_frames;
        gravity.up_sum += glm::dvec3(axis);
        gravity.weight += 1.0;
        ++gravity.frames;
      }
    }
  }
  // A point hung on a joint that was not seen (non-finite) keeps its own world position.
  for (int i = 0; i < k_pose_landmark_count; ++i)
    if (!std::isfinite(cam[i].x + cam[i].y + cam[i].z)) cam[i] = hips + w[i];
  const glm::vec3 up = gravity.up();
  const glm::mat3 r = gravity_rotation(up);
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    const glm::vec3 p = r * (cam[i] - hm);
    out.world[i] = in.pose_world[i];
    out.world[i].x = p.x;
    out.world[i].y = p.y;
    out.world[i].z = p.z;
  }
  out.hips = r * hm;
  // The floor: the feet's lowest point, gravity's down from the camera. Frames whose feet are
  // near it (not in the air) keep it current; a frame well above it is a jump.
  int lowest_i = idx(pl::left_ankle);
  bool feet_seen = true;
  for (int i = idx(pl::left_ankle); i <= idx(pl::right_foot_index); ++i) {
    if (out.world[i].y > out.world[lowest_i].y) lowest_i = i;  // y is down
    if (v.c(i) < k_min_confidence) feet_seen = false;
  }
  const float lowest = out.world[lowest_i].y;
  const double below = double(out.hips.y) + double(lowest);
  out.feet_above_floor = 0.f;
  if (feet_seen && std::isfinite(below)) {
    const glm::dvec3 up_now(up);
    if (!gravity.has_floor) {
      if (learn) {
        gravity.floor_below_camera = below;
        gravity.floor_up = up_now;
        gravity.has_floor = true;
        gravity.airborne_since = camera_gravity::k_not_airborne;
      }
    } else {
      // The level was learnt under the vertical of its time: turned to today's (the resting
      // points' mean along the change), so a vertical that has turned since reads as neither a
      // jump nor a sunk floor.
      double level = gravity.floor_below_camera;
      if (gravity.floor_n > 0.0)
        level -= glm::dot(up_now - gravity.floor_up, gravity.floor_m1 / gravity.floor_n);
      const double above = level - below;
      // A jump is short: feet "in the air" longer than k_max_airborne_seconds stand on a floor
      // seen higher than learnt (a camera's pitch not yet known tilts the floor along the
      // walk), which becomes the level.
      const bool in_air = above > k_jump_min_height;
      const bool grounded_long = in_air &&
                                 gravity.airborne_since != camera_gravity::k_not_airborne &&
                                 in.t - gravity.airborne_since > k_max_airborne_seconds;
      if (in_air && !grounded_long) {
        out.feet_above_floor = float(above - k_jump_min_height);
        if (learn && gravity.airborne_since == camera_gravity::k_not_airborne)
          gravity.airborne_since = in.t;
      } else if (learn) {
        gravity.floor_below_camera = grounded_long ? below : level + k_floor_rate * (below - level);
        gravity.floor_up = up_now;
        gravity.airborne_since = camera_gravity::k_not_airborne;
        if (fresh && !grounded_long && learn_view)
          gravity.add_floor_point(glm::dvec3(cam[lowest_i]));
      }
    }
  }
  out.valid = true;
  return true;
}

}  // namespace avatarmap::solve_detail
