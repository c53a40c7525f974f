#include "capture/input_spec.hpp"

#include <cctype>
#include <cstddef>

namespace avatarmap {

namespace {

bool is_alpha(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }
bool is_alnum(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

input_spec classify_input(const std::string& text, bool exists) {
  input_spec r;
  r.target = text;
  if (exists) return r;
  if (text.compare(0, 5, "file:") == 0) {
    r.target = text.substr(5);
    r.kind = r.target.find('%') != std::string::npos ? input_kind::pattern : input_kind::path;
    return r;
  }
  // RFC 3986's scheme: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ).
  std::size_t i = 0;
  if (!text.empty() && is_alpha(text[0])) {
    i = 1;
    while (i < text.size() &&
           (is_alnum(text[i]) || text[i] == '+' || text[i] == '-' || text[i] == '.'))
      ++i;
    if (text.compare(i, 3, "://") == 0) {
      r.kind = input_kind::url;
      r.name = lower(text.substr(0, i));
      r.target = r.name + text.substr(i);
      return r;
    }
  }
  // An FFmpeg format name: letters, digits and '_' ("v4l2", "x11grab", "video4linux2").
  i = 0;
  while (i < text.size() && (is_alnum(text[i]) || text[i] == '_')) ++i;
  if (i >= 2 && i < text.size() && text[i] == ':') {
    r.kind = input_kind::device;
    r.name = text.substr(0, i);
    r.target = text.substr(i + 1);
    return r;
  }
  if (text.find('%') != std::string::npos) r.kind = input_kind::pattern;
  return r;
}

}  // namespace avatarmap
