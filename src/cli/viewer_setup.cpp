// src/cli/viewer_setup.hpp.
#include "cli/viewer_setup.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "avatarmap/avatar/builtin_avatar.hpp"

namespace avatarmap::cli {

namespace {

bool is_dir(const char* p) {
  struct stat st {};
  return ::stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

std::string page_folder() {
  if (const char* env = std::getenv("AVATARMAP_VIEWER_PAGE"); env && *env) return env;
#ifdef AVATARMAP_VIEWER_PAGE_DIR
  if (is_dir(AVATARMAP_VIEWER_PAGE_DIR)) return AVATARMAP_VIEWER_PAGE_DIR;
#endif
#ifdef AVATARMAP_INSTALLED_VIEWER_PAGE_DIR
  if (is_dir(AVATARMAP_INSTALLED_VIEWER_PAGE_DIR)) return AVATARMAP_INSTALLED_VIEWER_PAGE_DIR;
#endif
  return "viewer";
}

std::string modules_folder() {
  if (const char* env = std::getenv("AVATARMAP_VIEWER_MODULES"); env && *env) return env;
#ifdef AVATARMAP_DEFAULT_VIEWER_MODULES_DIR
  return AVATARMAP_DEFAULT_VIEWER_MODULES_DIR;
#else
  return ".cache/avatarmap/viewer";
#endif
}

}  // namespace

pose_server_options default_viewer_options(const char* command) {
  pose_server_options o;
  o.page_dir = page_folder();
  o.modules_dir = modules_folder();
  std::string prefix = std::string(command) + ": ";
  o.on_event = [prefix](std::string_view line) {
    std::fprintf(stderr, "%s%.*s\n", prefix.c_str(), static_cast<int>(line.size()), line.data());
  };
  return o;
}

bool parse_host_port(const std::string& text, std::string& out_host, int& out_port,
                     std::string& error) {
  std::string host = out_host, port = text;
  if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
      host = host.substr(1, host.size() - 2);
  }
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 0 || p > 65535 || host.empty()) {
    error = "'" + text + "' is not PORT or HOST:PORT with a port in 0..65535";
    return false;
  }
  out_host = host;
  out_port = static_cast<int>(p);
  return true;
}

status builtin_avatar_file::write() {
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
  const std::string p = (ec ? std::filesystem::path(".") : dir).string() + "/avatarmap-viewer-" +
                        std::to_string(static_cast<long>(getpid())) + ".vrm";
  if (status st = write_builtin_avatar(p); !st) return st;
  path = p;
  return {};
}

builtin_avatar_file::~builtin_avatar_file() {
  if (!path.empty()) std::remove(path.c_str());
}

}  // namespace avatarmap::cli
