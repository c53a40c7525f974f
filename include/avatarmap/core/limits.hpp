// The limits every edge checks against (the CLI's flags, the library's validate(), the C API's
// documented ranges, the Python package), each written once here. The C header repeats the
// ones its callers need as AVM_* macros; bindings/c/src/c_info.cpp checks that they are equal,
// and tests/python/test_options.py checks the Python package's copies.
#pragma once

#include <cstdio>
#include <string>

namespace avatarmap {

/// The highest frame rate anything accepts, frames per second: resampled outputs (solve --fps,
/// convert --fps, clip_output_job::fps, avm_clip_write), live output rates, synthetic
/// recordings, video files written and the frame rate asked of a device. Rates are in
/// (0, k_max_fps]; where 0 has a meaning of its own (one pose per input frame, the device's
/// default) the field says so. A millisecond per frame is already finer than any camera or
/// display; the bound keeps times and frame counts far from overflow.
inline constexpr double k_max_fps = 1000.0;

/// The most threads an estimator's models may use (--threads, avm_estimator_options.threads).
inline constexpr int k_max_model_threads = 64;

/// A limit as messages print it: "1000", "0.5", "64".
inline std::string limit_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace avatarmap
