#include "cli/rig_select.hpp"

#include <sys/stat.h>

#include <cstdlib>

namespace avatarmap::cli {
namespace {

bool is_dir(const std::string& p) {
  struct stat st {};
  return !p.empty() && ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

int count_bound(const bone_binding& b) {
  int n = 0;
  for (int j : b) n += j >= 0;
  return n;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
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
  out.table = nullptr;
  out.binding.fill(-1);
  const std::string what = option.empty() ? std::string("auto") : option;
  if (what == "auto" && r.declared_humanoid[idx(bone::hips)] >= 0) {
    out.binding = r.declared_humanoid;
    out.bound = count_bound(out.binding);
    out.description = std::string(r.source == rig_source::vrm0 ? "VRM 0.x" : "VRM 1.0") +
                      " humanoid declared by the file (" + std::to_string(out.bound) + " bones)";
    return {};
  }
  if (ends_with(what, ".json")) {
    status st = load_mapping(what, out.custom);
    if (!st.ok()) return st;
    mapping_match m;
    if (match_score(out.custom, r, m) <= 0)
      return status::error(r.file + ": the mapping table " + what +
                           " does not fit this rig: " + m.summary());
    out.table = &out.custom;
    out.binding = m.joint;
    out.bound = m.matched;
    out.description = "table " + out.custom.name + " (" + what + "): " + m.summary();
    return {};
  }
  const std::string folder = mappings_folder();
  status st = load_mapping_folder(folder, out.tables);
  if (!st.ok())
    return status::error(st.message() +
                         " (set AVATARMAP_MAPPINGS to the folder of the mapping tables)");
  if (what == "auto") {
    int best = -1;
    mapping_match m;
    st = auto_detect(out.tables, r, best, m);
    if (!st.ok()) return st;
    out.table = &out.tables[static_cast<size_t>(best)];
    out.binding = m.joint;
    out.bound = m.matched;
    out.description = "detected " + out.table->name + ": " + m.summary();
    return {};
  }
  std::string names;
  for (const mapping_table& t : out.tables) {
    if (t.name == what) {
      mapping_match m;
      if (match_score(t, r, m) <= 0)
        return status::error(r.file + ": table " + what + " does not fit this rig: " + m.summary());
      out.table = &t;
      out.binding = m.joint;
      out.bound = m.matched;
      out.description = "table " + t.name + ": " + m.summary();
      return {};
    }
    names += (names.empty() ? "" : ", ") + t.name;
  }
  return status::error("unknown rig table '" + what + "' (shipped: " + names +
                       "; or give auto or a .json file)");
}

}  // namespace avatarmap::cli
