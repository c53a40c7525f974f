#include "avatarmap/rig/rig_binding.hpp"

#include <vector>

namespace avatarmap {
namespace {

int count_bound(const bone_binding& b) {
  int n = 0;
  for (int j : b) n += j >= 0;
  return n;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A table that matched: copies it and its match into `out`.
void take(rig_binding_choice& out, const mapping_table& t, const mapping_match& m,
          std::string description) {
  out.uses_table = true;
  out.table = t;
  out.binding = m.joint;
  out.bound = m.matched;
  out.description = std::move(description);
}

}  // namespace

status select_binding(const rig& r, const std::string& option, const std::string& mappings_folder,
                      rig_binding_choice& out) {
  out = rig_binding_choice{};
  out.binding.fill(-1);
  const std::string what = option.empty() ? std::string("auto") : option;
  const std::string rig_file = r.file.empty() ? std::string("the rig") : r.file;
  if (what == "auto" && r.declared_humanoid[idx(bone::hips)] >= 0) {
    out.binding = r.declared_humanoid;
    out.bound = count_bound(out.binding);
    out.description = std::string(r.source == rig_source::vrm0 ? "VRM 0.x" : "VRM 1.0") +
                      " humanoid declared by the file (" + std::to_string(out.bound) + " bones)";
    return {};
  }
  if (ends_with(what, ".json")) {
    mapping_table custom;
    // load_mapping's code says which: io (cannot be read) or parse (malformed).
    if (status st = load_mapping(what, custom); !st.ok()) return st;
    mapping_match m;
    if (match_score(custom, r, m) <= 0)
      return status::parse_error(rig_file + ": the mapping table " + what +
                                 " does not fit this rig: " + m.summary());
    take(out, custom, m, "table " + custom.name + " (" + what + "): " + m.summary());
    return {};
  }
  if (mappings_folder.empty())
    return status::io_error("no folder of mapping tables was given (needed for rig '" + what +
                            "'; set AVATARMAP_MAPPINGS)");
  std::vector<mapping_table> tables;
  status st = load_mapping_folder(mappings_folder, tables);
  if (!st.ok())  // io (cannot list or read) or parse (a malformed table), kept
    return st.with_message(st.message() +
                           " (set AVATARMAP_MAPPINGS to the folder of the mapping tables)");
  if (what == "auto") {
    int best = -1;
    mapping_match m;
    st = auto_detect(tables, r, best, m);
    if (!st.ok()) return st;  // parse: no table fits
    const mapping_table& t = tables[static_cast<std::size_t>(best)];
    take(out, t, m, "detected " + t.name + ": " + m.summary());
    return {};
  }
  std::string names;
  for (const mapping_table& t : tables) {
    if (t.name == what) {
      mapping_match m;
      if (match_score(t, r, m) <= 0)
        return status::parse_error(rig_file + ": table " + what +
                                   " does not fit this rig: " + m.summary());
      take(out, t, m, "table " + t.name + ": " + m.summary());
      return {};
    }
    names += (names.empty() ? "" : ", ") + t.name;
  }
  return status::invalid_argument("unknown rig table '" + what + "' (shipped: " + names +
                                  "; or give auto or a .json file)");
}

}  // namespace avatarmap
