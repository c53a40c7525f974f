// Stage 2c of the solver (internal): neck, head, eyes and expressions from the face mesh
// (or, without one, the head from the pose's face points). Rotations in VRM space
// (docs/conventions.md); expression weights in [0, 1].
#pragma once

#include <glm/gtc/quaternion.hpp>

#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// Neck and head relative to `upper_chest_w` (this frame's measured upper chest when
/// `base_measured`, else the last output's), eyes from the irises (478-point meshes) and the
/// expressions (m.expressions_valid when a face mesh was read). Nothing when the face part is
/// off. The neck's and head's world rotations are what the gate keeps: it takes their locals
/// relative to the torso it shows (solve_gate.cpp; docs/solver.md, "The head").
void measure_face(const prepared_frame& f, const solver_options& o, const glm::quat& upper_chest_w,
                  bool base_measured, frame_measurement& m);

}  // namespace avatarmap::solve_detail
