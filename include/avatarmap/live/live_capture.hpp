// The grabber of a pulled source (a camera, a network stream, or a file paced to its time
// stamps as if it were one) feeding the live loop (live/live_session.hpp): a thread pulls
// each frame, waits for its due time (a paced file) and pushes it into the session. The
// session is the loop: it keeps only the newest frame (a frame replaced before its worker
// took it is dropped and counted), processes it, measures the latency, and runs the outputs.
// The grabber only decodes, paces and pushes; it allocates nothing (the session copies each
// frame into buffers it grows only for a larger frame).
#pragma once

#include <functional>

#include "avatarmap/core/status.hpp"
#include "avatarmap/io/landmark_file.hpp"  // read_result
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/media/image.hpp"

namespace avatarmap {

/// Produces the next frame: read_result::frame with `out` (pixels valid until the next call)
/// and its time in seconds; end when there are no more; error for a frame that could not be
/// read (skipped, counted). Runs on the grabber thread.
using frame_grabber = std::function<read_result(image_view& out, double& t)>;

struct live_feed_options {
  /// Push each frame at its time stamp (relative to the first), as a camera would deliver
  /// it. Off: push as fast as the grabber decodes (a camera paces itself).
  bool pace_to_timestamps = true;
  /// Stop after this many seconds of wall time (0: run until the source ends or the session
  /// stops).
  double max_seconds = 0.0;
  /// Called once when the feed stops for another reason than the source's end (max_seconds,
  /// the session stopping), from the calling thread while the grabber may be inside the
  /// grab function: it must make that call return soon (video_source::interrupt), else the
  /// feed waits for the source's next frame or its own time-out. May be empty.
  std::function<void()> wake_grabber;
};

struct live_feed_stats {
  long grabbed = 0;           // frames pushed into the session
  long read_errors = 0;       // frames the source could not read (skipped)
  long refused = 0;           // frames the session refused (a bad image; skipped)
  bool source_ended = false;  // the source ended (else max_seconds or the session stopped)
  double wall_seconds = 0.0;  // from the start to the session's stop
};

/// Feeds `session` from `grab` until the source ends (the session then finishes: the frame
/// waiting is processed), max_seconds pass or the session stops by itself (its on_frame
/// returned false); then options.wake_grabber is called when the grabber may be blocked in
/// the source, and the session is stopped (live_session::stop: a frame still waiting is
/// dropped). Returns once the grabber has returned and the session has stopped: no callback
/// of the session runs after it. The session's stats() then hold what was processed,
/// dropped and the latency. Errors: no grabber. A grabber that throws is not supported (the
/// feed stops and rethrows).
status feed_live_session(const frame_grabber& grab, live_session& session,
                         const live_feed_options& options, live_feed_stats& stats);

}  // namespace avatarmap
