// File extensions compared as the jobs, `render` and `view` compare them (clip_output's
// formats, convert_file's inputs, videos): without regard to ASCII case.
#pragma once

#include <cstddef>
#include <string_view>

namespace avatarmap::jobs_detail {

/// True when `s` ends with `suffix`, compared without regard to ASCII case; `suffix` is given
/// in lower case (".pose.jsonl").
inline bool ends_with_nocase(std::string_view s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  const std::string_view tail = s.substr(s.size() - suffix.size());
  for (std::size_t i = 0; i < suffix.size(); ++i) {
    const char c = tail[i];
    const char lower = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
    if (lower != suffix[i]) return false;
  }
  return true;
}

}  // namespace avatarmap::jobs_detail
