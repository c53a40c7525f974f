// `avatarmap backends`, `synth`, `demo`, `import-tfjs`.
#include <cstdio>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {

int run_backends(int, char**) {
  estimator_backend_list list = estimator_backends();
  for (int i = 0; i < list.count; ++i)
    std::printf("%-10s %s\n", std::string(list.items[i].name).c_str(),
                std::string(list.items[i].description).c_str());
  return 0;
}

}  // namespace avatarmap::cli
