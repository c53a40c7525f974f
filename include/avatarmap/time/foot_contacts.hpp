// Foot contacts and root motion that follows planted feet (docs/contacts.md): the stage of a
// pose stream (solve/pose_stream.hpp) between the filter and the resampler. Per foot, from the
// pose's forward kinematics on the proxy skeleton (heel and toe tip; world = hips_position +
// FK, VRM space, metres), it measures the foot's speed, its height above the floor and its
// confidence, decides with hysteresis whether the foot is planted (slow and low; not the faster
// of two feet parting fast, not a foot that has stepped release_distance away), and writes
// proxy_pose::foot_contact, which moves from 0 to 1 (and back) over blend_seconds. With
// root_follows_contacts, a planted foot holds its anchor (where the contact began): the hips'
// X/Z are moved so that the foot stays there, each foot holding by its contact times (files)
// how slow it is (a planted foot that still moves lets the body go on); with none, the hips move by
// the filtered hips' frame-to-frame motion from where the corrected hips were (no jump). Y stays
// the filtered one: the solver holds the lowest foot point on the floor (Y = 0) in every frame, and
// a planted foot is within release_height of it.
//
// Floor: the stage's floor in each frame is that frame's lowest foot point (the solver puts
// the lowest foot point at Y = 0 in every frame, so the two agree when the proxy's
// proportions match the person's; with a person's other proportions the floor stays under the
// feet). A foot's height is its lowest point (heel or toe tip) above that floor.
//
// Two modes: both-sided (files: the offline filter) looks `window_frames` frames ahead and
// behind (the speed is the smaller of the backward and forward finite differences over that
// window), delaying the output by window_frames frames (finish with flush()); causal (live) has
// no added latency: push() returns the pose it was given, with the speed over the last frame,
// so a landing foot is planted on the first slow frame after it (within 2 frames).
//
// Fallbacks: a foot whose lower leg, foot or toes confidence is below min_confidence (never
// seen: 0) is never planted — locking is off for that leg. A pose whose hips or foot points are
// not finite plants nothing and passes through (hips that are not finite get the previous
// output's, when there is one). A time step over 0.5 s (or a pose without finite points before
// it) lifts every foot; the hips go on from where they were. A time that is not after the
// previous one is a new take: the hips start again from the filtered ones. Output values are
// finite whenever the input's are.
//
// Memory: a ring of 2 x window_frames + 1 poses allocated at construction; push(), flush() and
// reset() allocate nothing. Thread-safety: one stage per stream, one thread at a time.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <limits>
#include <memory>

#include "avatarmap/core/option_table.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

/// The contact stage's options (docs/contacts.md). Speeds in m/s, heights in metres above the
/// frame's floor, times in seconds.
struct foot_contact_options {
  /// Detect contacts and write proxy_pose::foot_contact; false: the stage passes poses through
  /// untouched (foot_contact 0).
  bool enabled = true;
  /// Move the hips so that planted feet stay at their anchors; false: only foot_contact is
  /// written (the hips as filtered).
  bool root_follows_contacts = true;
  /// A foot slower than this and lower than plant_height plants ...
  float plant_speed = 0.5f;
  float plant_height = 0.05f;
  /// ... and a planted foot lifts when faster than this or higher than release_height.
  float release_speed = 0.8f;
  float release_height = 0.12f;
  /// ... or when it has moved this far (metres, horizontally) from where it planted: a slow
  /// step stays under release_speed. Not when the other foot moved with it slower than 5 cm/s
  /// since the plant (the hips' measurement drifting under a person standing still). It plants
  /// again once settled (under half plant_speed).
  float release_distance = 0.12f;
  /// Below this confidence (the least of the lower leg's, the foot's and the toes') a foot is
  /// never planted. Low on purpose: an estimator still reports a foot outside the image or
  /// turned away with a visibility of a few percent, and its pose is what the avatar shows;
  /// holding it while it is slow and low beats letting it slide (docs/contacts.md).
  float min_confidence = 0.01f;
  /// Time foot_contact takes to go from 0 to 1 or back (> 0: no snaps).
  float blend_seconds = 0.1f;
  /// Both-sided mode: frames looked at on each side (the output's delay in frames).
  int window_frames = 4;

  /// Checks every field against k_foot_contact_option_table, then release_speed >= plant_speed
  /// and release_height >= plant_height. The message names the field ("foot_contacts.X").
  status validate() const;
};

/// The rows of foot_contact_options (core/option_table.hpp), the library's names. The front
/// ends take `enabled` and `root_follows_contacts` through the solve-file job's table
/// (jobs/solve_file.hpp: avm_solver_options.foot_contacts and root_follows_contacts,
/// --no-foot-contacts, --no-root-follow); the thresholds are the library's only.
inline constexpr option_row<foot_contact_options> k_foot_contact_option_table[] = {
    option_row<foot_contact_options>("enabled",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, enabled))
        .boolean()
        .not_in_c()
        .help("detect planted feet (avm_solver_options.foot_contacts, --no-foot-contacts)"),
    option_row<foot_contact_options>(
        "root_follows_contacts",
        AVATARMAP_OPTION_FIELD(foot_contact_options, root_follows_contacts))
        .boolean()
        .not_in_c()
        .help("move the hips so that a planted foot stays where it landed "
              "(avm_solver_options.root_follows_contacts, --no-root-follow)"),
    option_row<foot_contact_options>("contact_plant_speed",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, plant_speed))
        .number(0, 100, true)
        .not_in_c()
        .help("a foot slower than this (m/s) and low plants"),
    option_row<foot_contact_options>("contact_plant_height",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, plant_height))
        .number(0, 10, true)
        .not_in_c()
        .help("a foot lower than this above the floor (m) and slow plants"),
    option_row<foot_contact_options>("contact_release_speed",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, release_speed))
        .number(0, 100, true)
        .not_in_c()
        .help("a planted foot faster than this (m/s) lifts"),
    option_row<foot_contact_options>("contact_release_height",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, release_height))
        .number(0, 10, true)
        .not_in_c()
        .help("a planted foot higher than this above the floor (m) lifts"),
    option_row<foot_contact_options>("contact_release_distance",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, release_distance))
        .number(0, 10, true)
        .not_in_c()
        .help("a planted foot that has moved this far (m) from where it planted lifts"),
    option_row<foot_contact_options>("contact_min_confidence",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, min_confidence))
        .number(0, 1)
        .not_in_c()
        .help("a foot less confident than this (lower leg, foot, toes) is never planted"),
    option_row<foot_contact_options>("contact_blend_seconds",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, blend_seconds))
        .number(0, 10, true)
        .not_in_c()
        .help("time foot_contact takes from 0 to 1 or back (seconds)"),
    option_row<foot_contact_options>("contact_window_frames",
                                     AVATARMAP_OPTION_FIELD(foot_contact_options, window_frames))
        .integer(1, 16)
        .not_in_c()
        .help("files: frames looked at on each side to measure a foot's speed"),
};

/// Largest window_frames (the ring's size bound).
inline constexpr int k_max_contact_window_frames = 16;

/// One foot's measurement in one frame (VRM space, metres).
struct foot_measure {
  glm::vec3 point{0.f};  // the sole's middle: halfway between heel and toe tip
  float height = 0.f;    // lowest point (heel or toe tip) above the frame's floor
  bool usable = false;   // confident and finite
};

/// Heel, toe tip and usability of both feet of `pose` ([0] left, [1] right), the floor being
/// the lowest of the four points (the legs' forward kinematics only, compute_proxy_feet).
/// `skeleton` gives the proportions. Allocates nothing.
void measure_feet(const proxy_skeleton& skeleton, const proxy_pose& pose, float min_confidence,
                  std::array<foot_measure, 2>& out);

class foot_contact_stage {
 public:
  /// `options` must pass validate() (asserted). `both_sided`: files (delay window_frames);
  /// false: live (no delay). `skeleton`: the proportions FK uses (the 1.70 m proxy by default).
  foot_contact_stage(const foot_contact_options& options, bool both_sided,
                     const proxy_skeleton& skeleton = make_proxy_skeleton());
  ~foot_contact_stage();
  foot_contact_stage(const foot_contact_stage&) = delete;
  foot_contact_stage& operator=(const foot_contact_stage&) = delete;

  /// Takes the next pose (in time order). Returns true when `out` holds the next output pose:
  /// always in causal mode (the same pose, contacts written, hips corrected); in both-sided
  /// mode once window_frames later poses have come. With options.enabled false: `out` = `in`.
  /// `out` must not be `in`.
  bool push(const proxy_pose& in, proxy_pose& out) noexcept;
  /// No more input: true while `out` receives one more pose still held (both-sided mode);
  /// call until it returns false. Then the stage starts a new take.
  bool flush(proxy_pose& out) noexcept;
  /// Forgets everything (a new take).
  void reset() noexcept;
  /// The performer's leg length (hip socket to ankle, metres; frame_solver::
  /// performer_leg_length()): the skeleton given at construction is scaled so that its thigh +
  /// shin equals it, so that a held foot stays held on the performer's proportions (and on a
  /// rig, which `convert` scales by the standing hips height). 0, negative or not finite: the
  /// skeleton as given. A change under 1 % is ignored. Kept by reset(); the pose stream sets it
  /// at the file job's warm-up end (pose_stream::restart_take). Allocates nothing.
  void set_leg_length(float leg_length) noexcept;
  /// The skeleton in use (scaled by set_leg_length()).
  const proxy_skeleton& skeleton() const noexcept { return skeleton_; }

  const foot_contact_options& options() const noexcept { return options_; }
  bool both_sided() const noexcept { return both_sided_; }

 private:
  struct slot;
  // Output processing of the held pose at ring index `k` into `out`.
  void emit(int k, proxy_pose& out) noexcept;
  slot& at(long i) noexcept;

  foot_contact_options options_;
  bool both_sided_;
  proxy_skeleton base_skeleton_;  // as given at construction
  proxy_skeleton skeleton_;       // base_skeleton_ scaled to the leg length in use
  float leg_length_ = 0.f;        // set_leg_length()'s value in use (0: none)
  std::unique_ptr<slot[]> ring_;
  int capacity_ = 1;
  long pushed_ = 0;   // poses taken since the take began
  long emitted_ = 0;  // poses given out since the take began
  // Per-foot state.
  std::array<bool, 2> planted_{};
  std::array<bool, 2> stepped_{};           // released by distance: plants again once settled
  std::array<glm::vec3, 2> plant_point_{};  // the foot's point (filtered hips) when it planted
  std::array<glm::vec3, 2> plant_apart_{};  // ... less the other foot's, then
  std::array<double, 2> plant_t_{};         // ... and when
  std::array<float, 2> contact_{};
  std::array<bool, 2> anchored_{};
  std::array<glm::vec3, 2> anchor_{};
  // Root motion: the previous output hips and the previous filtered hips.
  bool have_root_ = false;
  glm::vec3 root_prev_{0.f}, measured_prev_{0.f};
  double t_prev_ = 0.0;
};

}  // namespace avatarmap
