// Stage 1 of the solver: landmark frame -> prepared points. See solve_prepare.hpp.
#include "solve/solve_prepare.hpp"

#include <algorithm>
#include <cmath>

#include "solve/solve_fit.hpp"

namespace avatarmap::solve_detail {
namespace {

void prepare_body(const landmark_frame& in, const solver_options& o, prepared_frame& f) {
  body_points& b = f.body;
  b.valid = false;
  const bool world = in.has(frame_part::pose_world);
  if (!world && !in.has(frame_part::pose)) return;
  const auto& src = world ? (f.fit ? f.fit->world : in.pose_world) : in.pose;
  // world -> VRM (x, -y, -z), or image -> VRM pixels (x W, -y H, -z W); the mirror flips X.
  const float mx = o.mirror ? -1.f : 1.f;
  const float kx = world ? mx : mx * f.width, ky = world ? -1.f : -f.height,
              kz = world ? -1.f : -f.width;
  // Face points (0..10) give the head when there is no face mesh, and beside a mesh teach the
  // solver their offset from it (solve_face.cpp); hand points (17..22) serve only when a hand's
  // own landmarks are missing: skip converting them otherwise.
  const bool need_face = o.parts.face;
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
  h.metric = world;
  if (!world && !in.has(image_part)) return;
  const auto& src = world ? (person_left ? in.left_hand_world : in.right_hand_world)
                          : (person_left ? in.left_hand : in.right_hand);
  // Points go straight into the canonical (left-hand) space the finger code works in: the
  // avatar's right hand is mirrored through X, and the mirror option flips X once more.
  const float sx = ((side == 1) != o.mirror) ? -1.f : 1.f;
  const float kx = world ? sx : sx * f.width, ky = world ? -1.f : -f.height,
              kz = world ? -1.f : -f.width;
  // Confidence: the points' mean (MediaPipe's hand model writes none, which reads as 1; a
  // file that marks occluded points lowers it). 0 when any point is not finite.
  bool finite = true;
  float sum = 0.f;
  for (int i = 0; i < k_hand_landmark_count; ++i) {
    const float x = src[i].x * kx, y = src[i].y * ky, z = src[i].z * kz;
    if (x * 0.f + y * 0.f + z * 0.f != 0.f) finite = false;  // NaN or infinite
    h.p[i] = glm::vec3(x, y, z);
    sum += landmark_confidence(src[i]);
  }
  h.c = finite ? sum / float(k_hand_landmark_count) : 0.f;
}

void prepare_face(const landmark_frame& in, const solver_options& o, prepared_frame& f) {
  face_points& fp = f.face;
  fp.valid = false;
  if (!in.has(frame_part::face) ||
      (in.face_count != k_face_mesh_count && in.face_count != k_face_mesh_iris_count))
    return;
  namespace fi = face_index;
  // Perspective: each point is seen along its own viewing ray. A landmark's depth z (in
  // image widths, relative to the face's centre at depth d, scaled like x: z W = f (z_c - d) /
  // d) gives its camera depth z_c = d (1 + z W / f), so its camera coordinates are
  // (u - W/2, v - H/2) (1 + z W / f) in units of d / f: unproject every point so that the head's
  // rotation is relative to the camera's axes, not to the rays (focal length f in pixels from
  // the field of view; principal point at the image centre). Dropping the per-point factor (a
  // shear by the face centre's ray only) leaves errors of 5-12 degrees in pitch and yaw for a
  // face turned far (60 degrees) at 0.6-1 m (docs/solver.md, "The head").
  const float focal = f.focal;
  const float inv_focal = 1.f / focal;
  const float cx = 0.5f * f.width, cy = 0.5f * f.height;
  bool ok = std::isfinite(inv_focal) && inv_focal > 0.f;
  const float mx = o.mirror ? -1.f : 1.f;
  auto get = [&](int i) {
    const landmark& l = in.face[i];
    const float zp = l.z * f.width;
    // A point behind the camera (1 + z W / f <= 0) is not a face seen through this lens.
    const float s = std::max(1.f + zp * inv_focal, 0.05f);
    const float x = mx * (l.x * f.width - cx) * s, y = -(l.y * f.height - cy) * s;
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
  // Expression points MediaPipe's mesh has beyond face_index's (docs/expressions.md).
  fp.lip_top = get(0);
  fp.lip_bottom = get(17);
  fp.nose_base = get(2);
  fp.nose_tip = get(1);
  fp.upper_side[l] = get(269);
  fp.upper_side[r] = get(39);
  fp.lower_side[l] = get(405);
  fp.lower_side[r] = get(181);
  fp.nose_wing[l] = get(327);
  fp.nose_wing[r] = get(98);
  el.brow_inner = get(336);
  el.brow_outer = get(300);
  er.brow_inner = get(107);
  er.brow_outer = get(70);
  el.under = get(450);
  er.under = get(230);
  el.has_iris = er.has_iris = false;
  if (in.face_count == k_face_mesh_iris_count) {
    bool before = ok;
    // Each iris's centre and its 4-point ring averaged: the ring's points sit about the centre
    // and each carries its own noise (docs/expressions.md: with the second outer-corner point
    // below, the generator's noisy gaze error falls from 5.5 to 3.8 degrees, clean unchanged).
    auto iris = [&](int centre) {
      glm::vec3 sum(0.f);
      for (int k = 0; k < 5; ++k) sum += get(centre + k);
      return 0.2f * sum;
    };
    // The iris is read from the corners' midpoint; MediaPipe's mesh has a second point at each
    // outer corner (33 right, 359 left): the midpoint with the outer corners averaged, applied
    // as a shift of the iris (same reading, less of the corners' noise).
    el.iris = iris(fi::left_iris) - 0.25f * (get(359) - el.outer);
    er.iris = iris(fi::right_iris) - 0.25f * (get(33) - er.outer);
    el.has_iris = er.has_iris = ok;
    ok = before;  // a broken iris loses gaze only
  }
  fp.valid = ok;
}

}  // namespace

void prepare_frame(const landmark_frame& in, const solver_options& o, float focal_per_width,
                   prepared_frame& f, const body_fit* fit) {
  f.fit = fit != nullptr && fit->valid ? fit : nullptr;
  const bool sized = o.image_width > 0.f && o.image_height > 0.f;
  f.width = sized ? o.image_width : 1.f;
  f.height = sized ? o.image_height : 1.f;
  f.focal = focal_per_width * f.width;
  prepare_hand(in, o, 0, f);
  prepare_hand(in, o, 1, f);
  prepare_face(in, o, f);
  prepare_body(in, o, f);  // after hands and face: it skips the points they replace
}

}  // namespace avatarmap::solve_detail
