#include "rig/gltf_document.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <vector>

#include "common/json_limits.hpp"

namespace avatarmap::gltf_detail {
namespace {

constexpr std::uint32_t k_chunk_json = 0x4E4F534A;  // "JSON", little-endian
constexpr std::uint32_t k_chunk_bin = 0x004E4942;   // "BIN\0", little-endian
constexpr std::size_t k_glb_header = 12;
constexpr std::size_t k_chunk_header = 8;

// tinygltf joins every external URI to the base folder we give it and asks our FsCallbacks
// for the result. We give it this marker instead of a real folder, so that a path that does
// not start with it (tinygltf also tries the current directory) is never found, and the rest
// of the path is the URI as tinygltf decoded it.
const std::string k_root_marker = "\x01avatarmap-gltf-root";

// Text from a file for a message: at most `max` characters, control bytes escaped (a hostile
// file must not write escape sequences to a terminal).
std::string printable(std::string_view s, std::size_t max = 200) {
  std::string r;
  const std::size_t n = std::min(s.size(), max);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) {
      static const char* hex = "0123456789abcdef";
      r += "\\x";
      r += hex[c >> 4];
      r += hex[c & 15];
    } else {
      r += static_cast<char>(c);
    }
  }
  if (s.size() > n) r += "...(" + std::to_string(s.size()) + " characters)";
  return r;
}

// A URI or path for a message, quoted.
std::string shown(std::string_view s) { return "'" + printable(s) + "'"; }

std::uint32_t read_u32(std::string_view b, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 3])) << 24;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

bool starts_with_nocase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    char c = s[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != prefix[i]) return false;
  }
  return true;
}

// Reads the regular file `path` whole. `what` starts every message. `max` bounds its size.
// `no_follow`: refuse a symbolic link as the last component (resolved paths have none, so a
// link found there was put in place after the check).
status read_regular_file(const std::string& path, const std::string& what, std::uint64_t max,
                         bool no_follow, std::string& out) {
  // O_NONBLOCK: opening a FIFO named as an avatar must not wait for a writer (it is then
  // refused as not a regular file); reads of a regular file ignore the flag.
  const int fd =
      ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | (no_follow ? O_NOFOLLOW : 0));
  if (fd < 0) {
    const int e = errno;
    return status::io_error(what + ": cannot open the file: " + std::strerror(e) +
                            (e == ENOENT ? " (check the path)" : ""));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    return status::io_error(what + ": cannot read the file: " + std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return status::io_error(what + ": not a regular file (a folder, device or pipe); give a file");
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max) {
    ::close(fd);
    return status::parse_error(what + ": the file is " + std::to_string(size) +
                               " bytes, more than the limit of " + std::to_string(max) +
                               " bytes; this program does not read files that large");
  }
  out.resize(static_cast<std::size_t>(size));
  std::size_t got = 0;
  while (got < out.size()) {
    const ssize_t n = ::read(fd, &out[got], out.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = n < 0 ? errno : 0;
      ::close(fd);
      out.clear();
      return status::io_error(what + ": cannot read the file: " +
                              (n < 0 ? std::string(std::strerror(e))
                                     : std::string("it became shorter while being read")));
    }
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return {};
}

std::string folder_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// ---- the GLB container ---------------------------------------------------------------------

status split_glb(gltf_document& doc) {
  const std::string_view b = doc.bytes;
  const std::string& p = doc.path;
  const std::size_t size = b.size();
  if (size < k_glb_header)
    return status::parse_error(p + ": binary glTF (GLB) truncated: " + std::to_string(size) +
                               " bytes, shorter than the 12-byte header");
  const std::uint32_t version = read_u32(b, 4);
  if (version != 2)
    return status::parse_error(p + ": GLB version " + std::to_string(version) +
                               " is not supported (glTF 2.0 files have version 2)");
  const std::uint32_t length = read_u32(b, 8);
  if (length != size)
    return status::parse_error(p + ": the GLB header declares " + std::to_string(length) +
                               " bytes but the file has " + std::to_string(size) +
                               (length > size
                                    ? " (the file is truncated: download or export it again)"
                                    : " (bytes after the declared end: the file is damaged)"));
  if (size < k_glb_header + k_chunk_header)
    return status::parse_error(p + ": the GLB has no JSON chunk (it ends after its header)");
  const std::uint32_t json_length = read_u32(b, 12);
  const std::uint32_t json_type = read_u32(b, 16);
  if (json_type != k_chunk_json)
    return status::parse_error(p + ": the GLB's first chunk has type " + hex32(json_type) +
                               ", not JSON (" + hex32(k_chunk_json) +
                               "); the JSON chunk must come first");
  std::size_t at = k_glb_header + k_chunk_header;
  if (json_length > size - at)
    return status::parse_error(
        p + ": the GLB's JSON chunk declares " + std::to_string(json_length) + " bytes but only " +
        std::to_string(size - at) + " follow (the file is truncated or damaged)");
  if (json_length == 0) return status::parse_error(p + ": the GLB's JSON chunk is empty");
  doc.json_offset = at;
  doc.json_size = json_length;
  at += json_length;
  // Chunks after the JSON one: BIN, at most once and right after JSON (tinygltf reads it
  // there), then any others, which the glTF spec says to ignore; every length must fit.
  for (int chunk = 1; at < size; ++chunk) {
    if (size - at < k_chunk_header)
      return status::parse_error(p + ": the GLB has " + std::to_string(size - at) +
                                 " stray bytes after chunk " + std::to_string(chunk - 1) +
                                 ", too few for a chunk header (the file is damaged)");
    const std::uint32_t length_c = read_u32(b, at);
    const std::uint32_t type_c = read_u32(b, at + 4);
    const std::string name = type_c == k_chunk_bin ? "BIN chunk" : "chunk " + std::to_string(chunk);
    if (length_c > size - at - k_chunk_header)
      return status::parse_error(p + ": the GLB's " + name + " declares " +
                                 std::to_string(length_c) + " bytes but only " +
                                 std::to_string(size - at - k_chunk_header) +
                                 " follow (the file is truncated or damaged)");
    if (type_c == k_chunk_json)
      return status::parse_error(p + ": the GLB has a second JSON chunk (chunk " +
                                 std::to_string(chunk) + "); a GLB has exactly one");
    if (type_c == k_chunk_bin) {
      if (chunk != 1)
        return status::parse_error(p + ": the GLB's BIN chunk is chunk " + std::to_string(chunk) +
                                   "; it must directly follow the JSON chunk (and appear once)");
      if (length_c == 0 || length_c % 4 != 0)
        return status::parse_error(p + ": the GLB's BIN chunk length " + std::to_string(length_c) +
                                   " is not a positive multiple of 4 (glTF requires the padding; "
                                   "export the file again)");
      doc.bin_offset = at + k_chunk_header;
      doc.bin_size = length_c;
    } else if (chunk == 1) {
      return status::parse_error(
          p + ": the GLB's second chunk has type " + hex32(type_c) + ", not BIN (" +
          hex32(k_chunk_bin) +
          "); this program reads GLBs whose binary chunk follows the JSON chunk");
    }
    at += k_chunk_header + length_c;
  }
  return {};
}

// ---- the JSON ------------------------------------------------------------------------------

// Integers of the core schema that tinygltf reads into `int` (truncating): anything outside
// int's range is refused here with its JSON path. Extras and extensions are skipped: tinygltf
// does not index with them, and our own readers of extensions check their numbers.
status check_core_integers(const nlohmann::json& v, std::string& where, const std::string& p) {
  if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (it.key() == "extras" || it.key() == "extensions") continue;
      const std::size_t keep = where.size();
      where += (where.empty() ? "" : ".") + it.key();
      if (status s = check_core_integers(it.value(), where, p); !s) return s;
      where.resize(keep);
    }
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::size_t keep = where.size();
      where += "[" + std::to_string(i) + "]";
      if (status s = check_core_integers(v[i], where, p); !s) return s;
      where.resize(keep);
    }
  } else if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      return status::parse_error(p + ": " + where + " is " + std::to_string(u) +
                                 ", out of range (an index or count of a glTF file is below 2^31); "
                                 "the file is damaged or hostile");
  } else if (v.is_number_integer()) {
    const auto i = v.get<std::int64_t>();
    if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max())
      return status::parse_error(p + ": " + where + " is " + std::to_string(i) +
                                 ", out of range (an index or count of a glTF file is below 2^31); "
                                 "the file is damaged or hostile");
  }
  return {};
}

status parse_json(gltf_document& doc) {
  const std::string& p = doc.path;
  const std::string_view text = doc.json_text();
  io_detail::json_limits jl;
  jl.max_depth = doc.limits.max_json_depth;
  jl.max_bytes = doc.limits.max_json_bytes;
  if (status s = io_detail::check_json_limits(text, p, jl); !s) return s;
  try {
    doc.json = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann's text after "syntax error" says what was expected; its prefix is not ours.
    const std::string what = e.what();
    const std::size_t at = what.find("syntax error");
    const std::size_t byte = doc.json_offset + (e.byte > 0 ? e.byte - 1 : 0);
    return status::parse_error(
        p + ": the JSON is malformed at byte " + std::to_string(byte) +
        (at == std::string::npos ? std::string() : " (" + what.substr(at) + ")") +
        "; the file is damaged or not glTF");
  } catch (const nlohmann::json::out_of_range&) {
    return status::parse_error(p +
                               ": the JSON holds a number too large for a double (such as 1e400); "
                               "the file is damaged or hostile");
  } catch (const nlohmann::json::exception&) {
    return status::parse_error(p + ": the JSON cannot be read; the file is damaged or not glTF");
  }
  if (!doc.json.is_object())
    return status::parse_error(p + ": the JSON's top level is not an object; not a glTF file");
  const auto asset = doc.json.find("asset");
  if (asset == doc.json.end() || !asset->is_object() || !asset->contains("version") ||
      !(*asset)["version"].is_string() ||
      (*asset)["version"].get_ref<const std::string&>().rfind("2.", 0) != 0)
    return status::parse_error(p +
                               ": asset.version is missing or not \"2.x\"; not a glTF 2.0 file");
  std::string where;
  return check_core_integers(doc.json, where, p);
}

// ---- URIs ----------------------------------------------------------------------------------

// RFC 3986 scheme: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":" (a relative reference cannot
// have a colon in its first segment). Empty when `uri` has none.
std::string scheme_of(std::string_view uri) {
  if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return {};
  for (std::size_t i = 1; i < uri.size(); ++i) {
    const char c = uri[i];
    if (c == ':') return std::string(uri.substr(0, i));
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.') return {};
  }
  return {};
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// RFC 3986 percent-decoding ('+' stays '+'). False on a malformed escape or a NUL byte.
bool percent_decode(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    char c = in[i];
    if (c == '%') {
      if (i + 2 >= in.size()) return false;
      const int hi = hex_value(in[i + 1]), lo = hex_value(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      c = static_cast<char>(hi * 16 + lo);
      i += 2;
    }
    if (c == '\0') return false;
    out += c;
  }
  return true;
}

// Resolves `relative` (already decoded) inside doc.folder: not absolute, no `..` above the
// folder, and its real path (symbolic links resolved) still inside it. `what` starts the
// messages. `missing` is set when the only fault is that the file does not exist.
status resolve_relative(const gltf_document& doc, const std::string& relative,
                        const std::string& what, std::string& out_file, bool& missing) {
  missing = false;
  if (relative.empty()) return status::parse_error(what + " is empty");
  if (relative[0] == '/')
    return status::parse_error(
        what +
        " is an absolute path; only files inside the avatar's folder are read "
        "(put the file next to the avatar and name it relatively)");
  int depth = 0;
  std::size_t start = 0;
  while (start <= relative.size()) {
    std::size_t end = relative.find('/', start);
    if (end == std::string::npos) end = relative.size();
    const std::string_view part = std::string_view(relative).substr(start, end - start);
    if (part == "..") {
      if (--depth < 0)
        return status::parse_error(what + " leaves the avatar's folder (..); only files inside " +
                                   shown(doc.folder) + " are read");
    } else if (!part.empty() && part != ".") {
      ++depth;
    }
    start = end + 1;
  }
  const std::string candidate = doc.folder + (doc.folder == "/" ? "" : "/") + relative;
  char* real = ::realpath(candidate.c_str(), nullptr);
  if (real == nullptr) {
    const int e = errno;
    missing = e == ENOENT || e == ENOTDIR;
    return status::io_error(what + ": " +
                            (missing
                                 ? std::string("no such file in the folder ") + shown(doc.folder)
                                 : std::string(std::strerror(e))));
  }
  const std::string resolved = real;
  std::free(real);
  const std::string prefix = doc.folder == "/" ? "/" : doc.folder + "/";
  if (resolved.compare(0, prefix.size(), prefix) != 0 || resolved.size() == prefix.size())
    return status::parse_error(what + " resolves through a symbolic link to " + shown(resolved) +
                               ", outside the avatar's folder " + shown(doc.folder) +
                               "; refused (copy the file into the folder)");
  struct stat st {};
  if (::stat(resolved.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
    return status::io_error(what + " is not a regular file");
  out_file = resolved;
  return {};
}

// Checks a buffer's or image's URI by our rules. Data URIs: true in `is_data`.
status check_uri(const gltf_document& doc, const std::string& uri, const std::string& where,
                 bool& is_data, std::string& out_file, bool& missing) {
  is_data = false;
  missing = false;
  const std::string what = doc.path + ": " + where + " " + shown(uri);
  if (starts_with_nocase(uri, "data:")) {
    is_data = true;
    if (uri.size() > doc.limits.max_data_uri_bytes)
      return status::parse_error(what + ": a data: URI of " + std::to_string(uri.size()) +
                                 " characters, more than the limit of " +
                                 std::to_string(doc.limits.max_data_uri_bytes) +
                                 " (store the data in a .glb instead)");
    if (uri.find(";base64,") == std::string::npos)
      return status::parse_error(what +
                                 ": a data: URI that is not base64; only base64 data URIs are "
                                 "read");
    return {};
  }
  if (const std::string scheme = scheme_of(uri); !scheme.empty())
    return status::parse_error(what + ": URIs with a scheme (" + scheme +
                               ":) are not read; only files inside the avatar's folder (relative "
                               "paths) and data: URIs are");
  std::string decoded;
  if (!percent_decode(uri, decoded))
    return status::parse_error(what + " has a malformed %-escape or a NUL byte");
  return resolve_relative(doc, decoded, what, out_file, missing);
}

// Every buffer and image URI, checked before tinygltf sees the file. A missing buffer file is
// an error; a missing image is not (the skeleton does not need it; the writer keeps its URI).
// A buffer's data: URI must have one of the two media types glTF defines for buffers (the
// only ones tinygltf decodes; any other it would look for as a file).
status check_all_uris(const gltf_document& doc) {
  for (const char* array : {"buffers", "images"}) {
    const auto it = doc.json.find(array);
    if (it == doc.json.end() || !it->is_array()) continue;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& entry = (*it)[i];
      if (!entry.is_object()) continue;
      const auto u = entry.find("uri");
      if (u == entry.end()) continue;
      const std::string where = std::string(array) + "[" + std::to_string(i) + "].uri";
      if (!u->is_string()) return status::parse_error(doc.path + ": " + where + " is not a string");
      bool is_data = false, missing = false;
      std::string file;
      const std::string& uri = u->get_ref<const std::string&>();
      status s = check_uri(doc, uri, where, is_data, file, missing);
      if (!s && !(missing && std::string(array) == "images")) return s;
      if (is_data && std::string(array) == "buffers" &&
          uri.rfind("data:application/octet-stream;base64,", 0) != 0 &&
          uri.rfind("data:application/gltf-buffer;base64,", 0) != 0)
        return status::parse_error(doc.path + ": " + where + " " + shown(uri.substr(0, 40)) +
                                   ": a buffer's data: URI must be application/octet-stream or "
                                   "application/gltf-buffer (base64)");
    }
  }
  return {};
}

// Integer member `key` of `v` (default `fallback` when absent); false when present but not a
// non-negative integer.
bool size_member(const nlohmann::json& v, const char* key, std::int64_t fallback,
                 std::int64_t& out) {
  const auto it = v.find(key);
  if (it == v.end()) {
    out = fallback;
    return true;
  }
  if (!it->is_number_integer()) return false;
  out = it->get<std::int64_t>();
  return out >= 0;
}

// Every bufferView inside its buffer, every image's bufferView in range: tinygltf takes the
// address of an image's first byte without checking it (`&data[byteOffset]`).
status check_buffer_views(const gltf_document& doc) {
  const std::string& p = doc.path;
  const nlohmann::json& j = doc.json;
  const auto buffers = j.find("buffers");
  const auto views = j.find("bufferViews");
  const std::size_t buffer_count = buffers != j.end() && buffers->is_array() ? buffers->size() : 0;
  const std::size_t view_count = views != j.end() && views->is_array() ? views->size() : 0;
  for (std::size_t i = 0; i < view_count; ++i) {
    const nlohmann::json& v = (*views)[i];
    const std::string where = "bufferViews[" + std::to_string(i) + "]";
    std::int64_t b = -1, offset = 0, length = -1, buffer_length = -1;
    if (!v.is_object() || !size_member(v, "buffer", -1, b) || b < 0 ||
        static_cast<std::size_t>(b) >= buffer_count)
      return status::parse_error(p + ": " + where + " names no buffer of the file's " +
                                 std::to_string(buffer_count));
    if (!size_member(v, "byteOffset", 0, offset) || !size_member(v, "byteLength", -1, length) ||
        length < 0)
      return status::parse_error(p + ": " + where + " has no valid byteOffset/byteLength");
    const nlohmann::json& buffer = (*buffers)[static_cast<std::size_t>(b)];
    if (!buffer.is_object() || !size_member(buffer, "byteLength", -1, buffer_length) ||
        buffer_length < 0)
      return status::parse_error(p + ": buffers[" + std::to_string(b) +
                                 "] has no valid byteLength");
    if (offset + length > buffer_length)
      return status::parse_error(p + ": " + where + " (bytes " + std::to_string(offset) + " to " +
                                 std::to_string(offset + length) + ") lies outside buffers[" +
                                 std::to_string(b) + "] (" + std::to_string(buffer_length) +
                                 " bytes); the file is damaged");
  }
  const auto images = j.find("images");
  if (images != j.end() && images->is_array()) {
    for (std::size_t i = 0; i < images->size(); ++i) {
      const nlohmann::json& image = (*images)[i];
      if (!image.is_object() || !image.contains("bufferView")) continue;
      std::int64_t v = -1;
      if (!size_member(image, "bufferView", -1, v) || static_cast<std::size_t>(v) >= view_count)
        return status::parse_error(p + ": images[" + std::to_string(i) +
                                   "].bufferView names no bufferView of the file's " +
                                   std::to_string(view_count));
    }
  }
  return {};
}

// ---- base64 (data: URIs) ---------------------------------------------------------------------

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;  // '-' and '_': the URL-safe alphabet
  if (c == '/' || c == '_') return 63;
  return -1;
}

bool base64_decode(std::string_view in, std::string& out) {
  out.clear();
  out.reserve(in.size() / 4 * 3 + 3);
  std::uint32_t acc = 0;
  int bits = 0;
  std::size_t i = 0;
  for (; i < in.size() && in[i] != '='; ++i) {
    const int v = base64_value(in[i]);
    if (v < 0) return false;
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  for (; i < in.size(); ++i)
    if (in[i] != '=') return false;  // only padding after the first '='
  return true;
}

// ---- tinygltf's callbacks ------------------------------------------------------------------

struct fs_context {
  const gltf_document* doc = nullptr;
  std::uint64_t total_read = 0;
  std::string refusal;  // first URI refused by our rules (fails the load even if tinygltf
                        // would only warn, as it does for images)
  std::string missing;  // first file not found (reported if tinygltf fails)
};

bool strip_root(const std::string& path, std::string& relative) {
  const std::string prefix = k_root_marker + "/";
  if (path.compare(0, prefix.size(), prefix) != 0) return false;
  relative = path.substr(prefix.size());
  return true;
}

bool fs_resolve(fs_context& c, const std::string& path, std::string& file) {
  std::string relative;
  if (!strip_root(path, relative)) return false;
  // A data: URI tinygltf does not recognise (e.g. data:image/webp) reaches us as a "file";
  // it is no file of ours. Images are optional to tinygltf, so the load goes on.
  if (starts_with_nocase(relative, "data:")) return false;
  bool missing = false;
  status s = resolve_relative(*c.doc, relative, c.doc->path + ": external file " + shown(relative),
                              file, missing);
  if (s) return true;
  std::string& slot = missing ? c.missing : c.refusal;
  if (slot.empty()) slot = s.message();
  return false;
}

bool fs_exists(const std::string& path, void* user) {
  try {
    std::string file;
    return fs_resolve(*static_cast<fs_context*>(user), path, file);
  } catch (...) {
    return false;
  }
}

std::string fs_expand(const std::string& path, void*) { return path; }

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path,
             void* user) {
  try {
    fs_context& c = *static_cast<fs_context*>(user);
    std::string file;
    if (!fs_resolve(c, path, file)) {
      if (err) *err = "refused";
      return false;
    }
    const gltf_limits& l = c.doc->limits;
    const std::uint64_t left =
        l.max_total_resource_bytes > c.total_read ? l.max_total_resource_bytes - c.total_read : 0;
    std::string bytes;
    status s = read_regular_file(file, c.doc->path + ": external file " + shown(file),
                                 std::min(l.max_resource_bytes, left), true, bytes);
    if (!s) {
      if (c.refusal.empty()) c.refusal = s.message();
      if (err) *err = "refused";
      return false;
    }
    c.total_read += bytes.size();
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (...) {
    if (err) *err = "out of memory";
    return false;
  }
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed while reading";
  return false;
}

// The skeleton and the animation need no pixels, and decoding a stranger's image is a risk
// of its own: keep tinygltf from decoding anything.
bool keep_no_pixels(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                    const unsigned char*, int, void*) {
  return true;
}

// tinygltf's error text: without our root marker, one line per problem, bounded (it may quote
// a whole data: URI).
std::string tidy_tinygltf_error(std::string err, const gltf_document& doc) {
  for (std::size_t at; (at = err.find(k_root_marker)) != std::string::npos;)
    err.replace(at, k_root_marker.size(), doc.folder);
  while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
  for (char& c : err)
    if (c == '\n') c = ';';
  return printable(err, 400);
}

}  // namespace

status open_gltf_document(const std::string& path, gltf_document& out, const gltf_limits& limits) {
  out = gltf_document{};
  out.path = path;
  out.limits = limits;
  if (status s = read_regular_file(path, path, limits.max_file_bytes, false, out.bytes); !s)
    return s;
  if (out.bytes.empty()) return status::parse_error(path + ": the file is empty, not a glTF file");
  {
    char* real = ::realpath(folder_of(path).c_str(), nullptr);
    if (real == nullptr)
      return status::io_error(path + ": cannot resolve the file's folder: " + std::strerror(errno));
    out.folder = real;
    std::free(real);
  }
  out.binary = out.bytes.compare(0, 4, "glTF") == 0;
  if (out.binary) {
    if (status s = split_glb(out); !s) return s;
  } else {
    std::size_t start = 0;
    if (out.bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) start = 3;  // UTF-8 byte order mark
    while (start < out.bytes.size() && (out.bytes[start] == ' ' || out.bytes[start] == '\t' ||
                                        out.bytes[start] == '\n' || out.bytes[start] == '\r'))
      ++start;
    if (start >= out.bytes.size() || out.bytes[start] != '{')
      return status::parse_error(
          path +
          ": not a glTF file (neither binary glTF, which starts with 'glTF', "
          "nor a JSON object)");
    out.json_offset = start;
    out.json_size = out.bytes.size() - start;
  }
  if (status s = parse_json(out); !s) return s;
  if (status s = check_buffer_views(out); !s) return s;
  return check_all_uris(out);
}

status parse_gltf_model(const gltf_document& doc, tinygltf::Model& out) {
  out = tinygltf::Model{};
  fs_context context;
  context.doc = &doc;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_no_pixels, nullptr);
  tinygltf::FsCallbacks fs{};
  fs.FileExists = &fs_exists;
  fs.ExpandFilePath = &fs_expand;
  fs.ReadWholeFile = &fs_read;
  fs.WriteWholeFile = &fs_write;
  fs.user_data = &context;
  loader.SetFsCallbacks(fs);
  std::string err, warn;
  bool ok = false;
  try {
    const std::string_view text = doc.json_text();
    ok = doc.binary
             ? loader.LoadBinaryFromMemory(
                   &out, &err, &warn, reinterpret_cast<const unsigned char*>(doc.bytes.data()),
                   static_cast<unsigned int>(doc.bytes.size()), k_root_marker)
             : loader.LoadASCIIFromString(&out, &err, &warn, text.data(),
                                          static_cast<unsigned int>(text.size()), k_root_marker);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception&) {
    ok = false;
  }
  if (!context.refusal.empty()) return status::parse_error(context.refusal);
  if (!ok) {
    if (!context.missing.empty()) return status::io_error(context.missing);
    return status::parse_error(
        doc.path + ": not valid glTF 2.0" +
        (err.empty() ? std::string(" (the glTF reader gave no reason)")
                     : ": " + tidy_tinygltf_error(err, doc)) +
        "; export the file again or check it with the Khronos glTF Validator");
  }
  return {};
}

status read_gltf_uri(const gltf_document& doc, const std::string& uri, const std::string& where,
                     std::uint64_t& total_read, std::string& out, bool* out_missing) {
  out.clear();
  bool is_data = false, missing = false;
  std::string file;
  if (out_missing) *out_missing = false;
  if (status s = check_uri(doc, uri, where, is_data, file, missing); !s) {
    if (out_missing) *out_missing = missing;
    return s;
  }
  const gltf_limits& l = doc.limits;
  const std::uint64_t left =
      l.max_total_resource_bytes > total_read ? l.max_total_resource_bytes - total_read : 0;
  if (is_data) {
    const std::size_t comma = uri.find(";base64,");
    if (!base64_decode(std::string_view(uri).substr(comma + 8), out))
      return status::parse_error(doc.path + ": " + where +
                                 ": the data: URI's base64 text is malformed");
    if (out.size() > left)
      return status::parse_error(doc.path + ": " + where + ": the data goes past the limit of " +
                                 std::to_string(l.max_total_resource_bytes) +
                                 " bytes read per file");
  } else {
    if (status s = read_regular_file(file, doc.path + ": " + where + " " + shown(uri),
                                     std::min(l.max_resource_bytes, left), true, out);
        !s)
      return s;
  }
  total_read += out.size();
  return {};
}

std::string sniff_image_mime_type(std::string_view b) {
  auto at = [&](std::size_t offset, std::string_view magic) {
    return b.size() >= offset + magic.size() && b.substr(offset, magic.size()) == magic;
  };
  if (at(0, "\x89PNG\r\n\x1a\n")) return "image/png";
  if (at(0, "\xFF\xD8\xFF")) return "image/jpeg";
  if (at(0, "RIFF") && at(8, "WEBP")) return "image/webp";
  if (at(0, "\xABKTX 20\xBB\r\n\x1a\n")) return "image/ktx2";
  if (at(4, "ftypavif") || at(4, "ftypavis")) return "image/avif";
  if (at(0, "DDS ")) return "image/vnd-ms.dds";
  if (at(0, "GIF87a") || at(0, "GIF89a")) return "image/gif";
  if (at(0, "BM")) return "image/bmp";
  return {};
}

}  // namespace avatarmap::gltf_detail
