// Small hand-made glTF files for the hostile-input tests of the avatar loader, the VRMA
// reader and the animated .glb writer: a GLB packer (with every header field settable, to
// break them one at a time), a minimal three-node humanoid avatar, deep JSON.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace avatarmap::test {

inline void append_u32_le(std::string& s, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) s += static_cast<char>((v >> (8 * k)) & 0xFF);
}

/// The fields of a GLB, each overridable (-1: the correct value).
struct glb_parts {
  std::string json;  // the JSON chunk's text (padded with spaces here)
  std::string bin;   // the BIN chunk's payload (padded with zeros here); empty: no BIN chunk
  std::int64_t version = 2;
  std::int64_t total_length = -1;
  std::int64_t json_length = -1;
  std::int64_t json_type = 0x4E4F534A;
  std::int64_t bin_length = -1;
  std::int64_t bin_type = 0x004E4942;
};

inline std::string make_glb(glb_parts p) {
  while (p.json.size() % 4) p.json += ' ';
  while (p.bin.size() % 4) p.bin += '\0';
  std::string out = "glTF";
  const std::size_t total = 12 + 8 + p.json.size() + (p.bin.empty() ? 0 : 8 + p.bin.size());
  append_u32_le(out, static_cast<std::uint32_t>(p.version));
  append_u32_le(out, static_cast<std::uint32_t>(p.total_length >= 0 ? p.total_length : total));
  append_u32_le(out,
                static_cast<std::uint32_t>(p.json_length >= 0 ? p.json_length : p.json.size()));
  append_u32_le(out, static_cast<std::uint32_t>(p.json_type));
  out += p.json;
  if (!p.bin.empty()) {
    append_u32_le(out, static_cast<std::uint32_t>(p.bin_length >= 0 ? p.bin_length : p.bin.size()));
    append_u32_le(out, static_cast<std::uint32_t>(p.bin_type));
    out += p.bin;
  }
  return out;
}

inline std::string make_glb(const nlohmann::json& j, const std::string& bin = "") {
  glb_parts p;
  p.json = j.dump();
  p.bin = bin;
  return make_glb(p);
}

/// A VRM 1.0 avatar of three nodes (root > hips > spine), hips at 1 m, no mesh, no buffer.
inline nlohmann::json minimal_vrm1() {
  nlohmann::json j;
  j["asset"] = {{"version", "2.0"}};
  j["nodes"] = nlohmann::json::array(
      {{{"name", "root"}, {"children", {1}}},
       {{"name", "hips"}, {"children", {2}}, {"translation", {0.0, 1.0, 0.0}}},
       {{"name", "spine"}, {"translation", {0.0, 0.1, 0.0}}}});
  j["scenes"] = nlohmann::json::array({{{"nodes", {0}}}});
  j["scene"] = 0;
  j["extensionsUsed"] = {"VRMC_vrm"};
  j["extensions"]["VRMC_vrm"] = {
      {"specVersion", "1.0"},
      {"humanoid", {{"humanBones", {{"hips", {{"node", 1}}}, {"spine", {{"node", 2}}}}}}}};
  return j;
}

/// `depth` nested arrays, innermost holding 1: [[[1]]] for depth 3.
inline std::string deep_json_array(int depth) {
  return std::string(static_cast<std::size_t>(depth), '[') + "1" +
         std::string(static_cast<std::size_t>(depth), ']');
}

/// `j` as text with the string value "@RAW@" replaced by `raw` (JSON text nlohmann must not
/// be asked to hold, such as 20,000 levels of nesting).
inline std::string dump_with_raw(const nlohmann::json& j, const std::string& raw) {
  std::string text = j.dump();
  const std::string mark = "\"@RAW@\"";
  const std::size_t at = text.find(mark);
  if (at != std::string::npos) text.replace(at, mark.size(), raw);
  return text;
}

/// True when `text` contains `part`.
inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The little-endian uint32 at byte `at` of `b` (GLB header and chunk fields).
inline std::uint32_t u32_at(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

}  // namespace avatarmap::test
