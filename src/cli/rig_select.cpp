#include "cli/rig_select.hpp"

#include <sys/stat.h>

#include <cstdlib>

namespace avatarmap::cli {
namespace {

bool is_dir(const std::string& p) {
  struct stat st {};
  return !p.empty() && ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

}  // namespace

std::string mappings_folder() {
  if (const char* env = std::getenv("AVATARMAP_MAPPINGS"); env && *env) return env;
#ifdef AVATARMAP_MAPPINGS_DIR
  if (is_dir(AVATARMAP_MAPPINGS_DIR)) return AVATARMAP_MAPPINGS_DIR;
#endif
#ifdef AVATARMAP_INSTALLED_MAPPINGS_DIR
  if (is_dir(AVATARMAP_INSTALLED_MAPPINGS_DIR)) return AVATARMAP_INSTALLED_MAPPINGS_DIR;
#endif
  return "mappings";
}

status select_rig_binding(const rig& r, const std::string& option, rig_selection& out) {
  status st = select_binding(r, option, mappings_folder(), out.choice);
  out.table = out.choice.table_or_null();
  out.binding = out.choice.binding;
  out.bound = out.choice.bound;
  out.description = out.choice.description;
  // The library says what did not fit; the command line says what to do about it.
  if (!st.ok() && out.choice.failure == rig_binding_failure::no_fit) {
    const std::string avatar = r.file.empty() ? std::string("AVATAR") : r.file;
    return status::error(st.message() +
                         "\nTo drive this rig with convert or animate: name a table that fits "
                         "with --rig NAME (a table in " +
                         mappings_folder() +
                         ") or --rig FILE.json (your own, see docs/mappings.md), or bind the "
                         "bones yourself with --bind BONE=JOINT (repeatable, e.g. --bind "
                         "hips=Pelvis; `avatarmap inspect " +
                         avatar + "` lists the joints)");
  }
  return st;
}

}  // namespace avatarmap::cli
