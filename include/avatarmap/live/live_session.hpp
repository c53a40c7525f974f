// A live capture an application drives: its camera thread pushes images, a worker thread of the
// session processes the newest one (capture_pipeline: landmarks -> proxy pose -> live filter),
// and any thread asks for the pose at any time (resampled between processed frames). What the
// C API's live handle is made of. Only the newest image is processed: one pushed while the
// worker is busy replaces the waiting one (dropped, counted), so latency stays one frame's
// processing time instead of a queue.
//
// Memory: three image buffers (the caller's copy, the waiting one, the worker's), each grown
// only when a larger image comes; push(), sample() and latest() allocate nothing otherwise.
// Thread-safety: push(), sample(), latest(), stats() and last_error() from any threads,
// concurrently (pushes from several threads are serialised: each waits for the one in
// progress); the destructor stops and joins the worker and must not run concurrently with any
// other call (the C API's avm_live_destroy waits for the calls in flight).
#pragma once

#include <memory>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap {

struct live_session_options {
  capture_pipeline_options pipeline;
  /// How far sample() extrapolates past the newest processed frame.
  pose_resampler_options resampler;
  /// Latency samples kept for the percentiles (a ring; allocated once). >= 1.
  int latency_samples = 4096;
};

struct live_session_stats {
  long pushed = 0;              // images pushed
  long processed = 0;           // images the worker processed
  long dropped = 0;             // images replaced before the worker took them
  long failed = 0;              // images the pipeline refused (bad image, estimator error)
  double latency_p50_ms = 0.0;  // push -> pose ready, over the kept samples
  double latency_p95_ms = 0.0;
  double latency_max_ms = 0.0;
  double newest_t = 0.0;  // capture time of the newest processed pose (0: none yet)
};

class live_session {
 public:
  /// Makes the pipeline (loads the models) and starts the worker.
  static status create(const live_session_options& options, std::unique_ptr<live_session>& out);
  ~live_session();
  live_session(const live_session&) = delete;
  live_session& operator=(const live_session&) = delete;

  /// Camera thread (several are serialised): copies `image` (capture time `t`, seconds,
  /// increasing) for the worker and returns at once. Errors: a bad image (check_image) or a
  /// time that is not finite; nothing is queued then.
  status push(const image_view& image, double t);
  /// Any thread: the pose at capture time `t` (slerp between processed frames, a short
  /// extrapolation past the newest, then held). false before the first processed frame.
  bool sample(double t, proxy_pose& out) const;
  /// Any thread: the newest processed pose. false before the first.
  bool latest(proxy_pose& out) const;
  live_session_stats stats() const;
  /// The last error the worker met processing an image (ok when none); it keeps going.
  status last_error() const;

 private:
  struct impl;
  explicit live_session(std::unique_ptr<impl> p);
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
