// `avatarmap backends`, `synth`, `demo`, `import-tfjs`.
#include <cstdio>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {

int run_backends(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(
        "Usage: avatarmap backends\n"
        "\n"
        "Lists the landmark estimator backends in this build, one per line: name, description.\n",
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
  return 0;
}

}  // namespace avatarmap::cli
