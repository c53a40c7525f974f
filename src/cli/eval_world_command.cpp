// `avatarmap eval-world`: a solved take against the motion capture it was synthesised from
// (include/avatarmap/jobs/world_score.hpp, docs/world-benchmark.md).
#include <cstdio>
#include <string>

#include "avatarmap/jobs/world_score.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {
namespace {

const char* k_eval_world_help =
    "Usage: avatarmap eval-world TRUTH.bvh SOLVED [--json] [--feet-only] [options]\n"
    "\n"
    "Scores SOLVED against the motion capture TRUTH.bvh that `avatarmap synth --mocap` made its\n"
    "landmarks from, in the world (docs/world-benchmark.md). The truth is sampled at each solved\n"
    "frame's time. SOLVED is a *.pose.jsonl (its poses put on the proxy skeleton with the\n"
    "truth's segment lengths) or a .bvh (e.g. `convert --avatar` onto a rig; joints matched by\n"
    "name). Figures: MPJPE and PA-MPJPE (mm, hips-relative), torso lean error (deg), acceleration\n"
    "error (mm/frame^2), root error (cm, after the best yaw + translation of the take), foot\n"
    "skate (cm/s of the solved ankles/toes where the truth's are planted; beside it the truth's\n"
    "own speed there, the figure's floor), penetration (cm below\n"
    "Y = 0 of the solved toe tips and heels), lowest toe (cm), frames matched.\n"
    "\n"
    "Options:\n"
    "  --json             one JSON object on standard output\n"
    "  --feet-only        only skate, penetration and lowest toe (a rig of other proportions)\n"
    "  --units F          metres per TRUTH unit (default 0.056444, the CMU clips')\n"
    "  --solved-units F   metres per SOLVED .bvh unit (default 0.01: convert writes cm)\n"
    "  --planted-speed M  planted when the truth's point is slower (m/s, default 0.10) ...\n"
    "  --planted-height M ... and within this of its lowest height (m, default 0.05)\n";

bool ends_with(const std::string& s, const std::string& e) {
  if (s.size() < e.size()) return false;
  for (std::size_t i = 0; i < e.size(); ++i) {
    char c = s[s.size() - e.size() + i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != e[i]) return false;
  }
  return true;
}

}  // namespace

int run_eval_world(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_eval_world_help, stdout);
    return 0;
  }
  const bool json = a.flag("--json");
  world_score_options o;
  o.feet_only = a.flag("--feet-only");
  double units = k_cmu_units_to_metres, solved_units = 0.01, v = 0;
  if (a.number("--units", v)) units = v;
  if (a.number("--solved-units", v)) solved_units = v;
  if (a.number("--planted-speed", v)) o.planted_speed = static_cast<float>(v);
  if (a.number("--planted-height", v)) o.planted_height = static_cast<float>(v);
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 2) {
    std::fprintf(stderr, "avatarmap eval-world: %s\n",
                 a.error().empty() ? "give TRUTH.bvh and SOLVED (see --help)" : a.error().c_str());
    return 2;
  }
  if (!(units > 0 && units <= 1000) || !(solved_units > 0 && solved_units <= 1000) ||
      !(o.planted_speed > 0) || !(o.planted_height > 0)) {
    std::fprintf(stderr,
                 "avatarmap eval-world: --units, --solved-units, --planted-speed and "
                 "--planted-height must be positive\n");
    return 2;
  }
  const std::string& truth_path = a.rest()[0];
  const std::string& solved_path = a.rest()[1];
  mocap_take truth;
  status st = truth.load(truth_path, static_cast<float>(units));
  world_take solved;
  if (st) {
    st = ends_with(solved_path, ".bvh")
             ? read_world_take_bvh(solved_path, static_cast<float>(solved_units), solved)
             : read_world_take_poses(solved_path, proxy_skeleton_like(truth), solved);
  }
  world_scores s;
  if (st) st = score_world(truth, solved, o, s);
  if (!st) {
    std::fprintf(stderr, "avatarmap eval-world: %s\n", st.message().c_str());
    return 1;
  }
  if (json) {
    std::printf("%s\n", world_scores_json(s).c_str());
    return 0;
  }
  std::printf("frames matched   %ld (planted point-frames %ld)\n", s.frames, s.planted);
  if (!s.feet_only) {
    std::printf("MPJPE            %8.1f mm\n", s.mpjpe_mm);
    std::printf("PA-MPJPE         %8.1f mm\n", s.pa_mpjpe_mm);
    std::printf("torso lean error %8.2f deg\n", s.lean_deg);
    std::printf("accel error      %8.2f mm/frame^2\n", s.accel_mm);
    std::printf("root error       %8.2f cm\n", s.root_cm);
  }
  std::printf("foot skate       %8.2f cm/s (the truth's own: %.2f)\n", s.skate_cm_s,
              s.truth_skate_cm_s);
  std::printf("penetration      %8.3f cm\n", s.penetration_cm);
  std::printf("lowest toe       %8.2f cm\n", s.lowest_toe_cm);
  return 0;
}

}  // namespace avatarmap::cli
