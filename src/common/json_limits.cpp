#include "common/json_limits.hpp"

namespace avatarmap::io_detail {

status check_json_limits(std::string_view text, const std::string& what,
                         const json_limits& limits) {
  if (text.size() > limits.max_bytes) {
    return status::parse_error(what + ": JSON text is " + std::to_string(text.size()) +
                               " bytes, more than the limit of " +
                               std::to_string(limits.max_bytes) +
                               " bytes; not a file this program reads (is it the right file?)");
  }
  // One pass, no allocation: only brackets outside strings count, so a name like "[[[" or an
  // escaped quote inside a string cannot push the depth. Unbalanced closers are left to the
  // parser (its message is better); the depth is clamped at 0 so they cannot hide openers.
  int depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    switch (c) {
      case '"':
        in_string = true;
        break;
      case '[':
      case '{':
        if (++depth > limits.max_depth) {
          return status::parse_error(
              what + ": JSON nests deeper than " + std::to_string(limits.max_depth) +
              " levels (at byte " + std::to_string(i) +
              "); not a valid file of this kind, or an extension/extras value "
              "that cannot be read: remove the deep value or use another file");
        }
        break;
      case ']':
      case '}':
        if (depth > 0) --depth;
        break;
      default:
        break;
    }
  }
  return {};
}

}  // namespace avatarmap::io_detail
