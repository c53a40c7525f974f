// `avatarmap inspect AVATAR [--json]`: what avatarmap sees in an avatar file.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/rig/rig.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {

namespace {

const char* k_inspect_usage =
    "Usage: avatarmap inspect AVATAR [--json]\n"
    "\n"
    "Loads an avatar (.vrm, .glb, .gltf, .vrma; binary or text glTF chosen by content) and\n"
    "prints its format (glTF / VRM 0.x / VRM 1.0), joint count, the humanoid bones the file\n"
    "declares and the required ones it lacks, the height of the hips joint and the expression\n"
    "names.\n"
    "\n"
    "  --json   machine-readable output (one JSON object)\n";

const char* format_name(rig_source s) {
  switch (s) {
    case rig_source::gltf:
      return "glTF";
    case rig_source::vrm0:
      return "VRM 0.x";
    case rig_source::vrm1:
      return "VRM 1.0";
    case rig_source::test:
      return "test";
    case rig_source::unknown:
      break;
  }
  return "unknown";
}

const char* format_key(rig_source s) {
  switch (s) {
    case rig_source::gltf:
      return "gltf";
    case rig_source::vrm0:
      return "vrm0";
    case rig_source::vrm1:
      return "vrm1";
    case rig_source::test:
      return "test";
    case rig_source::unknown:
      break;
  }
  return "unknown";
}

// The bones a VRM 1.0 file must declare (docs/conventions.md, "Real rigs"); VRM 0.x also
// requires chest and neck.
std::vector<bone> required_bones(rig_source s) {
  std::vector<bone> r = {bone::hips,
                         bone::spine,
                         bone::head,
                         bone::left_upper_arm,
                         bone::left_lower_arm,
                         bone::left_hand,
                         bone::right_upper_arm,
                         bone::right_lower_arm,
                         bone::right_hand,
                         bone::left_upper_leg,
                         bone::left_lower_leg,
                         bone::left_foot,
                         bone::right_upper_leg,
                         bone::right_lower_leg,
                         bone::right_foot};
  if (s == rig_source::vrm0) {
    r.insert(r.begin() + 2, bone::chest);
    r.insert(r.begin() + 3, bone::neck);
  }
  return r;
}

std::string json_string(const std::string& s) {
  std::string r = "\"";
  for (char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      r += '\\';
      r += c;
    } else if (u < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      r += buf;
    } else {
      r += c;
    }
  }
  return r + "\"";
}

}  // namespace

int run_inspect(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_inspect_usage, stdout);
    return 0;
  }
  const bool json = a.flag("--json");
  if (!a.check_no_options()) {
    std::fprintf(stderr, "avatarmap inspect: %s\n", a.error().c_str());
    return 2;
  }
  if (a.rest().size() != 1) {
    std::fprintf(stderr, "avatarmap inspect: expected exactly one AVATAR file, got %zu\n\n%s",
                 a.rest().size(), k_inspect_usage);
    return 2;
  }
  const std::string path = a.rest()[0];

  // Loaded, built and bound as `convert --avatar` binds it (--rig auto). A binding that fails
  // is reported below, not an error: inspect shows what the file is.
  bound_avatar avatar;
  const status bound = bind_avatar(path, bind_avatar_options{}, avatar);
  if (avatar.failed_step == bind_avatar_step::load ||
      avatar.failed_step == bind_avatar_step::build) {
    std::fprintf(stderr, "avatarmap inspect: %s\n", bound.message().c_str());
    return 1;
  }
  const rig& r = avatar.rig;

  const bool vrm = r.source == rig_source::vrm0 || r.source == rig_source::vrm1;
  int declared = 0;
  for (int j : r.declared_humanoid) declared += j >= 0;
  std::vector<bone> missing;
  if (vrm)
    for (bone b : required_bones(r.source))
      if (r.declared_humanoid[idx(b)] < 0) missing.push_back(b);
  const int hips = r.declared_humanoid[idx(bone::hips)];
  const float hips_height = hips >= 0 ? r.rest_world[hips][3].y : NAN;

  if (json) {
    std::string o = "{\"file\":" + json_string(path) + ",\"format\":\"" + format_key(r.source) +
                    "\",\"format_name\":\"" + format_name(r.source) +
                    "\",\"joints\":" + std::to_string(r.joint_count()) +
                    ",\"humanoid\":{\"declared_by_file\":" + (vrm ? "true" : "false") +
                    ",\"declared\":" + std::to_string(declared) + ",\"bones\":{";
    bool first = true;
    for (int b = 0; b < k_bone_count; ++b) {
      const int j = r.declared_humanoid[b];
      if (j < 0) continue;
      o += std::string(first ? "" : ",") + "\"" + std::string(bone_name(static_cast<bone>(b))) +
           "\":" + json_string(r.names[j]);
      first = false;
    }
    o += "},\"missing_required\":[";
    for (size_t i = 0; i < missing.size(); ++i)
      o += std::string(i ? "," : "") + "\"" + std::string(bone_name(missing[i])) + "\"";
    o += "]},\"hips_height\":";
    if (std::isfinite(hips_height)) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(hips_height));
      o += buf;
    } else {
      o += "null";
    }
    o += ",\"expressions\":[";
    for (size_t i = 0; i < r.expressions.size(); ++i)
      o += (i ? "," : "") + json_string(r.expressions[i]);
    o += "]}\n";
    std::fputs(o.c_str(), stdout);
    return 0;
  }

  std::printf("file: %s\n", path.c_str());
  std::printf("format: %s\n", format_name(r.source));
  std::printf("joints: %d\n", r.joint_count());
  if (!vrm) {
    std::printf("humanoid: not declared by the file; matching the shipped mapping tables:\n");
    std::printf("  %s\n", bound.ok() ? avatar.description.c_str() : bound.message().c_str());
  } else {
    std::printf("humanoid: declared: %d of %d bones\n", declared, k_bone_count);
    std::string m;
    for (bone b : missing) m += (m.empty() ? "" : ", ") + std::string(bone_name(b));
    std::printf("  missing required: %s\n", m.empty() ? "none" : m.c_str());
    for (int b = 0; b < k_bone_count; ++b) {
      const int j = r.declared_humanoid[b];
      if (j >= 0)
        std::printf("  %-24s %s\n", std::string(bone_name(static_cast<bone>(b))).c_str(),
                    r.names[j].c_str());
    }
  }
  if (std::isfinite(hips_height))
    std::printf("hips height: %.3f (world Y of the hips joint, file units)\n", hips_height);
  else
    std::printf("hips height: unknown (no hips bone declared)\n");
  std::string e;
  for (const std::string& x : r.expressions) e += (e.empty() ? "" : ", ") + x;
  std::printf("expressions: %zu%s%s\n", r.expressions.size(), e.empty() ? "" : ": ", e.c_str());
  return 0;
}

}  // namespace avatarmap::cli
