// Internal: limits checked on JSON text before any parser that recurses per nesting level
// (tinygltf's conversion of extras/extensions, nlohmann's value tree) sees it, so a hostile
// file gets an error instead of a stack overflow or an unbounded allocation.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap::io_detail {

struct json_limits {
  /// Deepest nesting of arrays/objects accepted ({"a":[1]} has depth 2).
  int max_depth = 128;
  /// Largest JSON text accepted, in bytes.
  std::size_t max_bytes = std::size_t{256} << 20;
};

/// Scans `text` (strings and escapes honoured; not a full validation) and fails when it nests
/// deeper or is larger than `limits`. The message starts with `what` (usually the file name)
/// and names the limit and what to do: "FILE: JSON nests deeper than 128 levels (at byte
/// 4711); not a valid avatar/mapping, or an extension that cannot be read". Its code is
/// status_code::parse (the content is not one this program reads).
status check_json_limits(std::string_view text, const std::string& what,
                         const json_limits& limits = {});

}  // namespace avatarmap::io_detail
