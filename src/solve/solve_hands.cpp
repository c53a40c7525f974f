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

// The rotation R_z(phi) * R_y(spread) that turns +X exactly onto the direction of v (a
// finger segment in its parent bone's frame, whose +X runs along the parent): phi is the
// flexion about the hinge axis Z, spread the sideways bend. The segment is followed exactly,
// hinge or not; the decomposition only fixes the twist (none about the segment beyond what
// the two turns give). A zero v gives the identity. No trig calls.
glm::quat swing_zy(const glm::vec3& v) {
  const float l2 = glm::dot(v, v);
  if (!(l2 > 1e-24f)) return identity_quat();
  const glm::vec3 u = v * inv_sqrt(l2);
  const float r2 = u.x * u.x + u.y * u.y;
  float cf = 1.f, sf = 0.f, cs = 0.f;
  if (r2 > 1e-24f) {
    const float ir = inv_sqrt(r2);
    cf = u.x * ir;
    sf = u.y * ir;
    cs = r2 * ir;
  }
  const float ss = -u.z;
  // R_z * R_y of two single-axis quaternions, multiplied out: (a_w b_w, -a_z b_y, a_w b_y,
  // a_z b_w).
  const glm::quat a = axis_cos_sin(k_z, cf, sf), b = axis_cos_sin(k_y, cs, ss);
  return glm::quat(a.w * b.w, -a.z * b.y, a.w * b.y, a.z * b.w);
}

// Finger bones of the avatar's left hand (canonical space), given the hand's world rotation.
// Every bone points exactly at its child joint: each segment's rotation relative to the bone
// before it is swing_zy of the segment seen in that bone's frame (only the thumb's metacarpal
// needs a world rotation).
void measure_fingers(const hand_points& h, const glm::quat& hand_w, float c, bool left,
                     frame_measurement& m) {
  const int first = left ? idx(bone::left_thumb_metacarpal) : idx(bone::right_thumb_metacarpal);
  auto emit_local = [&](int offset, const glm::quat& local) {
    set_local(m, static_cast<bone>(first + offset), left ? local : mirror_x(local), c);
  };
  // Thumb: CMC 1, MCP 2, IP 3, tip 4. The metacarpal's twist (opposition) comes from the plane
  // the thumb bends in; the later joints follow their segments in that frame.
  {
    const glm::vec3 d = h.p[2] - h.p[1];
    const glm::vec3 bend_to = h.p[4] - h.p[2];
    const glm::quat g =
        aim_with_bend<k_px, k_ny>(hand_w * k_thumb_frame, d, bend_to, glm::vec3(0.f));
    const glm::quat inv_f = glm::conjugate(k_thumb_frame);
    const glm::quat mc_w = g * inv_f;
    set(m, static_cast<bone>(first), left ? mc_w : mirror_x(mc_w), c);
    const glm::quat to_g = glm::conjugate(g);
    const glm::quat q1 = swing_zy(to_g * (h.p[3] - h.p[2]));
    const glm::quat q2 = swing_zy(glm::conjugate(q1) * (to_g * (h.p[4] - h.p[3])));
    // In the thumb frame F the turn is q; relative to the bone's own rest frame, F q F^-1.
    emit_local(1, k_thumb_frame * q1 * inv_f);
    emit_local(2, k_thumb_frame * q2 * inv_f);
  }
  // Other fingers, in the hand's frame (columns of its matrix = the hand's axes in world).
  const glm::mat3 hm = glm::mat3_cast(hand_w);
  auto to_hand = [&](const glm::vec3& v) {
    return glm::vec3(glm::dot(hm[0], v), glm::dot(hm[1], v), glm::dot(hm[2], v));
  };
  for (int finger = 1; finger < 5; ++finger) {
    const int j = finger_base_landmark(finger);
    const glm::quat prox = swing_zy(to_hand(h.p[j + 1] - h.p[j]));
    const glm::quat to_prox = glm::conjugate(prox);
    const glm::quat mid = swing_zy(to_prox * to_hand(h.p[j + 2] - h.p[j + 1]));
    const glm::quat dist =
        swing_zy(glm::conjugate(mid) * (to_prox * to_hand(h.p[j + 3] - h.p[j + 2])));
    emit_local(3 * finger, prox);
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
