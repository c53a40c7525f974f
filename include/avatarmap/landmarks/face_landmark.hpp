// Face mesh landmark counts and the indices avatarmap reads (MediaPipe's canonical face mesh;
// "left"/"right" are the person's sides: in a non-mirrored image the left eye has larger x).
#pragma once

namespace avatarmap {

inline constexpr int k_face_mesh_count = 468;       // face mesh without iris
inline constexpr int k_face_mesh_iris_count = 478;  // with iris refinement

namespace face_index {
// Head frame.
inline constexpr int forehead = 10;
inline constexpr int chin = 152;
inline constexpr int right_cheek = 234;
inline constexpr int left_cheek = 454;
inline constexpr int right_temple = 21;
inline constexpr int left_temple = 251;
// Eyes: corners, then three upper-lid and three matching lower-lid points.
inline constexpr int right_eye_outer = 130;
inline constexpr int right_eye_inner = 133;
inline constexpr int right_eye_upper[3] = {160, 159, 158};
inline constexpr int right_eye_lower[3] = {144, 145, 153};
inline constexpr int left_eye_outer = 263;
inline constexpr int left_eye_inner = 362;
inline constexpr int left_eye_upper[3] = {387, 386, 385};
inline constexpr int left_eye_lower[3] = {373, 374, 380};
// Mouth: inner lips and corners.
inline constexpr int upper_lip_inner = 13;
inline constexpr int lower_lip_inner = 14;
inline constexpr int mouth_right = 61;
inline constexpr int mouth_left = 291;
// Brows (middle of each brow) and the upper lid below them.
inline constexpr int right_brow = 105;
inline constexpr int left_brow = 334;
// Iris centres (478-point meshes only). 468..472 is the right iris, 473..477 the left.
inline constexpr int right_iris = 468;
inline constexpr int left_iris = 473;
}  // namespace face_index

}  // namespace avatarmap
