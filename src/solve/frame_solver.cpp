// Landmarks -> proxy pose. See include/avatarmap/solve/frame_solver.hpp and docs/solver.md.
#include "avatarmap/solve/frame_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/core/spaces.hpp"
#include "solve/solve_geometry.hpp"

namespace avatarmap {
namespace {

using namespace solve_detail;

// ---- input preparation --------------------------------------------------------------------

float landmark_confidence(const landmark& l) {
  // x * 0 is NaN for NaN and +-inf: one comparison tests all three coordinates.
  const float probe = l.x * 0.f + l.y * 0.f + l.z * 0.f;
  if (probe != 0.f) return 0.f;
  const float c = std::min(l.visibility, l.presence);  // NaN compares false below
  return c >= 0.f ? (c <= 1.f ? c : 1.f) : 0.f;
}

// Pose points in VRM space after mirroring: metres when from pose_world, else VRM pixels.
struct body_points {
  std::array<glm::vec3, k_pose_landmark_count> p;
  std::array<float, k_pose_landmark_count> c;
  bool valid = false;
  bool metric = false;
};

// A hand's 21 points in canonical left-hand space (the avatar's right hand mirrored through X).
struct hand_points {
  std::array<glm::vec3, k_hand_landmark_count> p;
  float c = 0.f;  // 1 when every point is finite, else 0
};

// The face mesh points the solver reads, in VRM pixels, sides after mirroring
// (index 0 = avatar's left).
struct eye_points {
  glm::vec3 outer, inner, upper[3], lower[3], iris, brow;
  bool has_iris = false;
};
struct face_points {
  bool valid = false;
  glm::vec3 forehead, chin, cheek[2], mouth[2], lip_upper, lip_lower;
  eye_points eye[2];
};

struct prepared_frame {
  body_points body;
  hand_points hand[2];  // 0 = avatar's left
  face_points face;
  float width = 1.f, height = 1.f;
  float focal = 1.f;  // pixels, from the horizontal field of view
};

void prepare_body(const landmark_frame& in, const solver_options& o, prepared_frame& f) {
  body_points& b = f.body;
  b.valid = false;
  const bool world = in.has(frame_part::pose_world);
  if (!world && !in.has(frame_part::pose)) return;
  const auto& src = world ? in.pose_world : in.pose;
  // world -> VRM (x, -y, -z), or image -> VRM pixels (x W, -y H, -z W); the mirror flips X.
  const float mx = o.mirror ? -1.f : 1.f;
  const float kx = world ? mx : mx * f.width, ky = world ? -1.f : -f.height,
              kz = world ? -1.f : -f.width;
  // Face points (0..10) serve only when there is no face mesh, hand points (17..22) only when
  // a hand's own landmarks are missing: skip converting them otherwise.
  const bool need_face = o.parts.face && !f.face.valid;
  const bool need_hands = o.parts.hands && (f.hand[0].c <= 0.f || f.hand[1].c <= 0.f);
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    if ((i <= idx(pose_landmark::mouth_right) && !need_face) ||
        (i >= idx(pose_landmark::left_pinky) && i <= idx(pose_landmark::right_thumb) &&
         !need_hands)) {
      b.c[i] = 0.f;
      continue;
    }
    int s = o.mirror ? pose_mirror_index(i) : i;
    const landmark& l = src[s];
    float c = landmark_confidence(l);
    // Scalar arithmetic and one vec3 store: building glm vectors here compiled to partial
    // vector stores that the later scalar loads could not forward from (measured 4% slower).
    float x = l.x * kx, y = l.y * ky, z = l.z * kz;
    if (x * 0.f + y * 0.f + z * 0.f != 0.f) {  // NaN or infinite (also after scaling)
      x = y = z = 0.f;
      c = 0.f;
    }
    b.p[i] = glm::vec3(x, y, z);
    b.c[i] = c;
  }
  b.valid = true;
  b.metric = world;
}

void prepare_hand(const landmark_frame& in, const solver_options& o, int side, prepared_frame& f) {
  // side 0 = avatar's left. Without mirroring that is the person's left hand.
  bool person_left = (side == 0) != o.mirror;
  frame_part world_part = person_left ? frame_part::left_hand_world : frame_part::right_hand_world;
  frame_part image_part = person_left ? frame_part::left_hand : frame_part::right_hand;
  hand_points& h = f.hand[side];
  h.c = 0.f;
  const bool world = in.has(world_part);
  if (!world && !in.has(image_part)) return;
  const auto& src = world ? (person_left ? in.left_hand_world : in.right_hand_world)
                          : (person_left ? in.left_hand : in.right_hand);
  // Points go straight into the canonical (left-hand) space the finger code works in: the
  // avatar's right hand is mirrored through X, and the mirror option flips X once more.
  const float sx = ((side == 1) != o.mirror) ? -1.f : 1.f;
  const float kx = world ? sx : sx * f.width, ky = world ? -1.f : -f.height,
              kz = world ? -1.f : -f.width;
  bool finite = true;
  for (int i = 0; i < k_hand_landmark_count; ++i) {
    const float x = src[i].x * kx, y = src[i].y * ky, z = src[i].z * kz;
    if (x * 0.f + y * 0.f + z * 0.f != 0.f) finite = false;  // NaN or infinite
    h.p[i] = glm::vec3(x, y, z);
  }
  h.c = finite ? 1.f : 0.f;
}

void prepare_face(const landmark_frame& in, const solver_options& o, prepared_frame& f) {
  face_points& fp = f.face;
  fp.valid = false;
  if (!in.has(frame_part::face) ||
      (in.face_count != k_face_mesh_count && in.face_count != k_face_mesh_iris_count))
    return;
  namespace fi = face_index;
  // Perspective: a face off the optical axis is seen along its own viewing ray, so its image
  // points are sheared by (x/z, y/z) of that ray times their depth. Undo it with the ray of
  // the face's centre (focal length from the field of view) so that the head's rotation is
  // relative to the camera's axes, not to the ray.
  const landmark& c0 = in.face[fi::forehead];
  const landmark& c1 = in.face[fi::chin];
  const float focal = f.focal;
  const float shear_x = (0.5f * (c0.x + c1.x) * f.width - 0.5f * f.width) / focal;
  const float shear_y = (0.5f * (c0.y + c1.y) * f.height - 0.5f * f.height) / focal;
  bool ok = std::isfinite(shear_x) && std::isfinite(shear_y);
  const float mx = o.mirror ? -1.f : 1.f;
  auto get = [&](int i) {
    const landmark& l = in.face[i];
    const float zp = l.z * f.width;
    const float x = mx * (l.x * f.width + shear_x * zp), y = -(l.y * f.height + shear_y * zp);
    if (x * 0.f + y * 0.f + zp * 0.f != 0.f) {  // NaN or infinite
      ok = false;
      return glm::vec3(0.f);
    }
    return glm::vec3(x, y, -zp);
  };
  const int l = o.mirror ? 1 : 0;  // slot of the person's left side
  const int r = 1 - l;
  fp.forehead = get(fi::forehead);
  fp.chin = get(fi::chin);
  fp.cheek[l] = get(fi::left_cheek);
  fp.cheek[r] = get(fi::right_cheek);
  fp.mouth[l] = get(fi::mouth_left);
  fp.mouth[r] = get(fi::mouth_right);
  fp.lip_upper = get(fi::upper_lip_inner);
  fp.lip_lower = get(fi::lower_lip_inner);
  eye_points& el = fp.eye[l];
  eye_points& er = fp.eye[r];
  el.outer = get(fi::left_eye_outer);
  el.inner = get(fi::left_eye_inner);
  er.outer = get(fi::right_eye_outer);
  er.inner = get(fi::right_eye_inner);
  for (int k = 0; k < 3; ++k) {
    el.upper[k] = get(fi::left_eye_upper[k]);
    el.lower[k] = get(fi::left_eye_lower[k]);
    er.upper[k] = get(fi::right_eye_upper[k]);
    er.lower[k] = get(fi::right_eye_lower[k]);
  }
  el.brow = get(fi::left_brow);
  er.brow = get(fi::right_brow);
  el.has_iris = er.has_iris = false;
  if (in.face_count == k_face_mesh_iris_count) {
    bool before = ok;
    el.iris = get(fi::left_iris);
    er.iris = get(fi::right_iris);
    el.has_iris = er.has_iris = ok;
    ok = before;  // a broken iris loses gaze only
  }
  fp.valid = ok;
}

// ---- body ---------------------------------------------------------------------------------

float min_conf(const body_points& b, std::initializer_list<int> ids) {
  float c = 1.f;
  for (int i : ids) c = std::min(c, b.c[i]);
  return c;
}

void set(frame_measurement& m, bone b, const glm::quat& world, float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = world;
  bm.confidence = c;
  bm.has_local = false;
}
// A bone measured only relative to its (measured) parent: `world` stays unset (identity);
// use it for bones whose children are all measured relative to them too.
void set_local(frame_measurement& m, bone b, const glm::quat& local, float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = identity_quat();
  bm.local = local;
  bm.confidence = c;
  bm.has_local = true;
}
// Same, with the rotation relative to the (measured) parent known already.
void set(frame_measurement& m, bone b, const glm::quat& world, const glm::quat& local, float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = world;
  bm.local = local;
  bm.confidence = c;
  bm.has_local = true;
}

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
  const glm::quat third = nlerp_shortest(identity_quat(), bend, 1.f / 3.f);
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
      set(m, left ? bone::left_hand : bone::right_hand, out(hand), 0.999f * c_h);
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
      m.hips_height_valid = std::isfinite(m.hips_height);
    }
  }
  if (!in.has(frame_part::pose) || !in.has(frame_part::pose_world)) return;
  // Least-squares fit image_px = s * world_xy + t over confident torso and leg points. The
  // world origin is the hip midpoint, so t is the hip midpoint's pixel position.
  static constexpr int k_ids[] = {11, 12, 23, 24, 25, 26, 27, 28};
  glm::vec2 wp[8], ip[8];
  glm::vec2 mw(0.f), mi(0.f);
  int n = 0;
  // With world landmarks present, b.c holds their confidences (mirrored indices, hence the
  // mirror of i); only the image points' confidence is new here.
  for (int i : k_ids) {
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
  if (n < 4) return;
  mw /= float(n);
  mi /= float(n);
  float num = 0.f, den = 0.f;
  for (int k = 0; k < n; ++k) {
    glm::vec2 dw = wp[k] - mw;
    num += glm::dot(dw, ip[k] - mi);
    den += glm::dot(dw, dw);
  }
  if (!(den > 1e-6f) || !(num > 0.f)) return;
  const float s = num / den;        // pixels per metre
  const glm::vec2 t = mi - s * mw;  // hip midpoint in pixels
  const float focal = f.focal;
  const float depth = focal / s;
  float x = (t.x - 0.5f * f.width) / focal * depth;
  if (o.mirror) x = -x;
  m.hips_ground = glm::vec2(x, -depth);
  m.hips_ground_valid = is_finite(glm::vec3(m.hips_ground, 0.f));
}

// ---- hands --------------------------------------------------------------------------------

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

// ---- face ---------------------------------------------------------------------------------

// Blink thresholds on the eye's opening ratio (mean lid gap / corner distance).
constexpr float k_eye_open_ratio = 0.18f;
constexpr float k_eye_closed_ratio = 0.05f;
// Iris: rest position along the corner line (from the inner corner) and above it, and the
// eyeball radius, all as fractions of the eye's width.
constexpr float k_iris_rest_u = 0.55f;
constexpr float k_iris_rest_v = 0.06f;
constexpr float k_eyeball_radius = 0.4f;
// Mouth: neutral width as a fraction of the cheek-to-cheek width.
constexpr float k_mouth_neutral_width = 0.05f / 0.14f;
// Brow height above the upper lid, as a fraction of the eye's width: rest, up, down range.
constexpr float k_brow_rest = 0.4f;
constexpr float k_brow_up_range = 0.267f;
constexpr float k_brow_down_range = 0.167f;

struct viseme_prototype {
  expression e;
  float open;   // inner-lip gap / mouth width
  float width;  // mouth width / neutral width
};
constexpr viseme_prototype k_visemes[] = {{expression::aa, 0.60f, 1.00f},
                                          {expression::ih, 0.20f, 1.10f},
                                          {expression::ou, 0.25f, 0.72f},
                                          {expression::ee, 0.25f, 1.22f},
                                          {expression::oh, 0.45f, 0.80f}};

void measure_face(const prepared_frame& f, const solver_options& o, const glm::quat& upper_chest_w,
                  bool base_measured, frame_measurement& m) {
  if (!o.parts.face) return;
  const face_points& fp = f.face;
  glm::quat head_w;
  float c_head = 0.f;
  if (fp.valid) {
    glm::vec3 lateral = (fp.eye[0].outer - fp.eye[1].outer) + (fp.cheek[0] - fp.cheek[1]);
    head_w = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), fp.forehead - fp.chin);
    c_head = 1.f;
  } else if (f.body.valid) {
    const body_points& b = f.body;
    using pl = pose_landmark;
    glm::vec3 lateral = b.p[idx(pl::left_ear)] - b.p[idx(pl::right_ear)];
    glm::vec3 up = 0.5f * (b.p[idx(pl::left_eye)] + b.p[idx(pl::right_eye)]) -
                   0.5f * (b.p[idx(pl::mouth_left)] + b.p[idx(pl::mouth_right)]);
    head_w = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), up);
    c_head = min_conf(b, {idx(pl::left_ear), idx(pl::right_ear), idx(pl::left_eye),
                          idx(pl::right_eye), idx(pl::mouth_left), idx(pl::mouth_right)});
  }
  if (c_head > 0.f) {
    const glm::quat& base = upper_chest_w;
    const glm::quat neck_local = quat_fraction(glm::conjugate(base) * head_w, 0.5f);
    const glm::quat neck_w = base * neck_local;
    // The neck's rotation is relative to the upper chest only when that was measured too.
    if (base_measured)
      set(m, bone::neck, neck_w, neck_local, c_head);
    else
      set(m, bone::neck, neck_w, c_head);
    set(m, bone::head, head_w, c_head);
  }
  if (!fp.valid) return;

  // Expressions. Distances are 3-D in pixel units, so they hold for any aspect ratio and for
  // moderate head turns.
  auto& ex = m.expressions;
  ex.fill(0.f);
  const glm::vec3 head_up = head_w * k_y;
  float closure[2];
  float yaw_sum = 0.f, pitch_sum = 0.f;
  int gaze_n = 0;
  for (int s = 0; s < 2; ++s) {
    const eye_points& e = fp.eye[s];
    glm::vec3 across = e.outer - e.inner;
    float width = glm::length(across);
    if (!(width > 1e-9f)) {
      closure[s] = 0.f;
      continue;
    }
    const float inv_width = 1.f / width;
    float gap = 0.f;
    for (int k = 0; k < 3; ++k) gap += glm::length(e.upper[k] - e.lower[k]);
    const float ratio = gap * (1.f / 3.f) * inv_width;
    closure[s] =
        glm::clamp((k_eye_open_ratio - ratio) / (k_eye_open_ratio - k_eye_closed_ratio), 0.f, 1.f);
    const glm::vec3 ax = across * inv_width;
    glm::vec3 up_dir = normalize_or(orth(head_up, ax), k_y);
    // Brows: height of the brow above the middle of the upper lid.
    const float brow = glm::dot(e.brow - e.upper[1], up_dir) * inv_width;
    ex[idx(s == 0 ? expression::brow_up_left : expression::brow_up_right)] =
        glm::clamp((brow - k_brow_rest) / k_brow_up_range, 0.f, 1.f);
    ex[idx(s == 0 ? expression::brow_down_left : expression::brow_down_right)] =
        glm::clamp((k_brow_rest - brow) / k_brow_down_range, 0.f, 1.f);
    if (e.has_iris && closure[s] < 0.7f) {
      const float u = glm::dot(e.iris - e.inner, ax) * inv_width;
      const float v = glm::dot(e.iris - 0.5f * (e.inner + e.outer), up_dir) * inv_width;
      // The left eye's outer corner is on the avatar's left (+X): moving toward it is a
      // positive yaw. For the right eye the corner line points the other way.
      // The iris moves by the eyeball's radius times the sine of the eye's turn.
      yaw_sum += (u - k_iris_rest_u) / k_eyeball_radius * (s == 0 ? 1.f : -1.f);
      pitch_sum += (v - k_iris_rest_v) / k_eyeball_radius;
      ++gaze_n;
    }
  }
  const float both = std::min(closure[0], closure[1]);
  ex[idx(expression::blink)] = both;
  ex[idx(expression::blink_left)] = closure[0] - both;
  ex[idx(expression::blink_right)] = closure[1] - both;
  if (gaze_n > 0) {
    // Sines of the gaze angles, both eyes averaged, clamped to 35 degrees of yaw and 25 of
    // pitch.
    constexpr float k_sin35 = 0.57357644f, k_sin25 = 0.42261826f, k_sin20 = 0.34202014f;
    const float sy = glm::clamp(yaw_sum / float(gaze_n), -k_sin35, k_sin35);
    const float sp = glm::clamp(pitch_sum / float(gaze_n), -k_sin25, k_sin25);
    // Eye bones: yaw about Y (toward +X), then pitch up (a negative turn about X).
    const glm::quat yq = axis_cos_sin(k_y, std::sqrt(1.f - sy * sy), sy);
    const glm::quat pq = axis_cos_sin(k_x, std::sqrt(1.f - sp * sp), -sp);
    // R_y * R_x of two single-axis quaternions: (a_w b_w, a_w b_x, a_y b_w, -a_y b_x).
    const glm::quat eye_local(yq.w * pq.w, yq.w * pq.x, yq.y * pq.w, -yq.y * pq.x);
    set(m, bone::left_eye, head_w * eye_local, eye_local, 1.f);
    set(m, bone::right_eye, head_w * eye_local, eye_local, 1.f);
    // look* weights: the gaze's sine over that of 25 degrees (sideways) or 20 (up/down).
    ex[idx(expression::look_left)] = glm::clamp(sy / k_sin25, 0.f, 1.f);
    ex[idx(expression::look_right)] = glm::clamp(-sy / k_sin25, 0.f, 1.f);
    ex[idx(expression::look_up)] = glm::clamp(sp / k_sin20, 0.f, 1.f);
    ex[idx(expression::look_down)] = glm::clamp(-sp / k_sin20, 0.f, 1.f);
  }
  // Mouth: a point in (openness, width) space, softly assigned to the nearest vowel shape.
  const float mouth_w = glm::length(fp.mouth[0] - fp.mouth[1]);
  const float face_w = glm::length(fp.cheek[0] - fp.cheek[1]);
  if (mouth_w > 1e-9f && face_w > 1e-9f) {
    float open = glm::length(fp.lip_upper - fp.lip_lower) / mouth_w;
    float width = (mouth_w / face_w) / k_mouth_neutral_width;
    auto kernel = [&](float po, float pw) {
      const float dox = (open - po) / 0.6f, dwx = (width - pw) / 0.5f;
      const float e = (dox * dox + dwx * dwx) / (0.12f * 0.12f);
      return e > 12.f ? 0.f : std::exp(-e);  // exp(-12) = 6e-6: skip the far shapes
    };
    float total = kernel(0.f, 1.f);  // closed, neutral mouth
    float k[5];
    for (int i = 0; i < 5; ++i) total += (k[i] = kernel(k_visemes[i].open, k_visemes[i].width));
    if (total > 0.f)
      for (int i = 0; i < 5; ++i) ex[idx(k_visemes[i].e)] = glm::clamp(k[i] / total, 0.f, 1.f);
  }
  m.expressions_valid = true;
}

float smooth01(float x) {
  x = glm::clamp(x, 0.f, 1.f);
  return x * x * (3.f - 2.f * x);
}

}  // namespace

// ---- frame_solver -------------------------------------------------------------------------

frame_solver::frame_solver(const solver_options& options)
    : options_(options.validate().ok() ? options : solver_options{}) {
  focal_per_width_ = 0.5f / std::tan(0.5f * options_.horizontal_fov_degrees * k_deg);
  reset();
}

void frame_solver::reset() {
  for (auto& b : bones_) b = bone_state{};
  prev_world_.fill(identity_quat());
  world_stamp_.fill(0);
  world_generation_ = 1;
  have_arm_reference_[0] = have_arm_reference_[1] = false;
  hips_height_state_ = scalar_state{};
  ground_state_ = scalar_state{};
  face_state_ = scalar_state{};
  hips_height_ = hips_height_held_ = options_.rest_hips_height;
  ground_ = ground_origin_ = glm::vec2(0.f);
  have_origin_ = false;
  expressions_held_.fill(0.f);
  last_t_ = 0.0;
  started_ = false;
  have_prev_world_ = false;
}

void frame_solver::measure(const landmark_frame& in, frame_measurement& m) const {
  for (auto& b : m.bones) b.confidence = 0.f;  // the other fields are written with it
  m.hips_height_valid = m.hips_ground_valid = m.expressions_valid = false;
  m.expressions.fill(0.f);
  prepared_frame f;
  if (options_.image_width > 0.f && options_.image_height > 0.f) {
    f.width = options_.image_width;
    f.height = options_.image_height;
  }
  f.focal = focal_per_width_ * f.width;
  prepare_hand(in, options_, 0, f);
  prepare_hand(in, options_, 1, f);
  prepare_face(in, options_, f);
  prepare_body(in, options_, f);  // after hands and face: it skips the points they replace
  const glm::quat* arm_ref[2] = {have_arm_reference_[0] ? &arm_reference_[0] : nullptr,
                                 have_arm_reference_[1] ? &arm_reference_[1] : nullptr};
  measure_body(f, options_, arm_ref, m);
  measure_hips_position(in, f, options_, m);
  measure_hands(f, options_, m);
  const bone_measurement& uc = m.bones[idx(bone::upper_chest)];
  const bool have_uc = uc.confidence > 0.f;
  measure_face(f, options_, have_uc ? uc.world : previous_world(idx(bone::upper_chest)), have_uc,
               m);
}

const glm::quat& frame_solver::previous_world(int b) const {
  // World rotation of bone b in the last output, computed on demand (few bones need it) and
  // memoised until the next output.
  if (world_stamp_[b] == world_generation_) return prev_world_[b];
  const int p = bone_parent(b);
  prev_world_[b] = p == k_no_parent ? bones_[b].output : previous_world(p) * bones_[b].output;
  world_stamp_[b] = world_generation_;
  return prev_world_[b];
}

float frame_solver::gate(scalar_state& s, float c, double t) const {
  // Returns the blend weight of the measurement (1 = use it) and updates hysteresis.
  const confidence_options& co = options_.confidence;
  if (s.tracked && (c <= 0.f || c < co.lost_below)) {
    s.tracked = false;
    s.lost_at = t;
  } else if (!s.tracked && c > 0.f && c >= co.found_above) {
    s.tracked = true;
    s.found_at = s.ever_tracked ? t : -1e9;
    s.ever_tracked = true;
  }
  return s.tracked ? 1.f : 0.f;
}

void frame_solver::solve(const landmark_frame& in, proxy_pose& out) {
  const double t = std::isfinite(in.t) ? in.t : last_t_;
  if (started_ && t < last_t_) reset();
  started_ = true;
  last_t_ = t;
  const confidence_options& co = options_.confidence;

  frame_measurement& m = scratch_;
  measure(in, m);
  for (int side = 0; side < 2; ++side) {
    const bone_measurement& ua =
        m.bones[idx(side == 0 ? bone::left_upper_arm : bone::right_upper_arm)];
    if (ua.confidence > 0.f) {
      arm_reference_[side] = ua.world;
      have_arm_reference_[side] = true;
    }
  }

  // Local rotation of a measured bone, relative to the measured parent when there is one,
  // else to the parent's last output.
  auto local_of = [&](int b) -> glm::quat {
    const bone_measurement& bm = m.bones[b];
    const int p = bone_parent(b);
    if (p == k_no_parent) return bm.world;
    if (m.bones[p].confidence > 0.f)
      return bm.has_local ? bm.local : glm::conjugate(m.bones[p].world) * bm.world;
    return glm::conjugate(previous_world(p)) * bm.world;
  };
  // Move a share of the wrist's twist about the forearm into the lower arm.
  glm::quat split[4];  // left lower arm, left hand, right lower arm, right hand
  bool has_split[2] = {false, false};
  for (int side = 0; side < 2; ++side) {
    int la = idx(side == 0 ? bone::left_lower_arm : bone::right_lower_arm);
    int hd = idx(side == 0 ? bone::left_hand : bone::right_hand);
    if (m.bones[la].confidence <= 0.f || m.bones[hd].confidence <= 0.f) continue;
    const glm::quat hand_local = local_of(hd);
    glm::vec3 axis = bone_rest_direction(static_cast<bone>(hd));
    glm::quat twist = nlerp_shortest(identity_quat(), swing_twist(hand_local, axis).twist,
                                     options_.forearm_twist_share);
    split[2 * side] = local_of(la) * twist;
    split[2 * side + 1] = glm::conjugate(twist) * hand_local;
    has_split[side] = true;
  }
  std::uint64_t split_mask = 0;
  if (has_split[0])
    split_mask |= (1ull << idx(bone::left_lower_arm)) | (1ull << idx(bone::left_hand));
  if (has_split[1])
    split_mask |= (1ull << idx(bone::right_lower_arm)) | (1ull << idx(bone::right_hand));
  auto measured_local = [&](int b) -> glm::quat {
    if (!((split_mask >> b) & 1u)) return local_of(b);
    if (b == idx(bone::left_lower_arm)) return split[0];
    if (b == idx(bone::left_hand)) return split[1];
    if (b == idx(bone::right_lower_arm)) return split[2];
    return split[3];
  };

  // Confidence gating per bone: hold, ease to rest, blend back in.
  const float inv_regain = co.regain_seconds > 0.f ? 1.f / co.regain_seconds : 0.f;
  const float inv_ease = co.ease_seconds > 0.f ? 1.f / co.ease_seconds : 0.f;
  for (int b = 0; b < k_bone_count; ++b) {
    bone_state& s = bones_[b];
    const float c = m.bones[b].confidence;
    if (s.tracked) {
      if (c <= 0.f || c < co.lost_below) {
        s.tracked = false;
        s.lost_at = t;
        s.last_good = s.output;  // hold what was last shown: continuous even mid-blend
      }
    } else if (c > 0.f && c >= co.found_above) {
      s.tracked = true;
      s.blending = s.ever_tracked && inv_regain > 0.f;
      s.regain_from = s.output;
      s.found_at = t;
      s.ever_tracked = true;
    }
    if (s.tracked) {
      const glm::quat local = measured_local(b);
      s.output = local;
      if (s.blending) {
        const float k = float(t - s.found_at) * inv_regain;
        if (k < 1.f)
          s.output = slerp_shortest(s.regain_from, local, smooth01(k));
        else
          s.blending = false;
      }
      out.confidence[b] = c;
    } else {
      if (s.ever_tracked) {
        const double age = t - s.lost_at;
        if (age <= co.hold_seconds) {
          s.output = s.last_good;
        } else {
          const float e = inv_ease > 0.f ? float(age - co.hold_seconds) * inv_ease : 1.f;
          s.output = e >= 1.f ? identity_quat()
                              : slerp_shortest(s.last_good, identity_quat(), smooth01(e));
        }
      }
      out.confidence[b] = 0.f;
    }
    out.rotations[b] = s.output;
  }
  ++world_generation_;
  have_prev_world_ = true;

  // Hips height: hold, then ease to the last standing height (or the rest height).
  {
    float w = gate(hips_height_state_, m.hips_height_valid ? 1.f : 0.f, t);
    if (w > 0.f) {
      hips_height_ = hips_height_held_ = m.hips_height;
    } else if (hips_height_state_.ever_tracked) {
      double age = t - hips_height_state_.lost_at;
      float e = age <= co.hold_seconds  ? 0.f
                : co.ease_seconds > 0.f ? float((age - co.hold_seconds) / co.ease_seconds)
                                        : 1.f;
      hips_height_ = glm::mix(hips_height_held_, options_.rest_hips_height, smooth01(e));
    }
    // Ground position: relative to where the person was first seen; held while unseen.
    float g = gate(ground_state_, m.hips_ground_valid ? 1.f : 0.f, t);
    if (g > 0.f) {
      if (!have_origin_) {
        ground_origin_ = m.hips_ground;
        have_origin_ = true;
      }
      ground_ = m.hips_ground - ground_origin_;
    }
    out.hips_position = glm::vec3(ground_.x, hips_height_, ground_.y);
  }
  // Expressions: held, then eased to 0.
  {
    float w = gate(face_state_, m.expressions_valid ? 1.f : 0.f, t);
    if (w > 0.f) {
      expressions_held_ = m.expressions;
      out.expressions = m.expressions;
    } else {
      double age = t - face_state_.lost_at;
      float e = !face_state_.ever_tracked ? 1.f
                : age <= co.hold_seconds  ? 0.f
                : co.ease_seconds > 0.f   ? float((age - co.hold_seconds) / co.ease_seconds)
                                          : 1.f;
      float k = 1.f - smooth01(e);
      for (int i = 0; i < k_expression_count; ++i) out.expressions[i] = expressions_held_[i] * k;
    }
  }
  out.t = t;
}

}  // namespace avatarmap
