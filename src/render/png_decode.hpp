// Internal: decodes PNG bytes (the browser's screenshots) into RGB8 with FFmpeg's PNG decoder.
// The decoder and the frame are made once and reused; a build without FFmpeg fails saying so.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "avatarmap/core/status.hpp"

namespace avatarmap::render_detail {

class png_decoder {
 public:
  png_decoder();
  ~png_decoder();
  png_decoder(const png_decoder&) = delete;
  png_decoder& operator=(const png_decoder&) = delete;

  /// Decodes `size` bytes at `data` (followed by at least k_png_padding readable bytes) and
  /// copies the image, which must be `width` x `height`, as RGB8 into `out` (rows
  /// `stride_bytes` apart).
  status decode(const std::uint8_t* data, std::size_t size, int width, int height,
                std::uint8_t* out, int stride_bytes);

  static constexpr std::size_t k_png_padding = 64;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap::render_detail
