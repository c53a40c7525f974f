// The avatarmap tool's commands. Each returns the process exit status: 0 success,
// 1 failure while working (I/O, bad data), 2 wrong usage.
#pragma once

#include <string>
#include <vector>

#include "cli/option_flags.hpp"

namespace avatarmap::cli {

/// Runs one command with `args` as its argv ({"avatarmap", "capture", ...}), for the commands
/// that chain others (animate, demo): each stage keeps its own options, checks and messages.
inline int run_with_args(std::vector<std::string> args, int (*command)(int, char**)) {
  std::vector<char*> argv;
  for (std::string& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  return command(static_cast<int>(args.size()), argv.data());
}

int run_solve(int argc, char** argv);
int run_convert(int argc, char** argv);
int run_capture(int argc, char** argv);
int run_animate(int argc, char** argv);
int run_live_command(int argc, char** argv);
int run_synth(int argc, char** argv);
int run_demo(int argc, char** argv);
int run_import_tfjs(int argc, char** argv);
int run_backends(int argc, char** argv);
int run_inspect(int argc, char** argv);
int run_eval_pose(int argc, char** argv);
int run_eval_world(int argc, char** argv);
int run_avatar(int argc, char** argv);
int run_view(int argc, char** argv);
int run_render(int argc, char** argv);
int run_options(int argc, char** argv);

/// Every flag `capture` takes (its own and its option tables'), as `animate` hands them on;
/// the help says --hands/--face default to `hands_face_default`.
void add_capture_command_flag_specs(bool hands_face_default, std::vector<flag_spec>& out);
/// Every flag `convert` takes (its own and its option tables').
void add_convert_command_flag_specs(std::vector<flag_spec>& out);

}  // namespace avatarmap::cli
