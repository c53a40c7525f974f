// Stage 2b of the solver (internal): wrists and finger bones from the 21 hand landmarks of
// each hand (prepared in canonical left-hand space). Rotations in VRM space
// (docs/conventions.md): the hands' world rotations, the fingers' relative to their parents.
#pragma once

#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// Both hands whose landmarks are present and finite; nothing when the hands part is off.
/// A hand measured here replaces the coarse one measure_body took from the pose.
void measure_hands(const prepared_frame& f, const solver_options& o, frame_measurement& m);

}  // namespace avatarmap::solve_detail
