// video_source: FFmpeg demuxing + decoding + swscale to RGB8 (or a stub without FFmpeg).
#include "avatarmap/capture/video_source.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "capture/frame_pattern.hpp"

#if AVATARMAP_HAVE_FFMPEG
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/avutil.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libavutil/mem.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}
#endif

namespace avatarmap {

namespace fs = std::filesystem;

namespace {

status check_options(const video_source_options& o) {
  if (o.output_format != pixel_format::rgb8)
    return status::error("video_source: output_format must be rgb8 (the only one supported)");
  if (o.max_threads < 0 || o.max_threads > 64)
    return status::error("video_source: max_threads is " + std::to_string(o.max_threads) +
                         ", allowed 0..64 (0 = FFmpeg chooses)");
  if (!(o.sequence_fps > 0.0) || !std::isfinite(o.sequence_fps))
    return status::error("video_source: sequence_fps must be a finite number > 0");
  if (o.max_size < 1 || o.max_size > 16384)
    return status::error("video_source: max_size is " + std::to_string(o.max_size) +
                         ", allowed 1..16384");
  return {};
}

}  // namespace

#if AVATARMAP_HAVE_FFMPEG

namespace {

// Names that a folder's listing takes as images.
bool is_image_extension(std::string ext) {
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const char* const k_exts[] = {".jpg",  ".jpeg", ".png", ".bmp", ".tif",
                                       ".tiff", ".webp", ".ppm", ".pgm", ".pnm"};
  for (const char* e : k_exts)
    if (ext == e) return true;
  return false;
}

std::string pattern_name(const std::string& prefix, const std::string& suffix, int width,
                         long index) {
  std::string n = std::to_string(index);
  if (static_cast<int>(n.size()) < width) n.insert(0, width - n.size(), '0');
  return prefix + n + suffix;
}

// The image files of a folder, sorted by name (byte order).
std::vector<std::string> folder_images(const std::string& dir) {
  std::vector<std::string> r;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code ec2;
    if (!it->is_regular_file(ec2)) continue;
    if (is_image_extension(it->path().extension().string())) r.push_back(it->path().string());
  }
  std::sort(r.begin(), r.end());
  return r;
}

// The files of a pattern: from the first of 0..4 that exists, while they exist.
std::vector<std::string> pattern_images(const std::string& prefix, const std::string& suffix,
                                        int width) {
  std::vector<std::string> r;
  std::error_code ec;
  long first = -1;
  for (long i = 0; i <= 4 && first < 0; ++i)
    if (fs::is_regular_file(pattern_name(prefix, suffix, width, i), ec)) first = i;
  if (first < 0) return r;
  for (long i = first;; ++i) {
    std::string name = pattern_name(prefix, suffix, width, i);
    if (!fs::is_regular_file(name, ec)) break;
    r.push_back(std::move(name));
  }
  return r;
}

std::string av_error_text(int err) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(err, buf, sizeof buf);
  return buf;
}

// Pixel formats FFmpeg marks deprecated (full-range "J" YUV): swscale wants the plain ones
// with the range given separately, and warns otherwise.
AVPixelFormat unjpeg(AVPixelFormat f, bool& out_full_range) {
  switch (f) {
    case AV_PIX_FMT_YUVJ420P:
      out_full_range = true;
      return AV_PIX_FMT_YUV420P;
    case AV_PIX_FMT_YUVJ422P:
      out_full_range = true;
      return AV_PIX_FMT_YUV422P;
    case AV_PIX_FMT_YUVJ444P:
      out_full_range = true;
      return AV_PIX_FMT_YUV444P;
    case AV_PIX_FMT_YUVJ440P:
      out_full_range = true;
      return AV_PIX_FMT_YUV440P;
    case AV_PIX_FMT_YUVJ411P:
      out_full_range = true;
      return AV_PIX_FMT_YUV411P;
    default:
      return f;
  }
}

// Consecutive errors without a decoded frame after which a source gives up (reports end):
// a caller that goes on after every error must not loop forever on a hopeless file.
constexpr int k_max_consecutive_errors = 64;

}  // namespace

struct video_source::impl {
  video_source_options options;
  video_info info;
  std::string path;
  std::string error;
  bool open = false;

  // The file being decoded (the whole video, or one image of a sequence).
  std::string file;
  AVFormatContext* fmt = nullptr;
  AVCodecContext* dec = nullptr;
  int stream = -1;
  double time_base = 0.0;      // seconds per time-stamp unit of the stream
  std::int64_t start_pts = 0;  // subtracted so that the first frame is at 0
  bool eof_sent = false;       // the decoder is draining
  bool finished = false;       // the decoder has given everything
  std::string deferred_error;  // a read error, reported once the decoder is drained
  int consecutive_errors = 0;
  std::int64_t frames_out = 0;  // frames returned so far (all files)

  // Image sequences.
  std::vector<std::string> files;
  std::size_t next_file = 0;

  // Reused across frames.
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  SwsContext* sws = nullptr;
  const SwsContext* sws_for = nullptr;  // the context sws_key was applied to
  int sws_key[5] = {};                  // w, h, format, colorspace, range last applied
  std::uint8_t* pixels = nullptr;       // av_malloc'ed (aligned for swscale's SIMD)
  std::size_t capacity = 0;

  ~impl() {
    close_file();
    sws_freeContext(sws);
    av_frame_free(&frame);
    av_packet_free(&packet);
    av_free(pixels);
  }

  void close_file() {
    avcodec_free_context(&dec);
    avformat_close_input(&fmt);
    stream = -1;
    eof_sent = false;
    finished = false;
    deferred_error.clear();
  }

  // Opens `name` (a file, or a device when `device_format` is given) and its decoder; on
  // success fills the parts of `info` that come from the stream.
  status open_file(const std::string& name, const AVInputFormat* device_format,
                   video_info& out_info) {
    close_file();
    file = name;
    AVDictionary* fmt_options = nullptr;
    std::string url = name;
    if (!device_format) {
      // A file name is a file name: never a protocol ("concat:", "http:" ...), also not
      // for what the file refers to (playlists), and never a pattern (image2 reads '%').
      url = "file:" + name;
      av_dict_set(&fmt_options, "protocol_whitelist", "file", 0);
      av_dict_set(&fmt_options, "pattern_type", "none", 0);
    }
    int err = avformat_open_input(&fmt, url.c_str(), device_format, &fmt_options);
    av_dict_free(&fmt_options);
    if (err < 0) {
      fmt = nullptr;
      if (device_format)
        return status::error(name + ": cannot open the camera (" + av_error_text(err) + ")");
      return status::error(name + ": cannot be read as media (" + av_error_text(err) +
                           "): not a media file, or a truncated or corrupt one");
    }
    // Probing may decode a first picture; FFmpeg refuses pictures over about 16250x16250
    // itself (av_image_check_size), so the allocation is bounded as with max_size's limit.
    // max_pixels is not given here: the size must come out to be reported against max_size.
    err = avformat_find_stream_info(fmt, nullptr);
    if (err < 0)
      return status::error(name + ": cannot read the stream information (" + av_error_text(err) +
                           ")");

    const AVCodec* codec = nullptr;
    stream = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
    if (stream == AVERROR_STREAM_NOT_FOUND)
      return status::error(name + ": no video stream (" + std::to_string(fmt->nb_streams) +
                           " other stream(s))");
    if (stream < 0 || !codec) {
      const AVCodecID id =
          stream >= 0 ? fmt->streams[stream]->codecpar->codec_id : AV_CODEC_ID_NONE;
      return status::error(name + ": no decoder for the video codec '" + avcodec_get_name(id) +
                           "' in this FFmpeg build");
    }
    AVStream* st = fmt->streams[stream];
    const AVCodecParameters* par = st->codecpar;
    if (par->width <= 0 || par->height <= 0)
      return status::error(name + ": no picture could be read (size " + std::to_string(par->width) +
                           "x" + std::to_string(par->height) +
                           "): a broken or empty image or video, or one over FFmpeg's own " +
                           "size limit (about 16000x16000)");
    if (par->width > options.max_size || par->height > options.max_size)
      return status::error(name + ": the image is " + std::to_string(par->width) + "x" +
                           std::to_string(par->height) + ", larger than the " +
                           std::to_string(options.max_size) + "x" +
                           std::to_string(options.max_size) + " limit");

    dec = avcodec_alloc_context3(codec);
    if (!dec) return status::error(name + ": out of memory");
    err = avcodec_parameters_to_context(dec, par);
    if (err < 0) return status::error(name + ": bad codec parameters (" + av_error_text(err) + ")");
    const std::string max_pixels =
        std::to_string(static_cast<std::int64_t>(options.max_size) * options.max_size);
    dec->thread_count = options.max_threads;
    dec->pkt_timebase = st->time_base;
    AVDictionary* dec_options = nullptr;
    av_dict_set(&dec_options, "max_pixels", max_pixels.c_str(), 0);
    err = avcodec_open2(dec, codec, &dec_options);
    av_dict_free(&dec_options);
    if (err < 0)
      return status::error(name + ": cannot open the '" + codec->name + "' decoder (" +
                           av_error_text(err) + ")");

    time_base = av_q2d(st->time_base);
    start_pts = st->start_time != AV_NOPTS_VALUE ? st->start_time : 0;

    const char* demuxer = fmt->iformat->name;
    const bool still =
        std::strcmp(demuxer, "image2") == 0 || std::strstr(demuxer, "_pipe") != nullptr;
    out_info.kind = device_format ? video_source_kind::camera
                                  : (still ? video_source_kind::image : video_source_kind::video);
    out_info.width = par->width;
    out_info.height = par->height;
    out_info.codec = avcodec_get_name(par->codec_id);
    if (still) {
      out_info.fps = 0.0;
      out_info.frame_count = 1;
      out_info.duration = 0.0;
    } else {
      const AVRational rate = av_guess_frame_rate(fmt, st, nullptr);
      out_info.fps = rate.num > 0 && rate.den > 0 ? av_q2d(rate) : 0.0;
      out_info.frame_count = st->nb_frames > 0 ? st->nb_frames : 0;
      if (st->duration != AV_NOPTS_VALUE && st->duration > 0)
        out_info.duration = st->duration * time_base;
      else if (fmt->duration != AV_NOPTS_VALUE && fmt->duration > 0)
        out_info.duration = static_cast<double>(fmt->duration) / AV_TIME_BASE;
    }
    return {};
  }

  // Converts `frame` into the reused RGB8 buffer.
  bool convert(image_view& out) {
    const int w = frame->width;
    const int h = frame->height;
    if (w <= 0 || h <= 0 || w > options.max_size || h > options.max_size) {
      error = file + ": decoded frame " + std::to_string(frames_out) + " is " + std::to_string(w) +
              "x" + std::to_string(h) + ", outside 1.." + std::to_string(options.max_size);
      return false;
    }
    bool full_range = frame->color_range == AVCOL_RANGE_JPEG;
    const AVPixelFormat src = unjpeg(static_cast<AVPixelFormat>(frame->format), full_range);
    if (src == AV_PIX_FMT_NONE) {
      error = file + ": decoded frame " + std::to_string(frames_out) + " has no pixel format";
      return false;
    }
    // Full chroma interpolation: a third closer to stb_image/libjpeg on 4:2:0 JPEGs (mean
    // 0.50 levels, not 0.75) at no measurable cost. Not SWS_ACCURATE_RND: it leaves the
    // SIMD paths (2.4x slower on 720p video) and is no closer.
    sws = sws_getCachedContext(sws, w, h, src, w, h, AV_PIX_FMT_RGB24,
                               SWS_BILINEAR | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr);
    if (!sws) {
      error = file + ": cannot convert frame " + std::to_string(frames_out) + " from " +
              (av_get_pix_fmt_name(src) ? av_get_pix_fmt_name(src) : "?") + " to RGB";
      return false;
    }
    // YUV: the frame's matrix and range (unspecified: BT.601, limited unless "J" or
    // full-range flagged). Gray images are full range unless flagged otherwise. RGB and
    // palette sources need neither.
    const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(src);
    const bool yuv = desc && !(desc->flags & (AV_PIX_FMT_FLAG_RGB | AV_PIX_FMT_FLAG_PAL)) &&
                     desc->nb_components >= 3;
    const bool gray = desc && !(desc->flags & (AV_PIX_FMT_FLAG_RGB | AV_PIX_FMT_FLAG_PAL)) &&
                      desc->nb_components <= 2;
    if (gray) full_range = frame->color_range != AVCOL_RANGE_MPEG;
    int colorspace = SWS_CS_DEFAULT;
    if (frame->colorspace == AVCOL_SPC_BT709)
      colorspace = SWS_CS_ITU709;
    else if (frame->colorspace == AVCOL_SPC_BT2020_NCL || frame->colorspace == AVCOL_SPC_BT2020_CL)
      colorspace = SWS_CS_BT2020;
    else if (frame->colorspace == AVCOL_SPC_SMPTE240M)
      colorspace = SWS_CS_SMPTE240M;
    // Set again only when the source changes: it rebuilds swscale's tables.
    const int key[5] = {w, h, static_cast<int>(src), colorspace, full_range ? 1 : 0};
    if ((yuv || gray) && (sws != sws_for || std::memcmp(key, sws_key, sizeof key) != 0)) {
      sws_setColorspaceDetails(sws, sws_getCoefficients(colorspace), full_range ? 1 : 0,
                               sws_getCoefficients(SWS_CS_DEFAULT), 1, 0, 1 << 16, 1 << 16);
    }
    sws_for = sws;
    std::memcpy(sws_key, key, sizeof key);

    const int stride = (w * 3 + 63) & ~63;  // aligned rows for swscale's SIMD
    const std::size_t size = static_cast<std::size_t>(stride) * h + 64;
    if (size > capacity) {
      av_free(pixels);
      pixels = static_cast<std::uint8_t*>(av_malloc(size));
      capacity = pixels ? size : 0;
      if (!pixels) {
        error = file + ": out of memory for a " + std::to_string(w) + "x" + std::to_string(h) +
                " frame";
        return false;
      }
    }
    std::uint8_t* dst[4] = {pixels, nullptr, nullptr, nullptr};
    int dst_stride[4] = {stride, 0, 0, 0};
    if (sws_scale(sws, frame->data, frame->linesize, 0, h, dst, dst_stride) != h) {
      error = file + ": cannot convert frame " + std::to_string(frames_out) + " to RGB";
      return false;
    }
    out = {pixels, w, h, stride, pixel_format::rgb8};
    return true;
  }

  read_result fail(std::string message) {
    error = std::move(message);
    // Each image of a sequence gives at most one error: only a video can loop.
    if (info.kind != video_source_kind::sequence &&
        ++consecutive_errors >= k_max_consecutive_errors) {
      error += " (giving up after " + std::to_string(consecutive_errors) + " errors in a row)";
      finished = true;
      files.clear();
    }
    return read_result::error;
  }

  // One step of the decoder of the open file: frame, end (of this file) or error.
  read_result decode(image_view& out, double& out_t) {
    for (;;) {
      if (finished) {
        if (deferred_error.empty()) return read_result::end;
        std::string m = std::move(deferred_error);
        deferred_error.clear();
        return fail(std::move(m));
      }
      int err = avcodec_receive_frame(dec, frame);
      if (err == 0) {
        const std::int64_t pts = frame->best_effort_timestamp;
        const bool ok = convert(out);
        const double t = pts != AV_NOPTS_VALUE
                             ? static_cast<double>(pts - start_pts) * time_base
                             : (info.fps > 0.0 ? static_cast<double>(frames_out) / info.fps : 0.0);
        av_frame_unref(frame);
        if (!ok) return fail(error);
        out_t = t;
        ++frames_out;
        consecutive_errors = 0;
        return read_result::frame;
      }
      if (err == AVERROR_EOF) {
        finished = true;
        continue;
      }
      if (err != AVERROR(EAGAIN))
        return fail(file + ": decode error after frame " + std::to_string(frames_out) + " (" +
                    av_error_text(err) + ")");
      if (eof_sent) {  // a draining decoder asking for input: nothing more will come
        finished = true;
        continue;
      }
      err = av_read_frame(fmt, packet);
      if (err < 0) {
        if (err != AVERROR_EOF && !(fmt->pb && avio_feof(fmt->pb)))
          deferred_error = file + ": read error after frame " + std::to_string(frames_out) + " (" +
                           av_error_text(err) + "): truncated or corrupt data";
        avcodec_send_packet(dec, nullptr);
        eof_sent = true;
        continue;
      }
      if (packet->stream_index != stream) {
        av_packet_unref(packet);
        continue;
      }
      const std::int64_t packet_pts = packet->pts;
      err = avcodec_send_packet(dec, packet);
      av_packet_unref(packet);
      if (err < 0 && err != AVERROR(EAGAIN)) {
        std::string where = "after frame " + std::to_string(frames_out);
        if (packet_pts != AV_NOPTS_VALUE)
          where += ", packet at t = " +
                   std::to_string(static_cast<double>(packet_pts - start_pts) * time_base) + " s";
        return fail(file + ": decode error " + where + " (" + av_error_text(err) + ")");
      }
    }
  }

  read_result next_in_sequence(image_view& out, double& out_t) {
    for (;;) {
      if (fmt) {
        const read_result r = decode(out, out_t);
        if (r == read_result::frame) {
          out_t = static_cast<double>(next_file - 1) / options.sequence_fps;
          close_file();  // one image per file
          return r;
        }
        if (r == read_result::error) {
          close_file();  // one error per broken image; go on with the next file
          return r;
        }
        // end without a frame: an image that decodes to nothing.
        close_file();
        return fail(file + ": no frame could be decoded from the image");
      }
      if (next_file >= files.size()) return read_result::end;
      const std::string name = files[next_file++];
      video_info file_info;
      status st = open_file(name, nullptr, file_info);
      if (!st) {
        close_file();
        return fail(st.message());
      }
    }
  }
};

video_source::video_source() = default;
video_source::~video_source() = default;
video_source::video_source(video_source&&) noexcept = default;
video_source& video_source::operator=(video_source&&) noexcept = default;

bool video_source_available() { return true; }

void video_source_quiet_log(bool quiet) { av_log_set_level(quiet ? AV_LOG_QUIET : AV_LOG_INFO); }

status video_source::open(const std::string& path, const video_source_options& options) {
  close();
  if (status st = check_options(options); !st) return st;
  auto p = std::make_unique<impl>();
  p->options = options;
  p->path = path;
  p->packet = av_packet_alloc();
  p->frame = av_frame_alloc();
  if (!p->packet || !p->frame) return status::error(path + ": out of memory");

  // A camera: FORMAT:DEVICE where FORMAT is an input device FFmpeg knows.
  const std::size_t colon = path.find(':');
  if (colon != std::string::npos && colon > 1 && path.compare(0, 5, "file:") != 0) {
    const std::string format = path.substr(0, colon);
    std::error_code ec;
    if (!fs::exists(path, ec) && (format == "v4l2" || format == "video4linux2" ||
                                  format == "avfoundation" || format == "dshow")) {
      const AVInputFormat* device = av_find_input_format(format.c_str());
      if (!device)
        return status::error(path + ": camera input '" + format +
                             "' is not available: avatarmap is built without libavdevice");
      if (status st = p->open_file(path.substr(colon + 1), device, p->info); !st) return st;
      p->open = true;
      impl_ = std::move(p);
      return {};
    }
  }

  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    p->files = folder_images(path);
    if (p->files.empty())
      return status::error(path +
                           ": the folder has no image files (jpg, png, bmp, tif, webp, "
                           "ppm)");
  } else if (fs::exists(path, ec)) {
    if (!fs::is_regular_file(path, ec)) return status::error(path + ": not a regular file");
    if (fs::file_size(path, ec) == 0) return status::error(path + ": empty file");
    if (status st = p->open_file(path, nullptr, p->info); !st) return st;
    p->open = true;
    impl_ = std::move(p);
    return {};
  } else {
    std::string prefix, suffix;
    int width = 0;
    if (path.find('%') == std::string::npos)
      return status::error(path + ": no such file or folder");
    if (!parse_frame_pattern(path, prefix, suffix, width))
      return status::error(path + ": not a file, and not a pattern with one %d or %0Nd");
    p->files = pattern_images(prefix, suffix, width);
    if (p->files.empty())
      return status::error(path + ": no file matches the pattern (looked for numbers 0..4: " +
                           pattern_name(prefix, suffix, width, 0) + ", ...)");
  }

  // A sequence: the first image gives the size and codec.
  video_info first;
  if (status st = p->open_file(p->files.front(), nullptr, first); !st) return st;
  p->close_file();
  p->info.kind = video_source_kind::sequence;
  p->info.width = first.width;
  p->info.height = first.height;
  p->info.codec = first.codec;
  p->info.fps = options.sequence_fps;
  p->info.frame_count = static_cast<std::int64_t>(p->files.size());
  p->info.duration = static_cast<double>(p->files.size()) / options.sequence_fps;
  p->open = true;
  impl_ = std::move(p);
  return {};
}

read_result video_source::next(image_view& out, double& out_t) {
  if (!impl_ || !impl_->open) return read_result::error;
  impl& s = *impl_;
  s.error.clear();
  if (s.info.kind == video_source_kind::sequence) return s.next_in_sequence(out, out_t);
  if (!s.fmt) return read_result::end;
  const read_result r = s.decode(out, out_t);
  if (r == read_result::frame && s.info.kind == video_source_kind::image) {
    // A still image is one frame: of a file of concatenated images, the first.
    out_t = 0.0;
    s.finished = true;
    s.deferred_error.clear();
  }
  return r;
}

const video_info& video_source::info() const {
  static const video_info k_none{};
  return impl_ ? impl_->info : k_none;
}

const std::string& video_source::error() const {
  static const std::string k_empty;
  return impl_ ? impl_->error : k_empty;
}

bool video_source::is_open() const { return impl_ && impl_->open; }

void video_source::close() { impl_.reset(); }

#else  // !AVATARMAP_HAVE_FFMPEG

struct video_source::impl {
  video_info info;
  std::string error;
};

video_source::video_source() = default;
video_source::~video_source() = default;
video_source::video_source(video_source&&) noexcept = default;
video_source& video_source::operator=(video_source&&) noexcept = default;

bool video_source_available() { return false; }

void video_source_quiet_log(bool) {}

status video_source::open(const std::string& path, const video_source_options& options) {
  close();
  if (status st = check_options(options); !st) return st;
  return status::error(path +
                       ": cannot decode video or images: avatarmap was built without FFmpeg "
                       "(install libavformat-dev libavcodec-dev libavutil-dev libswscale-dev "
                       "and configure with AVATARMAP_WITH_FFMPEG=ON)");
}

read_result video_source::next(image_view&, double&) { return read_result::error; }

const video_info& video_source::info() const {
  static const video_info k_none{};
  return k_none;
}

const std::string& video_source::error() const {
  static const std::string k_empty;
  return k_empty;
}

bool video_source::is_open() const { return false; }

void video_source::close() { impl_.reset(); }

#endif  // AVATARMAP_HAVE_FFMPEG

}  // namespace avatarmap
