// Landmark frames in, proxy poses out: solve (frame_solver; landmark_filter first when asked)
// -> filter (time/filter_rules.hpp: offline_smoother, pose_filter or none) -> foot contacts
// (time/foot_contacts.hpp: foot_contact and the hips following planted feet; both-sided with
// the offline filter, window_frames more delay, else causal without delay) -> resample
// (pose_resampler: at any time through sample(), and, with output_fps, on a fixed grid). The
// one assembly of that chain, used by the solve-file job (files and frames in memory), the
// capture pipeline (one image at a time; the live session samples it) and the C API's solver
// handle.
//
// Output poses: with output_fps 0, every filtered pose, in order (the offline filter and the
// both-sided contact stage delay them by their lookahead; finish() hands over the rest). With
// output_fps > 0, the poses at t0 + j / output_fps for j = 0, 1, 2, ... (t0 = the first filtered
// pose's time) sampled from the resampler as soon as the filtered poses around them are known; a
// filtered pose whose time is not finite gives none. A counted j (not a time advanced by 1 / fps)
// keeps the number of poses per frame exact and bounded whatever the times' magnitude.
//
// Memory: everything is allocated at construction (the offline filter's window only in
// offline mode, the contact stage's ring, the point filter and its frame only when enabled):
// push(), finish() and sample() allocate nothing, but the message of an error. Thread-safety: one
// stream per thread at a time; sample() only reads the resampler (a caller that samples from
// another thread than the one pushing must lock around both).
#pragma once

#include <memory>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/filter_rules.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap {

struct pose_stream_options {
  /// The solver's options. With filters.filter_mode offline the stream opens the confidence
  /// gate (thresholds 0: the smoother decides what was observed; filter_rules.hpp).
  solver_options solver;
  /// Which filter after solving, its options, the channels that take it, point filtering.
  pose_stream_filters filters;
  /// How far sample() (and the grid at output_fps) extrapolates past the newest filtered pose.
  pose_resampler_options resampler;
  /// 0 = one output pose per filtered pose. > 0: output poses on the grid t0 + j / fps. Any
  /// finite rate is safe (the count is bounded below); callers keep their own upper limit.
  double output_fps = 0.0;
  /// Hands every filtered pose to the resampler, for sample() (true), or only when output_fps
  /// needs it (false: a caller that never samples, the solve-file job, saves the copy).
  bool sample_any_time = true;
  /// What messages call the input (a file's name) and output_fps (the CLI says "--fps").
  std::string name;
  std::string output_fps_name = "output_fps";

  /// Checks the solver's options (with the gate as the stream sets it), the filters
  /// (pose_stream_filters::validate), max_extrapolation_seconds finite and >= 0, output_fps
  /// finite and >= 0. The message names the field.
  status validate() const;
};

/// What went through a stream since construction or reset().
struct pose_stream_stats {
  long frames = 0;    // frames pushed (solved)
  long filtered = 0;  // poses out of the filter
  long emitted = 0;   // output poses handed to the caller's emit
  /// Range of the filtered hips_position.y (metres); 0 .. 0 before the first filtered pose.
  float hips_height_min = 0.f;
  float hips_height_max = 0.f;
  /// Filtered poses with each foot's contact above 0.5 ([0] left, [1] right).
  long planted_frames[2] = {0, 0};
};

class pose_stream {
 public:
  /// `options` must pass validate() (checked by assertion).
  explicit pose_stream(const pose_stream_options& options);
  ~pose_stream();
  pose_stream(const pose_stream&) = delete;
  pose_stream& operator=(const pose_stream&) = delete;

  /// Solves `frame` (its time frame.t, seconds), filters the pose and hands every output pose
  /// now ready to `emit`, a callable `status(const proxy_pose&)` (none, one or, with the
  /// offline filter or a grid finer than the frames, several). Stops at the first error
  /// `emit` returns (that error), or when output_fps would write more than
  /// k_max_resampled_frames poses (time/resample_clip.hpp; an error naming `name`, the frame
  /// and output_fps_name).
  template <class Emit>
  status push(const landmark_frame& frame, Emit&& emit) {
    solve(frame);
    return drain(emit);
  }
  /// No more frames: hands the poses the offline filter still holds to `emit` (nothing for
  /// the other filters). The stream takes no more frames until reset().
  template <class Emit>
  status finish(Emit&& emit) {
    finish_filter();
    return drain(emit);
  }

  /// The pose at capture time `t` (seconds) from the resampler (pose_resampler::sample: slerp
  /// between filtered poses, bounded extrapolation past the newest); false before the first
  /// filtered pose or for a `t` that is not finite.
  bool sample(double t, proxy_pose& out) const noexcept { return resampler_.sample(t, out); }

  /// Forgets everything: solver, filters, resampler, grid and stats (a new take).
  void reset();
  /// The file job's warm-up (jobs/solve_file.hpp): learns the camera and the performer's
  /// proportions from a frame without output (the pose state it also advances is forgotten by
  /// restart_take()).
  void learn_camera(const landmark_frame& frame);
  /// Forgets the pose state, filters included, keeping what the solver learnt of the camera
  /// and the performer (frame_solver::restart_take(keep_view)); the stream then starts anew.
  /// The contact stage takes the performer's leg length learnt so far (docs/contacts.md).
  void restart_take(bool keep_view = true);
  /// frame_solver::hold_view.
  void hold_view(bool hold = true) { solver_.hold_view(hold); }
  /// New solver options (a new image size): the solver is remade with fresh state and the
  /// filters start again; the resampler, the grid and the stats are kept. Allocates what a
  /// frame_solver does.
  void restart(const solver_options& solver);

  const pose_stream_options& options() const noexcept { return options_; }
  const pose_stream_stats& stats() const noexcept { return stats_; }
  /// The solver (its field-of-view estimate, the options it runs with).
  const frame_solver& solver() const noexcept { return solver_; }
  /// The solver, to calibrate its face over a take (frame_solver::calibrate_face) before the
  /// first frame is pushed; changing it mid-stream is the caller's responsibility.
  frame_solver& solver() noexcept { return solver_; }

 private:
  // The point filter (when on), then the solver, into solved_.
  void solve_points(const landmark_frame& frame);
  // Everything after the solver back to its start: filters, contacts, resampler, grid, stats.
  void reset_after_solver();
  struct point_stage;  // landmark_filter and its output frame (only when enabled)

  void solve(const landmark_frame& frame);
  void finish_filter() noexcept;
  // Takes the next filtered pose, through the contact stage, into filtered_ (counted, pushed
  // to the resampler); false when none is ready.
  bool next_filtered() noexcept;
  // The last grid index at or before filtered_.t (the grid starts at the first filtered
  // pose), or the error when the grid would exceed k_max_resampled_frames poses.
  status grid_last(long& j_last);

  template <class Emit>
  status drain(Emit& emit) {
    while (next_filtered()) {
      if (!(options_.output_fps > 0.0)) {
        if (status st = emit(static_cast<const proxy_pose&>(filtered_)); !st.ok()) return st;
        ++stats_.emitted;
        continue;
      }
      if (!pushed_) continue;  // a time that is not finite: nothing to sample around
      long j_last = 0;
      if (status st = grid_last(j_last); !st.ok()) return st;
      for (; j_next_ <= j_last; ++j_next_) {
        const double rt = t_grid0_ + static_cast<double>(j_next_) / options_.output_fps;
        if (!resampler_.sample(rt, sampled_)) break;
        sampled_.t = rt;
        if (status st = emit(static_cast<const proxy_pose&>(sampled_)); !st.ok()) return st;
        ++stats_.emitted;
      }
    }
    return {};
  }

  pose_stream_options options_;
  frame_solver solver_;
  pose_filter filter_;
  std::unique_ptr<offline_smoother> smoother_;  // filter_mode offline only
  std::unique_ptr<point_stage> points_;         // filters.landmark_filter.enabled only
  foot_contact_stage contacts_;
  pose_resampler resampler_;
  proxy_pose solved_, staged_, filtered_, sampled_;  // staged_: out of the filter
  bool pending_ = false;    // live / none: staged_ holds a pose not yet taken
  bool finishing_ = false;  // finish(): the contact stage hands over what it holds
  bool pushed_ = false;     // the resampler took filtered_
  pose_stream_stats stats_;
  // The grid (output_fps > 0): its start and the next index to write.
  double t_grid0_ = 0.0;
  bool have_grid_ = false;
  long j_next_ = 0;
};

}  // namespace avatarmap
