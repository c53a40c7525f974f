// `avatarmap synth`, `demo` and `import-tfjs` (filled in below once the generator lands).
#include <cstdio>

#include "cli/commands.hpp"

namespace avatarmap::cli {
int run_synth(int, char**) {
  std::fprintf(stderr, "avatarmap synth: not available yet\n");
  return 1;
}
int run_demo(int, char**) {
  std::fprintf(stderr, "avatarmap demo: not available yet\n");
  return 1;
}
int run_import_tfjs(int, char**) {
  std::fprintf(stderr, "avatarmap import-tfjs: not available yet\n");
  return 1;
}
}  // namespace avatarmap::cli
