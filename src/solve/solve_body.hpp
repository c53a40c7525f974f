// Stage 2a of the solver (internal): body bones and the hips position from prepared pose
// points. Rotations are world rotations in VRM space (docs/conventions.md); the limbs are
// solved on the avatar's left side and mirrored for the right (solve_geometry.hpp).
#pragma once

#include <glm/gtc/quaternion.hpp>

#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// Hips, spine chain, shoulders, arms, legs and feet, plus the coarse wrist orientation from
/// the pose's hand points where a hand's own landmarks are missing. `arm_reference[side]`:
/// the upper arm's world rotation last measured (side 0 = avatar's left), or null when there
/// is none: it keeps a straight arm's twist continuous (the coupling to the previous frame).
/// Writes nothing when the pose is missing or the body part is off.
void measure_body(const prepared_frame& f, const solver_options& o,
                  const glm::quat* const arm_reference[2], frame_measurement& m);

/// Hips height above the floor (lowest foot point) from metric points, and the hips' ground
/// position from the image (weak-perspective scale -> depth). Sets m.hips_height_valid /
/// m.hips_ground_valid only for finite results.
void measure_hips_position(const landmark_frame& in, const prepared_frame& f,
                           const solver_options& o, frame_measurement& m);

}  // namespace avatarmap::solve_detail
