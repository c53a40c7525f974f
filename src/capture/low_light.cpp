// Dim, low-contrast model inputs lifted (include/avatarmap/capture/low_light.hpp).
#include "avatarmap/capture/low_light.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace avatarmap {

namespace {

constexpr int k_bins = 1024;

// The first tensor row / column inside the letterbox bands and one past the last.
struct pixel_box {
  int x0, y0, x1, y1;
};
pixel_box unpadded(const crop_options& o, const crop_transform& t) {
  const int w = o.output_width, h = o.output_height;
  pixel_box b{static_cast<int>(std::ceil(t.letterbox_padding[0] * static_cast<float>(w))),
              static_cast<int>(std::ceil(t.letterbox_padding[1] * static_cast<float>(h))),
              w - static_cast<int>(std::ceil(t.letterbox_padding[2] * static_cast<float>(w))),
              h - static_cast<int>(std::ceil(t.letterbox_padding[3] * static_cast<float>(h)))};
  b.x0 = std::clamp(b.x0, 0, w);
  b.x1 = std::clamp(b.x1, b.x0, w);
  b.y0 = std::clamp(b.y0, 0, h);
  b.y1 = std::clamp(b.y1, b.y0, h);
  return b;
}

}  // namespace

float lift_low_light(float* tensor, const crop_options& options, const crop_transform& transform,
                     const low_light_options& lift) {
  if (tensor == nullptr || !(lift.target_range > 0.f) || !(lift.max_gain > 1.f)) return 1.f;
  const float lo_v = options.range_min, span = options.range_max - options.range_min;
  if (!(span > 0.f)) return 1.f;
  const pixel_box b = unpadded(options, transform);
  if (b.x1 <= b.x0 || b.y1 <= b.y0) return 1.f;
  const int w = options.output_width;
  // The histogram of every other pixel of every other row (a quarter of the cost; the
  // percentiles of a picture barely move).
  std::array<std::uint32_t, k_bins> hist{};
  long count = 0;
  for (int y = b.y0; y < b.y1; y += 2) {
    const float* p = tensor + (static_cast<long>(y) * w + b.x0) * 3;
    for (int x = b.x0; x < b.x1; x += 2, p += 6) {
      const float luma = ((0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2]) - lo_v) / span;
      const int bin = static_cast<int>(std::clamp(luma, 0.f, 1.f) * (k_bins - 1) + 0.5f);
      ++hist[static_cast<std::size_t>(bin)];
      ++count;
    }
  }
  // The 1st and 99th percentiles (bin centres).
  const long lo_rank = count / 100, hi_rank = count - 1 - count / 100;
  long seen = 0;
  int lo_bin = -1, hi_bin = k_bins - 1;
  for (int i = 0; i < k_bins; ++i) {
    seen += hist[static_cast<std::size_t>(i)];
    if (lo_bin < 0 && seen > lo_rank) lo_bin = i;
    if (seen > hi_rank) {
      hi_bin = i;
      break;
    }
  }
  const float lo = static_cast<float>(lo_bin) / (k_bins - 1);
  const float hi = static_cast<float>(hi_bin) / (k_bins - 1);
  const float range = std::max(hi - lo, 1.f / (k_bins - 1));
  const float gain = std::clamp(lift.target_range / range, 1.f, lift.max_gain);
  if (!(gain > 1.f)) return 1.f;
  const float m = 0.5f * (lo + hi);
  const float m2 = m + (0.5f - m) * (1.f - 1.f / gain);
  // v' = ((v - lo_v) / span - m) * gain + m2, back in the input's range: one multiply-add.
  const float a = gain;
  const float c = lo_v + span * m2 - gain * (lo_v + span * m);
  const float vmin = options.range_min, vmax = options.range_max;
  for (int y = b.y0; y < b.y1; ++y) {
    float* p = tensor + (static_cast<long>(y) * w + b.x0) * 3;
    for (int x = 3 * b.x0; x < 3 * b.x1; ++x, ++p) *p = std::clamp(a * *p + c, vmin, vmax);
  }
  return gain;
}

}  // namespace avatarmap
