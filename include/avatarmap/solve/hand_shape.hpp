// A hand's landmarks fitted to the shape of that hand (the solver's stage between preparing a
// frame and measuring the hands; docs/solver.md, "The hand's shape").
//
// A palm is rigid (the wrist, the thumb's carpometacarpal joint and the four knuckles keep
// their places in the hand; every humanoid skeleton fixes them to the hand bone) and each
// finger segment keeps its length. Landmark noise keeps neither: 5 mm of noise on the points
// of a 2-4 cm finger bone turns it by ~12-24 degrees a frame. hand_shape learns the hand as
// frames stream in — running means over ~10 s of confident frames of the palm's shape, of the
// segments' squared lengths, and of the noise (how far the palm strays from its shape) — and
// fit() moves a frame's points to the nearest ones that have that shape:
//   1. the palm: the rigid motion that best carries the learnt palm onto its six points
//      (rotation by Gauss-Newton from the points' own axes, translation by the centroids);
//   2. each finger, from its fitted root: the three segments at their learnt lengths whose
//      joints lie nearest to the observed ones (least squares by block coordinate descent).
// A segment's learnt length is its mean squared observed length less the noise's share
// (2 points x 3 coordinates x sigma^2), which would otherwise lengthen every finger.
//
// Points that already have the learnt shape (exact landmarks of a rigid skeleton) stay where
// they are, so every bone still points exactly at its observed child joint. A finger with an
// observed segment off its learnt length by more than half of it or 5 deviations of the
// length's noise (a failed depth estimate, or a segment seen end-on) keeps its observed points
// (between 30 % or 3 deviations and that, it takes part of the fit); nothing moves before the
// shape has been learnt from k_min_frames frames.
//
// Points are in metres (a hand's world landmarks, any axes and handedness, the same for every
// frame). Allocation-free; plain storage. Not thread-safe (one per hand and solver).
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/landmarks/hand_landmark.hpp"

namespace avatarmap {

class hand_shape {
 public:
  using points = std::array<glm::vec3, k_hand_landmark_count>;
  /// The palm's points: wrist, thumb CMC, and the index, middle, ring and pinky knuckles.
  static constexpr int k_palm_points = 6;
  static constexpr int k_palm[k_palm_points] = {0, 1, 5, 9, 13, 17};
  /// Finger segments: 3 per finger, thumb first; segment 3 f + k runs from landmark
  /// finger_base_landmark(f) + k to the next one.
  static constexpr int k_segments = 15;
  /// Confident frames learnt before fit() moves anything.
  static constexpr int k_min_frames = 10;
  /// Frames the running means reach back (an exponential mean after that): ~10 s at 30 fps.
  static constexpr int k_horizon_frames = 300;
  /// Least confidence of a frame that is learnt from.
  static constexpr float k_learn_above = 0.5f;

  /// Forgets the hand.
  void reset() { *this = hand_shape{}; }
  /// Learns from one frame's points (the observed ones, before fit()), seen with
  /// `confidence`. A frame below k_learn_above, with a non-finite point, or whose palm strays
  /// from the learnt one by more than 4 x the noise (at least 3 mm; a wrong detection) is not
  /// learnt from; 30 strays in a row start the shape afresh (another hand).
  void learn(const points& p, float confidence);
  /// Moves p (seen with `confidence`) to the nearest points with the learnt shape (see above);
  /// a no-op until the shape is known, when a point is not finite, and when a hand seen with
  /// confidence >= k_learn_above strays from the learnt palm as in learn() (a mirrored or wrong
  /// detection is not forced into the shape). A barely-seen hand is fitted whatever its
  /// residual: its points stray because they are poor, and the shape is what it has.
  void fit(points& p, float confidence = 1.f) const;
  /// fit(p) with the shape learnt so far, then learn(the observed p, confidence), with one
  /// alignment of the palm for both (what the solver runs each frame).
  void fit_and_learn(points& p, float confidence);

  /// True once fit() moves points.
  bool ready() const { return frames_ >= k_min_frames; }
  /// Frames learnt from so far (at most k_horizon_frames count in the means).
  int frames() const { return frames_; }
  /// The learnt noise of one coordinate of a point (metres; 0 until two frames were learnt).
  float noise_sigma() const;
  /// The learnt length of segment s in [0, 15) (metres; 0 until a frame was learnt).
  float segment_length(int s) const;

 private:
  using palm_points = std::array<glm::vec3, k_palm_points>;
  // Whether a palm this far from the learnt one (align()'s residual) is another hand or a
  // wrong detection: more than 4 x the learnt noise per coordinate, at least 3 mm.
  bool strays(float residual) const;
  // The palm's six points less their centroid; false when a point of p is not finite.
  static bool centred_palm(const points& p, palm_points& b, glm::vec3& centre);
  // The rotation carrying the learnt palm onto `observed` (both centroid-free) and the summed
  // squared distance left.
  glm::quat align(const palm_points& observed, float* residual) const;
  // learn() and fit() once the palm is aligned (r, residual: align()'s; any on the first frame).
  void learn_aligned(const points& p, float confidence, const palm_points& b, const glm::quat& r,
                     float residual);
  void fit_aligned(points& p, const glm::vec3& centre, const glm::quat& r) const;

  palm_points palm_{};                         // centroid-free, in the first frame's axes
  std::array<float, k_segments> length_sq_{};  // running mean of squared observed lengths
  double noise_var_ = 0.0;                     // per coordinate, m^2
  int frames_ = 0;
  int strays_ = 0;
};

}  // namespace avatarmap
