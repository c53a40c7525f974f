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
//
// Several people (options.estimator.max_people > 1; docs/capture-people.md): each person the
// estimator follows is solved through a pose stream of its own, in a slot 0..max_people-1. A
// new id takes the lowest free slot (its stream starts afresh); the slot stays the person's
// while it is in view and for k_person_hold_seconds after it was last seen (the estimator
// keeps a lost person's id that long to give it back), then it is free. A slot is so one
// person's for as long as its id lives: the live outputs use it as the person's place (the
// k-th VMC destination, the viewer's k-th avatar). Every person's hips_position X/Z is
// measured from one origin, where the first person placed was first seen, so that the people
// stand apart as in the image (one person alone starts at its own origin, as with one).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/people_tracker.hpp"
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

/// How long a person's slot is kept after the person was last seen (seconds of capture time):
/// the estimator's wait before a lost id is given up (people_tracker.hpp).
inline constexpr double k_person_hold_seconds = k_keep_lost_seconds;

/// One person of a frame, solved (several people).
struct person_pose {
  int id = -1;    // the person's id (landmark_frame::person)
  int slot = -1;  // its pose stream, 0..max_people-1 (kept while the id lives)
  const landmark_frame* frame = nullptr;  // its landmarks; valid until the next estimate()
  proxy_pose pose;                        // solved and filtered by its own stream (pose.t = t)
};

/// Every person of a frame, ascending by id.
struct people_poses {
  std::array<person_pose, k_max_people> people;
  int count = 0;
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
  /// The pose stream (stream().sample(t): the pose at any capture time); with several people,
  /// slot 0's.
  const pose_stream& stream() const { return *streams_[0]; }

  /// The most people followed (options.estimator.max_people).
  int max_people() const { return static_cast<int>(streams_.size()); }
  /// Several people: solves every person of the last estimate() through its slot's stream into
  /// `out` (ascending id; count 0 when nobody is in view), giving new ids their slots and
  /// freeing the slots of people unseen for k_person_hold_seconds. With one person: the frame
  /// estimate() gave, in slot 0 with id 0 (count 1, or 0 when it has no body). Allocates
  /// nothing. `frame` is what estimate() wrote.
  void solve_people(const landmark_frame& frame, people_poses& out);
  /// Slot `slot`'s stream (0 <= slot < max_people()).
  const pose_stream& stream(int slot) const { return *streams_[slot]; }
  /// The id holding slot `slot` (-1: free) and when it was last seen (capture time).
  int slot_person(int slot) const { return slots_[slot].id; }
  double slot_seen(int slot) const { return slots_[slot].seen_t; }

  /// Where the time of the last process() went in the estimator (nullptr: no stages).
  const estimator_timings* last_timings() const;
  /// Forgets the stream's state: solver, filter, resampler (a new take).
  void reset();
  const capture_pipeline_options& options() const { return options_; }

 private:
  capture_pipeline() = default;
  capture_pipeline_options options_;
  std::unique_ptr<estimator> estimator_;
  std::vector<std::unique_ptr<pose_stream>> streams_;  // one per slot (one person: one)
  struct slot_state {
    int id = -1;  // -1: free
    double seen_t = 0.0;
  };
  std::array<slot_state, k_max_people> slots_{};
  glm::vec2 shared_origin_{0.f};  // several people: the one ground origin
  bool have_shared_origin_ = false;
  // The slot for `id` seen at `t`: its own, else the lowest free one (its stream restarted).
  int slot_for(int id, double t);
  estimate_args args_;
  int solver_width_ = 0, solver_height_ = 0;  // image size the solver was made for
};

}  // namespace avatarmap
