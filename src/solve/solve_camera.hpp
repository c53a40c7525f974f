// Stage 1b of the solver: the camera's focal length from the body's image and world points,
// for files and streams whose field of view is not given (docs/solver.md, "Field of view").
//
// BlazePose's world points are metric, centred on the hips and aligned with the camera's axes
// (x right, y down, z away from the camera); its image points are their perspective
// projection. With the camera at depth Tz from the hips and the principal point at the image
// centre, every confident point i gives two equations linear in (Tz, f, f Tx, f Ty):
//   du_i Tz - f X_i - f Tx = -du_i Z_i,   dv_i Tz - f Y_i - f Ty = -dv_i Z_i
// (du, dv: pixels from the centre). The perspective information is in the points' spread in
// depth, so one frame tells f only roughly; frame_solver combines the frames of a take, each
// weighted by how much it tells (the inverse variance of its f once the other three unknowns
// are solved for), starting from a prior at 60 degrees +-30 %. BlazePose's world points lean
// toward the camera (docs/solver.md): each frame's fit also searches the lean about the
// camera's x axis (+-30 degrees) that best explains the image, so the lean does not pass for
// perspective.
#pragma once

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap::solve_detail {

/// One frame's estimate: focal length in pixels and its information (1 / variance, 1/px^2);
/// information 0 when the frame tells nothing (too few points, degenerate, implausible).
struct focal_evidence {
  double focal = 0.0;
  double information = 0.0;
  /// The world points' lean about the camera's x axis that the fit found (radians; the turn
  /// that puts them onto the image, solve_fit.hpp's convention), with the focal length free.
  double lean = 0.0;
};

/// Estimate from one frame's pose and pose_world points, for an image of width x height
/// pixels (both > 0). Points with a confidence (visibility, presence) below 0.5 are left out.
focal_evidence estimate_focal(const landmark_frame& in, float width, float height);

}  // namespace avatarmap::solve_detail
