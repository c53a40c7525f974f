// The shared GLB building code; see src/rig/export/glb_builder.hpp.
#include "rig/export/glb_builder.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace avatarmap::export_detail {
namespace {

using json = nlohmann::json;

constexpr std::uint32_t k_magic = 0x46546C67;       // "glTF"
constexpr std::uint32_t k_chunk_json = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t k_chunk_bin = 0x004E4942;   // "BIN\0"

void pad_to_4(std::string& s, char fill) {
  while (s.size() % 4) s += fill;
}

void append_le(std::string& s, std::uint32_t v, int bytes) {
  for (int k = 0; k < bytes; ++k) s += static_cast<char>((v >> (8 * k)) & 0xFF);
}

int component_bytes(int component_type) {
  return component_type == k_component_ubyte ? 1 : component_type == k_component_ushort ? 2 : 4;
}

}  // namespace

glb_builder::glb_builder(json& doc) : doc_(doc) {
  if (!doc_.contains("bufferViews") || !doc_["bufferViews"].is_array())
    doc_["bufferViews"] = json::array();
  if (!doc_.contains("accessors") || !doc_["accessors"].is_array())
    doc_["accessors"] = json::array();
}

std::size_t glb_builder::append(std::string_view bytes) {
  pad_to_4(bin_, '\0');
  const std::size_t offset = bin_.size();
  bin_.append(bytes.data(), bytes.size());
  return offset;
}

std::size_t glb_builder::add_view(std::string_view bytes, int target) {
  const std::size_t offset = append(bytes);
  json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes.size()}};
  if (target != 0) view["target"] = target;
  doc_["bufferViews"].push_back(std::move(view));
  return doc_["bufferViews"].size() - 1;
}

std::size_t glb_builder::add_floats(const std::vector<float>& values, const char* type,
                                    int components, bool with_bounds, int target) {
  std::string bytes;
  bytes.reserve(values.size() * 4);
  for (float f : values) {
    std::uint32_t u = 0;
    std::memcpy(&u, &f, 4);
    append_le(bytes, u, 4);
  }
  const auto comps = static_cast<std::size_t>(components);
  json acc = {{"bufferView", add_view(bytes, target)},
              {"componentType", k_component_float},
              {"count", values.size() / comps},
              {"type", type}};
  if (with_bounds && !values.empty()) {
    std::vector<double> lo(comps, std::numeric_limits<double>::infinity());
    std::vector<double> hi(comps, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      lo[i % comps] = std::min(lo[i % comps], double(values[i]));
      hi[i % comps] = std::max(hi[i % comps], double(values[i]));
    }
    acc["min"] = lo;
    acc["max"] = hi;
  }
  doc_["accessors"].push_back(std::move(acc));
  return doc_["accessors"].size() - 1;
}

std::size_t glb_builder::add_unsigned(const std::vector<std::uint32_t>& values, int component_type,
                                      const char* type, int components, bool with_bounds,
                                      int target) {
  const int size = component_bytes(component_type);
  std::string bytes;
  bytes.reserve(values.size() * static_cast<std::size_t>(size));
  for (std::uint32_t v : values) append_le(bytes, v, size);
  const auto comps = static_cast<std::size_t>(components);
  json acc = {{"bufferView", add_view(bytes, target)},
              {"componentType", component_type},
              {"count", values.size() / comps},
              {"type", type}};
  if (with_bounds && !values.empty()) {
    std::vector<std::uint32_t> lo(comps, std::numeric_limits<std::uint32_t>::max());
    std::vector<std::uint32_t> hi(comps, 0);
    for (std::size_t i = 0; i < values.size(); ++i) {
      lo[i % comps] = std::min(lo[i % comps], values[i]);
      hi[i % comps] = std::max(hi[i % comps], values[i]);
    }
    acc["min"] = lo;
    acc["max"] = hi;
  }
  doc_["accessors"].push_back(std::move(acc));
  return doc_["accessors"].size() - 1;
}

status make_glb(json& doc, std::string& bin, const std::string& path, std::string& out) {
  pad_to_4(bin, '\0');
  if (bin.empty())
    doc.erase("buffers");
  else
    doc["buffers"] = json::array({json{{"byteLength", bin.size()}}});
  // Strings the writers put in were valid UTF-8; `replace` only guards the dump itself.
  std::string text = doc.dump(-1, ' ', false, json::error_handler_t::replace);
  pad_to_4(text, ' ');
  const std::uint64_t total = 12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size());
  if (total > std::numeric_limits<std::uint32_t>::max())
    return status::error(path + ": the file would be " + std::to_string(total) +
                         " bytes, more than a GLB can hold (4 GiB)");
  out.clear();
  out.reserve(static_cast<std::size_t>(total));
  append_le(out, k_magic, 4);
  append_le(out, 2, 4);
  append_le(out, static_cast<std::uint32_t>(total), 4);
  append_le(out, static_cast<std::uint32_t>(text.size()), 4);
  append_le(out, k_chunk_json, 4);
  out += text;
  if (!bin.empty()) {
    append_le(out, static_cast<std::uint32_t>(bin.size()), 4);
    append_le(out, k_chunk_bin, 4);
    out += bin;
  }
  return {};
}

}  // namespace avatarmap::export_detail
