// Internal: the one guarded way the library opens a glTF file (avatars .gltf/.glb/.vrm, VRM
// Animation .vrma, and the avatar the .glb writer copies). Everything a stranger's file can
// use to crash the process or to read other files is checked here, in our words, before a
// library that trusts its input (tinygltf) sees it:
//  - the file's size (gltf_limits::max_file_bytes);
//  - the GLB container (magic, version 2, total length equal to the file's, chunk lengths and
//    types, the JSON chunk first, at most one BIN chunk right after it);
//  - the JSON text's nesting depth and size (io_detail::check_json_limits), because tinygltf
//    converts extras/extensions recursively, one stack frame per level;
//  - integers of the glTF core schema (indices, counts, enums) outside the range of `int`,
//    which tinygltf silently truncates (node 2^40 would become node 0);
//  - every buffer and image URI: data URIs bounded (max_data_uri_bytes), other schemes
//    (file:, http:, ...), absolute paths and `..` leaving the file's folder refused, and a
//    relative path must still lie inside the folder once symbolic links are resolved
//    (realpath). The same resolver serves tinygltf (through its FsCallbacks) and the .glb
//    writer, so no other code path reads a file an avatar names.
// Images are never decoded (tinygltf gets an image loader that keeps nothing; the writer
// copies their bytes as they are).
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap::gltf_detail {

/// Limits of what open_gltf_document accepts. The defaults are documented in
/// docs/security.md; tests lower them.
struct gltf_limits {
  /// The .gltf/.glb/.vrm/.vrma file itself.
  std::uint64_t max_file_bytes = std::uint64_t{1} << 30;  // 1 GiB
  /// Nesting of the JSON (json_limits::max_depth); VRM and glTF need about 10.
  int max_json_depth = 128;
  /// The JSON text (a .gltf with base64 buffers is mostly JSON).
  std::size_t max_json_bytes = std::size_t{256} << 20;  // 256 MiB
  /// One external buffer or image file.
  std::uint64_t max_resource_bytes = std::uint64_t{1} << 30;  // 1 GiB
  /// All external files one document reads, together.
  std::uint64_t max_total_resource_bytes = std::uint64_t{2} << 30;  // 2 GiB
  /// One data: URI, as written (its base64 text; the decoded bytes are 3/4 of it).
  std::size_t max_data_uri_bytes = std::size_t{256} << 20;  // 256 MiB
};

/// An opened, checked glTF file. Copyable; holds the file's bytes.
struct gltf_document {
  std::string path;    // as given, for messages
  std::string folder;  // canonical (realpath) folder of `path`: relative URIs stay inside it
  bool binary = false;
  nlohmann::json json;  // the whole glTF JSON, parsed after the depth check
  gltf_limits limits;

  /// The JSON text as stored in the file (GLB: the JSON chunk without its padding).
  std::string_view json_text() const {
    return std::string_view(bytes).substr(json_offset, json_size);
  }
  /// The GLB BIN chunk's payload (empty for text glTF or a GLB without one).
  std::string_view bin() const { return std::string_view(bytes).substr(bin_offset, bin_size); }

  std::string bytes;  // the whole file
  std::size_t json_offset = 0, json_size = 0;
  std::size_t bin_offset = 0, bin_size = 0;
};

/// Reads and checks the file at `path` (see the top of this header). Binary or text is decided
/// by the content ("glTF" magic), not the extension. On failure `out` is unspecified and the
/// message starts with `path` and says what is wrong and what to do. Never throws but for
/// std::bad_alloc.
status open_gltf_document(const std::string& path, gltf_document& out,
                          const gltf_limits& limits = {});

/// Parses `doc` with tinygltf: external buffers and images are read only through the resolver
/// (read_gltf_uri's rules), images are not decoded (Image::image stays empty). Messages start
/// with the document's path. Never throws but for std::bad_alloc.
status parse_gltf_model(const gltf_document& doc, tinygltf::Model& out);

/// The bytes a buffer's or image's `uri` names: a data: URI decoded (base64 only), or a file
/// inside the document's folder. `where` names the property in messages ("images[2].uri").
/// `total_read` accumulates the bytes read by one operation; a read that would take it past
/// limits.max_total_resource_bytes fails. Fails (message with the path, `where` and the URI) on
/// a refused URI (see the top of this header), a missing or unreadable file, or a size over the
/// limits; `out_missing` (when given) tells a file that does not exist (an allowed URI) from
/// the other failures.
status read_gltf_uri(const gltf_document& doc, const std::string& uri, const std::string& where,
                     std::uint64_t& total_read, std::string& out, bool* out_missing = nullptr);

/// Media type of an image from its first bytes (PNG, JPEG, WebP, KTX2, GIF, BMP), or "" when
/// not recognised.
std::string sniff_image_mime_type(std::string_view bytes);

}  // namespace avatarmap::gltf_detail
