// One image in, its landmarks and the proxy pose out: the estimator (capture/estimator.hpp),
// the solver (solve/frame_solver.hpp) and the live filter (time/pose_filter.hpp) behind one
// call. It is the per-frame step of every live workflow (the C API's estimator and live
// handles; live_session.hpp). Frames must come in capture order (the solver and the filter
// keep state between them).
//
// Memory: everything is made at create(); process() allocates nothing beyond what the
// estimator's backend does (ONNX Runtime). The solver takes the image size from the first
// image (unless given in the options) and is remade, with fresh state, when it changes.
// Thread-safety: one pipeline per thread at a time.
#pragma once

#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/pose_filter.hpp"

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

  /// Checks the solver's options and the backend name; the message names the field.
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

  /// Estimates the landmarks of `image` (capture time `t`, seconds) into `frame` and solves and
  /// filters them into `pose` (pose.t = t). A frame with no person is not an error (the solver
  /// holds and eases what it lost). Errors: a bad image (check_image), the estimator's.
  status process(const image_view& image, double t, landmark_frame& frame, proxy_pose& pose);

  /// Where the time of the last process() went in the estimator (nullptr: no stages).
  const estimator_timings* last_timings() const;
  /// Forgets the solver's and the filter's state (a new take).
  void reset();
  const capture_pipeline_options& options() const { return options_; }

 private:
  capture_pipeline() = default;
  capture_pipeline_options options_;
  std::unique_ptr<estimator> estimator_;
  frame_solver solver_;
  pose_filter filter_;
  estimate_args args_;
  int solver_width_ = 0, solver_height_ = 0;  // image size the solver was made for
};

}  // namespace avatarmap
