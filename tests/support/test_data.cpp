#include "support/test_data.hpp"

#include <cstdlib>

namespace avatarmap::test {

std::string test_data_dir() {
  const char* v = std::getenv("AVATARMAP_TEST_DATA");
  return v ? std::string(v) : std::string();
}

std::string test_data_path(const std::string& relative) {
  std::string dir = test_data_dir();
  if (dir.empty()) return {};
  return dir + "/" + relative;
}

}  // namespace avatarmap::test
