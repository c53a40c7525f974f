// The avatarmap tool's commands. Each returns the process exit status: 0 success,
// 1 failure while working (I/O, bad data), 2 wrong usage.
#pragma once

namespace avatarmap::cli {

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
int run_avatar(int argc, char** argv);
int run_view(int argc, char** argv);

}  // namespace avatarmap::cli
