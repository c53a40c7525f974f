// A fresh, empty folder under the system's temporary directory for one test; removed with
// everything in it when the object goes out of scope.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace avatarmap::test {

class temp_dir {
 public:
  explicit temp_dir(const std::string& tag = "test") {
    static int counter = 0;
    path_ =
        std::filesystem::temp_directory_path() /
        ("avatarmap_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(++counter));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~temp_dir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  temp_dir(const temp_dir&) = delete;
  temp_dir& operator=(const temp_dir&) = delete;

  /// Path of `name` inside the folder (not created).
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Names of the entries in the folder.
  std::vector<std::string> entries() const {
    std::vector<std::string> r;
    for (auto& e : std::filesystem::directory_iterator(path_))
      r.push_back(e.path().filename().string());
    return r;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The whole content of a file ("" when it cannot be read).
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Replaces a file's content with `text` (binary, no newline added).
inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace avatarmap::test
