// Internal: reading a whole JSON document (mapping tables, the tfjs recordings) with nlohmann,
// safely and in our words: the depth and size limits of json_limits.hpp are checked before
// nlohmann builds its value tree (which recurses per level), and a syntax error becomes
// "FILE: invalid JSON at line L, column C: what is wrong" instead of the library's
// "[json.exception.parse_error.101] ..." text. No exception leaves these functions.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"
#include "common/json_limits.hpp"

namespace avatarmap::io_detail {

/// Parses `text` into `out` (null on failure). Fails, with a message starting with `what`
/// (usually the file name), when the text breaks `limits` (nesting, size), is not valid JSON
/// (naming the line and column and the token: unexpected character, unclosed string or
/// bracket, a number beyond a double's range, a bad \u escape): status_code::parse, or memory
/// runs out: status_code::out_of_memory.
status parse_json_text(std::string_view text, const std::string& what, nlohmann::json& out,
                       const json_limits& limits = {});

/// Reads the file at `path` and parses it as parse_json_text() does, `path` naming the file in
/// messages. A file larger than limits.max_bytes is refused before it is read. Codes: io (the
/// file cannot be opened or read: "PATH: cannot read the file"), parse (too large, too deep,
/// not valid JSON), out_of_memory.
status read_json_file(const std::string& path, nlohmann::json& out, const json_limits& limits = {});

/// "a number", "a string", "an object", "an array", "true or false", "null": what a value is,
/// for messages such as "expected a string, got a number".
const char* json_type_text(const nlohmann::json& v);

}  // namespace avatarmap::io_detail
