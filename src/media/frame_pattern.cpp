#include "media/frame_pattern.hpp"

#include <cctype>
#include <cstddef>

namespace avatarmap {

bool parse_frame_pattern(const std::string& path, std::string& out_prefix, std::string& out_suffix,
                         int& out_width) {
  std::string text;
  bool found = false;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] != '%') {
      text += path[i];
      continue;
    }
    if (i + 1 < path.size() && path[i + 1] == '%') {
      text += '%';
      ++i;
      continue;
    }
    if (found) return false;  // a second conversion
    std::size_t j = i + 1;
    int width = 0;
    bool zero = false;
    if (j < path.size() && path[j] == '0') {
      zero = true;
      ++j;
    }
    const std::size_t digits_begin = j;
    while (j < path.size() && std::isdigit(static_cast<unsigned char>(path[j])) &&
           j - digits_begin < 2)
      width = width * 10 + (path[j++] - '0');
    if (j >= path.size() || path[j] != 'd') return false;
    if (zero && width == 0) return false;
    out_prefix = text;
    text.clear();
    out_width = width;
    found = true;
    i = j;
  }
  out_suffix = text;
  return found;
}

}  // namespace avatarmap
