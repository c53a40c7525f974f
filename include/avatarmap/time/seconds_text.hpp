// Short text for a time or a duration in seconds, for messages and summaries. Times come from
// files a user may not trust: "%.2f" of 1.7e308 prints 300 digits, so every message that shows
// a time goes through here.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace avatarmap {

/// `seconds` with `decimals` (0..9) fixed decimals while |seconds| < 1e9, else in exponent form
/// with 6 significant digits ("1.7e+308"); "nan", "inf" or "-inf" when not finite. No unit.
/// Never longer than 20 characters.
inline std::string seconds_text(double seconds, int decimals = 3) {
  char buf[48];
  if (decimals < 0) decimals = 0;
  if (decimals > 9) decimals = 9;
  if (std::isfinite(seconds) && std::fabs(seconds) < 1e9)
    std::snprintf(buf, sizeof buf, "%.*f", decimals, seconds);
  else
    std::snprintf(buf, sizeof buf, "%.6g", seconds);
  return buf;
}

}  // namespace avatarmap
