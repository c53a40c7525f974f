// include/avatarmap/io/resources.hpp. The build gives this file (and only this file) the
// locations it needs (CMakeLists.txt): AVATARMAP_SOURCE_DIR, the source tree;
// AVATARMAP_DATA_FROM_BINDIR and AVATARMAP_DATA_FROM_LIBDIR, the installed data folder
// (DATADIR/avatarmap) relative to the installed executables and libraries.
#include "avatarmap/io/resources.hpp"

#include <dlfcn.h>
#include <link.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

namespace avatarmap {

namespace {

bool is_dir(const std::string& p) {
  struct stat st {};
  return !p.empty() && ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

std::string folder_of(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

// The folder of the file that holds this code: the shared library (libavatarmap_c.so, as
// loaded) or, when this code is linked into the program, the executable. Empty when unknown.
std::string module_folder() {
  Dl_info info{};
  link_map* map = nullptr;
  if (::dladdr1(reinterpret_cast<void*>(&module_folder), &info, reinterpret_cast<void**>(&map),
                RTLD_DL_LINKMAP) != 0 &&
      map != nullptr && map->l_name != nullptr && map->l_name[0] == '/')
    return folder_of(map->l_name);
  // The main program (its link map has no name): the executable's own path.
  char buffer[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buffer, sizeof buffer - 1);
  if (n <= 0) return {};
  return folder_of(std::string(buffer, static_cast<std::size_t>(n)));
}

// Below the data folder (installed) and the source tree.
struct layout {
  const char* installed;
  const char* source_tree;
};

layout layout_of(resource kind) {
  switch (kind) {
    case resource::mappings:
      return {"mappings", "mappings"};
    case resource::models:
      return {"models/onnx", ".cache/avatarmap/models/onnx"};
    case resource::viewer_page:
      return {"viewer", "viewer"};
    case resource::viewer_modules:
      return {"viewer-modules", ".cache/avatarmap/viewer"};
  }
  return {"", ""};
}

}  // namespace

const char* resource_name(resource kind) {
  switch (kind) {
    case resource::mappings:
      return "mappings";
    case resource::models:
      return "models";
    case resource::viewer_page:
      return "viewer page";
    case resource::viewer_modules:
      return "viewer modules";
  }
  return "?";
}

const char* resource_environment(resource kind) {
  switch (kind) {
    case resource::mappings:
      return "AVATARMAP_MAPPINGS";
    case resource::models:
      return "AVATARMAP_MODELS";
    case resource::viewer_page:
      return "AVATARMAP_VIEWER_PAGE";
    case resource::viewer_modules:
      return "AVATARMAP_VIEWER_MODULES";
  }
  return "";
}

resource_lookup find_resource(resource kind, const std::string& explicit_folder) {
  resource_lookup out;
  auto given = [&](const std::string& folder, const std::string& rule) {
    out.tried.push_back(folder + " (" + rule + ")");
    out.folder = folder;
    out.source = rule;
  };
  auto if_folder = [&](const std::string& folder, const char* rule) {
    const bool found = is_dir(folder);
    out.tried.push_back(folder + " (" + rule + ")" + (found ? "" : ": not a folder"));
    if (found) {
      out.folder = folder;
      out.source = rule;
    }
    return found;
  };

  if (!explicit_folder.empty()) {
    given(explicit_folder, "argument");
    return out;
  }
  const char* variable = resource_environment(kind);
  if (const char* env = std::getenv(variable); env != nullptr && *env != '\0') {
    given(kind == resource::models ? std::string(env) + "/onnx" : std::string(env),
          std::string("environment ") + variable);
    return out;
  }
  const layout where = layout_of(kind);
#if defined(AVATARMAP_DATA_FROM_BINDIR) && defined(AVATARMAP_DATA_FROM_LIBDIR)
  if (const std::string module = module_folder(); !module.empty()) {
    // "PREFIX/bin/../share/avatarmap/mappings" printed as "PREFIX/share/avatarmap/mappings".
    auto below = [&](const char* relative) {
      return std::filesystem::path(module + "/" + relative + "/" + where.installed)
          .lexically_normal()
          .string();
    };
    const std::string from_bin = below(AVATARMAP_DATA_FROM_BINDIR);
    const std::string from_lib = below(AVATARMAP_DATA_FROM_LIBDIR);
    if (if_folder(from_bin, "installed")) return out;
    if (from_lib != from_bin && if_folder(from_lib, "installed")) return out;
  }
#endif
#ifdef AVATARMAP_SOURCE_DIR
  if (if_folder(std::string(AVATARMAP_SOURCE_DIR) + "/" + where.source_tree, "source tree"))
    return out;
#endif
  return out;
}

std::string program_command() {
  char buffer[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buffer, sizeof buffer - 1);
  if (n <= 0) return "avatarmap";
  const std::string self(buffer, static_cast<std::size_t>(n));
  struct stat mine {};
  if (::stat(self.c_str(), &mine) != 0) return self;
  // The first `avatarmap` on the PATH, as a shell would pick it (an empty entry is ".").
  const char* path = std::getenv("PATH");
  const std::string dirs = path != nullptr ? path : "";
  std::size_t begin = 0;
  while (begin <= dirs.size()) {
    std::size_t end = dirs.find(':', begin);
    if (end == std::string::npos) end = dirs.size();
    std::string dir = dirs.substr(begin, end - begin);
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/avatarmap";
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        ::access(candidate.c_str(), X_OK) == 0)
      return st.st_dev == mine.st_dev && st.st_ino == mine.st_ino ? "avatarmap" : self;
    begin = end + 1;
  }
  return self;
}

std::string script_command(const std::string& relative) {
#ifdef AVATARMAP_SOURCE_DIR
  const std::string in_tree = std::string(AVATARMAP_SOURCE_DIR) + "/" + relative;
  if (::access(in_tree.c_str(), X_OK) == 0) return in_tree;
#endif
  return relative + " (in a checkout of avatarmap)";
}

}  // namespace avatarmap
