// The live loop, written once: images are pushed in (an application's camera thread through
// the C API's live handle and Python's Live, or the CLI's grabber, live/live_capture.hpp), a
// worker thread of the session processes the newest one (capture_pipeline: landmarks -> the
// pose stream: solve, live filter, resampler), any thread asks for the pose at any time
// (resampled between processed frames), and, with output_fps, an output thread of the session
// samples the stream on its own clock at that rate and hands each pose to the outputs (the
// caller's callbacks: a pose file, the browser viewer, a VMC receiver). Only the newest image is
// processed: one pushed while the worker is busy replaces the waiting one (dropped, counted),
// so latency stays one frame's processing time instead of a queue.
//
// Latency (stats(), one statistic for every report: time/latency_stats.hpp) is measured per
// processed image from its push to its pose reaching the stream.
//
// Memory: three image buffers (the caller's copy, the waiting one, the worker's), each grown
// only when a larger image comes, and the latency ring; push(), sample() and latest()
// allocate nothing otherwise, nor do the worker and the output thread (but what the
// callbacks do).
// Thread-safety: push(), sample(), latest(), stats(), last_error(), stopped(), finish() and
// the waits from any threads, concurrently (pushes from several threads are serialised: each
// waits for the one in progress). stop() and the destructor join the threads and must not run
// concurrently with each other (the C API's avm_live_destroy waits for the calls in flight);
// neither may be called from a callback. on_frame runs on the worker thread, the outputs on
// the output thread, one call at a time each.
//
// Several people (pipeline.estimator.max_people > 1): each person has its own pose stream in a
// slot (capture_pipeline.hpp); the output thread hands every held person's pose to every output
// at each tick (live_output_report::person and slot say whose), people() lists them and
// sample_person() samples one. sample() and latest() give the lowest id held.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <vector>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// What the worker tells live_session_options::on_frame about each image it took. Pointers
/// are valid during the call only.
struct live_frame_report {
  long index = 0;                 // the image's push, 0-based (pushes that were dropped count)
  double t = 0.0;                 // its capture time (seconds)
  const status* error = nullptr;  // nullptr: processed; else why the pipeline refused it
  const landmark_frame* frame = nullptr;       // the landmarks (processed images only)
  const proxy_pose* pose = nullptr;            // the solved and filtered pose (processed only)
  const estimator_timings* timings = nullptr;  // the estimator's stages (nullptr: none)
  double latency_ms = 0.0;                     // push -> pose in the stream (processed only)
  long dropped_so_far = 0;                     // images dropped before this one was taken
  /// Several people: every person of the image (frame and pose above are the first's); nullptr
  /// with one person.
  const people_poses* people = nullptr;
};

/// What the output thread tells each output with a pose.
struct live_output_report {
  /// The first output since a newly processed image reached the stream: `pushed_at` is when
  /// that image was pushed (an output measures its own push -> delivery latency from it).
  bool carries_new_frame = false;
  std::chrono::steady_clock::time_point pushed_at{};
  /// Whose pose: the person's id (-1 with one person) and slot (0..max_people-1, the person's
  /// place for as long as its id lives: the k-th VMC destination, the viewer's k-th avatar; 0
  /// with one person).
  int person = -1;
  int slot = 0;
};

/// A person a live session holds (several people).
struct live_person {
  int id = -1;
  int slot = -1;
  double seen_t = 0.0;  // capture time it was last seen
};

/// An output of the session: called on the output thread with each sampled pose (pose.t is its
/// time on the stream's clock, always increasing). Must not block for long (the next sample
/// waits for it) nor call stop().
using live_output = std::function<void(const proxy_pose& pose, const live_output_report& report)>;

struct live_session_options {
  /// Estimator, solver, live filter and sample()'s extrapolation (pipeline.resampler).
  capture_pipeline_options pipeline;
  /// Latency samples kept for the percentiles (a ring; allocated once). >= 1.
  int latency_samples = 4096;
  /// Worker thread, after each image it took (processed or refused by the pipeline). Return
  /// false to stop the session: the worker takes no more images and stopped() turns true.
  /// May be empty (the session then goes on after an error, counting it).
  std::function<bool(const live_frame_report&)> on_frame;
  /// > 0: an output thread samples the stream every 1 / output_fps seconds of wall time at
  /// the stream's clock (the newest processed image's capture time advanced by the wall time
  /// since its pose reached the stream, always increasing) and hands each pose to every
  /// output in order. 0: no output thread (callers sample()). At most k_max_fps.
  double output_fps = 0.0;
  std::vector<live_output> outputs;
  /// Several people, output thread: called once for a person the outputs were handed when it
  /// is no longer held (unseen for k_person_hold_seconds: its slot is freed), with its id and
  /// former slot, before the next poses go out (the viewer's server forgets the slot's pose).
  /// Same rules as an output.
  std::vector<std::function<void(int person, int slot)>> on_person_gone;
};

struct live_session_stats {
  long pushed = 0;     // images pushed
  long processed = 0;  // images the worker processed
  long dropped = 0;    // images replaced before the worker took them (or left at stop())
  long failed = 0;     // images the pipeline refused (bad image, estimator error)
  long outputs = 0;    // poses the output thread sampled and handed to the outputs
  // push -> pose ready (latency_stats: mean and max over all, nearest-rank percentiles over
  // the last latency_samples).
  double latency_mean_ms = 0.0;
  double latency_p50_ms = 0.0;
  double latency_p95_ms = 0.0;
  double latency_max_ms = 0.0;
  double newest_t = 0.0;  // capture time of the newest processed pose (0: none yet)
};

class live_session {
 public:
  /// Makes the pipeline (loads the models) and starts the worker (and the output thread with
  /// output_fps > 0). Errors: bad options (the message names the field), the pipeline's.
  static status create(const live_session_options& options, std::unique_ptr<live_session>& out);
  ~live_session();
  live_session(const live_session&) = delete;
  live_session& operator=(const live_session&) = delete;

  /// Camera thread (several are serialised): copies `image` (capture time `t`, seconds,
  /// increasing) for the worker and returns at once. Errors: a bad image (check_image), a
  /// time that is not finite, a session that has stopped or finishes; nothing is queued then.
  status push(const image_view& image, double t);
  /// Any thread: the pose at capture time `t` (slerp between processed frames, a short
  /// extrapolation past the newest, then held). false before the first processed frame.
  bool sample(double t, proxy_pose& out) const;
  /// Any thread: the newest processed pose. false before the first.
  bool latest(proxy_pose& out) const;
  /// Any thread, several people: the people held now (in view, or unseen for under
  /// k_person_hold_seconds), ascending by id, into out[0 .. min(count, capacity)); returns the
  /// count. One person: one entry (id 0, slot 0) once a pose was processed.
  int people(live_person* out, int capacity) const;
  /// Any thread: as sample(), for the person `id`; false when it is not held.
  bool sample_person(int id, double t, proxy_pose& out) const;
  live_session_stats stats() const;
  /// The last error the worker met processing an image (ok when none); it keeps going unless
  /// on_frame says otherwise.
  status last_error() const;

  /// No more images will come: the worker processes the one waiting, then stops. Pushes fail
  /// from now on.
  void finish();
  /// Whether the worker has stopped (finish() drained, on_frame returned false, or stop()).
  bool stopped() const;
  /// Waits until stopped(); with a deadline, returns stopped() when it passes.
  void wait_stopped() const;
  bool wait_stopped_until(std::chrono::steady_clock::time_point deadline) const;
  /// Stops now: an image still waiting is dropped (counted), the worker and the output thread
  /// are joined, and no callback runs after it returns. Idempotent; the destructor calls it.
  void stop();

 private:
  struct impl;
  explicit live_session(std::unique_ptr<impl> p);
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
