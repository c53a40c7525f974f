// video_writer: RGB8 -> (swscale) -> encoder -> muxer or PNG files, written to temporary
// files renamed into place by close() (common/atomic_file.hpp: unique names, never through a
// symlink, modes kept, removed on failure and on SIGINT/SIGTERM); a stub without FFmpeg.
#include "avatarmap/media/video_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "common/atomic_file.hpp"
#include "media/frame_pattern.hpp"

#if AVATARMAP_HAVE_FFMPEG
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/avutil.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/mem.h>
#include <libavutil/opt.h>
#include <libavutil/rational.h>
#include <libswscale/swscale.h>
}
#endif

namespace avatarmap {

namespace fs = std::filesystem;

namespace {

constexpr double k_min_fps = 0.01;

status check_arguments(const std::string& path, int width, int height, double fps,
                       const video_writer_options& o) {
  if (o.max_size < 1 || o.max_size > 16384)
    return status::error(path + ": video_writer max_size is " + std::to_string(o.max_size) +
                         ", allowed 1..16384");
  if (width < 1 || height < 1 || width > o.max_size || height > o.max_size)
    return status::error(path + ": frame size " + std::to_string(width) + "x" +
                         std::to_string(height) + " is outside 1.." + std::to_string(o.max_size) +
                         " per side");
  if (!(fps >= k_min_fps && fps <= k_max_fps))
    return status::error(path + ": fps must be a number in 0.01.." + limit_text(k_max_fps));
  if (o.crf < 0 || o.crf > 51)
    return status::error(path + ": video_writer crf is " + std::to_string(o.crf) +
                         ", allowed 0..51");
  if (o.mpeg4_quality < 1 || o.mpeg4_quality > 31)
    return status::error(path + ": video_writer mpeg4_quality is " +
                         std::to_string(o.mpeg4_quality) + ", allowed 1..31");
  if (o.max_threads < 0 || o.max_threads > 64)
    return status::error(path + ": video_writer max_threads is " + std::to_string(o.max_threads) +
                         ", allowed 0..64 (0 = FFmpeg chooses)");
  if (o.first_number < 0 || o.first_number > 999999999)
    return status::error(path + ": video_writer first_number is " + std::to_string(o.first_number) +
                         ", allowed 0..999999999");
  if (!o.encoder.empty() && o.encoder != "libx264" && o.encoder != "mpeg4")
    return status::error(path + ": video_writer encoder '" + o.encoder +
                         "' is not one of \"\" (automatic), \"libx264\", \"mpeg4\"");
  return {};
}

}  // namespace

#if AVATARMAP_HAVE_FFMPEG

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string av_error_text(int err) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(err, buf, sizeof buf);
  return buf;
}

// Writes all of [data, data + size) to fd; false with errno set on failure.
bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

struct video_writer::impl {
  std::string path;
  video_writer_kind kind = video_writer_kind::none;
  int width = 0;  // of the frames given to write()
  int height = 0;
  int out_width = 0;  // of the frames in the file
  int out_height = 0;
  AVRational time_base{1, 30};
  double rate = 30.0;  // ticks per second
  std::string encoder_name;
  std::int64_t frames = 0;

  // Time stamps.
  double t0 = 0.0;
  bool have_t0 = false;
  std::int64_t last_pts = -1;

  // Encoding (video and PNG).
  AVCodecContext* enc = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;

  // Video: muxer and conversion.
  AVFormatContext* fmt = nullptr;
  AVStream* stream = nullptr;
  bool header_written = false;
  io_detail::atomic_file out;  // FFmpeg writes to out.temp_path() by name
  SwsContext* sws = nullptr;
  std::uint8_t* padded = nullptr;  // out_width x out_height RGB, for odd input sizes
  int padded_stride = 0;

  // PNG: names are formatted into buffers sized by open().
  std::string prefix;  // before the number (single PNG: the whole path)
  std::string suffix;  // after it
  int number_width = 0;
  bool numbered = false;
  // Frame 0's temporary file is temp_base (unique, beside it); frame i's is temp_base + ".i",
  // so that one registration removes them all on a signal.
  std::string temp_base;
  std::unique_ptr<io_detail::temp_file_registration> temp_registration;
  std::vector<char> final_name;
  std::vector<char> temp_name;
  int first_fd = -1;           // the temporary file of the first PNG, created by open()
  std::int64_t png_temps = 0;  // temporary PNG files created (including first_fd's)

  bool failed = false;
  status failure;  // the first failure, repeated by later calls

  ~impl() { discard(); }

  // Frees everything and removes the temporary files.
  void discard() {
    if (fmt) {
      if (fmt->pb) avio_closep(&fmt->pb);
      avformat_free_context(fmt);
      fmt = nullptr;
      stream = nullptr;
    }
    out.discard();  // after FFmpeg has closed it
    if (first_fd >= 0) {
      ::close(first_fd);
      first_fd = -1;
    }
    for (std::int64_t i = 0; i < png_temps; ++i) ::unlink(png_temp(i));
    png_temps = 0;
    temp_registration.reset();
    avcodec_free_context(&enc);
    av_frame_free(&frame);
    av_packet_free(&packet);
    sws_freeContext(sws);
    sws = nullptr;
    av_freep(&padded);
    kind = video_writer_kind::none;
  }

  // Names of PNG number i (counted from 0): final and temporary. Valid until the next call.
  const char* png_final(std::int64_t i) {
    if (!numbered) return prefix.c_str();
    std::snprintf(final_name.data(), final_name.size(), "%s%0*lld%s", prefix.c_str(), number_width,
                  static_cast<long long>(first_number + i), suffix.c_str());
    return final_name.data();
  }
  const char* png_temp(std::int64_t i) {
    if (i == 0) return temp_base.c_str();
    std::snprintf(temp_name.data(), temp_name.size(), "%s.%lld", temp_base.c_str(),
                  static_cast<long long>(i));
    return temp_name.data();
  }
  int first_number = 0;

  status fail(status_code code, std::string message) {
    discard();
    failed = true;
    failure = status::failure(code, std::move(message));
    return failure;
  }

  std::int64_t next_pts(double t) {
    if (frames == 0) {
      have_t0 = std::isfinite(t);
      t0 = have_t0 ? t : 0.0;
      return 0;
    }
    const std::int64_t next = last_pts + 1;
    if (!std::isfinite(t)) return next;
    if (!have_t0) {  // the first finite time: as if it were at the next tick
      have_t0 = true;
      t0 = t - static_cast<double>(next) / rate;
      return next;
    }
    const double ticks = std::round((t - t0) * rate);
    if (!(ticks > static_cast<double>(last_pts))) return next;
    constexpr double k_limit = 9.0e15;  // well inside int64 and exact in double
    return static_cast<std::int64_t>(std::min(ticks, k_limit));
  }

  // Sends `f` (null: flush) and writes what the encoder gives.
  status encode(AVFrame* f) {
    int err = avcodec_send_frame(enc, f);
    if (err < 0 && !(f == nullptr && err == AVERROR_EOF))
      return fail(status_code::internal, path + ": the " + encoder_name +
                                             " encoder refused frame " + std::to_string(frames) +
                                             " (" + av_error_text(err) + ")");
    for (;;) {
      err = avcodec_receive_packet(enc, packet);
      if (err == AVERROR(EAGAIN) || err == AVERROR_EOF) return {};
      if (err < 0)
        return fail(status_code::internal,
                    path + ": the " + encoder_name + " encoder failed at frame " +
                        std::to_string(frames) + " (" + av_error_text(err) + ")");
      if (kind == video_writer_kind::video) {
        av_packet_rescale_ts(packet, enc->time_base, stream->time_base);
        packet->stream_index = stream->index;
        err = av_interleaved_write_frame(fmt, packet);  // takes the packet's data
        if (err >= 0 && fmt->pb && fmt->pb->error < 0) err = fmt->pb->error;
        if (err < 0)
          return fail(status_code::io, path + ": cannot write to " + out.temp_path() + " (" +
                                           av_error_text(err) + ")");
      } else {
        status st = write_png(packet->data, static_cast<std::size_t>(packet->size));
        if (!st) return st;  // fail() has freed the packet with everything else
        av_packet_unref(packet);
      }
    }
  }

  // One encoded PNG into the next temporary file.
  status write_png(const std::uint8_t* data, std::size_t size) {
    int fd = first_fd;
    first_fd = -1;
    if (fd < 0) {
      // Registered before it exists, so a signal right after the open() still removes it.
      temp_registration->set_sequence_count(png_temps + 1);
      fd = ::open(png_temp(png_temps), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
      if (fd < 0) {
        const int e = errno;
        temp_registration->set_sequence_count(png_temps);
        return fail(status_code::io,
                    path + ": cannot create " + png_temp(png_temps) + ": " + std::strerror(e));
      }
      ++png_temps;
    }
    const bool ok = write_all(fd, data, size);
    const int saved = errno;
    if (::close(fd) != 0 || !ok)
      return fail(status_code::io, path + ": cannot write " + png_temp(png_temps - 1) + ": " +
                                       std::strerror(ok ? errno : saved));
    return {};
  }

  status open_video(const std::string& ext, const video_writer_options& o) {
    const char* format = ext == ".mp4"   ? "mp4"
                         : ext == ".mov" ? "mov"
                         : ext == ".mkv" ? "matroska"
                                         : "avi";
    const AVCodec* codec = nullptr;
    const bool want_x264 = o.encoder == "libx264" || (o.encoder.empty() && ext != ".avi");
    if (want_x264) {
      if (ext == ".avi")
        return status::error(path + ": the libx264 encoder is not offered for .avi (use mpeg4)");
      codec = avcodec_find_encoder_by_name("libx264");
      if (!codec && o.encoder == "libx264")
        return status::unsupported(path + ": this FFmpeg has no libx264 encoder");
    }
    if (!codec) {
      codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
      if (!codec) return status::unsupported(path + ": this FFmpeg has no mpeg4 encoder");
    }
    encoder_name = codec->name;
    const bool x264 = encoder_name == "libx264";

    // yuv420p has chroma for 2x2 blocks: both sides must be even.
    out_width = width + (width & 1);
    out_height = height + (height & 1);

    enc = avcodec_alloc_context3(codec);
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (!enc || !frame || !packet) return status::out_of_memory(path + ": out of memory");
    enc->width = out_width;
    enc->height = out_height;
    enc->pix_fmt = AV_PIX_FMT_YUV420P;
    enc->time_base = time_base;
    enc->framerate = av_inv_q(time_base);
    enc->sample_aspect_ratio = AVRational{1, 1};
    enc->thread_count = o.max_threads;
    enc->colorspace = AVCOL_SPC_SMPTE170M;  // BT.601, as converted below
    enc->color_range = AVCOL_RANGE_MPEG;
    if (x264) {
      av_opt_set(enc->priv_data, "preset", o.preset.c_str(), 0);
      av_opt_set_double(enc->priv_data, "crf", o.crf, 0);
    } else {
      enc->flags |= AV_CODEC_FLAG_QSCALE;
      enc->global_quality = FF_QP2LAMBDA * o.mpeg4_quality;
    }

    int err = avformat_alloc_output_context2(&fmt, nullptr, format, nullptr);
    if (err < 0 || !fmt)
      return status::unsupported(path + ": no '" + format + "' muxer in this FFmpeg (" +
                                 av_error_text(err) + ")");
    if (fmt->oformat->flags & AVFMT_GLOBALHEADER) enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    err = avcodec_open2(enc, codec, nullptr);
    if (err < 0)
      return status::internal(path + ": cannot open the " + encoder_name + " encoder for " +
                              std::to_string(out_width) + "x" + std::to_string(out_height) +
                              (x264 ? " (preset '" + o.preset + "')" : std::string()) + " (" +
                              av_error_text(err) + ")");
    stream = avformat_new_stream(fmt, nullptr);
    if (!stream) return status::out_of_memory(path + ": out of memory");
    err = avcodec_parameters_from_context(stream->codecpar, enc);
    if (err < 0)
      return status::internal(path + ": bad encoder parameters (" + av_error_text(err) + ")");
    stream->time_base = enc->time_base;
    stream->avg_frame_rate = enc->framerate;

    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = out_width;
    frame->height = out_height;
    frame->colorspace = AVCOL_SPC_SMPTE170M;
    frame->color_range = AVCOL_RANGE_MPEG;
    if (av_frame_get_buffer(frame, 0) < 0) return status::out_of_memory(path + ": out of memory");
    sws = sws_getContext(out_width, out_height, AV_PIX_FMT_RGB24, out_width, out_height,
                         AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr, nullptr, nullptr);
    if (!sws) return status::internal(path + ": cannot set up the RGB to YUV conversion");
    // RGB is full range; the video limited-range BT.601, as the stream says.
    const int* bt601 = sws_getCoefficients(SWS_CS_ITU601);
    sws_setColorspaceDetails(sws, bt601, 1, bt601, 0, 0, 1 << 16, 1 << 16);
    if (out_width != width || out_height != height) {
      padded_stride = (out_width * 3 + 63) & ~63;
      padded = static_cast<std::uint8_t*>(
          av_malloc(static_cast<std::size_t>(padded_stride) * out_height + 64));
      if (!padded) return status::out_of_memory(path + ": out of memory");
    }

    // The temporary file, then the container's header.
    // `out` keeps its descriptor open (unused) until commit() fsyncs and renames the file.
    if (status st = out.open(path); !st) return st;
    const std::string url = "file:" + out.temp_path();
    err = avio_open(&fmt->pb, url.c_str(), AVIO_FLAG_WRITE);
    if (err < 0)
      return status::io_error(path + ": cannot open " + out.temp_path() + " (" +
                              av_error_text(err) + ")");
    av_freep(&fmt->url);
    fmt->url = av_strdup(url.c_str());  // +faststart reopens the file by this name
    AVDictionary* mux_options = nullptr;
    if (std::strcmp(format, "mp4") == 0 || std::strcmp(format, "mov") == 0)
      av_dict_set(&mux_options, "movflags", "+faststart", 0);
    err = avformat_write_header(fmt, &mux_options);
    av_dict_free(&mux_options);
    if (err < 0)
      return status::io_error(path + ": cannot write the " + format + " header (" +
                              av_error_text(err) + ")");
    header_written = true;
    kind = video_writer_kind::video;
    return {};
  }

  status open_png(bool is_numbered) {
    const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_PNG);
    if (!codec) return status::unsupported(path + ": this FFmpeg has no png encoder");
    encoder_name = codec->name;
    out_width = width;
    out_height = height;
    enc = avcodec_alloc_context3(codec);
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (!enc || !frame || !packet) return status::out_of_memory(path + ": out of memory");
    enc->width = width;
    enc->height = height;
    enc->pix_fmt = AV_PIX_FMT_RGB24;
    enc->time_base = time_base;
    enc->thread_count = 1;
    int err = avcodec_open2(enc, codec, nullptr);
    if (err < 0)
      return status::internal(path + ": cannot open the png encoder (" + av_error_text(err) + ")");
    frame->format = AV_PIX_FMT_RGB24;
    frame->width = width;
    frame->height = height;
    if (av_frame_get_buffer(frame, 0) < 0) return status::out_of_memory(path + ": out of memory");

    numbered = is_numbered;
    final_name.assign(prefix.size() + suffix.size() + 32, '\0');
    // The first file's temporary name is unique (create_temp_file); the later frames' names
    // are derived from it.
    const std::string first_final = png_final(0);
    int fd = -1;
    if (status st = io_detail::create_temp_file(first_final, fd, temp_base); !st) return st;
    first_fd = fd;
    png_temps = 1;
    temp_registration = std::make_unique<io_detail::temp_file_registration>(temp_base);
    temp_name.assign(temp_base.size() + 24, '\0');
    kind = numbered ? video_writer_kind::png_sequence : video_writer_kind::png_single;
    return {};
  }

  // Copies `rgb` into `dst` (rows dst_stride apart, out_width x out_height), repeating the
  // last column and row where the output is larger.
  void copy_padded(const image_view& rgb, std::uint8_t* dst, int dst_stride) const {
    const std::size_t row_bytes = static_cast<std::size_t>(width) * 3;
    for (int y = 0; y < out_height; ++y) {
      const std::uint8_t* s =
          rgb.data + static_cast<std::ptrdiff_t>(std::min(y, height - 1)) * rgb.stride_bytes;
      std::uint8_t* d = dst + static_cast<std::ptrdiff_t>(y) * dst_stride;
      std::memcpy(d, s, row_bytes);
      for (int x = width; x < out_width; ++x) std::memcpy(d + 3 * x, s + 3 * (width - 1), 3);
    }
  }
};

video_writer::video_writer() = default;
video_writer::~video_writer() = default;
video_writer::video_writer(video_writer&&) noexcept = default;
video_writer& video_writer::operator=(video_writer&&) noexcept = default;

bool video_writer_available() { return true; }

status video_writer::open(const std::string& path, int width, int height, double fps,
                          const video_writer_options& options) {
  impl_.reset();
  if (status st = check_arguments(path, width, height, fps, options); !st) return st;
  const std::string ext = lower_extension(path);
  const bool video = ext == ".mp4" || ext == ".mov" || ext == ".mkv" || ext == ".avi";
  if (!video && ext != ".png")
    return status::error(path + ": unknown output format '" + ext +
                         "': use .mp4, .mov, .mkv, .avi or .png (a %05d-style pattern for one "
                         "PNG per frame)");

  auto p = std::make_unique<impl>();
  p->path = path;
  p->width = width;
  p->height = height;
  p->first_number = options.first_number;
  p->time_base = av_d2q(1.0 / fps, 65535);
  if (p->time_base.num <= 0 || p->time_base.den <= 0)
    return status::error(path + ": fps " + std::to_string(fps) + " has no usable time base");
  p->rate = static_cast<double>(p->time_base.den) / p->time_base.num;

  // Where the files go: the folder must exist, and the final name must not be a folder.
  std::string first_final = path;
  bool numbered = false;
  if (!video) {
    bool has_percent = false;
    has_percent = path.find('%') != std::string::npos;
    numbered = parse_frame_pattern(path, p->prefix, p->suffix, p->number_width);
    if (has_percent && !numbered)
      return status::error(path +
                           ": a '%' in a PNG path must be one %d or %0Nd (a pattern for one "
                           "file per frame) or be written %%");
    if (!numbered) p->prefix = path;
    if (numbered) {
      p->final_name.assign(p->prefix.size() + p->suffix.size() + 32, '\0');
      p->numbered = true;
      first_final = p->png_final(0);
    }
  }
  const fs::path folder = fs::path(first_final).parent_path();
  std::error_code ec;
  if (!folder.empty() && !fs::is_directory(folder, ec))
    return status::io_error(path + ": the folder " + folder.string() +
                            " does not exist (or is not a folder)");
  if (fs::is_directory(first_final, ec))
    return status::io_error(path + ": " + first_final + " is a folder");

  status st = video ? p->open_video(ext, options) : p->open_png(numbered);
  if (!st) return st;  // p's destructor removes what was created
  impl_ = std::move(p);
  return {};
}

status video_writer::write(const image_view& rgb, double t) {
  if (!impl_) return status::error("video_writer: write() without a successful open()");
  impl& s = *impl_;
  if (s.failed) return s.failure;
  if (rgb.format != pixel_format::rgb8 || !rgb.data || rgb.width != s.width ||
      rgb.height != s.height || rgb.stride_bytes < rgb.width * 3) {
    std::string why;
    if (rgb.format != pixel_format::rgb8)
      why = "the frame is not rgb8";
    else if (!rgb.data)
      why = "the frame has no data";
    else if (rgb.width != s.width || rgb.height != s.height)
      why = "the frame is " + std::to_string(rgb.width) + "x" + std::to_string(rgb.height) +
            ", the writer was opened for " + std::to_string(s.width) + "x" +
            std::to_string(s.height);
    else
      why = "stride_bytes " + std::to_string(rgb.stride_bytes) + " is less than width * 3";
    return status::error(s.path + ": frame " + std::to_string(s.frames) + " refused: " + why);
  }
  if (s.kind == video_writer_kind::png_single && s.frames > 0) return {};  // only the first

  const std::int64_t pts = s.next_pts(t);
  int err = av_frame_make_writable(s.frame);  // the encoder may still hold the last one
  if (err < 0)
    return s.fail(status_code::out_of_memory,
                  s.path + ": out of memory (" + av_error_text(err) + ")");
  if (s.kind == video_writer_kind::video) {
    const std::uint8_t* src = rgb.data;
    int src_stride = rgb.stride_bytes;
    if (s.padded) {
      s.copy_padded(rgb, s.padded, s.padded_stride);
      src = s.padded;
      src_stride = s.padded_stride;
    }
    const std::uint8_t* planes[4] = {src, nullptr, nullptr, nullptr};
    const int strides[4] = {src_stride, 0, 0, 0};
    if (sws_scale(s.sws, planes, strides, 0, s.out_height, s.frame->data, s.frame->linesize) !=
        s.out_height)
      return s.fail(status_code::internal,
                    s.path + ": cannot convert frame " + std::to_string(s.frames) + " to YUV");
  } else {
    s.copy_padded(rgb, s.frame->data[0], s.frame->linesize[0]);
  }
  s.frame->pts = pts;
  if (status st = s.encode(s.frame); !st) return st;
  s.last_pts = pts;
  ++s.frames;
  return {};
}

status video_writer::close() {
  if (!impl_) return {};
  std::unique_ptr<impl> p = std::move(impl_);  // closed afterwards whatever happens
  impl& s = *p;
  if (s.failed) return s.failure;
  if (s.frames == 0) return status::error(s.path + ": no frame was written; no file made");
  if (status st = s.encode(nullptr); !st) return st;

  if (s.kind == video_writer_kind::video) {
    int err = av_write_trailer(s.fmt);
    if (err >= 0 && s.fmt->pb->error < 0) err = s.fmt->pb->error;
    const int close_err = avio_closep(&s.fmt->pb);
    if (err >= 0) err = close_err;
    if (err < 0)
      return s.fail(status_code::io, s.path + ": cannot finish " + s.out.temp_path() + " (" +
                                         av_error_text(err) + ")");
    if (status st = s.out.commit(); !st) return s.fail(st.code(), st.message());
    return {};
  }

  // PNG: every file was closed after its frame; rename them in order.
  const std::int64_t n = s.png_temps;
  for (std::int64_t i = 0; i < n; ++i) {
    const std::string from = s.png_temp(i);
    const std::string to = s.png_final(i);
    if (status st = io_detail::commit_temp_file(from, to); !st) {
      std::string message = st.message();
      if (i > 0) message += " (" + std::to_string(i) + " file(s) renamed before it stay)";
      for (std::int64_t j = i; j < n; ++j) ::unlink(s.png_temp(j));
      s.png_temps = 0;
      return s.fail(st.code(), message);
    }
  }
  s.png_temps = 0;
  s.temp_registration.reset();
  return {};
}

bool video_writer::is_open() const { return impl_ && !impl_->failed; }

video_writer_kind video_writer::kind() const {
  return impl_ ? impl_->kind : video_writer_kind::none;
}
int video_writer::output_width() const { return impl_ ? impl_->out_width : 0; }
int video_writer::output_height() const { return impl_ ? impl_->out_height : 0; }
const std::string& video_writer::encoder_name() const {
  static const std::string k_empty;
  return impl_ ? impl_->encoder_name : k_empty;
}
std::int64_t video_writer::frames_written() const { return impl_ ? impl_->frames : 0; }

#else  // !AVATARMAP_HAVE_FFMPEG

struct video_writer::impl {};

video_writer::video_writer() = default;
video_writer::~video_writer() = default;
video_writer::video_writer(video_writer&&) noexcept = default;
video_writer& video_writer::operator=(video_writer&&) noexcept = default;

bool video_writer_available() { return false; }

status video_writer::open(const std::string& path, int width, int height, double fps,
                          const video_writer_options& options) {
  impl_.reset();
  if (status st = check_arguments(path, width, height, fps, options); !st) return st;
  return status::unsupported(path +
                             ": cannot encode video or images: avatarmap was built without FFmpeg "
                             "(install libavformat-dev libavcodec-dev libavutil-dev libswscale-dev "
                             "and configure with AVATARMAP_WITH_FFMPEG=ON)");
}

status video_writer::write(const image_view&, double) {
  return status::error("video_writer: write() without a successful open()");
}
status video_writer::close() { return {}; }
bool video_writer::is_open() const { return false; }
video_writer_kind video_writer::kind() const { return video_writer_kind::none; }
int video_writer::output_width() const { return 0; }
int video_writer::output_height() const { return 0; }
const std::string& video_writer::encoder_name() const {
  static const std::string k_empty;
  return k_empty;
}
std::int64_t video_writer::frames_written() const { return 0; }

#endif  // AVATARMAP_HAVE_FFMPEG

}  // namespace avatarmap
