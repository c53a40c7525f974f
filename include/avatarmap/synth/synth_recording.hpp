// A whole synthetic recording, frame by frame: the true proxy pose (the motion) and the
// landmarks the generator reports for it, plus the scenario presets that the accuracy figures
// are measured on (docs/accuracy.md).
//
// Truth: the pose played (demo_motion_pose or random_motion), with confidence used as the
// low-visibility marker: 1 for every bone, 0 for the bones of a limb in a low-visibility burst
// at that frame (synth_limb_of). This is what `avatarmap synth --truth` writes
// (docs/file-formats.md) and what `avatarmap eval-pose` reads (pose_accuracy.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/synth/head_sweep.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_motion.hpp"

namespace avatarmap {

/// Presets:
/// - demo: the scripted demo motion, fixed 60 degree camera at 3.5 m, no noise (the defaults of
///   synth_options; `avatarmap synth` without --scenario).
/// - clean: random motion (random_motion.hpp), random camera (field of view 50-90 degrees,
///   1.5-4 m away, 0.8-1.5 m high, the person up to half the half-width off centre), person
///   height 1.55-1.90 m, exact landmarks.
/// - noisy: clean plus Gaussian noise of 10 mm on the body, 5 mm on the hands, 1 mm on the
///   face, and low-visibility bursts of about 1 s on 12 % of each limb's time (visibility
///   0.02-0.3, 30 mm extra noise on the limb's points).
enum class synth_scenario : std::uint8_t { demo, clean, noisy };

/// "demo", "clean", "noisy" -> the preset; nullopt for anything else.
std::optional<synth_scenario> synth_scenario_from_name(std::string_view name);
const char* synth_scenario_name(synth_scenario s);

/// The options of a preset for `seed` (person_height drawn from the seed for clean/noisy).
synth_options synth_scenario_options(synth_scenario scenario, std::uint32_t seed);

/// Motion + landmark generator of one recording. Allocation-free per frame after
/// construction; not thread-safe (one object per thread).
class synth_recording {
 public:
  /// `options` must validate() (asserted; invalid options are replaced by the defaults in
  /// release builds, as landmark_synth does).
  explicit synth_recording(const synth_options& options);

  /// The frame at time t seconds (call with increasing t: bursts are scheduled along it):
  /// out_truth is the pose played with the low-visibility marker in its confidence,
  /// out_frame the landmarks (out_frame.t = out_truth.t = t).
  void generate(double t, proxy_pose& out_truth, landmark_frame& out_frame);

  const landmark_synth& landmarks() const { return synth_; }

 private:
  landmark_synth synth_;
  random_motion motion_;
  head_sweep head_;
};

}  // namespace avatarmap
