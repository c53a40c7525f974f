// Frames for the capture stage: a video file (mp4, webm, mkv, ...), a still image (jpg, png,
// ...), an image sequence (a folder of images or a printf pattern), an input device (a
// camera "v4l2:/dev/video0", FFmpeg's test patterns "lavfi:testsrc", ...) or a network
// stream (udp://, rtp://, rtsp://, srt://, http://, ...), decoded to RGB8 through FFmpeg's
// libraries (libavformat, libavcodec, libswscale; libavdevice for devices). No FFmpeg type
// appears here; a build without FFmpeg (AVATARMAP_WITH_FFMPEG=OFF or the libraries not
// found) keeps this interface, and open() then fails saying so.
//
// Frames are converted into a buffer owned by the source and reused from frame to frame: a
// video in its steady state allocates nothing per frame in avatarmap (FFmpeg's decoders
// keep their own pools). Image sequences open each file in turn, which FFmpeg allocates for.
//
// Devices and URLs ("live inputs") never block for ever: open() gives up after
// options.open_timeout_seconds without a picture, next() after options.stall_timeout_seconds
// without a frame (it then returns end and end_reason() says why), and interrupt() makes a
// next() blocked in another thread return. Details and figures: docs/live.md.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/option_table.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/io/landmark_file.hpp"  // read_result
#include "avatarmap/media/image.hpp"

namespace avatarmap {

/// Options of video_source::open(); a struct so that fields can be added compatibly.
struct video_source_options {
  /// Decoder threads: 1 (the default) leaves the other cores to the estimator; 0 lets FFmpeg
  /// choose. Accepted range 0..64.
  int max_threads = 1;
  /// Pixel format of the frames next() returns. Only rgb8 is supported; others fail open().
  pixel_format output_format = pixel_format::rgb8;
  /// Frame rate of image sequences (folder or pattern), frames per second, > 0: frame i is
  /// given the time i / sequence_fps. Videos use their own time stamps.
  double sequence_fps = 30.0;
  /// Largest accepted frame, in pixels per side (1..16384). Larger images are refused with
  /// a message, before their pixels are allocated where the container says their size.
  int max_size = 16384;

  // Devices only (FORMAT:DEVICE); given for any other input, open() fails. Each is passed
  // to the device as FFmpeg's option of that name; a device without the option fails open()
  // with a message naming it.
  /// Frame size asked of the device, "WIDTHxHEIGHT" (each 1..16384); "" = its default.
  std::string video_size;
  /// Frame rate asked of the device, frames per second, (0, 1000]; 0 = its default.
  double framerate = 0.0;
  /// Pixel format or codec asked of the device (v4l2's input_format, other devices'
  /// pixel_format): "mjpeg", "yuyv422", ...; letters, digits and '_', at most 32; "" = its
  /// default.
  std::string input_format;

  // Devices and URLs only.
  /// Seconds open() waits for the input to connect and show its first picture, 0.1..3600.
  double open_timeout_seconds = 10.0;
  /// Seconds next() waits for a frame before it reports the input stalled (returns end,
  /// end_reason() "no frame from INPUT for S s: ..."), 0.1..3600.
  double stall_timeout_seconds = 5.0;
};

/// The options a user gives for devices and URLs (the CLI's input flags of capture, live and
/// animate), one row each; video_source::open() checks them.
inline constexpr option_row<video_source_options> k_video_source_option_table[] = {
    option_row<video_source_options>("video_size",
                                     AVATARMAP_OPTION_TEXT(video_source_options, video_size))
        .cli("--video-size", "WxH")
        .not_in_c()
        .help("devices: frame size to ask for (e.g. 1280x720)"),
    option_row<video_source_options>("framerate",
                                     AVATARMAP_OPTION_FIELD(video_source_options, framerate))
        .number(0, k_max_fps, true)
        .or_zero()
        .cli("--framerate", "N")
        .not_in_c()
        .help("devices: frame rate to ask for; 0: the device's"),
    option_row<video_source_options>("input_format",
                                     AVATARMAP_OPTION_TEXT(video_source_options, input_format))
        .cli("--input-format", "NAME")
        .not_in_c()
        .help("devices: pixel format or codec to ask for (v4l2: mjpeg, yuyv422)"),
    option_row<video_source_options>(
        "open_timeout_seconds", AVATARMAP_OPTION_FIELD(video_source_options, open_timeout_seconds))
        .number(0.1, 3600)
        .cli("--open-seconds", "S")
        .not_in_c()
        .help("devices and URLs: give up when no picture came within S s of opening"),
    option_row<video_source_options>(
        "stall_timeout_seconds",
        AVATARMAP_OPTION_FIELD(video_source_options, stall_timeout_seconds))
        .number(0.1, 3600)
        .cli("--stall-seconds", "S")
        .not_in_c()
        .help("devices and URLs: stop when no frame came for S s: \"no frame from INPUT for S "
              "s: the stream stalled or ended\""),
};

/// What kind of input open() found: camera is any input device (FORMAT:DEVICE, a test
/// pattern too), stream a URL.
enum class video_source_kind : std::uint8_t { none, video, image, sequence, camera, stream };

/// Description of an opened source. Sizes are those of the first frame; the frames of an
/// image sequence may differ (each frame's image_view says its own size).
struct video_info {
  video_source_kind kind = video_source_kind::none;
  int width = 0;                 // pixels
  int height = 0;                // pixels
  double fps = 0.0;              // frames per second; 0 = unknown (and for a still image)
  std::int64_t frame_count = 0;  // 0 = unknown (a camera, a container without a count)
  double duration = 0.0;         // seconds; 0 = unknown (and for a still image)
  std::string codec;             // FFmpeg's codec name ("h264", "mjpeg", "png", ...)
};

/// A decoding source of frames. Not copyable; movable. Not thread-safe: one thread at a time.
class video_source {
 public:
  video_source();
  ~video_source();
  video_source(video_source&&) noexcept;
  video_source& operator=(video_source&&) noexcept;
  video_source(const video_source&) = delete;
  video_source& operator=(const video_source&) = delete;

  /// Opens `path` (closing what was open). What it names is decided in this order:
  ///  - an existing file or folder is always that, even with a '%' or ':' in its name;
  ///  - "file:PATH" is the file, folder or pattern PATH;
  ///  - a URL "SCHEME://...": a network stream, for the schemes this build reads
  ///    (video_source_supported_inputs(): udp, rtp, rtsp, srt, http, https, tcp, ... — what
  ///    FFmpeg's protocols provide, never a local one). Read with low latency: little probing
  ///    (256 KiB, 0.5 s), nothing kept from it (the first frame returned is the newest), the
  ///    decoder in low-delay mode; a lost UDP packet is lost, not fatal. A stream may refer
  ///    only to network protocols (no file, pipe or concat), whatever it contains;
  ///  - "FORMAT:DEVICE", FORMAT two or more letters, digits or '_': FFmpeg's input device
  ///    FORMAT (v4l2:/dev/video0, x11grab::0.0, lavfi:testsrc=size=640x480:rate=30, ...)
  ///    with options.video_size, framerate and input_format; opened non-blocking so that a
  ///    stalled device cannot hang next(). Needs a build with libavdevice;
  ///  - with a '%': a printf pattern with one %d or %0Nd (e.g. "frames/%05d.png"), numbered
  ///    from the first of 0..4 that exists on, until a number is missing; frame i at
  ///    t = i / options.sequence_fps;
  ///  - otherwise a missing file.
  /// A video file gives its frames at their own time stamps; a still image one frame at
  /// t = 0 (of a file of concatenated images, the first); a folder its image files (jpg,
  /// jpeg, png, bmp, tif, tiff, webp, ppm, pgm, pnm) in the byte order of their names, frame
  /// i at t = i / options.sequence_fps; a device or URL its frames at their time stamps from
  /// the first one seen.
  /// Fails, with a message that names the path and says what to check, on: a missing file
  /// or folder, an empty file, a file FFmpeg cannot read as media, no video stream, no
  /// decoder for the codec, a zero-size image, an image over options.max_size, a folder with
  /// no images, a pattern with no first file, an unknown URL scheme (listing those this
  /// build reads), a stream that cannot be reached or shows no picture within
  /// open_timeout_seconds, a device this build does not have (listing those it has), a
  /// device that is not there or is busy (for v4l2 listing the /dev/video* present), a
  /// device option the device does not take, device options for another input, bad
  /// options, or a build without FFmpeg.
  status open(const std::string& path, const video_source_options& options = {});

  /// Decodes the next frame into `out` (RGB8, rows `out.stride_bytes` apart) and its
  /// presentation time in seconds from the start into `out_t`. The pixels belong to the
  /// source and stay valid until the next call to next(), open(), close() or destruction.
  /// Returns:
  ///  - frame: `out`/`out_t` are set;
  ///  - end: no more frames (and on every later call);
  ///  - error: a frame could not be decoded or read (corrupt or truncated data, an unreadable
  ///    file of a sequence); error() says what, naming the file. The caller may call next()
  ///    again to go on with what can still be decoded. Data cut short is reported after the
  ///    frames that could still be decoded from it.
  ///  - For a device or URL, end also when no frame came for options.stall_timeout_seconds,
  ///    when the stream ends or breaks off, or after interrupt(); end_reason() says which.
  /// Calling next() on a source that is not open returns error.
  read_result next(image_view& out, double& out_t);

  /// Why next() returned end on a device or URL: "no frame from INPUT for S s: the stream
  /// stalled or ended", "INPUT: the stream ended", "INPUT: read error ...: the stream broke
  /// off" (or the device's versions of these). "" for files, before the end, and after
  /// interrupt().
  const std::string& end_reason() const;

  /// Makes a next() running in another thread return end soon (within about 0.1 s for a
  /// stream waiting on the network), and every later next() too. The one call that may come
  /// from another thread, while next() runs; not while open(), close() or the destructor
  /// run.
  void interrupt();

  /// Valid after a successful open().
  const video_info& info() const;
  /// The message of the last error returned by next(); "" when there was none.
  const std::string& error() const;
  bool is_open() const;
  void close();

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

/// Whether this build decodes with FFmpeg (false: open() always fails).
bool video_source_available();

/// What video_source::open() reads besides files, in this build, sorted.
struct video_source_inputs {
  /// FFmpeg's video input devices, by each of their names ("lavfi", "v4l2", "video4linux2",
  /// "x11grab", ...): FORMAT in FORMAT:DEVICE. Empty without libavdevice.
  std::vector<std::string> devices;
  /// URL schemes: FFmpeg's network protocols for reading ("http", "https", "rtp", "srt",
  /// "tcp", "udp", ...) and "rtsp"/"rtsps" (FFmpeg's RTSP client).
  std::vector<std::string> url_schemes;
};
video_source_inputs video_source_supported_inputs();

/// Process-wide: silences (true) or restores to FFmpeg's default (false) the log that
/// FFmpeg's libraries write to stderr (warnings on corrupt data, probing notes). What goes
/// wrong still reaches open()'s status and next()'s error(). Changes global FFmpeg state:
/// call it from one thread, before decoding. No effect in a build without FFmpeg.
void video_source_quiet_log(bool quiet);

/// `text` as messages and logs show it: a URL's password (and a user name without one) is
/// replaced by "***" ("rtsp://cam:secret@10.0.0.5/live" -> "rtsp://cam:***@10.0.0.5/live"),
/// since what users paste from a camera's settings often carries them. Other texts unchanged.
std::string shown_input(const std::string& text);

}  // namespace avatarmap
