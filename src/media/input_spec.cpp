#include "media/input_spec.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>

#include "avatarmap/media/video_source.hpp"  // shown_input

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

std::string shown_input(const std::string& text) {
  const std::size_t scheme_end = text.find("://");
  if (scheme_end == std::string::npos) return text;
  const std::size_t start = scheme_end + 3;
  // The authority ends at the first '/', '?' or '#'; credentials are what precede its last '@'.
  const std::size_t end = std::min(text.find_first_of("/?#", start), text.size());
  const std::size_t at = text.rfind('@', end == 0 ? 0 : end - 1);
  if (at == std::string::npos || at < start) return text;
  const std::size_t colon = text.find(':', start);
  const std::size_t user_end = colon != std::string::npos && colon < at ? colon + 1 : start;
  return text.substr(0, user_end) + "***" + text.substr(at);
}

}  // namespace avatarmap
