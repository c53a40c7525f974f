// Printf-style frame name patterns ("frames/%05d.png"), shared by the video source (reading
// image sequences) and the video writer (writing one PNG per frame). Internal to src/capture.
#pragma once

#include <string>

namespace avatarmap {

/// Splits a path with exactly one %d or %0Nd conversion (N up to two digits; "%%" is a
/// literal '%', returned as '%'). On success `out_prefix`/`out_suffix` surround the number
/// and `out_width` is N (0: none). False for no conversion, two, or a malformed one.
bool parse_frame_pattern(const std::string& path, std::string& out_prefix, std::string& out_suffix,
                         int& out_width);

}  // namespace avatarmap
