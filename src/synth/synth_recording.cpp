// A synthetic recording and its scenario presets. See
// include/avatarmap/synth/synth_recording.hpp.
#include "avatarmap/synth/synth_recording.hpp"

#include <random>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace avatarmap {

namespace {

// Noise of the noisy preset (metres): body, hands, face.
constexpr float k_noisy_body_sigma = 0.010f;
constexpr float k_noisy_hand_sigma = 0.005f;
constexpr float k_noisy_face_sigma = 0.001f;
// Low-visibility bursts of the noisy preset.
constexpr float k_noisy_burst_fraction = 0.12f;
constexpr float k_noisy_burst_seconds = 1.f;
// Person heights of the clean and noisy presets (metres).
constexpr float k_min_person_height = 1.55f;
constexpr float k_max_person_height = 1.90f;

random_motion_options motion_options(const synth_options& o) {
  random_motion_options m;
  m.limits.finger_side_bend = o.finger_side_bend_degrees;
  m.max_wrist_speed = o.max_wrist_speed;
  return m;
}

}  // namespace

std::optional<synth_scenario> synth_scenario_from_name(std::string_view name) {
  if (name == "demo") return synth_scenario::demo;
  if (name == "clean") return synth_scenario::clean;
  if (name == "noisy") return synth_scenario::noisy;
  return std::nullopt;
}

const char* synth_scenario_name(synth_scenario s) {
  switch (s) {
    case synth_scenario::clean:
      return "clean";
    case synth_scenario::noisy:
      return "noisy";
    default:
      return "demo";
  }
}

synth_options synth_scenario_options(synth_scenario scenario, std::uint32_t seed) {
  synth_options o;
  o.seed = seed;
  if (scenario == synth_scenario::demo) return o;
  o.motion = synth_motion::random;
  o.random_camera = true;
  o.face_variation = true;  // each seed its own face (synth_face_shape)
  // Its own generator: the height draw must not shift the camera, noise or burst sequences.
  std::mt19937 g(seed ^ 0x4e16417u);
  o.person_height =
      std::uniform_real_distribution<float>(k_min_person_height, k_max_person_height)(g);
  if (scenario == synth_scenario::noisy) {
    o.body_noise_sigma = k_noisy_body_sigma;
    o.hand_noise_sigma = k_noisy_hand_sigma;
    o.face_noise_sigma = k_noisy_face_sigma;
    o.low_visibility_fraction = k_noisy_burst_fraction;
    o.low_visibility_seconds = k_noisy_burst_seconds;
  }
  return o;
}

synth_recording::synth_recording(const synth_options& options)
    : synth_(options),
      motion_(synth_.skeleton(), synth_.options().seed, motion_options(synth_.options())),
      head_(synth_.options().seed) {}

void synth_recording::generate(double t, proxy_pose& out_truth, landmark_frame& out_frame) {
  if (synth_.options().motion == synth_motion::random) {
    motion_.pose_at(t, out_truth);
  } else if (synth_.options().motion == synth_motion::head) {
    // The torso upright (so the head's world turn is the sweep's), the head swept, half of
    // its turn in the neck.
    motion_.pose_at(t, out_truth);
    for (bone b : {bone::hips, bone::spine, bone::chest, bone::upper_chest})
      out_truth.rotations[idx(b)] = identity_quat();
    const glm::quat half = quat_fraction(head_turn(head_.at(t)), 0.5f);
    out_truth.rotations[idx(bone::neck)] = half;
    out_truth.rotations[idx(bone::head)] = half;
    ground_pose(synth_.skeleton(), out_truth);
  } else {
    out_truth = demo_motion_pose(t, synth_.skeleton());
  }
  out_truth.t = t;
  synth_.generate(out_truth, out_frame);
  out_frame.t = t;
  for (int b = 0; b < k_bone_count; ++b)
    out_truth.confidence[b] = synth_.bone_low_visibility(static_cast<bone>(b)) ? 0.f : 1.f;
}

}  // namespace avatarmap
