// Stage 1 of the solver (internal): landmark frame -> prepared points. Checks every point
// (non-finite = not seen), applies the mirror option and the image's aspect ratio, and puts
// each part in the space its measuring stage works in (VRM space; see docs/conventions.md).
// Nothing here allocates; a prepared_frame is plain storage that is overwritten each frame.
#pragma once

#include <algorithm>
#include <array>
#include <glm/glm.hpp>

#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/solve/solver_options.hpp"

namespace avatarmap::solve_detail {

struct body_fit;  // solve_fit.hpp

/// A landmark's confidence in [0, 1]: min(visibility, presence), 0 when a coordinate or the
/// confidence itself is not finite.
inline float landmark_confidence(const landmark& l) {
  // x * 0 is NaN for NaN and +-inf: one comparison tests all three coordinates.
  const float probe = l.x * 0.f + l.y * 0.f + l.z * 0.f;
  if (probe != 0.f) return 0.f;
  const float c = std::min(l.visibility, l.presence);  // NaN compares false below
  return c >= 0.f ? (c <= 1.f ? c : 1.f) : 0.f;
}

/// Pose points in VRM space after mirroring: metres when from pose_world, else VRM pixels
/// (x W, -y H, -z W). Points the frame does not need (the face's without a face mesh, the
/// hands' without hand landmarks) have confidence 0 and unset positions.
struct body_points {
  std::array<glm::vec3, k_pose_landmark_count> p;
  std::array<float, k_pose_landmark_count> c;
  bool valid = false;
  bool metric = false;  // from pose_world (metres)
};

/// A hand's 21 points in canonical left-hand space (the avatar's right hand mirrored through
/// X), metres or VRM pixels.
struct hand_points {
  std::array<glm::vec3, k_hand_landmark_count> p;
  float c = 0.f;        // the points' mean confidence; 0 when a point is not finite
  bool metric = false;  // from the hand's world landmarks (metres)
};

/// The face mesh points the solver reads, in VRM pixels with the perspective shear of the
/// face's viewing ray removed, sides after mirroring (index 0 = avatar's left).
/// Per eye: corners, three upper- and lower-lid points, the iris centre (478 points), the
/// brow's inner and outer ends (107/336, 70/300) and the point below the lower lid (230/450).
struct eye_points {
  glm::vec3 outer, inner, upper[3], lower[3], iris, brow_inner, brow_outer, under;
  bool has_iris = false;
};
/// lip_upper/lip_lower: the inner lips (13, 14); lip_top/lip_bottom: the outer lips' middle
/// (0, 17); nose_base: below the nose (2); nose_tip (1). Per side: upper_side/lower_side, the
/// outer lips two points out from the middle (269/39, 405/181), and nose_wing, the nose's
/// wing beside the nostril (327/98). docs/expressions.md lists every index.
struct face_points {
  bool valid = false;
  glm::vec3 forehead, chin, cheek[2], mouth[2], lip_upper, lip_lower, lip_top, lip_bottom,
      nose_base, nose_tip, upper_side[2], lower_side[2], nose_wing[2];
  eye_points eye[2];
};

/// Everything the measuring stages read.
struct prepared_frame {
  body_points body;
  hand_points hand[2];  // 0 = avatar's left
  face_points face;
  float width = 1.f, height = 1.f;  // image size in pixels (1 x 1 when unknown: square pixels)
  float focal = 1.f;                // pixels, from the horizontal field of view
  /// The body fitted to the image (solve_fit.hpp) when that stage ran on this frame: its
  /// points replace pose_world, its hips give the hips' ground position. Null otherwise.
  const body_fit* fit = nullptr;
};

/// Fills `out` from `in`. `focal_per_width` is the focal length over the image width (from
/// the horizontal field of view). Hands and face are prepared before the body, which skips
/// the pose points they replace.
void prepare_frame(const landmark_frame& in, const solver_options& o, float focal_per_width,
                   prepared_frame& out, const body_fit* fit = nullptr);

}  // namespace avatarmap::solve_detail
