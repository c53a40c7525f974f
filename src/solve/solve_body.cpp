// Stage 2a of the solver: body bones and the hips position. See solve_body.hpp.
#include "solve/solve_body.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/core/spaces.hpp"
#include "solve/solve_fit.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_measurement.hpp"

namespace avatarmap::solve_detail {
namespace {

// Share of the hips-to-shoulders turn given to each of spine and chest (the upper chest
// closes the chain exactly). BlazePose sees no point along the spine, so the curvature is not
// observable: an even split is the project's choice (docs/solver.md, "Known limits").
constexpr float k_spine_share = 1.f / 3.f;
// Confidence of a wrist orientation taken from the pose's pinky, index and wrist points,
// relative to those points' own confidence: just below 1, so that with perfect points it
// still reads 0.999 and the output's per-bone confidence tells this coarse estimate from one
// made from the hand's own 21 landmarks (confidence 1).
constexpr float k_pose_hand_confidence_scale = 0.999f;
// Ground position fit: the torso and leg points used (shoulders, hips, knees, ankles), how
// many of them must be confident (a least-squares scale and offset needs a spread of points;
// fewer than half of them is not trusted), and the least spread of their world x/y about
// their mean (square metres, summed) below which the fit is degenerate.
constexpr int k_ground_fit_points[] = {11, 12, 23, 24, 25, 26, 27, 28};
constexpr int k_ground_fit_min_points = 4;
constexpr float k_ground_fit_min_spread = 1e-6f;

// Arm of the avatar's left side, in (possibly mirrored) canonical space.
// `twist_reference` sets the twist of a straight arm (no bend plane): the upper arm's world
// rotation of the previous frame (temporal coherence), or the shoulder's on the first frame.
void measure_arm(const glm::vec3& sh, const glm::vec3& el, const glm::vec3& wr,
                 const glm::quat& twist_reference, glm::quat& out_upper, glm::quat& out_lower,
                 glm::quat& out_lower_local) {
  glm::vec3 d1 = el - sh;
  glm::vec3 d2 = wr - el;
  // The elbow is a hinge: the forearm leaves the upper arm toward the upper arm's local +Z.
  out_upper = aim_with_bend<k_px, k_pz>(twist_reference, d1, d2, glm::vec3(0.f));
  out_lower_local = swing_local(out_upper, k_x, d2);
  out_lower = out_upper * out_lower_local;
}

// Leg of the avatar's left side: hip, knee, ankle, heel, toe tip (foot index).
void measure_leg(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                 const glm::vec3& heel, const glm::vec3& toe, bool foot_ok,
                 const glm::quat& hips_world, glm::quat& out_upper, glm::quat& out_lower,
                 glm::quat& out_lower_local, glm::quat& out_foot) {
  glm::vec3 d1 = knee - hip;
  glm::vec3 d2 = ankle - knee;
  // The knee flexes backward: the shin leaves the thigh toward the thigh's local -Z. For a
  // straight leg the knee points where the foot points.
  glm::vec3 forward = foot_ok ? (toe - heel) : glm::vec3(0.f);
  out_upper = aim_with_bend<k_ny, k_nz>(hips_world, d1, d2, -forward);
  out_lower_local = swing_local(out_upper, -k_y, d2);
  out_lower = out_upper * out_lower_local;
  if (foot_ok) {
    constexpr glm::vec3 k_foot_rest(0.f, -0.44721360f, 0.89442719f);
    glm::vec3 dir = toe - ankle;
    // Heel, ankle and toe span the foot's sagittal plane; its normal is the foot's +X.
    glm::vec3 lateral = -glm::cross(toe - heel, ankle - heel);
    out_foot = frame_from_two_vectors(k_foot_rest, k_x, dir, lateral);
  } else {
    out_foot = out_lower;
  }
}

}  // namespace

// `arm_reference[side]`: the upper arm's world rotation last measured (side 0 = avatar's
// left), or null when there is none: it keeps a straight arm's twist continuous.
void measure_body(const prepared_frame& f, const solver_options& o,
                  const glm::quat* const arm_reference[2], frame_measurement& m) {
  const body_points& b = f.body;
  if (!b.valid || !o.parts.body) return;
  using pl = pose_landmark;
  const glm::vec3 hip_l = b.p[idx(pl::left_hip)], hip_r = b.p[idx(pl::right_hip)];
  const glm::vec3 sh_l = b.p[idx(pl::left_shoulder)], sh_r = b.p[idx(pl::right_shoulder)];
  const glm::vec3 hip_mid = 0.5f * (hip_l + hip_r);
  const glm::vec3 up = 0.5f * (sh_l + sh_r) - hip_mid;
  const float c_torso = min_conf(
      b, {idx(pl::left_hip), idx(pl::right_hip), idx(pl::left_shoulder), idx(pl::right_shoulder)});
  // Hips: yaw and roll from the hip line; a share of the torso's lean about the hip line.
  const glm::vec3 hip_line = normalize_or(hip_l - hip_r, k_x);
  const glm::quat upright = frame_from_axes<k_px, k_py>(hip_line, k_y);
  const glm::quat leaning = frame_from_axes<k_px, k_py>(hip_line, up);
  const glm::quat hips_w = nlerp_shortest(upright, leaning, o.hips_lean_share);
  // Spine chain: the rest of the way to the shoulder line's frame, split about evenly; the
  // upper chest closes the chain exactly, so the shoulder line is matched whatever the split.
  const glm::quat shoulders_w = frame_from_axes<k_px, k_py>(normalize_or(sh_l - sh_r, k_x), up);
  const glm::quat bend = glm::conjugate(hips_w) * shoulders_w;
  const glm::quat third = nlerp_shortest(identity_quat(), bend, k_spine_share);
  const glm::quat spine_w = hips_w * third;
  const glm::quat chest_w = spine_w * third;
  const glm::quat upper_chest_w = shoulders_w;
  set(m, bone::hips, hips_w, c_torso);
  set(m, bone::spine, spine_w, third, c_torso);
  set(m, bone::chest, chest_w, third, c_torso);
  set(m, bone::upper_chest, upper_chest_w, c_torso);
  // Clavicles are not observable from BlazePose's points: they follow the upper chest.
  set(m, bone::left_shoulder, upper_chest_w, identity_quat(), c_torso);
  set(m, bone::right_shoulder, upper_chest_w, identity_quat(), c_torso);

  for (int side = 0; side < 2; ++side) {
    const bool left = side == 0;
    auto P = [&](pl l_id, pl r_id) {
      glm::vec3 v = b.p[idx(left ? l_id : r_id)];
      return left ? v : mirror_x(v);
    };
    auto C = [&](std::initializer_list<pl> ids_l, std::initializer_list<pl> ids_r) {
      float c = 1.f;
      for (pl i : (left ? ids_l : ids_r)) c = std::min(c, b.c[idx(i)]);
      return c;
    };
    auto out = [&](const glm::quat& q) { return left ? q : mirror_x(q); };
    const glm::quat uc = left ? upper_chest_w : mirror_x(upper_chest_w);
    const glm::quat hw = left ? hips_w : mirror_x(hips_w);

    glm::quat ua, la, la_local;
    glm::quat twist_ref = uc;
    if (arm_reference[side])
      twist_ref = left ? *arm_reference[side] : mirror_x(*arm_reference[side]);
    measure_arm(P(pl::left_shoulder, pl::right_shoulder), P(pl::left_elbow, pl::right_elbow),
                P(pl::left_wrist, pl::right_wrist), twist_ref, ua, la, la_local);
    float c_ua = C({pl::left_shoulder, pl::left_elbow}, {pl::right_shoulder, pl::right_elbow});
    float c_la = C({pl::left_elbow, pl::left_wrist}, {pl::right_elbow, pl::right_wrist});
    set(m, left ? bone::left_upper_arm : bone::right_upper_arm, out(ua), c_ua);
    set(m, left ? bone::left_lower_arm : bone::right_lower_arm, out(la), out(la_local), c_la);
    // Coarse wrist orientation from the pose's pinky, index and wrist points; replaced by
    // the hand landmarks when those are present.
    if (o.parts.hands && f.hand[side].c <= 0.f) {
      glm::vec3 wr = P(pl::left_wrist, pl::right_wrist);
      glm::vec3 pk = P(pl::left_pinky, pl::right_pinky);
      glm::vec3 ix = P(pl::left_index, pl::right_index);
      glm::quat hand =
          frame_from_axes<k_px, k_pz>(normalize_or(0.5f * (pk + ix) - wr, k_x), ix - pk);
      float c_h = C({pl::left_wrist, pl::left_pinky, pl::left_index},
                    {pl::right_wrist, pl::right_pinky, pl::right_index});
      set(m, left ? bone::left_hand : bone::right_hand, out(hand),
          k_pose_hand_confidence_scale * c_h);
    }

    glm::quat ul, ll, ll_local, foot;
    const float c_foot = C({pl::left_ankle, pl::left_heel, pl::left_foot_index},
                           {pl::right_ankle, pl::right_heel, pl::right_foot_index});
    measure_leg(P(pl::left_hip, pl::right_hip), P(pl::left_knee, pl::right_knee),
                P(pl::left_ankle, pl::right_ankle), P(pl::left_heel, pl::right_heel),
                P(pl::left_foot_index, pl::right_foot_index), c_foot > o.confidence.lost_below, hw,
                ul, ll, ll_local, foot);
    set(m, left ? bone::left_upper_leg : bone::right_upper_leg, out(ul),
        C({pl::left_hip, pl::left_knee}, {pl::right_hip, pl::right_knee}));
    set(m, left ? bone::left_lower_leg : bone::right_lower_leg, out(ll), out(ll_local),
        C({pl::left_knee, pl::left_ankle}, {pl::right_knee, pl::right_ankle}));
    set(m, left ? bone::left_foot : bone::right_foot, out(foot), c_foot);
    set(m, left ? bone::left_toes : bone::right_toes, out(foot), identity_quat(), c_foot);
  }
}

// Hips height above the floor (lowest foot point) from metric points, and the hips' ground
// position from the image (weak-perspective scale -> depth).
void measure_hips_position(const landmark_frame& in, const prepared_frame& f,
                           const solver_options& o, frame_measurement& m) {
  const body_points& b = f.body;
  if (!b.valid || !o.parts.body || !o.parts.hips_translation) return;
  using pl = pose_landmark;
  if (b.metric) {
    float c =
        min_conf(b, {idx(pl::left_hip), idx(pl::right_hip), idx(pl::left_knee), idx(pl::right_knee),
                     idx(pl::left_ankle), idx(pl::right_ankle), idx(pl::left_heel),
                     idx(pl::right_heel), idx(pl::left_foot_index), idx(pl::right_foot_index)});
    if (c > o.confidence.lost_below) {
      float floor_y = b.p[idx(pl::left_ankle)].y;
      for (int i = idx(pl::left_ankle); i <= idx(pl::right_foot_index); ++i)
        floor_y = std::min(floor_y, b.p[i].y);
      glm::vec3 hip_mid = 0.5f * (b.p[idx(pl::left_hip)] + b.p[idx(pl::right_hip)]);
      m.hips_height = hip_mid.y - floor_y;
      // Fitted to the image: feet above the floor learnt over the take lift the hips (a jump).
      if (f.fit) m.hips_height += f.fit->feet_above_floor;
      m.hips_height_valid = std::isfinite(m.hips_height);
    }
  }
  if (f.fit) {  // the fitted root: a full pinhole fit, turned to gravity (solve_fit.hpp)
    const float x = o.mirror ? -f.fit->hips.x : f.fit->hips.x;
    m.hips_ground = glm::vec2(x, -f.fit->hips.z);
    m.hips_ground_valid = is_finite(glm::vec3(m.hips_ground, 0.f));
    return;
  }
  if (!in.has(frame_part::pose) || !in.has(frame_part::pose_world)) return;
  // Least-squares fit image_px = s * world_xy + t over confident torso and leg points. The
  // world origin is the hip midpoint, so t is the hip midpoint's pixel position.
  constexpr int k_count = sizeof(k_ground_fit_points) / sizeof(k_ground_fit_points[0]);
  glm::vec2 wp[k_count], ip[k_count];
  glm::vec2 mw(0.f), mi(0.f);
  int n = 0;
  // With world landmarks present, b.c holds their confidences (mirrored indices, hence the
  // mirror of i); only the image points' confidence is new here.
  for (int i : k_ground_fit_points) {
    const landmark& w = in.pose_world[i];
    const landmark& p = in.pose[i];
    const float cw = b.c[o.mirror ? pose_mirror_index(i) : i];
    if (std::min(cw, landmark_confidence(p)) < o.confidence.found_above) continue;
    wp[n] = glm::vec2(w.x, w.y);
    ip[n] = glm::vec2(p.x * f.width, p.y * f.height);
    mw += wp[n];
    mi += ip[n];
    ++n;
  }
  if (n < k_ground_fit_min_points) return;
  mw /= float(n);
  mi /= float(n);
  float num = 0.f, den = 0.f;
  for (int k = 0; k < n; ++k) {
    glm::vec2 dw = wp[k] - mw;
    num += glm::dot(dw, ip[k] - mi);
    den += glm::dot(dw, dw);
  }
  if (!(den > k_ground_fit_min_spread) || !(num > 0.f)) return;
  const float s = num / den;        // pixels per metre
  const glm::vec2 t = mi - s * mw;  // hip midpoint in pixels
  const float focal = f.focal;
  const float depth = focal / s;
  float x = (t.x - 0.5f * f.width) / focal * depth;
  if (o.mirror) x = -x;
  m.hips_ground = glm::vec2(x, -depth);
  m.hips_ground_valid = is_finite(glm::vec3(m.hips_ground, 0.f));
}

}  // namespace avatarmap::solve_detail
