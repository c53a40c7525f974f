#include "fuzz_support.hpp"

#include <dirent.h>
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace avatarmap::fuzz {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "invariant failed: %s\n", what);
    std::abort();
  }
}

namespace {

// Calls `f(name)` for every entry of `dir` but . and ..; false when `dir` cannot be listed.
template <typename F>
bool for_each_entry(const std::string& dir, F f) {
  DIR* d = ::opendir(dir.c_str());
  if (!d) return false;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != "..") f(name);
  }
  ::closedir(d);
  return true;
}

// Removes the files of `dir` (the harnesses make no subfolders).
void clear_folder(const std::string& dir) {
  for_each_entry(dir, [&](const std::string& name) { ::unlink((dir + "/" + name).c_str()); });
}

void remove_scratch() {
  clear_folder(scratch_dir());
  ::rmdir(scratch_dir().c_str());
}

// A crashing input ends the process without atexit handlers (and -minimize_crash crashes on
// purpose, many times): remove the scratch folders of processes that no longer run.
void remove_stale_scratch(const std::string& parent) {
  const std::string prefix = "avatarmap-fuzz-";
  for_each_entry(parent, [&](const std::string& name) {
    if (name.rfind(prefix, 0) != 0) return;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      clear_folder(parent + "/" + name);
      ::rmdir((parent + "/" + name).c_str());
    }
  });
}

}  // namespace

const std::string& scratch_dir() {
  static const std::string dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    const std::string parent = tmp && *tmp ? tmp : "/tmp";
    remove_stale_scratch(parent);
    std::string pattern = parent + "/avatarmap-fuzz-" + std::to_string(::getpid()) + "-XXXXXX";
    if (!::mkdtemp(pattern.data())) {
      std::perror("avatarmap fuzz: mkdtemp");
      std::abort();
    }
    return pattern;
  }();
  static const bool registered = (std::atexit(remove_scratch), true);
  (void)registered;
  return dir;
}

std::string write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::string path = scratch_dir() + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  check(f != nullptr, "the harness can create its scratch file");
  const bool ok = (size == 0 || std::fwrite(data, 1, size, f) == size);
  check(std::fclose(f) == 0 && ok, "the harness can write its scratch file");
  return path;
}

int scratch_entries() {
  int n = 0;
  check(for_each_entry(scratch_dir(), [&](const std::string&) { ++n; }),
        "the scratch folder can be listed");
  return n;
}

void clear_scratch() { clear_folder(scratch_dir()); }

}  // namespace avatarmap::fuzz
