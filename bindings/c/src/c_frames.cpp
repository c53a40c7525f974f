// Conversions between the C API's frames and poses and the library's (c_frames.hpp).
#include "c_frames.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap::c_api {

namespace am = avatarmap;

namespace {
void copy_part(am::landmark_frame& dst, am::frame_part part, const avm_landmark* src, int n,
               am::landmark* out) {
  dst.set(part, src != nullptr);
  if (src == nullptr) return;
  for (int i = 0; i < n; ++i) {
    out[i].x = src[i].x;
    out[i].y = src[i].y;
    out[i].z = src[i].z;
    out[i].visibility = src[i].visibility;
    out[i].presence = src[i].presence;
  }
}

}  // namespace

// Checks a C frame; on failure returns a static message.
const char* check_frame(const avm_frame& f) noexcept {
  if (!std::isfinite(f.t)) return "avm_frame.t must be finite";
  if (f.face != nullptr && f.face_count != AVM_FACE_LANDMARK_COUNT &&
      f.face_count != AVM_FACE_IRIS_LANDMARK_COUNT)
    return "avm_frame.face_count must be 468 or 478 when face is not NULL";
  return nullptr;
}

void convert_frame(const avm_frame& f, am::landmark_frame& out) noexcept {
  out.clear();
  out.t = f.t;
  using fp = am::frame_part;
  copy_part(out, fp::pose, f.pose, AVM_POSE_LANDMARK_COUNT, out.pose.data());
  copy_part(out, fp::pose_world, f.pose_world, AVM_POSE_LANDMARK_COUNT, out.pose_world.data());
  copy_part(out, fp::left_hand, f.left_hand, AVM_HAND_LANDMARK_COUNT, out.left_hand.data());
  copy_part(out, fp::left_hand_world, f.left_hand_world, AVM_HAND_LANDMARK_COUNT,
            out.left_hand_world.data());
  copy_part(out, fp::right_hand, f.right_hand, AVM_HAND_LANDMARK_COUNT, out.right_hand.data());
  copy_part(out, fp::right_hand_world, f.right_hand_world, AVM_HAND_LANDMARK_COUNT,
            out.right_hand_world.data());
  copy_part(out, fp::face, f.face, f.face != nullptr ? f.face_count : 0, out.face.data());
  out.face_count = f.face != nullptr ? f.face_count : 0;
}

void to_c_pose(const am::proxy_pose& p, avm_pose& out) noexcept {
  out.t = p.t;
  out.hips_position[0] = p.hips_position.x;
  out.hips_position[1] = p.hips_position.y;
  out.hips_position[2] = p.hips_position.z;
  for (int b = 0; b < AVM_BONE_COUNT; ++b) {
    am::store_xyzw(p.rotations[b], out.rotations[b]);
    out.confidence[b] = p.confidence[b];
  }
  for (int e = 0; e < AVM_EXPRESSION_COUNT; ++e) out.expressions[e] = p.expressions[e];
  for (int f = 0; f < 2; ++f) out.foot_contact[f] = p.foot_contact[f];
  for (int s = 0; s < AVM_BLENDSHAPE_COUNT; ++s) out.blendshapes[s] = p.blendshapes[s];
  // Since 0.2.0 the struct ends in 4 bytes of padding (its size is a multiple of the double's
  // alignment): written as 0, so that a pose the library gives is the same bytes every time.
  constexpr std::size_t end = offsetof(avm_pose, blendshapes) + sizeof out.blendshapes;
  if constexpr (sizeof(avm_pose) > end)
    std::memset(reinterpret_cast<unsigned char*>(&out) + end, 0, sizeof(avm_pose) - end);
}

void to_c_frame(const am::landmark_frame& in, frame_storage& storage, avm_frame& out) noexcept {
  auto part = [&](am::frame_part p, const am::landmark* src, int n,
                  avm_landmark* dst) -> const avm_landmark* {
    if (!in.has(p)) return nullptr;
    for (int i = 0; i < n; ++i)
      dst[i] = {src[i].x, src[i].y, src[i].z, src[i].visibility, src[i].presence};
    return dst;
  };
  using fp = am::frame_part;
  out.t = in.t;
  out.pose = part(fp::pose, in.pose.data(), AVM_POSE_LANDMARK_COUNT, storage.pose.data());
  out.pose_world = part(fp::pose_world, in.pose_world.data(), AVM_POSE_LANDMARK_COUNT,
                        storage.pose_world.data());
  out.left_hand =
      part(fp::left_hand, in.left_hand.data(), AVM_HAND_LANDMARK_COUNT, storage.left_hand.data());
  out.left_hand_world = part(fp::left_hand_world, in.left_hand_world.data(),
                             AVM_HAND_LANDMARK_COUNT, storage.left_hand_world.data());
  out.right_hand = part(fp::right_hand, in.right_hand.data(), AVM_HAND_LANDMARK_COUNT,
                        storage.right_hand.data());
  out.right_hand_world = part(fp::right_hand_world, in.right_hand_world.data(),
                              AVM_HAND_LANDMARK_COUNT, storage.right_hand_world.data());
  const bool face = in.has(fp::face) && (in.face_count == AVM_FACE_LANDMARK_COUNT ||
                                         in.face_count == AVM_FACE_IRIS_LANDMARK_COUNT);
  out.face = face ? part(fp::face, in.face.data(), in.face_count, storage.face.data()) : nullptr;
  out.face_count = face ? in.face_count : 0;
}

}  // namespace avatarmap::c_api
