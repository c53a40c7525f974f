// The world benchmark's scorer: a solved take (proxy poses, or a BVH written on a rig) against
// the motion-capture truth it was synthesised from (jobs/mocap_synth.hpp), in the world:
// joint errors, torso lean, root trajectory, foot skate and floor penetration.
// docs/world-benchmark.md says how each figure is computed.
#pragma once

#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/jobs/mocap_synth.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

/// A solved take as timed anatomical points (world, metres, Y up; floor at Y = 0).
struct world_take {
  std::vector<double> t;
  std::vector<mocap_frame> frames;
};

/// The proxy skeleton with the truth's proportions, so that solved proxy poses put their joints
/// where the performer's are (rest lengths from take.rest()):
///   hip sockets at +-(half the truth's socket distance) along X from the hips joint;
///   spine, chest, upperChest and the hips->spine offset scaled together so that the neck
///   joint lies |neck - hip_mid| above the hips; neck = |head - neck|, head = |head top - head|;
///   the upper arm joint placed at the truth's (|dx|, dy, 0) from the neck joint (the clavicle
///   keeps the proxy's length); upper arm, forearm, thigh, shin, foot (ankle->toe) and toes
///   (toe->toe tip) the truth's lengths; hand = |wrist -> hand tip|; heel on the sole at the
///   proxy's rest toe-tip level, 25 % of the foot behind the ankle. Other bones: the proxy's at
///   the truth's rest height.
proxy_skeleton proxy_skeleton_like(const mocap_take& truth);

/// Reads a *.pose.jsonl and runs FK on `skeleton` (points as mocap_point). The hips go where
/// `convert` would put them on a rig of these proportions: hips_position scaled by the
/// skeleton's standing hips height over the clip's (jobs/retarget_clip.hpp's
/// standing_hips_height). Fails on a bad file, no frames or no standing height; frames with a
/// non-finite time or hips are skipped.
status read_world_take_poses(const std::string& path, const proxy_skeleton& skeleton,
                             world_take& out);
/// Reads a BVH (a rig written by `convert`, or any take) as points: mocap_take::load's names,
/// frame k at k * Frame Time.
status read_world_take_bvh(const std::string& path, float units_to_metres, world_take& out);

struct world_score_options {
  float planted_speed = 0.10f;   // m/s: the truth's point slower than this ...
  float planted_height = 0.05f;  // m: ... and within this of its own lowest height is planted
  /// Only the foot figures (skate, penetration, lowest toe): for a rig whose proportions differ
  /// from the truth's, where joint distances mean nothing.
  bool feet_only = false;
};

struct world_scores {
  long frames = 0;         // solved frames matched to the truth (t in [0, duration])
  long planted = 0;        // (point, frame) pairs where the truth's ankle or toe is planted
  double mpjpe_mm = 0;     // hips-relative, one yaw for the whole take
  double pa_mpjpe_mm = 0;  // after a similarity Procrustes per frame
  double lean_deg = 0;     // mean |lean(solved) - lean(truth)|, lean = angle(hips->neck, up)
  double accel_mm = 0;     // mean |second difference| error, mm / frame^2
  double root_cm = 0;      // hips trajectory after the best yaw + translation of the take
  double skate_cm_s = 0;   // solved ankle/toe horizontal speed where the truth's is planted
  /// The truth's own speed on those (point, frame) pairs: the floor of skate_cm_s (a planted
  /// foot rolls and its markers creep; a perfect solver scores this, not 0).
  double truth_skate_cm_s = 0;
  double penetration_cm = 0;  // mean depth below Y = 0 of solved toe tips and heels
  double lowest_toe_cm = 0;   // lowest toe tip over the take (solved, Y = 0 floor)
  bool feet_only = false;
};

/// Scores `solved` against `truth` sampled at the solved frames' times. Fails when fewer than
/// 3 frames fall in the truth's time span. Never throws.
status score_world(const mocap_take& truth, const world_take& solved,
                   const world_score_options& options, world_scores& out);

/// One JSON object of the figures.
std::string world_scores_json(const world_scores& s);

}  // namespace avatarmap
