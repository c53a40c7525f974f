// Writes RGB8 frames to a video file or to PNG image(s) through FFmpeg's libraries
// (libavformat, libavcodec, libswscale, libavutil). No FFmpeg type appears here; a build
// without FFmpeg (AVATARMAP_WITH_FFMPEG=OFF or the libraries not found) keeps this
// interface, and open() then fails saying so.
//
// The format follows the extension of the path (case-insensitive):
//  - .mp4, .mov, .mkv: H.264 through the "libx264" encoder when this FFmpeg has it (CRF
//    options.crf, preset options.preset), else FFmpeg's own "mpeg4" encoder (MPEG-4 part 2,
//    quantiser options.mpeg4_quality);
//  - .avi: "mpeg4";
//  - .png with one %d or %0Nd in it (e.g. "frames/%05d.png"; "%%" is a literal '%'): one
//    PNG per frame, numbered from options.first_number on;
//  - .png without a pattern: exactly one image, the first frame written; later frames are
//    accepted and ignored.
// Video frames are encoded as YUV 4:2:0 (BT.601, limited range, tagged so), which needs an
// even width and height: an odd size is padded to the next even one by repeating the last
// column and/or row, so a 33x17 input gives a 34x18 video. PNGs are lossless RGB at the size
// given.
//
// Atomic output: frames go to temporary files beside the final ones (the final name plus
// ".tmp." and a unique suffix); close() renames them into place once everything is written.
// Nothing ever appears under a final name half-written; after a failure or a destruction
// without close(), the temporary files are removed and nothing is left. An existing file of
// the same name is replaced only by close(); other files (e.g. a longer sequence of an
// earlier run) are left alone.
//
// Steady state: frames are converted into buffers allocated by open() and reused, and PNG
// file names are formatted into a buffer of open(): avatarmap allocates nothing per frame
// (FFmpeg's encoders and muxers keep their own pools).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/media/image.hpp"

namespace avatarmap {

/// Options of video_writer::open(); a struct so that fields can be added compatibly.
struct video_writer_options {
  /// Video encoder: "" chooses (libx264 when available for .mp4/.mov/.mkv, else mpeg4),
  /// "libx264" or "mpeg4" force one (open() fails when it is missing, and libx264 is not
  /// offered for .avi). Ignored for PNG.
  std::string encoder;
  /// libx264's constant rate factor, 0..51 (lower is better and larger; 23 is x264's default).
  int crf = 23;
  /// libx264's preset ("ultrafast" ... "veryslow"); an unknown one fails open().
  std::string preset = "veryfast";
  /// mpeg4's fixed quantiser, 1..31 (lower is better and larger).
  int mpeg4_quality = 3;
  /// Encoder threads 0..64: 1 (the default) leaves the other cores to the estimator; 0 lets
  /// FFmpeg choose.
  int max_threads = 1;
  /// Number of the first file of a PNG pattern, 0..999999999.
  int first_number = 0;
  /// Largest accepted frame, in pixels per side (1..16384).
  int max_size = 16384;
};

/// What open() is writing.
enum class video_writer_kind : std::uint8_t { none, video, png_sequence, png_single };

/// An encoding sink of frames. Not copyable; movable. Not thread-safe: one thread at a time.
class video_writer {
 public:
  video_writer();
  /// Without close(): discards what was written (temporary files removed).
  ~video_writer();
  video_writer(video_writer&&) noexcept;
  video_writer& operator=(video_writer&&) noexcept;
  video_writer(const video_writer&) = delete;
  video_writer& operator=(const video_writer&) = delete;

  /// Starts writing `path` (discarding what an earlier open() had not closed): frames of
  /// `width` x `height` pixels (1..options.max_size), nominal rate `fps` (frames per second,
  /// 0.01..1000: the time base of the video). Fails, with a message that names
  /// the path, on: a bad size, fps or option; an extension that is none of the above; a PNG
  /// path with a '%' that is not one %d / %0Nd; a folder that does not exist or cannot be
  /// written (the temporary file is created here); a missing encoder; a build without FFmpeg.
  status open(const std::string& path, int width, int height, double fps,
              const video_writer_options& options = {});

  /// Encodes one frame: `rgb` must be rgb8, of the size given to open(), with data set and
  /// stride_bytes >= width * 3; the caller keeps it only for the call. `t` is its time in
  /// seconds: times are measured from the first frame's t and snapped to ticks of 1 / fps
  /// (the first frame is at 0); a t that is not finite or does not reach a tick later than
  /// the previous frame's gets the next tick. PNG output ignores t.
  /// Errors:
  ///  - a bad frame (format, size, data, stride): the frame is refused, the writer stays
  ///    usable;
  ///  - an encoder or file error (disk full, ...): the writer is failed: its temporary files
  ///    are removed, and every later write() and close() returns this error;
  ///  - not open: an error.
  status write(const image_view& rgb, double t);

  /// Flushes the encoder, finishes the file(s) and renames them into place. On error nothing
  /// is left under the final name(s) (for a sequence whose renaming fails part way, the
  /// files renamed so far stay and the rest are removed; the message says so). The writer
  /// is closed afterwards either way. Closing a writer with no frame written is an error
  /// (no file is made). close() on a writer that is not open returns ok.
  status close();

  bool is_open() const;
  /// Valid after a successful open(): what is written, the size of the frames in the file
  /// (even-padded for video) and the encoder's FFmpeg name ("libx264", "mpeg4", "png").
  video_writer_kind kind() const;
  int output_width() const;
  int output_height() const;
  const std::string& encoder_name() const;
  /// Frames accepted by write() since open() (for a single PNG: 1 after the first).
  std::int64_t frames_written() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

/// Whether this build encodes with FFmpeg (false: open() always fails).
bool video_writer_available();

}  // namespace avatarmap
