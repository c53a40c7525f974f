#include "avatarmap/rig/bound_avatar.hpp"

#include <optional>

#include "avatarmap/io/resources.hpp"
#include "avatarmap/rig/avatar_loader.hpp"

namespace avatarmap {

status parse_bone_override(const std::string& text, bone_override& out) {
  const std::size_t eq = text.find('=');
  const std::optional<bone> b =
      eq == std::string::npos ? std::nullopt : bone_from_name(text.substr(0, eq));
  if (!b)
    return status::invalid_argument(
        "BONE=JOINT wants a VRM 1.0 bone name (hips, leftUpperArm, ...), got '" + text + "'");
  out.proxy_bone = *b;
  out.joint = text.substr(eq + 1);
  return {};
}

status bind_avatar(const std::string& path, const bind_avatar_options& options, bound_avatar& out) {
  out = bound_avatar{};
  out.path = path;
  out.binding.fill(-1);
  auto fail = [&out](bind_avatar_step step, status st) {
    out.failed_step = step;
    return st;
  };
  {
    raw_rig raw;  // only while building: the runtime rig keeps what later steps need
    if (status st = load_avatar(path, raw); !st.ok()) return fail(bind_avatar_step::load, st);
    if (status st = build_rig(raw, out.rig); !st.ok()) return fail(bind_avatar_step::build, st);
  }
  const resource_lookup tables = find_resource(resource::mappings, options.mappings_folder);
  out.mappings_folder = tables.folder;
  status st = select_binding(out.rig, options.rig, tables.folder, out.choice);
  const bool automatic = options.rig.empty() || options.rig == "auto";
  if (!st.ok() && automatic && !options.overrides.empty()) {
    // A rig no table fits can still be driven by the overrides alone.
    out.choice = rig_binding_choice{};
    out.choice.binding.fill(-1);
    out.choice.description = "bound by " + options.overrides_name + " only (no table fits)";
    st = status{};
  }
  if (!st.ok()) {
    if (tables.folder.empty() && st.code() == status_code::io) {
      // select_binding needed the folder and none was found: say where we looked.
      std::string tried;
      for (const std::string& t : tables.tried) tried += (tried.empty() ? "" : "; ") + t;
      st = st.with_message(path + ": rig '" + (automatic ? std::string("auto") : options.rig) +
                           "' needs the mapping tables and no folder of them was found (tried: " +
                           tried + "); set " + resource_environment(resource::mappings) +
                           " to the folder of the mapping tables");
    }
    return fail(bind_avatar_step::select, st);
  }
  out.binding = out.choice.binding;
  out.description = out.choice.description;
  for (const bone_override& o : options.overrides) {
    const int joint = o.joint == "none" ? -1 : out.rig.find(o.joint);
    if (o.joint != "none" && joint < 0)
      return fail(bind_avatar_step::overrides,
                  status::invalid_argument(path + ": " + options.overrides_name + " " +
                                           std::string(bone_name(o.proxy_bone)) + "=" + o.joint +
                                           ": the avatar has no joint '" + o.joint +
                                           "' (see `avatarmap inspect " + path + "`)"));
    // A joint drives one bone: taking it from another bone unbinds that one.
    for (int& j : out.binding)
      if (joint >= 0 && j == joint) j = -1;
    out.binding[idx(o.proxy_bone)] = joint;
  }
  if (!options.overrides.empty())
    out.description += "; " + std::to_string(options.overrides.size()) + " binding(s) from " +
                       options.overrides_name;
  out.bound = 0;
  for (int j : out.binding) out.bound += j >= 0;
  return {};
}

}  // namespace avatarmap
