// video_source: FFmpeg demuxing + decoding + swscale to RGB8 (or a stub without FFmpeg).
#include "avatarmap/media/video_source.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "media/frame_pattern.hpp"
#include "media/input_spec.hpp"

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
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
#if AVATARMAP_HAVE_AVDEVICE
#include <libavdevice/avdevice.h>
#endif
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
  if (!o.video_size.empty()) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(o.video_size.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
        w < 1 || h < 1 || w > 16384 || h > 16384)
      return status::error("video_source: video_size is '" + o.video_size +
                           "', wanted WIDTHxHEIGHT, each 1..16384 (e.g. 1280x720)");
  }
  if (!(o.framerate >= 0.0 && o.framerate <= k_max_fps))
    return status::error(
        "video_source: framerate must be 0 (the device's default) or in "
        "(0, " +
        limit_text(k_max_fps) + "] frames per second");
  if (o.input_format.size() > 32 ||
      !std::all_of(o.input_format.begin(), o.input_format.end(),
                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
    return status::error("video_source: input_format is '" + o.input_format +
                         "', wanted a pixel format or codec name (letters, digits, '_'; e.g. "
                         "mjpeg, yuyv422)");
  for (const double s : {o.open_timeout_seconds, o.stall_timeout_seconds})
    if (!(s >= 0.1 && s <= 3600.0))
      return status::error(
          "video_source: open_timeout_seconds and stall_timeout_seconds must "
          "be in 0.1..3600");
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

using steady = std::chrono::steady_clock;

// Network protocols a URL may use, also for what a stream opens in turn (RTSP's RTP over UDP
// or TCP, HTTPS's TLS, an HLS playlist's segments and keys): FFmpeg's protocol_whitelist.
// Local ones (file, pipe, fd, concat, subfile, data, unix, cache) are never in it, so that
// what a stream says cannot make avatarmap read a local file.
constexpr const char* k_network_protocols[] = {
    "udp",     "udplite", "rtp",    "srtp",      "tcp",         "tls",       "http",
    "https",   "srt",     "rist",   "rtmp",      "rtmpe",       "rtmps",     "rtmpt",
    "rtmpte",  "rtmpts",  "mmsh",   "mmst",      "ftp",         "sftp",      "gopher",
    "gophers", "sctp",    "crypto", "httpproxy", "ffrtmpcrypt", "ffrtmphttp"};
// Of those, helpers that a stream uses and a user does not write as a scheme.
constexpr const char* k_helper_protocols[] = {"crypto", "httpproxy", "ffrtmpcrypt", "ffrtmphttp"};

// Quick start of URLs: probing measures no frame rate from frames (FFmpeg's default reads
// 20 frames for it, unless the stream states its rate: 4 s at 5 fps). Probing still reads
// until it has seen the codec's parameters (a key frame), up to FFmpeg's default 5 MB / 5 s,
// which a stream joined between key frames needs. What probing read is still delivered (no
// fflags nobuffer): `capture` loses nothing, and the live loop drops what is stale (it keeps
// only the newest frame).
constexpr const char* k_stream_fpsprobesize = "0";  // frames
// A device opened non-blocking (so that a stalled one cannot hang next()) is polled this
// often while it has no frame.
constexpr std::chrono::milliseconds k_device_poll{1};

void register_devices() {
#if AVATARMAP_HAVE_AVDEVICE
  static std::once_flag once;
  std::call_once(once, [] { avdevice_register_all(); });
#endif
}

bool in_list(const std::string& name, const char* const* begin, const char* const* end) {
  return std::any_of(begin, end, [&](const char* p) { return name == p; });
}

std::string join(const std::vector<std::string>& v) {
  std::string r;
  for (const std::string& s : v) r += (r.empty() ? "" : ", ") + s;
  return r.empty() ? "none" : r;
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

// The camera nodes /dev/video* present now, for a message.
std::string present_cameras() {
  std::vector<std::string> r;
  std::error_code ec;
  for (fs::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().rfind("video", 0) == 0) r.push_back(it->path().string());
  std::sort(r.begin(), r.end());
  return r.empty() ? "none" : join(r);
}

}  // namespace

video_source_inputs video_source_supported_inputs() {
  video_source_inputs r;
#if AVATARMAP_HAVE_AVDEVICE
  register_devices();
  for (const AVInputFormat* f = nullptr; (f = av_input_video_device_next(f)) != nullptr;) {
    const std::string names = f->name;  // "video4linux2,v4l2": one format, two names
    for (std::size_t b = 0; b <= names.size();) {
      std::size_t e = names.find(',', b);
      if (e == std::string::npos) e = names.size();
      if (e > b) r.devices.push_back(names.substr(b, e - b));
      b = e + 1;
    }
  }
#endif
  void* opaque = nullptr;
  bool has_tls = false;
  while (const char* name = avio_enum_protocols(&opaque, 0)) {
    const std::string n = name;
    has_tls = has_tls || n == "tls";
    if (in_list(n, std::begin(k_network_protocols), std::end(k_network_protocols)) &&
        !in_list(n, std::begin(k_helper_protocols), std::end(k_helper_protocols)))
      r.url_schemes.push_back(n);
  }
  if (av_find_input_format("rtsp")) {  // a demuxer, not a protocol: it opens RTP, UDP, TCP
    r.url_schemes.push_back("rtsp");
    if (has_tls) r.url_schemes.push_back("rtsps");
  }
  for (auto* v : {&r.devices, &r.url_schemes}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  return r;
}

struct video_source::impl {
  video_source_options options;
  video_info info;
  std::string path;
  std::string error;
  std::string end_reason;
  bool open = false;
  bool live = false;  // a device or a URL: deadlines apply, the end is explained

  // The file being decoded (the whole video, or one image of a sequence); for a device or
  // URL, the input as given (messages name it).
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

  // FFmpeg's interrupt callback: blocking reads (network waits, device probing) return
  // AVERROR_EXIT once interrupt() was called or the deadline (steady clock, ns) has passed.
  std::atomic<bool> abort{false};
  std::atomic<std::int64_t> deadline{std::numeric_limits<std::int64_t>::max()};
  std::atomic<bool> deadline_hit{false};

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

  void set_deadline(double seconds) {
    deadline_hit = false;
    deadline = std::chrono::duration_cast<std::chrono::nanoseconds>(
                   steady::now().time_since_epoch() + std::chrono::duration<double>(seconds))
                   .count();
  }
  void clear_deadline() {
    deadline_hit = false;
    deadline = std::numeric_limits<std::int64_t>::max();
  }
  // True once interrupt() was called or the deadline passed (then deadline_hit is set).
  bool should_stop() {
    if (abort.load(std::memory_order_relaxed)) return true;
    const std::int64_t d = deadline.load(std::memory_order_relaxed);
    if (d == std::numeric_limits<std::int64_t>::max()) return false;
    const std::int64_t now =
        std::chrono::duration_cast<std::chrono::nanoseconds>(steady::now().time_since_epoch())
            .count();
    if (now < d) return false;
    deadline_hit = true;
    return true;
  }
  static int interrupt_callback(void* opaque) {
    return static_cast<impl*>(opaque)->should_stop() ? 1 : 0;
  }

  // Every nested open of a network input (an HLS playlist's segments and keys, a DASH
  // manifest's parts) passes here before FFmpeg's own whitelist refuses a local protocol:
  // the refusal is remembered so that the message says what happened, rather than "not a
  // stream FFmpeg can read".
  int (*default_io_open)(AVFormatContext*, AVIOContext**, const char*, int,
                         AVDictionary**) = nullptr;
  std::string refused_protocol;  // the local protocol a stream asked for ("file"), if any
  static int checked_io_open(AVFormatContext* s, AVIOContext** pb, const char* url, int flags,
                             AVDictionary** options) {
    impl* self = static_cast<impl*>(s->opaque);
    if (self->live && url != nullptr) {
      const char* proto = avio_find_protocol_name(url);
      const std::string name = proto ? proto : "";
      bool network = false;
      for (const char* p : k_network_protocols) network = network || name == p;
      if (!network) {
        if (self->refused_protocol.empty()) self->refused_protocol = name.empty() ? "?" : name;
        return AVERROR(EPERM);
      }
    }
    return self->default_io_open(s, pb, url, flags, options);
  }

  // Opens `url` with the demuxer `format` (nullptr: probed) and the options `opts` (freed
  // here) into `fmt`, with the interrupt callback; returns 0 or FFmpeg's error code.
  int open_input(const std::string& url, const AVInputFormat* format, AVDictionary*& opts,
                 bool nonblock) {
    close_file();
    fmt = avformat_alloc_context();
    if (!fmt) {
      av_dict_free(&opts);
      return AVERROR(ENOMEM);
    }
    fmt->interrupt_callback.callback = &impl::interrupt_callback;
    fmt->interrupt_callback.opaque = this;
    fmt->opaque = this;
    default_io_open = fmt->io_open;
    refused_protocol.clear();
    if (default_io_open) fmt->io_open = &impl::checked_io_open;
    if (nonblock) fmt->flags |= AVFMT_FLAG_NONBLOCK;
    const int err = avformat_open_input(&fmt, url.c_str(), format, &opts);
    av_dict_free(&opts);
    if (err < 0) fmt = nullptr;  // freed by avformat_open_input
    return err;
  }

  // Opens the file `name` and its decoder; on success fills the parts of `out_info` that
  // come from the stream.
  status open_file(const std::string& name, video_info& out_info) {
    file = name;
    AVDictionary* fmt_options = nullptr;
    // A file name is a file name: never a protocol ("concat:", "http:" ...), also not for
    // what the file refers to (playlists), and never a pattern (image2 reads '%').
    av_dict_set(&fmt_options, "protocol_whitelist", "file", 0);
    av_dict_set(&fmt_options, "pattern_type", "none", 0);
    const int err = open_input("file:" + name, nullptr, fmt_options, false);
    if (err < 0)
      return status::failure(err == AVERROR_INVALIDDATA ? status_code::parse : status_code::io,
                             name + ": cannot be read as media (" + av_error_text(err) +
                                 "): not a media file, or a truncated or corrupt one");
    return open_decoder(out_info, false);
  }

  // Opens the device FORMAT:DEVICE of `spec` with the options' size, rate and format.
  status open_device(const input_spec& spec) {
    file = path;
#if AVATARMAP_HAVE_AVDEVICE
    constexpr bool have_devices = true;
#else
    constexpr bool have_devices = false;
#endif
    if (!have_devices)
      return status::unsupported(path + ": no such file, and input devices (" + spec.name +
                                 ":DEVICE) are not available: avatarmap was built without "
                                 "libavdevice (install libavdevice-dev and rebuild)");
    const video_source_inputs inputs = video_source_supported_inputs();
    if (std::find(inputs.devices.begin(), inputs.devices.end(), spec.name) == inputs.devices.end())
      return status::error(path + ": no such file, and '" + spec.name +
                           "' is not a video input device of this FFmpeg (devices: " +
                           join(inputs.devices) + "; URLs are written SCHEME://...)");
    const AVInputFormat* device = av_find_input_format(spec.name.c_str());
    if (!device)
      return status::unsupported(path + ": the device '" + spec.name + "' is not available");
    // What the device accepts is in its private options.
    auto takes = [&](const char* option) {
      const AVClass* cls = device->priv_class;
      return cls && av_opt_find(&cls, option, nullptr, 0, AV_OPT_SEARCH_FAKE_OBJ) != nullptr;
    };
    AVDictionary* opts = nullptr;
    struct wanted {
      const char* flag;
      const char* option;
      std::string value;
    };
    const char* format_option = takes("input_format") ? "input_format" : "pixel_format";
    const wanted asked[] = {
        {"video size (--video-size)", "video_size", options.video_size},
        {"frame rate (--framerate)", "framerate",
         options.framerate > 0 ? seconds_text(options.framerate) : std::string()},
        {"input format (--input-format)", format_option, options.input_format}};
    for (const wanted& w : asked) {
      if (w.value.empty()) continue;
      if (!takes(w.option)) {
        av_dict_free(&opts);
        return status::error(path + ": the device '" + spec.name + "' takes no " + w.flag +
                             (spec.name == "lavfi" ? " (give it in the filter graph, e.g. "
                                                     "lavfi:testsrc=size=640x480:rate=30)"
                                                   : ""));
      }
      av_dict_set(&opts, w.option, w.value.c_str(), 0);
    }
    set_deadline(options.open_timeout_seconds);
    const int err = open_input(spec.target, device, opts, true);
    if (err < 0) {
      std::string m = path + ": cannot open the device (" + av_error_text(err) + ")";
      if (deadline_hit)
        m = path + ": nothing came from the device within " +
            seconds_text(options.open_timeout_seconds) +
            " s (--open-seconds); check that it is connected and delivering";
      else if (err == AVERROR(ENOENT) && (spec.name == "v4l2" || spec.name == "video4linux2"))
        m += ": no camera at " + spec.target + " (cameras here: " + present_cameras() +
             "); check the cable and the name";
      else if (err == AVERROR(EACCES) || err == AVERROR(EPERM))
        m += ": this user may not read it (on Linux: add the user to the 'video' group)";
      else if (err == AVERROR(EBUSY))
        m += ": another program is using it";
      else if (err == AVERROR(EINVAL) && !(options.video_size.empty() && options.framerate == 0 &&
                                           options.input_format.empty()))
        m += ": check that the device supports the size, rate and format asked";
      else
        m += ": check the device name, that it is connected, and that no other program "
             "holds it";
      return status::io_error(m);
    }
    const status st = open_decoder(info, true);
    clear_deadline();
    if (!st) return st;
    info.kind = video_source_kind::camera;
    return {};
  }

  // Opens the URL of `spec`: its scheme must be one of this build's network protocols.
  status open_url(const input_spec& spec) {
    file = path;
    const video_source_inputs inputs = video_source_supported_inputs();
    if (std::find(inputs.url_schemes.begin(), inputs.url_schemes.end(), spec.name) ==
        inputs.url_schemes.end())
      return status::error(path + ": unknown URL scheme '" + spec.name + "': this build reads " +
                           join(inputs.url_schemes) +
                           " (and files, folders, patterns, devices FORMAT:DEVICE)");
    std::string whitelist;
    for (const char* p : k_network_protocols)
      whitelist += (whitelist.empty() ? "" : ",") + std::string(p);
    const std::string stall_us =
        std::to_string(static_cast<std::int64_t>((options.stall_timeout_seconds + 1.0) * 1e6));
    AVDictionary* opts = nullptr;
    av_dict_set(&opts, "protocol_whitelist", whitelist.c_str(), 0);
    av_dict_set(&opts, "fpsprobesize", k_stream_fpsprobesize, 0);
    // Protocols' own time-outs, a second after the interrupt callback's (which gives the
    // clearer message): a read that waits longer fails.
    av_dict_set(&opts, "rw_timeout", stall_us.c_str(), 0);
    if (spec.name == "rtsp" || spec.name == "rtsps")
      av_dict_set(&opts, "timeout", stall_us.c_str(), 0);  // RTSP's socket time-out
    if (spec.name == "udp" || spec.name == "udplite") {
      // A reader that falls behind loses packets instead of failing the stream.
      av_dict_set(&opts, "overrun_nonfatal", "1", 0);
    }
    set_deadline(options.open_timeout_seconds);
    const int err = open_input(spec.target, nullptr, opts, false);
    if (err < 0) {
      std::string m = path + ": cannot open the stream (" + av_error_text(err) + ")";
      if (deadline_hit || err == AVERROR(ETIMEDOUT))
        m = path + ": nothing came within " + seconds_text(options.open_timeout_seconds) +
            " s (--open-seconds); check that the sender runs and sends to this address and "
            "port";
      else if (err == AVERROR(ECONNREFUSED))
        m += ": no server at this address and port; check the URL and that the server runs";
      else if (!refused_protocol.empty())
        m = path + ": the stream refers to something to read through '" + refused_protocol +
            "' (a local file or pipe), which avatarmap refuses for network inputs: a stream may "
            "only lead to other network addresses (docs/security.md)";
      else if (err == AVERROR_INVALIDDATA)
        m += ": what came is not a stream FFmpeg can read";
      else
        m += ": check the URL, and that the stream runs and is reachable from here";
      return status::io_error(m);
    }
    status st = open_decoder(info, false);
    if (st && fmt->pb && (deadline_hit || fmt->pb->error == AVERROR(ETIMEDOUT))) {
      // Probing waited for more than the stream sent (within the open time-out, or a read
      // within rw_timeout) and stopped with what it had, which was enough. The reader took
      // the time-out for an end: reading goes on from where it stopped.
      fmt->pb->eof_reached = 0;
      fmt->pb->error = 0;
    }
    clear_deadline();
    if (!st) {
      if (deadline_hit)
        return status::io_error(path + ": no picture within " +
                                seconds_text(options.open_timeout_seconds) +
                                " s (--open-seconds): " + st.message());
      return st;
    }
    info.kind = video_source_kind::stream;
    return {};
  }

  // Reads the stream information of the open `fmt` and opens the decoder of its video.
  status open_decoder(video_info& out_info, bool device) {
    const std::string& name = file;
    // Probing may decode a first picture; FFmpeg refuses pictures over about 16250x16250
    // itself (av_image_check_size), so the allocation is bounded as with max_size's limit.
    // max_pixels is not given here: the size must come out to be reported against max_size.
    int err = avformat_find_stream_info(fmt, nullptr);
    if (err < 0)
      return status::parse_error(name + ": cannot read the stream information (" +
                                 av_error_text(err) + ")");

    const AVCodec* codec = nullptr;
    stream = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
    if (stream == AVERROR_STREAM_NOT_FOUND)
      return status::parse_error(name + ": no video stream (" + std::to_string(fmt->nb_streams) +
                                 " other stream(s))");
    if (stream < 0 || !codec) {
      const AVCodecID id =
          stream >= 0 ? fmt->streams[stream]->codecpar->codec_id : AV_CODEC_ID_NONE;
      return status::unsupported(name + ": no decoder for the video codec '" +
                                 avcodec_get_name(id) + "' in this FFmpeg build");
    }
    AVStream* st = fmt->streams[stream];
    const AVCodecParameters* par = st->codecpar;
    if (par->width <= 0 || par->height <= 0)
      return status::parse_error(name + ": no picture could be read (size " +
                                 std::to_string(par->width) + "x" + std::to_string(par->height) +
                                 "): a broken or empty image or video, or one over FFmpeg's own " +
                                 "size limit (about 16000x16000)");
    if (par->width > options.max_size || par->height > options.max_size)
      return status::error(name + ": the image is " + std::to_string(par->width) + "x" +
                           std::to_string(par->height) + ", larger than the " +
                           std::to_string(options.max_size) + "x" +
                           std::to_string(options.max_size) + " limit");

    dec = avcodec_alloc_context3(codec);
    if (!dec) return status::out_of_memory(name + ": out of memory");
    err = avcodec_parameters_to_context(dec, par);
    if (err < 0)
      return status::parse_error(name + ": bad codec parameters (" + av_error_text(err) + ")");
    const std::string max_pixels =
        std::to_string(static_cast<std::int64_t>(options.max_size) * options.max_size);
    dec->thread_count = options.max_threads;
    dec->pkt_timebase = st->time_base;
    AVDictionary* dec_options = nullptr;
    av_dict_set(&dec_options, "max_pixels", max_pixels.c_str(), 0);
    err = avcodec_open2(dec, codec, &dec_options);
    av_dict_free(&dec_options);
    if (err < 0)
      return status::parse_error(name + ": cannot open the '" + codec->name + "' decoder (" +
                                 av_error_text(err) + ")");

    time_base = av_q2d(st->time_base);
    start_pts = st->start_time != AV_NOPTS_VALUE ? st->start_time : 0;

    const char* demuxer = fmt->iformat->name;
    const bool still =
        !live && (std::strcmp(demuxer, "image2") == 0 || std::strstr(demuxer, "_pipe") != nullptr);
    out_info.kind = device ? video_source_kind::camera
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
      if (err == AVERROR(EAGAIN) && !should_stop()) {  // a non-blocking device, no frame yet
        std::this_thread::sleep_for(k_device_poll);
        continue;
      }
      if (err < 0) {
        if (live)
          explain_end(err);
        else if (err != AVERROR_EOF && !(fmt->pb && avio_feof(fmt->pb)))
          deferred_error = file + ": read error after frame " + std::to_string(frames_out) + " (" +
                           av_error_text(err) + "): truncated or corrupt data";
        avcodec_send_packet(dec, nullptr);
        eof_sent = true;
        continue;
      }
      if (packet->stream_index != stream) {
        av_packet_unref(packet);
        if (live && should_stop()) {  // other streams' data, but no picture in time
          explain_end(AVERROR_EXIT);
          avcodec_send_packet(dec, nullptr);
          eof_sent = true;
        }
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

  // Why a live input stopped giving packets (`err` from av_read_frame), into end_reason.
  void explain_end(int err) {
    if (abort.load()) {
      end_reason.clear();  // the caller asked for it
      return;
    }
    const bool camera = info.kind == video_source_kind::camera;
    // A demuxer may turn its reader's failure into end of file: the reader keeps the cause
    // (sticky: a frame decoded since may have cleared deadline_hit). AVERROR_EXIT comes only
    // from the interrupt callback, and not from interrupt() here: the deadline.
    const int io_error = fmt->pb ? fmt->pb->error : 0;
    if (deadline_hit || err == AVERROR(ETIMEDOUT) || err == AVERROR_EXIT ||
        io_error == AVERROR(ETIMEDOUT) || io_error == AVERROR_EXIT)
      end_reason = "no frame from " + file + " for " + seconds_text(options.stall_timeout_seconds) +
                   (camera ? " s: the device stalled or was disconnected"
                           : " s: the stream stalled or ended");
    else if ((err == AVERROR_EOF || (fmt->pb && avio_feof(fmt->pb))) && io_error == 0)
      end_reason = file + (camera ? ": the device ended" : ": the stream ended");
    else
      end_reason =
          file +
          (camera ? ": the device failed or was disconnected" : ": the stream ended or broke off") +
          " (read error after frame " + std::to_string(frames_out) + ": " +
          av_error_text(io_error != 0 ? io_error : err) + ")";
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
      status st = open_file(name, file_info);
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
  std::error_code ec;
  const input_spec spec = classify_input(path, fs::exists(path, ec));
  // Messages name the input without a URL's credentials.
  const std::string shown = spec.kind == input_kind::url ? shown_input(path) : path;
  if (spec.kind != input_kind::device &&
      (!options.video_size.empty() || options.framerate > 0 || !options.input_format.empty()))
    return status::error(shown +
                         ": a video size, frame rate or input format is for devices "
                         "(FORMAT:DEVICE, e.g. v4l2:/dev/video0), not for files or URLs");
  auto p = std::make_unique<impl>();
  p->options = options;
  p->path = shown;
  p->packet = av_packet_alloc();
  p->frame = av_frame_alloc();
  if (!p->packet || !p->frame) return status::out_of_memory(shown + ": out of memory");

  if (spec.kind == input_kind::device || spec.kind == input_kind::url) {
    p->live = true;
    register_devices();
    if (status st = spec.kind == input_kind::device ? p->open_device(spec) : p->open_url(spec); !st)
      return st;
    p->open = true;
    impl_ = std::move(p);
    return {};
  }

  const std::string& file = spec.target;  // "file:" removed
  if (fs::is_directory(file, ec)) {
    p->files = folder_images(file);
    if (p->files.empty())
      return status::io_error(shown +
                              ": the folder has no image files (jpg, png, bmp, tif, webp, "
                              "ppm)");
  } else if (fs::exists(file, ec)) {
    if (!fs::is_regular_file(file, ec)) return status::io_error(shown + ": not a regular file");
    if (fs::file_size(file, ec) == 0) return status::parse_error(shown + ": empty file");
    if (status st = p->open_file(file, p->info); !st) return st;
    p->open = true;
    impl_ = std::move(p);
    return {};
  } else {
    std::string prefix, suffix;
    int width = 0;
    if (spec.kind != input_kind::pattern)
      return status::io_error(shown + ": no such file or folder");
    if (!parse_frame_pattern(file, prefix, suffix, width))
      return status::io_error(shown + ": not a file, and not a pattern with one %d or %0Nd");
    p->files = pattern_images(prefix, suffix, width);
    if (p->files.empty())
      return status::io_error(shown + ": no file matches the pattern (looked for numbers 0..4: " +
                              pattern_name(prefix, suffix, width, 0) + ", ...)");
  }

  // A sequence: the first image gives the size and codec.
  video_info first;
  if (status st = p->open_file(p->files.front(), first); !st) return st;
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
  if (s.live) s.set_deadline(s.options.stall_timeout_seconds);
  const read_result r = s.decode(out, out_t);
  if (s.live) s.clear_deadline();
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

const std::string& video_source::end_reason() const {
  static const std::string k_empty;
  return impl_ ? impl_->end_reason : k_empty;
}

bool video_source::is_open() const { return impl_ && impl_->open; }

void video_source::interrupt() {
  if (impl_) impl_->abort.store(true);
}

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
  return status::unsupported(path +
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

const std::string& video_source::end_reason() const {
  static const std::string k_empty;
  return k_empty;
}

bool video_source::is_open() const { return false; }

void video_source::interrupt() {}

void video_source::close() { impl_.reset(); }

video_source_inputs video_source_supported_inputs() { return {}; }

#endif  // AVATARMAP_HAVE_FFMPEG

}  // namespace avatarmap
