// Dim, low-contrast model inputs lifted before a model sees them (estimator_options::low_light).
//
// Google's models were trained on well-exposed photos: on a dark or washed-out image (a room at
// night, a person in shadow, fog) the pose detector's score falls under its threshold although
// the person is plain to see once the levels are stretched, and the landmark models drift. So
// each model input (a crop, image_crop.hpp) whose luma spans a narrow range is stretched: with
// lo and hi the 1st and 99th percentiles of its luma (0.299 R + 0.587 G + 0.114 B, the input's
// range mapped to [0, 1]; every other pixel of every other row, letterbox bands left out) and
// r = hi - lo,
//
//   gain = clamp(target_range / r, 1, max_gain)
//   v'   = (v - m) * gain + m + (0.5 - m) * (1 - 1 / gain),   m = (lo + hi) / 2,
//
// per channel, clamped to the input's range. The gain is 1 (the input untouched, bit for bit)
// for any input whose range is at least target_range, and grows continuously as the range
// shrinks; the middle moves toward mid-grey as the gain grows. Every shared photo and video
// spans a luma range of 0.33 or more, so none of them is touched (docs/capture.md "Low light").
// Memory: a histogram on the stack; nothing allocated.
#pragma once

#include "avatarmap/capture/image_crop.hpp"

namespace avatarmap {

struct low_light_options {
  float target_range = 0.3f;  // luma range (p99 - p1, of [0, 1]) below which an input is lifted
  float max_gain = 8.0f;      // at most this stretch (noise grows with it)
};

/// The options every pipeline lifts with (estimator_options::low_light on).
inline constexpr low_light_options k_low_light{};

/// Lifts the crop `tensor` (W x H x 3 floats in [options.range_min, options.range_max], as
/// image_crop_job writes it; `transform` its geometry, for the letterbox bands) in place as the
/// header says. Returns the gain applied (1: untouched).
float lift_low_light(float* tensor, const crop_options& options, const crop_transform& transform,
                     const low_light_options& lift = {});

}  // namespace avatarmap
