// Seeded random motion. See include/avatarmap/synth/random_motion.hpp.
#include "avatarmap/synth/random_motion.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/synth/landmark_synth.hpp"

namespace avatarmap {

namespace {

struct speed_range {
  float lo, hi;  // rad/s
};

float min_jerk(float s) {
  s = std::min(1.f, std::max(0.f, s));
  return s * s * s * (10.f + s * (-15.f + 6.f * s));
}

// Samples of a segment for its peak speed: the minimum-jerk peak is at s = 1/2, a sample.
constexpr int k_speed_samples = 32;

}  // namespace

motion_channel motion_channel_of(bone b) {
  switch (b) {
    case bone::hips:
    case bone::spine:
    case bone::chest:
    case bone::upper_chest:
      return motion_channel::torso;
    case bone::neck:
    case bone::head:
    case bone::left_eye:
    case bone::right_eye:
    case bone::jaw:
      return motion_channel::head;
    case bone::left_shoulder:
    case bone::left_upper_arm:
    case bone::left_lower_arm:
    case bone::left_hand:
      return motion_channel::left_arm;
    case bone::right_shoulder:
    case bone::right_upper_arm:
    case bone::right_lower_arm:
    case bone::right_hand:
      return motion_channel::right_arm;
    case bone::left_upper_leg:
    case bone::left_lower_leg:
    case bone::left_foot:
    case bone::left_toes:
      return motion_channel::left_leg;
    case bone::right_upper_leg:
    case bone::right_lower_leg:
    case bone::right_foot:
    case bone::right_toes:
      return motion_channel::right_leg;
    default:
      break;
  }
  return idx(b) <= idx(bone::left_little_distal) ? motion_channel::left_fingers
                                                 : motion_channel::right_fingers;
}

random_motion::random_motion(const proxy_skeleton& skeleton, std::uint32_t seed,
                             const random_motion_options& options)
    : skeleton_(skeleton), seed_(seed), options_(options) {
  restart();
}

void random_motion::restart() {
  for (int c = 0; c < k_motion_channel_count; ++c) {
    channel_state& ch = channels_[c];
    // One generator per channel: a channel's keys do not depend on when the others switch.
    ch.rng.seed(seed_ * 0x9e3779b1u + static_cast<std::uint32_t>(c) * 0x85ebca6bu + 1u);
    ch.a = random_pose(ch.rng, options_.limits);
    ch.b = random_pose(ch.rng, options_.limits);
    ch.t0 = 0.0;
    ch.t1 = segment_seconds(c, ch.a, ch.b);
  }
}

float random_motion::segment_seconds(int c, const proxy_pose& a, const proxy_pose& b) {
  channel_state& ch = channels_[c];
  auto draw = [&ch](float lo, float hi) {
    return std::uniform_real_distribution<float>(lo, hi)(ch.rng);
  };
  const motion_channel mc = static_cast<motion_channel>(c);
  if (mc == motion_channel::expressions) return draw(0.15f, 1.f);
  speed_range r{0.5f, 3.f};
  switch (mc) {
    case motion_channel::torso:
      r = {0.3f, 1.5f};
      break;
    case motion_channel::left_arm:
    case motion_channel::right_arm:
    case motion_channel::left_fingers:
    case motion_channel::right_fingers:
      r = {std::min(1.f, options_.max_wrist_speed), options_.max_wrist_speed};
      break;
    default:
      break;
  }
  // Peak world angular speed of the channel's bones over a 1 s segment, the rest of the body
  // at rest; a segment of T seconds has peak / T.
  proxy_pose p;
  std::array<glm::quat, k_bone_count> prev, cur;
  float peak = 0.f;
  for (int k = 0; k <= k_speed_samples; ++k) {
    const float w = min_jerk(static_cast<float>(k) / k_speed_samples);
    for (int bi = 0; bi < k_bone_count; ++bi)
      p.rotations[bi] = static_cast<int>(motion_channel_of(static_cast<bone>(bi))) == c
                            ? slerp_shortest(a.rotations[bi], b.rotations[bi], w)
                            : identity_quat();
    compute_world_rotations(p, cur);
    if (k > 0) {
      for (int bi = 0; bi < k_bone_count; ++bi) {
        if (static_cast<int>(motion_channel_of(static_cast<bone>(bi))) != c) continue;
        peak = std::max(peak, angle_between(cur[bi], prev[bi]) * k_speed_samples);
      }
    }
    prev = cur;
  }
  float t = peak / draw(r.lo, r.hi);
  t = std::min(k_max_segment_seconds, std::max(k_min_segment_seconds, t));
  return std::max(t, peak / r.hi);
}

void random_motion::advance(int c) {
  channel_state& ch = channels_[c];
  ch.a = ch.b;
  ch.b = random_pose(ch.rng, options_.limits);
  const double length = segment_seconds(c, ch.a, ch.b);
  ch.t0 = ch.t1;
  ch.t1 = ch.t0 + length;
}

void random_motion::pose_at(double t, proxy_pose& out) {
  if (!(t > 0.0)) t = 0.0;  // NaN too
  for (const channel_state& ch : channels_) {
    if (t < ch.t0) {
      restart();
      break;
    }
  }
  float w[k_motion_channel_count];
  for (int c = 0; c < k_motion_channel_count; ++c) {
    channel_state& ch = channels_[c];
    while (t >= ch.t1) advance(c);
    w[c] = min_jerk(static_cast<float>((t - ch.t0) / (ch.t1 - ch.t0)));
  }
  out.set_rest();
  out.t = t;
  out.confidence.fill(1.f);
  for (int bi = 0; bi < k_bone_count; ++bi) {
    const int c = static_cast<int>(motion_channel_of(static_cast<bone>(bi)));
    out.rotations[bi] =
        slerp_shortest(channels_[c].a.rotations[bi], channels_[c].b.rotations[bi], w[c]);
  }
  const int e = static_cast<int>(motion_channel::expressions);
  for (int i = 0; i < k_expression_count; ++i)
    out.expressions[i] = channels_[e].a.expressions[i] +
                         w[e] * (channels_[e].b.expressions[i] - channels_[e].a.expressions[i]);
  for (int i = 0; i < k_blendshape_count; ++i)
    out.blendshapes[i] = channels_[e].a.blendshapes[i] +
                         w[e] * (channels_[e].b.blendshapes[i] - channels_[e].a.blendshapes[i]);
  const channel_state& torso = channels_[static_cast<int>(motion_channel::torso)];
  const float wt = w[static_cast<int>(motion_channel::torso)];
  out.hips_position = torso.a.hips_position + wt * (torso.b.hips_position - torso.a.hips_position);
  ground_pose(skeleton_, out);
  set_truth_expressions(out);  // from the blendshapes and the eyes as they are now
}

}  // namespace avatarmap
