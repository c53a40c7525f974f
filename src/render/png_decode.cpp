// src/render/png_decode.hpp.
#include "render/png_decode.hpp"

#include <cstring>
#include <string>

#if AVATARMAP_HAVE_FFMPEG
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/frame.h>
}
#endif

namespace avatarmap::render_detail {

#if AVATARMAP_HAVE_FFMPEG
static_assert(png_decoder::k_png_padding >= AV_INPUT_BUFFER_PADDING_SIZE);

struct png_decoder::impl {
  AVCodecContext* context = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  ~impl() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&context);
  }
};

png_decoder::png_decoder() = default;
png_decoder::~png_decoder() = default;

status png_decoder::decode(const std::uint8_t* data, std::size_t size, int width, int height,
                           std::uint8_t* out, int stride_bytes) {
  if (!impl_) {
    auto d = std::make_unique<impl>();
    const AVCodec* codec = avcodec_find_decoder(AV_CODEC_ID_PNG);
    if (!codec) return status::unsupported("render: this FFmpeg has no PNG decoder");
    d->context = avcodec_alloc_context3(codec);
    d->packet = av_packet_alloc();
    d->frame = av_frame_alloc();
    if (!d->context || !d->packet || !d->frame)
      return status::out_of_memory("render: cannot make the PNG decoder");
    d->context->thread_count = 1;
    if (avcodec_open2(d->context, codec, nullptr) < 0)
      return status::internal("render: cannot open FFmpeg's PNG decoder");
    impl_ = std::move(d);
  }
  AVPacket* p = impl_->packet;
  p->data = const_cast<std::uint8_t*>(data);
  p->size = static_cast<int>(size);
  // Without the key flag FFmpeg's PNG decoder takes a packet for a "P-frame" added to the
  // previous picture (MNG-style); every screenshot is a whole picture.
  p->flags = AV_PKT_FLAG_KEY;
  int r = avcodec_send_packet(impl_->context, p);
  if (r >= 0) r = avcodec_receive_frame(impl_->context, impl_->frame);
  av_packet_unref(p);
  if (r < 0) return status::parse_error("render: a screenshot is not a PNG FFmpeg can decode");
  const AVFrame* f = impl_->frame;
  if (f->width != width || f->height != height) {
    const std::string got = std::to_string(f->width) + "x" + std::to_string(f->height);
    av_frame_unref(impl_->frame);
    return status::internal("render: a screenshot is " + got + ", not " + std::to_string(width) +
                            "x" + std::to_string(height));
  }
  const int format = f->format;
  if (format != AV_PIX_FMT_RGB24 && format != AV_PIX_FMT_RGBA) {
    av_frame_unref(impl_->frame);
    return status::unsupported("render: a screenshot's PNG has an unexpected pixel format");
  }
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* src = f->data[0] + static_cast<std::ptrdiff_t>(y) * f->linesize[0];
    std::uint8_t* dst = out + static_cast<std::ptrdiff_t>(y) * stride_bytes;
    if (format == AV_PIX_FMT_RGB24) {
      std::memcpy(dst, src, static_cast<std::size_t>(width) * 3);
    } else {
      for (int x = 0; x < width; ++x) {
        dst[3 * x] = src[4 * x];
        dst[3 * x + 1] = src[4 * x + 1];
        dst[3 * x + 2] = src[4 * x + 2];
      }
    }
  }
  av_frame_unref(impl_->frame);
  return {};
}
#else
struct png_decoder::impl {};
png_decoder::png_decoder() = default;
png_decoder::~png_decoder() = default;
status png_decoder::decode(const std::uint8_t*, std::size_t, int, int, std::uint8_t*, int) {
  return status::unsupported("render: this build has no FFmpeg (needed to decode frames)");
}
#endif

}  // namespace avatarmap::render_detail
