// One image in, its landmarks and the proxy pose out: the estimator (capture/estimator.hpp)
// and the pose stream (solve/pose_stream.hpp: the solver, the live filter and the resampler)
// behind one call. It is the per-frame step of every live workflow (the C API's estimator
// handle; live_session.hpp, the one live loop). Frames must come in capture order (the solver
// and the filter keep state between them).
//
// Memory: everything is made at create(); process() allocates nothing beyond what the
// estimator's backend does (ONNX Runtime). The solver takes the image size from the first
// image (unless given in the options) and is remade, with fresh state, when it changes.
// Thread-safety: one pipeline per thread at a time, except that stream().sample() touches
// only the resampler, which estimate() never does: a caller may run estimate() on one thread
// while another samples, if solve() and sample() are under one lock (live_session does so).
#pragma once

#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/pose_stream.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap {

/// Largest image side accepted (pixels): larger is a caller's mistake, not a camera.
inline constexpr int k_max_image_side = 16384;

/// Checks an image a caller hands in: pixels present, 1 <= width, height <= k_max_image_side,
/// a known pixel format, stride_bytes >= width x bytes per pixel. The message names the field
/// and what it must be.
status check_image(const image_view& image);

struct capture_pipeline_options {
  std::string backend = "onnx";  // estimator_backends(): "onnx", "replay"
  /// The backend's options; estimator.source is the models folder for "onnx". estimator.hands
  /// and estimator.face decide which parts are estimated.
  estimator_options estimator;
  /// The solver's options. image_width/height 0 (the default): taken from each image.
  solver_options solver;
  /// The live filter (One Euro + short extrapolation; enabled = false: the solver's poses).
  pose_filter_options filter;
  /// Foot contacts and the root following planted feet (causal: no added latency;
  /// docs/contacts.md).
  foot_contact_options foot_contacts;
  /// How far stream().sample() extrapolates past the newest pose (the live session's sample()).
  pose_resampler_options resampler;

  /// Checks the solver's options, the filter's parameters, max_extrapolation_seconds finite
  /// and >= 0, and the backend name; the message names the field.
  status validate() const;
};

class capture_pipeline {
 public:
  /// Makes the estimator (loads its models) and the solver. Fails with a message that says what
  /// is missing (an unknown backend, a models folder without the models).
  static status create(const capture_pipeline_options& options,
                       std::unique_ptr<capture_pipeline>& out);
  ~capture_pipeline();
  capture_pipeline(const capture_pipeline&) = delete;
  capture_pipeline& operator=(const capture_pipeline&) = delete;

  /// estimate(), then solve(): the landmarks of `image` (capture time `t`, seconds) into
  /// `frame`, their solved and filtered pose into `pose` (pose.t = t). A frame with no person
  /// is not an error (the solver holds and eases what it lost). Errors: estimate()'s.
  status process(const image_view& image, double t, landmark_frame& frame, proxy_pose& pose);
  /// The estimator's step: checks `image` (check_image; the replay backend needs no pixels)
  /// and `t` (finite), remakes the solver when the image size changed (unless the options give
  /// one), estimates the landmarks into `frame` (frame.t = t). Touches neither the resampler
  /// nor a pose. Errors: a bad image or time, the estimator's.
  status estimate(const image_view& image, double t, landmark_frame& frame);
  /// The pose stream's step: solves `frame`, filters it into `pose` and hands it to the
  /// resampler. Allocates nothing.
  void solve(const landmark_frame& frame, proxy_pose& pose);
  /// The pose stream (stream().sample(t): the pose at any capture time).
  const pose_stream& stream() const { return *stream_; }

  /// Where the time of the last process() went in the estimator (nullptr: no stages).
  const estimator_timings* last_timings() const;
  /// Forgets the stream's state: solver, filter, resampler (a new take).
  void reset();
  const capture_pipeline_options& options() const { return options_; }

 private:
  capture_pipeline() = default;
  capture_pipeline_options options_;
  std::unique_ptr<estimator> estimator_;
  std::unique_ptr<pose_stream> stream_;
  estimate_args args_;
  int solver_width_ = 0, solver_height_ = 0;  // image size the solver was made for
};

}  // namespace avatarmap
