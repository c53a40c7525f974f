// Internal: what the solver does with a frame whose body is not (all) followed
// (include/avatarmap/solve/body_plausibility.hpp; docs/solver.md, "Bodies that are not
// followed").
#pragma once

#include "avatarmap/solve/body_plausibility.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// Hips height while sitting, as a share of rest_hips_height: the shin and foot (knee to
/// sole) are ~0.52 of a standing person's hips height, so the held feet reach the floor.
inline constexpr float k_sitting_hips_share = 0.52f;
/// Share of the hips-to-shoulders turn given to each of spine and chest (as measure_body).
inline constexpr float k_spine_chain_share = 1.f / 3.f;

/// Rewrites the body's part of `m` for a frame that follows `follow`: the lower body at
/// `rest` (hips, legs, feet; hips height; the ground position not measured, so held), and for
/// upper_body the spine chain from the upright hips to the shoulders; for limbs_off the spine
/// chain and arms not measured. Nothing for body_follow::all or body_rest::off.
void hold_body(body_follow follow, body_rest rest, const prepared_frame& f, const solver_options& o,
               frame_measurement& m);

}  // namespace avatarmap::solve_detail
