// `avatarmap eval-pose`: accuracy of solved poses against the synthetic truth
// (include/avatarmap/synth/pose_accuracy.hpp, docs/accuracy.md).
#include <cstdio>
#include <string>

#include "avatarmap/synth/pose_accuracy.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {
namespace {

const char* k_eval_help =
    "Usage: avatarmap eval-pose TRUTH.pose.jsonl SOLVED.pose.jsonl [--json]\n"
    "       avatarmap eval-pose --jitter SOLVED.pose.jsonl [--json]\n"
    "\n"
    "Compares solved poses with the true ones written by `avatarmap synth --truth`, frame by\n"
    "frame at the same times: the mean angle between true and solved bone directions (world\n"
    "space, proxy skeleton), overall and per group (torso, arms, legs, fingers), the head's\n"
    "orientation error (mean, and its 95th percentile in the \"head p95\" row and\n"
    "\"head_p95\" in JSON), and the same over the low-visibility frames (truth confidence 0 marks\n"
    "a bone in a burst; 'marked' is over those bones only). Angles in degrees.\n"
    "The face: mean absolute error of each eye's blink, of jawOpen and of the visemes (weights\n"
    "0..1), and the gaze's angle per eye relative to the head (mean and 95th percentile;\n"
    "\"face\" in JSON). jawOpen is read from the files' blendshapes.\n"
    "\n"
    "Options:\n"
    "  --jitter SOLVED  no truth: the RMS of the second time derivative of the bones' world\n"
    "           directions (deg/s^2), overall and per group; steadier is smaller; compare\n"
    "           files at the same frame rate (real video: defaults against a reference)\n"
    "  --json   one JSON object on standard output instead of the table, with every\n"
    "           bone's figures too (\"bones\")\n"
    "  --tolerance MS   time difference allowed between matched frames (default 0.5)\n";

void print_stats_json(const char* name, const angle_stats& s, bool comma) {
  std::printf("\"%s\":{\"mean\":%.4f,\"max\":%.4f,\"count\":%ld}%s", name, s.mean(), s.max, s.count,
              comma ? "," : "");
}

void print_figures_json(const char* name, const accuracy_figures& f) {
  std::printf("\"%s\":{", name);
  print_stats_json("overall", f.direction, true);
  for (int g = 0; g < k_direction_group_count; ++g)
    print_stats_json(accuracy_group_name(static_cast<accuracy_group>(g)), f.groups[g], true);
  print_stats_json("head", f.head, false);
  std::printf(",\"head_p95\":%.4f}", f.head_histogram.quantile(0.95));
}

void print_figures_row(const char* name, const accuracy_figures& f) {
  std::printf("%-22s %8.2f", name, f.direction.mean());
  for (int g = 0; g < k_direction_group_count; ++g) std::printf(" %8.2f", f.groups[g].mean());
  std::printf(" %8.2f\n", f.head.mean());
}

void print_weight_json(const char* name, const weight_stats& s, bool comma) {
  std::printf("\"%s\":{\"mean\":%.4f,\"max\":%.4f,\"count\":%ld}%s", name, s.mean(), s.max, s.count,
              comma ? "," : "");
}

const char* const k_viseme_names[5] = {"aa", "ih", "ou", "ee", "oh"};

void print_face_json(const face_accuracy& f) {
  std::printf("\"face\":{");
  print_weight_json("blink", f.blink, true);
  print_weight_json("jawOpen", f.jaw_open, true);
  for (int v = 0; v < 5; ++v) print_weight_json(k_viseme_names[v], f.visemes[v], true);
  print_stats_json("gaze", f.gaze, false);
  std::printf(",\"gaze_p95\":%.4f},", f.gaze_histogram.quantile(0.95));
}

}  // namespace

int run_eval_pose(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_eval_help, stdout);
    return 0;
  }
  const bool json = a.flag("--json");
  std::string jitter_path;
  if (a.value("--jitter", jitter_path)) {
    if (!a.error().empty() || !a.check_no_options() || !a.rest().empty()) {
      std::fprintf(stderr, "avatarmap eval-pose: %s\n",
                   !a.error().empty() ? a.error().c_str()
                                      : "--jitter takes one SOLVED.pose.jsonl (see --help)");
      return 2;
    }
    pose_jitter j;
    if (const status st = measure_pose_jitter(jitter_path, j); !st.ok()) {
      std::fprintf(stderr, "avatarmap eval-pose: %s\n", st.message().c_str());
      return 1;
    }
    if (json) {
      std::printf(
          "{\"frames\":%ld,\"rms\":%.4f,\"torso\":%.4f,\"arms\":%.4f,\"legs\":%.4f,"
          "\"fingers\":%.4f,\"bones\":{",
          j.frames, j.rms, j.groups[0], j.groups[1], j.groups[2], j.groups[3]);
      bool first = true;
      for (int b = 0; b < k_bone_count; ++b) {
        if (bone_accuracy_group(static_cast<bone>(b)) == accuracy_group::head) continue;
        std::printf("%s\"%s\":%.4f", first ? "" : ",",
                    std::string(bone_name(static_cast<bone>(b))).c_str(), j.bones[b]);
        first = false;
      }
      std::printf("}}\n");
      return 0;
    }
    std::printf("%ld frames; RMS angular acceleration of bone directions in deg/s^2\n", j.frames);
    std::printf("%8s %8s %8s %8s %8s\n", "overall", "torso", "arms", "legs", "fingers");
    std::printf("%8.1f %8.1f %8.1f %8.1f %8.1f\n", j.rms, j.groups[0], j.groups[1], j.groups[2],
                j.groups[3]);
    return 0;
  }
  pose_accuracy_options options;
  double ms = 0;
  if (a.number("--tolerance", ms)) {
    if (!(ms >= 0 && ms <= 1000)) {
      std::fprintf(stderr, "avatarmap eval-pose: --tolerance must be in [0, 1000] ms\n");
      return 2;
    }
    options.time_tolerance = ms * 1e-3;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 2) {
    std::fprintf(stderr, "avatarmap eval-pose: %s\n",
                 !a.error().empty() ? a.error().c_str()
                                    : "give TRUTH.pose.jsonl and SOLVED.pose.jsonl (see --help)");
    return 2;
  }
  pose_accuracy acc;
  const status st = evaluate_pose_files(a.rest()[0], a.rest()[1], acc, options);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap eval-pose: %s\n", st.message().c_str());
    return 1;
  }
  if (json) {
    std::printf("{\"frames\":%ld,\"low_visibility_frames\":%ld,", acc.frames,
                acc.low_visibility_frames);
    print_figures_json("all", acc.all);
    std::printf(",");
    print_figures_json("low_visibility", acc.low_visibility);
    std::printf(",");
    print_stats_json("marked", acc.marked, true);
    print_face_json(acc.face);
    std::printf("\"bones\":{");
    bool first = true;
    for (int b = 0; b < k_bone_count; ++b) {
      if (acc.bones[b].count == 0) continue;
      std::printf("%s", first ? "" : ",");
      first = false;
      print_stats_json(std::string(bone_name(static_cast<bone>(b))).c_str(), acc.bones[b], false);
    }
    std::printf("}}\n");
    return 0;
  }
  std::printf("%ld frames, %ld with low-visibility bones; mean angles in degrees\n", acc.frames,
              acc.low_visibility_frames);
  std::printf("%-22s %8s %8s %8s %8s %8s %8s\n", "", "overall", "torso", "arms", "legs", "fingers",
              "head");
  print_figures_row("all frames", acc.all);
  if (acc.all.head.count > 0)
    std::printf("%-22s %8.2f  (head orientation, 95th percentile; max %.1f)\n", "head p95",
                acc.all.head_histogram.quantile(0.95), acc.all.head.max);
  const face_accuracy& fa = acc.face;
  if (fa.blink.count > 0) {
    std::printf("%-22s %8s %8s %8s %8s %8s %8s %8s %8s\n", "face", "blink", "jawOpen", "aa", "ih",
                "ou", "ee", "oh", "gaze");
    std::printf("%-22s %8.3f %8.3f", "mean abs error", fa.blink.mean(), fa.jaw_open.mean());
    for (int v = 0; v < 5; ++v) std::printf(" %8.3f", fa.visemes[v].mean());
    std::printf(" %8.2f  (gaze degrees; p95 %.2f)\n", fa.gaze.mean(),
                fa.gaze_histogram.quantile(0.95));
  }
  if (acc.low_visibility_frames > 0) {
    print_figures_row("low-visibility frames", acc.low_visibility);
    std::printf("%-22s %8.2f  (bones in a burst only; max %.1f)\n", "marked bones",
                acc.marked.mean(), acc.marked.max);
  }
  return 0;
}

}  // namespace avatarmap::cli
