// Frames for the capture stage: a video file (mp4, webm, mkv, ...), a still image (jpg, png,
// ...), an image sequence (a folder of images or a printf pattern) or a camera, decoded to
// RGB8 through FFmpeg's libraries (libavformat, libavcodec, libswscale). No FFmpeg type
// appears here; a build without FFmpeg (AVATARMAP_WITH_FFMPEG=OFF or the libraries not
// found) keeps this interface, and open() then fails saying so.
//
// Frames are converted into a buffer owned by the source and reused from frame to frame: a
// video in its steady state allocates nothing per frame in avatarmap (FFmpeg's decoders
// keep their own pools). Image sequences open each file in turn, which FFmpeg allocates for.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"  // image_view, pixel_format
#include "avatarmap/core/status.hpp"
#include "avatarmap/io/landmark_file.hpp"  // read_result

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
};

/// What kind of input open() found.
enum class video_source_kind : std::uint8_t { none, video, image, sequence, camera };

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

  /// Opens `path` (closing what was open):
  ///  - a video file, or a still image (one frame, at t = 0; of a file of concatenated
  ///    images, the first);
  ///  - a folder: its image files (jpg, jpeg, png, bmp, tif, tiff, webp, ppm, pgm, pnm), in
  ///    the byte order of their names, frame i at t = i / options.sequence_fps;
  ///  - a printf pattern with one %d or %0Nd (e.g. "frames/%05d.png"), numbered from the
  ///    first of 0..4 that exists on, until a number is missing; times as for a folder.
  ///    A path that names an existing file is always that file, even with a '%' in it.
  ///  - a camera "v4l2:/dev/video0" (FFmpeg's input device FORMAT:DEVICE). This build does
  ///    not link libavdevice, so cameras fail with a message saying so; the interface is
  ///    kept for a build that does. Cameras are not tested.
  /// Fails, with a message that names the path, on: a missing file or folder, an empty
  /// file, a file FFmpeg cannot read as media, no video stream, no decoder for the codec, a
  /// zero-size image, an image over options.max_size, a folder with no images, a pattern
  /// with no first file, bad options, or a build without FFmpeg.
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
  /// Calling next() on a source that is not open returns error.
  read_result next(image_view& out, double& out_t);

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

/// Process-wide: silences (true) or restores to FFmpeg's default (false) the log that
/// FFmpeg's libraries write to stderr (warnings on corrupt data, probing notes). What goes
/// wrong still reaches open()'s status and next()'s error(). Changes global FFmpeg state:
/// call it from one thread, before decoding. No effect in a build without FFmpeg.
void video_source_quiet_log(bool quiet);

}  // namespace avatarmap
