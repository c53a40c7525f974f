// Stage 2b of the solver: wrists and fingers from the hand landmarks. See solve_hands.hpp.
#include "solve/solve_hands.hpp"

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/core/spaces.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_measurement.hpp"

namespace avatarmap::solve_detail {
namespace {

// Wrist orientation of the avatar's left hand from the 21 hand points: +X along wrist ->
// middle knuckle, +Z toward the index side (palm faces -Y at rest).
glm::quat hand_world_from_points(const hand_points& h) {
  return frame_from_axes<k_px, k_pz>(
      normalize_or(h.p[idx(hand_landmark::middle_mcp)] - h.p[0], k_x),
      h.p[idx(hand_landmark::index_mcp)] - h.p[idx(hand_landmark::pinky_mcp)]);
}

// Thumb rest frame: X along the thumb's rest direction (1, 0, 1)/sqrt2, Y up.
const glm::quat k_thumb_frame = axis_angle(k_y, -0.25f * k_pi);

// Finger bones of the avatar's left hand (world rotations), given the hand's world rotation.
// Two hinge joints about the same local Z axis, from their segments' directions (x, y) in the
// frame of the bone before them: the first hinge's rotation, and the second's relative to the
// first (a complex division of the two unit 2-D directions). No trig calls.
void hinge_pair(float x2, float y2, float x3, float y3, glm::quat& out_first,
                glm::quat& out_second) {
  const float l2 = x2 * x2 + y2 * y2, l3 = x3 * x3 + y3 * y3;
  float c2 = 1.f, n2 = 0.f;
  if (l2 > 1e-24f) {
    const float i = inv_sqrt(l2);
    c2 = x2 * i;
    n2 = y2 * i;
  }
  float c3 = c2, n3 = n2;
  if (l3 > 1e-24f) {
    const float i = inv_sqrt(l3);
    c3 = x3 * i;
    n3 = y3 * i;
  }
  out_first = axis_cos_sin(k_z, c2, n2);
  out_second = axis_cos_sin(k_z, c3 * c2 + n3 * n2, n3 * c2 - c3 * n2);
}

// Finger bones of the avatar's left hand (canonical space), given the hand's world rotation.
// The proximal, intermediate and distal bones' rotations relative to their parents come out
// directly (only the thumb's metacarpal needs a world rotation).
void measure_fingers(const hand_points& h, const glm::quat& hand_w, float c, bool left,
                     frame_measurement& m) {
  const int first = left ? idx(bone::left_thumb_metacarpal) : idx(bone::right_thumb_metacarpal);
  auto emit_local = [&](int offset, const glm::quat& local) {
    set_local(m, static_cast<bone>(first + offset), left ? local : mirror_x(local), c);
  };
  // Thumb: CMC 1, MCP 2, IP 3, tip 4. The metacarpal's twist (opposition) comes from the plane
  // the thumb bends in; its later joints are hinges in that plane.
  {
    const glm::vec3 d = h.p[2] - h.p[1];
    const glm::vec3 bend_to = h.p[4] - h.p[2];
    const glm::quat g =
        aim_with_bend<k_px, k_ny>(hand_w * k_thumb_frame, d, bend_to, glm::vec3(0.f));
    const glm::quat inv_f = glm::conjugate(k_thumb_frame);
    const glm::quat mc_w = g * inv_f;
    set(m, static_cast<bone>(first), left ? mc_w : mirror_x(mc_w), c);
    const glm::quat to_g = glm::conjugate(g);
    const glm::vec3 s3 = to_g * (h.p[3] - h.p[2]);
    const glm::vec3 s4 = to_g * (h.p[4] - h.p[3]);
    glm::quat h1, h2;
    hinge_pair(s3.x, s3.y, s4.x, s4.y, h1, h2);
    // F * R_z(a) * F^-1 is the same turn about F's Z axis, (-1, 0, 1)/sqrt2.
    constexpr float k_r2 = 0.70710678f;
    emit_local(1, glm::quat(h1.w, -k_r2 * h1.z, 0.f, k_r2 * h1.z));
    emit_local(2, glm::quat(h2.w, -k_r2 * h2.z, 0.f, k_r2 * h2.z));
  }
  // Other fingers, in the hand's frame (columns of its matrix = the hand's axes in world).
  const glm::mat3 hm = glm::mat3_cast(hand_w);
  auto to_hand = [&](const glm::vec3& v) {
    return glm::vec3(glm::dot(hm[0], v), glm::dot(hm[1], v), glm::dot(hm[2], v));
  };
  for (int finger = 1; finger < 5; ++finger) {
    const int j = finger_base_landmark(finger);
    glm::vec3 v1 = normalize_or(to_hand(h.p[j + 1] - h.p[j]), k_x);
    const glm::vec3 v2 = to_hand(h.p[j + 2] - h.p[j + 1]);
    const glm::vec3 v3 = to_hand(h.p[j + 3] - h.p[j + 2]);
    // Proximal: R_z(phi) * R_y(spread) with phi = -flexion, spread = asin(-v.z); the cosines
    // and sines come straight from the unit direction v1 (no trig calls).
    const float r2 = v1.x * v1.x + v1.y * v1.y;
    float cf = 1.f, sf = 0.f, cs = 0.f;
    if (r2 > 1e-24f) {
      const float ir = inv_sqrt(r2);
      cf = v1.x * ir;
      sf = v1.y * ir;
      cs = r2 * ir;
    }
    const float ss = -v1.z;
    // R_z * R_y of two single-axis quaternions, multiplied out: (a_w b_w, -a_z b_y, a_w b_y,
    // a_z b_w).
    const glm::quat a = axis_cos_sin(k_z, cf, sf), b = axis_cos_sin(k_y, cs, ss);
    emit_local(3 * finger, glm::quat(a.w * b.w, -a.z * b.y, a.w * b.y, a.z * b.w));
    // The later segments in the proximal's frame: undo R_z(phi), then R_y(spread); only x and
    // y matter for hinges about Z.
    auto in_prox = [&](const glm::vec3& v, float& x, float& y) {
      const float xr = v.x * cf + v.y * sf;
      y = -v.x * sf + v.y * cf;
      x = xr * cs - v.z * ss;
    };
    float x2, y2, x3, y3;
    in_prox(v2, x2, y2);
    in_prox(v3, x3, y3);
    glm::quat mid, dist;
    hinge_pair(x2, y2, x3, y3, mid, dist);
    emit_local(3 * finger + 1, mid);
    emit_local(3 * finger + 2, dist);
  }
}

}  // namespace

void measure_hands(const prepared_frame& f, const solver_options& o, frame_measurement& m) {
  if (!o.parts.hands) return;
  for (int side = 0; side < 2; ++side) {
    const hand_points& h = f.hand[side];
    if (h.c <= 0.f) continue;
    const bool left = side == 0;
    const hand_points& hc = h;  // already in canonical (left-hand) space
    glm::quat hand_w = hand_world_from_points(hc);
    set(m, left ? bone::left_hand : bone::right_hand, left ? hand_w : mirror_x(hand_w), h.c);
    measure_fingers(hc, hand_w, h.c, left, m);
  }
}

}  // namespace avatarmap::solve_detail
