// Zero-phase smoothing and gap filling of a stream of proxy poses for files (the default of
// `solve`, `convert`, `animate` and avm_solve_file; docs/smoothing.md). It sees the future
// through a bounded window: poses are pushed in capture order and come out, smoothed, once
// `lookahead_seconds()` of later capture time has been pushed (or at finish()). Latency is
// that window; memory is `capacity_frames` poses, allocated once at construction; push() and
// pop() allocate nothing.
//
// Per bone, at the pose being emitted (the centre). "Confidence" below is the input's, except
// that a hand and its fingers are capped by their lower arm's (hands_follow_arms).
// - observed (confidence >= observed_above): a Gaussian-weighted local quadratic regression in
//   time (degree 2; degree 0 = weighted mean) over the observed poses within 3 sigma, each
//   weighted by kernel x confidence. Quaternions are hemisphere-aligned to the centre's first
//   (each neighbour flipped to its side, so nothing is averaged through the double cover), fitted
//   per component and normalised: for the spreads of a few degrees inside a kernel this is
//   the chordal estimate, within O(spread^3) of a fit in the tangent space, without
//   trigonometry. Sigma by group: body (torso, head, limbs) and fingers, whose noise is large
//   relative to their length. The quadratic follows the peaks of fast motion that a mean of the
//   same width would flatten, so the kernels can be wider for the same lag error.
// - seen with a low confidence of its own (0 < confidence < observed_above, e.g. an occluded
//   limb the estimator still places): smoothed over low_confidence_sigma_seconds with every
//   frame weighted by its confidence while such frames' measured noise says they still carry
//   the motion (per group -- the body; the fingers: at most 5 x the confident bones' noise and
//   below 1.8 rad per sample; the hand bones: below 1.8 rad; until measured the body's are,
//   the hands' and fingers' are not); else filled as a gap.
// - a hand or finger seen for less than 0.25 s between frames where it was not detected at all
//   (confidence 0) is a false detection: its frames become gaps (confidence written 0), and the
//   input's hold of it afterwards is replaced by what the input showed before it.
// - not observed (a gap: confidence 0, or a hand capped by its arm): filled from both sides.
//   When the last observed pose before and the next one after are at most max_gap_seconds
//   apart, the bone is the slerp between their smoothed rotations at the centre's time
//   fraction. Longer gaps (or a side that does not exist) hold the side's rotation for
//   hold_seconds and then ease it to rest (identity) over ease_seconds (confidence_gate.hpp's
//   hold_and_ease), from each side symmetrically; with both sides, the two are slerped by time
//   fraction so nothing snaps. A bone observed nowhere within reach keeps the input's rotations
//   (e.g. unobservable bones the solver sets from priors), smoothed.
// - confidence is copied unchanged (a filled bone stays marked as not observed; a false
//   detection is written 0); `t` is the centre's.
// The hips position and the expression and blendshape weights are Gaussian-smoothed (unweighted by
// confidence: the solver already holds and eases them).
//
// Time: frames are expected in increasing `t` (duplicates are fine). A frame whose `t` is
// earlier than the one before, or non-finite, starts a new segment: no smoothing or filling
// crosses a segment boundary (the segment before is emitted as it stands). When more than
// capacity_frames poses are waiting (a very high frame rate), the oldest is emitted with less
// lookahead than asked. Non-finite rotations, positions or weights in the input count as not
// observed (rotations) or are ignored (position, weights); the output is always finite.
// Thread-safety: one instance per stream.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Options of offline_smoother. Every time is in seconds of capture time.
struct offline_smoother_options {
  /// Scale on every sigma below (the CLI's --smoothing). 0 = no smoothing (gap filling only).
  float strength = 1.f;
  /// Gaussian sigma for torso, head, eyes, jaw, arms, legs.
  float body_sigma_seconds = 0.15f;
  /// Gaussian sigma for the 30 finger bones (5 mm of landmark noise on 2-4 cm bones).
  float finger_sigma_seconds = 0.30f;
  /// Gaussian sigma for the hips position.
  float position_sigma_seconds = 0.05f;
  /// Gaussian sigma for the expression weights and the ARKit blendshape weights.
  float expression_sigma_seconds = 0.03f;
  /// Least sigma in frame intervals (of the frames around the centre), for every sigma above
  /// while strength > 0: at a low frame rate a sigma of a fraction of a frame would smooth
  /// nothing (5 fps video: 0.1 s is half a frame). 1 frame keeps 30 fps unchanged (its sigmas
  /// are 1.5-6 frames, the expressions' 0.9) and gives 0.2 s at 5 fps. Capped at a third of
  /// the lookahead (the kernel's reach must fit the window). 0 = no floor.
  float min_sigma_frames = 1.f;
  /// Noise-adaptive widths: the sigmas above are for the noise of the synthetic "noisy"
  /// scenario at 30 fps (10 mm body, 5 mm hand points); each group's (body, fingers) sigma is
  /// scaled by (noise density / that reference)^(1/7), the rate at which a local quadratic's
  /// best width grows with its noise, clamped to [1/4, 1] (wider would flatten fast motion). The
  /// noise is measured on the input as it streams (second differences of the observed bones'
  /// rotations, a running mean over ~4 s) and its density is per-sample noise^2 / frame rate, so
  /// exact landmarks are barely smoothed and noisier capture is smoothed more. false = the sigmas
  /// as given.
  bool adapt_to_noise = true;
  /// Rotations: 0 = Gaussian-weighted mean; 2 = local quadratic regression with the same
  /// weights (keeps the peaks of fast motion; see docs/smoothing.md).
  int degree = 2;
  /// A bone is observed in a frame when its confidence is at least this (else it is a gap).
  float observed_above = 0.5f;
  /// A hand and its fingers count as observed only as far as their lower arm is: hand
  /// landmarks are found in a crop placed by the body's wrist, so when the body model marks the
  /// arm as barely visible the hand's points are unreliable even when the hand model is sure.
  bool hands_follow_arms = false;
  /// Bones seen with a low confidence of their own (0 < confidence < observed_above):
  /// smoothed with this sigma, every frame weighted by its confidence, instead of filled (when
  /// their measured noise allows; see above). 0 = always fill them as gaps.
  float low_confidence_sigma_seconds = 0.3f;
  /// Gaps up to this long (from the last observed frame to the next) are interpolated.
  float max_gap_seconds = 1.5f;
  /// Longer gaps: hold, then ease to rest (as the solver's confidence gate does).
  float hold_seconds = 0.5f;
  float ease_seconds = 1.0f;
  /// Poses held at most (the memory bound; ~2.8 kB each). 256 frames covers the default
  /// lookahead (1.5 s) up to ~160 fps.
  int capacity_frames = 256;

  /// The widest kernel a strength may give: strength x the largest of the four sigmas above is
  /// at most this (seconds; a window several seconds wide is a strength nobody means, and a
  /// large buffer).
  static constexpr float k_widest_sigma_seconds = 2.f;
  /// The largest strength validate() accepts with these sigmas: k_widest_sigma_seconds / the
  /// largest sigma (6.67 with the defaults; filter_rules.hpp's k_max_smoothing).
  constexpr float max_strength() const {
    const float widest = std::max({body_sigma_seconds, finger_sigma_seconds, position_sigma_seconds,
                                   expression_sigma_seconds});
    return widest > 0.f ? k_widest_sigma_seconds / widest : 0.f;
  }

  /// Checks every field: strength and sigmas finite and >= 0 (sigmas > 0), strength at most
  /// max_strength(), observed_above in [0, 1], times finite and >= 0 (max_gap, hold, ease at
  /// most 60 s), min_sigma_frames in [0, 10], capacity_frames in [8, 65536]. The message
  /// names the field and its range.
  status validate() const;
};

/// The smoother. Construct, push() poses in capture order, pop() while it returns true, call
/// finish() after the last push and pop() the rest.
class offline_smoother {
 public:
  /// `options` must pass validate() (checked by assertion; invalid values are clamped).
  explicit offline_smoother(const offline_smoother_options& options = {});
  ~offline_smoother();
  offline_smoother(const offline_smoother&) = delete;
  offline_smoother& operator=(const offline_smoother&) = delete;

  /// Capture time a pose waits for (the latency of the window): the longest of max_gap_seconds,
  /// hold + ease seconds, and 3 x the largest scaled sigma.
  double lookahead_seconds() const noexcept { return lookahead_; }
  int capacity() const noexcept { return capacity_; }
  /// Poses pushed and not yet popped, plus the past ones kept for smoothing.
  int buffered() const noexcept { return count_; }

  /// Adds the next pose. Never fails: when the window is full, call pop() first (push() on a
  /// full window drops the oldest pose that was already popped, or, when none has been, emits
  /// nothing and returns false).
  bool push(const proxy_pose& in) noexcept;
  /// Writes the next smoothed pose into `out` and returns true when one is ready; false
  /// otherwise (more input is needed, or everything has been popped after finish()).
  bool pop(proxy_pose& out) noexcept;
  /// No more input: every remaining pose becomes ready.
  void finish() noexcept { finished_ = true; }
  /// Forgets everything (as newly constructed).
  void reset() noexcept;

 private:
  struct slot;
  slot& at(int i) const noexcept;  // i-th oldest kept pose
  bool ready() const noexcept;
  // Which frames a kernel takes for a bone and how: none (the bone is not computed), all
  // alike, observed ones by confidence, all by confidence.
  enum class weighting : std::uint8_t { none, uniform, observed, confidence };
  // Kernel weights and u = dt / sigma of the poses [lo, hi] around `centre` (indices from the
  // oldest), for one sigma; valid while `version` is the smoother's.
  struct kernel_table {
    int centre = -1, lo = 0, hi = -1;
    float sigma = 0.f;
    unsigned version = 0;
    float* w = nullptr;
    float* u = nullptr;
    std::uint64_t ones = 0;        // bit b: bone b has weight 1 in every pose lo..hi
    bool has_moments = false;      // whether `coefficient` is computed (once needed)
    float* coefficient = nullptr;  // each pose's factor in the estimate from w alone
    int* index = nullptr;          // the poses lo..hi: their slots (slot::index)
  };
  static constexpr int k_body_table = 0, k_finger_table = 1, k_low_confidence_table = 2,
                       k_next_table = 3, k_table_count = 4;
  const kernel_table& kernel_for(int table, int centre, float sigma) noexcept;
  // The kernel's estimate at its centre of every bone b in [first, end) with how[b] != none,
  // written to out[b] (out has k_bone_count entries).
  void smooth_rotations(kernel_table& k, int first, int end, const weighting* how,
                        glm::quat* out) const noexcept;
  void emit(proxy_pose& out) noexcept;

  offline_smoother_options options_;
  double lookahead_ = 0.0;
  double past_seconds_ = 0.0;  // history kept behind the centre (3 sigma)
  double sigma_floor_ = 0.0;   // min_sigma_frames x the last centre's frame interval (capped)
  double sigma_widest_ = 0.0;  // widest adapted sigma used at the last centre
  void observe_noise() noexcept;
  void drop_flicker() noexcept;
  // Running mean of the second differences' size per group (body, fingers), radians per
  // sample, and of the frame interval; weights (seconds of evidence, capped).
  std::array<double, 2> noise_{};
  // The same over low-confidence observations (0 < weight < observed_above), per group
  // (k_low_groups: the body without the hands; the fingers; the two hand bones) and its
  // running weight.
  static constexpr int k_low_groups = 3;
  std::array<double, k_low_groups> low_noise_{};
  std::array<double, k_low_groups> low_noise_weight_{};
  // Whether low-confidence observations of each group still carry the motion (smoothed with
  // low_confidence_sigma_seconds) or not (filled as gaps); see observe_noise().
  std::array<bool, k_low_groups> low_informative_{};
  // drop_flicker(): bones whose false detection is being replaced, and by what.
  std::uint64_t flicker_bits_ = 0;
  std::array<glm::quat, k_bone_count> flicker_fill_{};
  double noise_dt_ = 0.0;
  double noise_weight_ = 0.0;
  int capacity_ = 0;
  std::unique_ptr<slot[]> slots_;
  std::unique_ptr<float[]> kernel_storage_;  // the tables' w, u and coefficient
  std::unique_ptr<int[]> index_storage_;     // the tables' index, capacity_ each
  std::unique_ptr<float[]> lanes_;           // the poses' values for smooth_rotations, by bone
  float* lanes_of_block(int block) const noexcept;           // of slot 0
  float* lanes_of(const slot& s, int block) const noexcept;  // of the slot of `s`
  std::array<kernel_table, k_table_count> tables_{};
  unsigned version_ = 0;  // bumped whenever the ring's indices may have moved
  int head_ = 0;          // ring index of the oldest kept pose
  int count_ = 0;         // poses kept
  int centre_ = 0;        // index (from the oldest) of the next pose to emit
  int segment_ = 0;       // current segment id
  bool finished_ = false;
  bool has_last_t_ = false;
  double last_t_ = 0.0;
  // Per bone: the last emitted observed rotation (the left side of a gap) and its time.
  std::array<glm::quat, k_bone_count> last_good_{};
  std::array<double, k_bone_count> last_good_t_{};
  std::array<int, k_bone_count> last_good_segment_{};
};

}  // namespace avatarmap
