#include "avatarmap/capture/image_crop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace avatarmap {
namespace {

constexpr double k_pi = 3.14159265358979323846;
// OpenCV's INTER_BITS: source positions are rounded to 1/32 pixel before interpolation.
constexpr int k_sub_bits = 5;
constexpr double k_sub_scale = 1 << k_sub_bits;
constexpr int k_sub_mask = (1 << k_sub_bits) - 1;
// Products of two 5-bit weights sum to 1024; OpenCV's 15-bit weights are these times 32, and
// (32 * s + 2^14) >> 15 == (s + 2^9) >> 10, so the shorter form is bit-identical.
constexpr int k_weight_bits = 2 * k_sub_bits;
constexpr int k_weight_round = 1 << (k_weight_bits - 1);
// ROIs reaching further than this from the origin (pixels) are rejected, which keeps every
// sample position * 32 within int range without a per-pixel clamp.
constexpr double k_coord_limit = static_cast<double>(1 << 24);
constexpr int k_floor_offset_int = 1 << 26;
constexpr double k_floor_offset = k_floor_offset_int;

bool finite(float v) { return std::isfinite(v); }

// Per-call constants of the warp, shared by every row.
struct warp_args {
  const std::uint8_t* data;
  const std::uint8_t* end;  // one past the image's last byte
  std::ptrdiff_t stride;
  int width;
  int height;
  int out_width;
  int out_height;
  double m[6];  // tensor pixel -> source pixel
  float scale;
  float offset;
  float* out;
};

// One kernel per (layout, border) pair, chosen once per call: no per-pixel dispatch. k_r, k_g,
// k_b are the byte offsets of the channels within a pixel (all 0 for gray).
template <int k_bpp, int k_r, int k_g, int k_b, bool k_zero_border>
void warp(const warp_args& a) {
  static const std::uint8_t k_zero_pixel[4] = {0, 0, 0, 0};
  const double m0 = a.m[0], m1 = a.m[1], m2 = a.m[2], m3 = a.m[3], m4 = a.m[4], m5 = a.m[5];
  const unsigned inner_w = static_cast<unsigned>(a.width - 1);
  const unsigned inner_h = static_cast<unsigned>(a.height - 1);
  const float scale = a.scale, offset = a.offset;
  float* out = a.out;

  for (int y = 0; y < a.out_height; ++y) {
    // Row start; the per-pixel step is m0 / m3 (OpenCV evaluates start + step * x in double
    // and rounds to 1/32 pixel, as here).
    const double row_x = m1 * y + m2;
    const double row_y = m4 * y + m5;
    for (int x = 0; x < a.out_width; ++x, out += 3) {
      const int ix = static_cast<int>(std::lrint((row_x + m0 * x) * k_sub_scale));
      const int iy = static_cast<int>(std::lrint((row_y + m3 * x) * k_sub_scale));
      const int sx = ix >> k_sub_bits;
      const int sy = iy >> k_sub_bits;
      const int ax = ix & k_sub_mask;
      const int ay = iy & k_sub_mask;
      const int w00 = (32 - ax) * (32 - ay);
      const int w01 = ax * (32 - ay);
      const int w10 = (32 - ax) * ay;
      const int w11 = ax * ay;

      const std::uint8_t *p00, *p01, *p10, *p11;
      if (static_cast<unsigned>(sx) < inner_w && static_cast<unsigned>(sy) < inner_h) {
        p00 = a.data + sy * a.stride + sx * k_bpp;
        p01 = p00 + k_bpp;
        p10 = p00 + a.stride;
        p11 = p10 + k_bpp;
      } else if (k_zero_border) {
        if (sx >= a.width || sx + 1 < 0 || sy >= a.height || sy + 1 < 0) {
          out[0] = out[1] = out[2] = offset;
          continue;
        }
        const bool x0_in = sx >= 0, x1_in = sx + 1 < a.width;
        const bool y0_in = sy >= 0, y1_in = sy + 1 < a.height;
        // Pointers are formed only for neighbours inside the image.
        const auto at = [&](int px, int py) { return a.data + py * a.stride + px * k_bpp; };
        p00 = x0_in && y0_in ? at(sx, sy) : k_zero_pixel;
        p01 = x1_in && y0_in ? at(sx + 1, sy) : k_zero_pixel;
        p10 = x0_in && y1_in ? at(sx, sy + 1) : k_zero_pixel;
        p11 = x1_in && y1_in ? at(sx + 1, sy + 1) : k_zero_pixel;
      } else {
        const int x0 = std::clamp(sx, 0, a.width - 1), x1 = std::clamp(sx + 1, 0, a.width - 1);
        const int y0 = std::clamp(sy, 0, a.height - 1), y1 = std::clamp(sy + 1, 0, a.height - 1);
        const std::uint8_t* r0 = a.data + y0 * a.stride;
        const std::uint8_t* r1 = a.data + y1 * a.stride;
        p00 = r0 + x0 * k_bpp;
        p01 = r0 + x1 * k_bpp;
        p10 = r1 + x0 * k_bpp;
        p11 = r1 + x1 * k_bpp;
      }

      const auto sample = [&](int c) {
        const int s = w00 * p00[c] + w01 * p01[c] + w10 * p10[c] + w11 * p11[c];
        return static_cast<float>((s + k_weight_round) >> k_weight_bits) * scale + offset;
      };
      if constexpr (k_bpp == 1) {
        out[0] = out[1] = out[2] = sample(0);
      } else {
        out[0] = sample(k_r);
        out[1] = sample(k_g);
        out[2] = sample(k_b);
      }
    }
  }
}

#if defined(__SSE2__)
// Four bytes from `p` as four floats.
inline __m128 load4(const std::uint8_t* p) {
  std::int32_t bytes;
  std::memcpy(&bytes, p, 4);
  const __m128i zero = _mm_setzero_si128();
  const __m128i b = _mm_cvtsi32_si128(bytes);
  return _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_unpacklo_epi8(b, zero), zero));
}
#endif

// The OpenGL converter's sampling (crop_sampling::gl): `a.m` already maps pixel centres
// (tensor x + 0.5 -> image position, pixel i's centre at i), bilinear weights in float, no
// rounding to 8 bits.
template <int k_bpp, int k_r, int k_g, int k_b, bool k_zero_border>
void warp_gl(const warp_args& a) {
  const double m0 = a.m[0], m1 = a.m[1], m2 = a.m[2], m3 = a.m[3], m4 = a.m[4], m5 = a.m[5];
  const int last_x = a.width - 1, last_y = a.height - 1;
  // MediaPipe's zero-border shader tests the texture coordinate against [0, 1]: positions
  // beyond the outer edge of the edge pixels.
  const double lo = -0.5, hi_x = a.width - 0.5, hi_y = a.height - 0.5;
  const float scale = a.scale, offset = a.offset;
  float* out = a.out;

  for (int y = 0; y < a.out_height; ++y) {
    const double row_x = m1 * y + m2;
    const double row_y = m4 * y + m5;
    for (int x = 0; x < a.out_width; ++x, out += 3) {
      const double px = row_x + m0 * x;
      const double py = row_y + m3 * x;
      if (k_zero_border && (px < lo || px > hi_x || py < lo || py > hi_y)) {
        out[0] = out[1] = out[2] = offset;
        continue;
      }
      // floor() by truncating a positive number: positions are bounded by k_coord_limit, so
      // adding twice that keeps them positive and in int range (and avoids a libm call).
      const int sx = static_cast<int>(px + k_floor_offset) - k_floor_offset_int;
      const int sy = static_cast<int>(py + k_floor_offset) - k_floor_offset_int;
      const float ax = static_cast<float>(px - sx), ay = static_cast<float>(py - sy);
      const int x0 = std::clamp(sx, 0, last_x), x1 = std::clamp(sx + 1, 0, last_x);
      const int y0 = std::clamp(sy, 0, last_y), y1 = std::clamp(sy + 1, 0, last_y);
      const std::uint8_t* r0 = a.data + y0 * a.stride;
      const std::uint8_t* r1 = a.data + y1 * a.stride;
      const std::uint8_t* p00 = r0 + x0 * k_bpp;
      const std::uint8_t* p01 = r0 + x1 * k_bpp;
      const std::uint8_t* p10 = r1 + x0 * k_bpp;
      const std::uint8_t* p11 = r1 + x1 * k_bpp;
      const float w00 = (1.f - ax) * (1.f - ay), w01 = ax * (1.f - ay);
      const float w10 = (1.f - ax) * ay, w11 = ax * ay;
#if defined(__SSE2__)
      // Three or four channels at once: each pixel's bytes as four floats, the same products
      // and sums in the same order as the scalar code below (bit-identical results). A
      // pixel's fourth byte (the next pixel's first, for RGB) is read only where the image has
      // one; the lane it lands in is never stored.
      if constexpr (k_bpp >= 3) {
        if (p11 + 4 <= a.end && p01 + 4 <= a.end) {
          const __m128 v =
              _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(w00), load4(p00)),
                                               _mm_mul_ps(_mm_set1_ps(w01), load4(p01))),
                                    _mm_mul_ps(_mm_set1_ps(w10), load4(p10))),
                         _mm_mul_ps(_mm_set1_ps(w11), load4(p11)));
          alignas(16) float c[4];
          _mm_store_ps(c, _mm_add_ps(_mm_mul_ps(v, _mm_set1_ps(scale)), _mm_set1_ps(offset)));
          out[0] = c[k_r];
          out[1] = c[k_g];
          out[2] = c[k_b];
          continue;
        }
      }
#endif
      const auto sample = [&](int c) {
        const float v = w00 * p00[c] + w01 * p01[c] + w10 * p10[c] + w11 * p11[c];
        return v * scale + offset;
      };
      if constexpr (k_bpp == 1) {
        out[0] = out[1] = out[2] = sample(0);
      } else {
        out[0] = sample(k_r);
        out[1] = sample(k_g);
        out[2] = sample(k_b);
      }
    }
  }
}

// The kernel for a sampling (k_gl: warp_gl, else warp), layout and border.
template <bool k_gl, int k_bpp, int k_r, int k_g, int k_b, bool k_zero_border>
void warp_kernel(const warp_args& a) {
  if constexpr (k_gl)
    warp_gl<k_bpp, k_r, k_g, k_b, k_zero_border>(a);
  else
    warp<k_bpp, k_r, k_g, k_b, k_zero_border>(a);
}

template <bool k_gl, bool k_zero_border>
void warp_any(pixel_format f, const warp_args& a) {
  switch (f) {
    case pixel_format::rgb8:
      return warp_kernel<k_gl, 3, 0, 1, 2, k_zero_border>(a);
    case pixel_format::bgr8:
      return warp_kernel<k_gl, 3, 2, 1, 0, k_zero_border>(a);
    case pixel_format::rgba8:
      return warp_kernel<k_gl, 4, 0, 1, 2, k_zero_border>(a);
    case pixel_format::bgra8:
      return warp_kernel<k_gl, 4, 2, 1, 0, k_zero_border>(a);
    case pixel_format::gray8:
      return warp_kernel<k_gl, 1, 0, 0, 0, k_zero_border>(a);
  }
}

}  // namespace

bool make_crop_transform(int image_width, int image_height, const normalized_rect& roi,
                         const crop_options& options, crop_transform& out) {
  if (image_width <= 0 || image_height <= 0 || options.output_width <= 0 ||
      options.output_height <= 0) {
    return false;
  }
  if (!finite(roi.x_center) || !finite(roi.y_center) || !finite(roi.width) || !finite(roi.height) ||
      !finite(roi.rotation) || !(roi.width > 0.0f) || !(roi.height > 0.0f)) {
    return false;
  }
  // Single precision throughout, as MediaPipe's GetRoi / PadRoi and cv::RotatedRect compute
  // it: the source positions are rounded to 1/32 pixel, so the float rounding of the corners
  // decides a measurable number of samples.
  const float center_x = roi.x_center * static_cast<float>(image_width);
  const float center_y = roi.y_center * static_cast<float>(image_height);
  float width = roi.width * static_cast<float>(image_width);
  float height = roi.height * static_cast<float>(image_height);
  if (!(width > 0.0f) || !(height > 0.0f)) return false;

  std::array<float, 4> padding{};
  if (options.keep_aspect_ratio) {
    const float tensor_aspect =
        static_cast<float>(options.output_height) / static_cast<float>(options.output_width);
    const float roi_aspect = height / width;
    if (tensor_aspect > roi_aspect) {
      const float vertical = (1.0f - roi_aspect / tensor_aspect) / 2.0f;
      height = width * tensor_aspect;
      padding = {0.0f, vertical, 0.0f, vertical};
    } else {
      const float horizontal = (1.0f - tensor_aspect / roi_aspect) / 2.0f;
      width = height / tensor_aspect;
      padding = {horizontal, 0.0f, horizontal, 0.0f};
    }
  }

  // The ROI's corners as cv::boxPoints computes them (angle through degrees and back).
  const float angle_degrees = static_cast<float>(roi.rotation * 180.0f / k_pi);
  const double angle = angle_degrees * k_pi / 180.0;
  const float b = static_cast<float>(std::cos(angle)) * 0.5f;
  const float a = static_cast<float>(std::sin(angle)) * 0.5f;
  const float bottom_left_x = center_x - a * height - b * width;
  const float bottom_left_y = center_y + b * height - a * width;
  const float top_left_x = center_x + a * height - b * width;
  const float top_left_y = center_y - b * height - a * width;
  const float top_right_x = 2.0f * center_x - bottom_left_x;
  const float top_right_y = 2.0f * center_y - bottom_left_y;

  // Tensor corners (0, 0), (W, 0), (0, H) land on the top-left, top-right and bottom-left
  // corners of the ROI.
  const double tw = options.output_width;
  const double th = options.output_height;
  std::array<double, 6> m{};
  m[0] = (static_cast<double>(top_right_x) - top_left_x) / tw;
  m[1] = (static_cast<double>(bottom_left_x) - top_left_x) / th;
  m[2] = top_left_x;
  m[3] = (static_cast<double>(top_right_y) - top_left_y) / tw;
  m[4] = (static_cast<double>(bottom_left_y) - top_left_y) / th;
  m[5] = top_left_y;
  const double det = m[0] * m[4] - m[1] * m[3];
  for (double v : m) {
    if (!std::isfinite(v)) return false;
  }
  if (!std::isfinite(det) || det == 0.0) return false;
  // Every sample lies in the parallelogram spanned by the corners.
  for (const double tx : {0.0, tw}) {
    for (const double ty : {0.0, th}) {
      if (std::abs(m[0] * tx + m[1] * ty + m[2]) > k_coord_limit ||
          std::abs(m[3] * tx + m[4] * ty + m[5]) > k_coord_limit) {
        return false;
      }
    }
  }

  std::array<double, 6> inv{};
  inv[0] = m[4] / det;
  inv[1] = -m[1] / det;
  inv[3] = -m[3] / det;
  inv[4] = m[0] / det;
  inv[2] = -(inv[0] * m[2] + inv[1] * m[5]);
  inv[5] = -(inv[3] * m[2] + inv[4] * m[5]);

  out.to_image = m;
  out.to_tensor = inv;
  out.roi_center_x = center_x;
  out.roi_center_y = center_y;
  out.roi_width = width;
  out.roi_height = height;
  out.roi_rotation = roi.rotation;
  out.letterbox_padding = padding;
  out.image_width = image_width;
  out.image_height = image_height;
  out.tensor_width = options.output_width;
  out.tensor_height = options.output_height;
  return true;
}

crop_point project_to_image(const crop_transform& t, crop_point p) {
  const auto& m = t.to_image;
  const double px = m[0] * p.x + m[1] * p.y + m[2];
  const double py = m[3] * p.x + m[4] * p.y + m[5];
  // z is scaled like x: tensor pixels -> image pixels (ROI width / tensor width) -> image
  // widths, which is what TensorsToLandmarks, LetterboxRemoval and Projection do together.
  const double z_scale =
      static_cast<double>(t.roi_width) / t.tensor_width / static_cast<double>(t.image_width);
  return {static_cast<float>(px / t.image_width), static_cast<float>(py / t.image_height),
          static_cast<float>(p.z * z_scale)};
}

crop_point project_to_tensor(const crop_transform& t, crop_point p) {
  const auto& m = t.to_tensor;
  const double ix = static_cast<double>(p.x) * t.image_width;
  const double iy = static_cast<double>(p.y) * t.image_height;
  const double z_scale =
      static_cast<double>(t.tensor_width) * t.image_width / static_cast<double>(t.roi_width);
  return {static_cast<float>(m[0] * ix + m[1] * iy + m[2]),
          static_cast<float>(m[3] * ix + m[4] * iy + m[5]), static_cast<float>(p.z * z_scale)};
}

bool image_crop_job::validate() const {
  const int bpp = image_bytes_per_pixel(image.format);
  if (image.data == nullptr || image.width <= 0 || image.height <= 0 || bpp == 0) return false;
  if (image.stride_bytes < image.width * bpp) return false;
  if (options.output_width <= 0 || options.output_height <= 0) return false;
  if (!finite(options.range_min) || !finite(options.range_max) ||
      !(options.range_min < options.range_max)) {
    return false;
  }
  if (options.border != crop_border::replicate && options.border != crop_border::zero) return false;
  if (options.sampling != crop_sampling::opencv && options.sampling != crop_sampling::gl)
    return false;
  if (output == nullptr || output_size < crop_output_size(options)) return false;
  crop_transform unused;
  return make_crop_transform(image.width, image.height, roi, options, unused);
}

bool image_crop_job::run() const {
  if (!validate()) return false;
  crop_transform t;
  make_crop_transform(image.width, image.height, roi, options, t);

  warp_args a{};
  a.data = image.data;
  a.stride = image.stride_bytes;
  a.end = image.data + static_cast<std::ptrdiff_t>(image.stride_bytes) * (image.height - 1) +
          static_cast<std::ptrdiff_t>(image.width) * image_bytes_per_pixel(image.format);
  a.width = image.width;
  a.height = image.height;
  a.out_width = options.output_width;
  a.out_height = options.output_height;
  std::copy(t.to_image.begin(), t.to_image.end(), a.m);
  // MediaPipe's GetValueRangeTransformation(0, 255, min, max).
  a.scale = (options.range_max - options.range_min) / 255.0f;
  a.offset = options.range_min;
  a.out = output;
  const bool zero = options.border == crop_border::zero;
  if (options.sampling == crop_sampling::gl) {
    // Tensor pixel centres (x + 0.5) onto image pixel centres (i + 0.5, i.e. minus 0.5 in this
    // file's integer-centre convention).
    a.m[2] += 0.5 * (a.m[0] + a.m[1]) - 0.5;
    a.m[5] += 0.5 * (a.m[3] + a.m[4]) - 0.5;
    if (zero) {
      warp_any<true, true>(image.format, a);
    } else {
      warp_any<true, false>(image.format, a);
    }
  } else if (zero) {
    warp_any<false, true>(image.format, a);
  } else {
    warp_any<false, false>(image.format, a);
  }
  if (out_transform != nullptr) *out_transform = t;
  return true;
}

}  // namespace avatarmap
