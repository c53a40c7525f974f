// The live loop: latest-frame-only processing. A grabber thread pulls frames from a source (a
// camera, or a file paced to its time stamps as if it were one) and publishes each into a
// one-frame mailbox; the processing side (the calling thread) always takes the newest frame.
// A frame that is replaced before processing took it is dropped and counted, so processing
// never falls behind the source: latency stays one frame's processing time, not a growing
// queue.
//
// Latency is measured per processed frame from the moment the frame was published (for a
// paced file: its due time) to the moment the consumer returns (landmarks, solve and output
// done). Two frame buffers besides the grabber's own are allocated when the first frame
// arrives (and again only if a larger frame comes); the steady state allocates nothing.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap {

/// Produces the next frame: read_result::frame with `out` (pixels valid until the next call)
/// and its time in seconds; end when there are no more; error for a frame that could not be
/// read (skipped, counted). Runs on the grabber thread.
using frame_grabber = std::function<read_result(image_view& out, double& t)>;

/// What the consumer learns about the frame it is given.
struct live_frame_info {
  long index = 0;           // index of the frame in the source (0-based), drops included
  double t = 0.0;           // the frame's time stamp, seconds
  double age_ms = 0.0;      // how long the frame waited in the mailbox before processing
  long dropped_so_far = 0;  // frames dropped before this one
};

/// Processes one frame (estimation, solving, output). Returns false to stop the loop.
using frame_consumer = std::function<bool(const image_view& image, const live_frame_info& info)>;

struct live_options {
  /// Publish each frame at its time stamp (relative to the first), as a camera would deliver
  /// it. Off: publish as fast as the grabber decodes (a camera paces itself).
  bool pace_to_timestamps = true;
  /// Stop after this many seconds of wall time (0: run until the source ends).
  double max_seconds = 0.0;
  /// Latency samples kept for the percentiles (older ones are overwritten). >= 1.
  int latency_samples = 1 << 16;
  /// Called once when the loop stops for another reason than the source's end (the
  /// consumer, max_seconds), from the calling thread while the grabber may be inside the
  /// grab function: it must make that call return soon (video_source::interrupt), else the
  /// loop waits for the source's next frame or its own time-out. May be empty.
  std::function<void()> wake_grabber;
};

struct live_stats {
  long grabbed = 0;    // frames published by the grabber
  long processed = 0;  // frames the consumer ran on
  long dropped = 0;    // frames replaced before processing took them
  long read_errors = 0;
  double wall_seconds = 0.0;
  double latency_mean_ms = 0.0;  // publish -> consumer done
  double latency_p50_ms = 0.0;
  double latency_p95_ms = 0.0;
  double latency_max_ms = 0.0;
};

/// Runs the loop until the source ends, the consumer returns false, or max_seconds pass
/// (then options.wake_grabber is called).
/// The consumer runs on the calling thread. Errors: bad options (latency_samples < 1). A
/// consumer that throws is not supported (the loop stops the grabber and rethrows).
status run_live(const frame_grabber& grab, const frame_consumer& consume,
                const live_options& options, live_stats& stats);

}  // namespace avatarmap
