// `avatarmap backends`, `options`.
#include <cstdio>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/option_table.hpp"
#include "avatarmap/io/resources.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/media/video_source.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/filter_rules.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {

int run_backends(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(
        "Usage: avatarmap backends\n"
        "\n"
        "Lists the landmark estimator backends in this build, one per line: name, description;\n"
        "then the shipped folders this tool uses (mappings, models, viewer page and modules),\n"
        "each with the rule that found it: the environment ($AVATARMAP_MAPPINGS,\n"
        "$AVATARMAP_MODELS/onnx, $AVATARMAP_VIEWER_PAGE, $AVATARMAP_VIEWER_MODULES), else the\n"
        "installed location, else the source tree (docs/architecture.md, \"Resources\").\n",
        stdout);
    return 0;
  }
  if (!a.check_no_options() || !a.rest().empty()) {
    std::fprintf(stderr, "avatarmap backends: %s\n",
                 a.error().empty() ? "takes no arguments (see --help)" : a.error().c_str());
    return 2;
  }
  estimator_backend_list list = estimator_backends();
  for (int i = 0; i < list.count; ++i)
    std::printf("%-10s %s\n", std::string(list.items[i].name).c_str(),
                std::string(list.items[i].description).c_str());
  std::printf("\nfolders (environment, else installed, else source tree):\n");
  for (resource kind :
       {resource::mappings, resource::models, resource::viewer_page, resource::viewer_modules}) {
    const resource_lookup r = find_resource(kind);
    if (!r.folder.empty()) {
      std::printf("%-15s %s (%s)\n", resource_name(kind), r.folder.c_str(), r.source.c_str());
      continue;
    }
    std::string tried;
    for (const std::string& t : r.tried) tried += (tried.empty() ? "" : "; ") + t;
    std::printf("%-15s not found: looked in %s\n", resource_name(kind), tried.c_str());
  }
  return 0;
}

int run_options(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(
        "Usage: avatarmap options [--json]\n"
        "\n"
        "Prints the option tables (core/option_table.hpp): every option of the solver, the\n"
        "solve-file job, the resampler, the estimator and the input, with its C field name,\n"
        "kind, range, default and command-line flag; the C API's avm_*_options_init and the\n"
        "Python package's mirrors are checked against them (tests/python/test_options.py).\n"
        "  --json                one JSON object: {\"limits\": {...}, \"sets\": [...]}\n",
        stdout);
    return 0;
  }
  const bool json = a.flag("--json");
  if (!a.check_no_options() || !a.rest().empty()) {
    std::fprintf(stderr, "avatarmap options: %s\n",
                 a.error().empty() ? "takes no arguments (see --help)" : a.error().c_str());
    return 2;
  }
  if (json) {
    std::printf(
        "{\"limits\": {\"max_fps\": %s, \"max_model_threads\": %d, "
        "\"max_smoothing\": %.9g},\n\"sets\": [\n",
        limit_text(k_max_fps).c_str(), k_max_model_threads, static_cast<double>(k_max_smoothing));
    std::printf("%s,\n",
                option_table_json("solver", "avm_solver_options", k_solver_option_table).c_str());
    std::printf(
        "%s,\n",
        option_table_json("solve_file", "avm_solver_options", k_solve_file_option_table).c_str());
    std::printf("%s,\n",
                option_table_json("resampler", "avm_solver_options", k_pose_resampler_option_table)
                    .c_str());
    std::printf("%s,\n",
                option_table_json("foot_contacts", nullptr, k_foot_contact_option_table).c_str());
    std::printf(
        "%s,\n",
        option_table_json("estimator", "avm_estimator_options", k_estimator_option_table).c_str());
    std::printf("%s\n]}\n",
                option_table_json("video_source", nullptr, k_video_source_option_table).c_str());
    return 0;
  }
  auto list = [](const char* title, const auto& table) {
    std::printf("%s\n", title);
    for (const auto& r : table)
      std::printf("  %-26s %-16s %-22s default %s\n", r.name,
                  r.flag       ? r.flag
                  : r.negation ? r.negation
                               : "-",
                  r.kind == option_kind::text ? "text" : option_range_text(r).c_str(),
                  option_default_text(r).c_str());
  };
  list("solver (avm_solver_options):", k_solver_option_table);
  list("solve file (avm_solver_options):", k_solve_file_option_table);
  list("resampler (avm_solver_options):", k_pose_resampler_option_table);
  list("foot contacts (library only; docs/contacts.md):", k_foot_contact_option_table);
  list("estimator (avm_estimator_options):", k_estimator_option_table);
  list("input:", k_video_source_option_table);
  return 0;
}

}  // namespace avatarmap::cli
