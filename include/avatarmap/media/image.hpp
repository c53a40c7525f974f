// An image as the library passes it between decoding, estimation and encoding: pixels owned
// by the caller, in one of a few 8-bit layouts.
#pragma once

#include <cstdint>

namespace avatarmap {

enum class pixel_format : std::uint8_t { rgb8, bgr8, rgba8, bgra8, gray8 };

/// Bytes per pixel of `format` (0 for a value that is not one of them).
constexpr int image_bytes_per_pixel(pixel_format format) {
  switch (format) {
    case pixel_format::rgb8:
    case pixel_format::bgr8:
      return 3;
    case pixel_format::rgba8:
    case pixel_format::bgra8:
      return 4;
    case pixel_format::gray8:
      return 1;
  }
  return 0;
}

/// A view of pixels owned by the caller, valid for the duration of the call. Rows are
/// `stride_bytes` apart (>= width * bytes per pixel). May be empty (data == nullptr) for
/// backends that need no pixels (replay).
struct image_view {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride_bytes = 0;
  pixel_format format = pixel_format::rgb8;
};

}  // namespace avatarmap
