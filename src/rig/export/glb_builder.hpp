// Internal: building a binary glTF (.glb) by hand, shared by every writer that makes one (.vrma,
// the animated .glb, the built-in avatar): the BIN chunk with the bufferViews and accessors that
// index into it, and the GLB container (12-byte header, JSON chunk, BIN chunk; docs/export.md).
// The document is a nlohmann::json held by the caller, so that every extension object and number
// is exactly as the writer puts it; no glTF library re-encodes anything. Numbers in the BIN
// chunk are written little-endian whatever the host.
#pragma once

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/status.hpp"

namespace avatarmap::export_detail {

// glTF accessor.componentType values.
constexpr int k_component_ubyte = 5121;
constexpr int k_component_ushort = 5123;
constexpr int k_component_uint = 5125;
constexpr int k_component_float = 5126;
// glTF bufferView.target values (0: none given).
constexpr int k_target_vertices = 34962;  // ARRAY_BUFFER
constexpr int k_target_indices = 34963;   // ELEMENT_ARRAY_BUFFER

/// The BIN chunk being built and the document's `bufferViews` and `accessors` arrays that index
/// into it (buffer 0). Keeps a reference to the document: it must outlive the builder.
class glb_builder {
 public:
  /// Creates `doc`'s bufferViews and accessors arrays when they are missing or not arrays;
  /// existing entries are kept and new ones appended.
  explicit glb_builder(nlohmann::json& doc);

  /// Appends `bytes` at the next 4-byte boundary; returns its offset in the BIN chunk.
  std::size_t append(std::string_view bytes);

  /// A new bufferView over `bytes` (`target`: k_target_vertices, k_target_indices or 0 for
  /// none); returns its index.
  std::size_t add_view(std::string_view bytes, int target = 0);

  /// A FLOAT accessor over `values` (`components` floats per element; `type` "SCALAR", "VEC2",
  /// "VEC3", "VEC4" or "MAT4" to match), with per-component min and max when `with_bounds`;
  /// returns its index. `values.size()` must be a multiple of `components`.
  std::size_t add_floats(const std::vector<float>& values, const char* type, int components,
                         bool with_bounds, int target = 0);

  /// An unsigned integer accessor: `values` stored as `component_type` (k_component_ubyte,
  /// k_component_ushort or k_component_uint; each value must fit), `components` per element;
  /// min and max when `with_bounds`. Returns its index.
  std::size_t add_unsigned(const std::vector<std::uint32_t>& values, int component_type,
                           const char* type, int components, bool with_bounds, int target = 0);

  /// The BIN chunk so far (unpadded at the end).
  std::string& bytes() { return bin_; }

 private:
  nlohmann::json& doc_;
  std::string bin_;
};

/// The GLB file of `doc` and its BIN chunk `bin`: `doc`'s buffers become one buffer of the BIN
/// chunk's padded length (no buffers when `bin` is empty), the JSON text is padded with spaces,
/// the BIN chunk with zeros, into `out` (replaced). Fails, naming `path`, when the file would be
/// larger than a GLB can describe (4 GiB). Never throws but for std::bad_alloc.
status make_glb(nlohmann::json& doc, std::string& bin, const std::string& path, std::string& out);

}  // namespace avatarmap::export_detail
