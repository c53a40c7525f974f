// Random poses and the scripted demo motion. See include/avatarmap/synth/random_pose.hpp.
#include "avatarmap/synth/random_pose.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/synth/landmark_synth.hpp"

namespace avatarmap {

namespace {

constexpr float k_deg = k_pi / 180.f;
const glm::vec3 k_x(1.f, 0.f, 0.f);
const glm::vec3 k_y(0.f, 1.f, 0.f);
const glm::vec3 k_z(0.f, 0.f, 1.f);

float uniform(std::mt19937& rng, float lo, float hi) {
  return std::uniform_real_distribution<float>(lo, hi)(rng);
}
float sym(std::mt19937& rng, float range_deg) {
  return uniform(rng, -range_deg, range_deg) * k_deg;
}
glm::quat xyz_rotation(std::mt19937& rng, float range_deg) {
  float a = sym(rng, range_deg), b = sym(rng, range_deg), c = sym(rng, range_deg);
  return axis_angle(k_y, a) * axis_angle(k_x, b) * axis_angle(k_z, c);
}

// Left-side constructions (the right side is mirror_x of them).
glm::quat finger_flex(float theta) { return axis_angle(-k_z, theta); }
glm::vec3 thumb_hinge() {
  return glm::normalize(glm::cross(bone_rest_direction(bone::left_thumb_metacarpal), -k_y));
}

void set_side(proxy_pose& p, bone left, const glm::quat& q, bool right) {
  if (right)
    p[mirror_bone(left)] = mirror_x(q);
  else
    p[left] = q;
}

// Finger curl of a whole hand, left-side rotations (proximal, intermediate, distal).
void curl_hand(proxy_pose& p, bool right, float curl) {
  for (int finger = 1; finger < 5; ++finger) {
    int b = idx(bone::left_thumb_metacarpal) + 3 * finger;
    for (int j = 0; j < 3; ++j)
      set_side(p, static_cast<bone>(b + j), finger_flex(curl * (j == 0 ? 1.2f : 1.4f)), right);
  }
  const glm::vec3 h = thumb_hinge();
  set_side(p, bone::left_thumb_proximal, axis_angle(h, 0.6f * curl), right);
  set_side(p, bone::left_thumb_distal, axis_angle(h, 0.7f * curl), right);
}

}  // namespace

proxy_pose random_pose(std::mt19937& rng, const random_pose_limits& L) {
  proxy_pose p;
  p.confidence.fill(1.f);
  p.hips_position = glm::vec3(uniform(rng, -L.hips_xz_range, L.hips_xz_range), L.hips_height,
                              uniform(rng, -L.hips_xz_range, L.hips_xz_range));
  const glm::quat hips_yaw = axis_angle(k_y, sym(rng, L.hips_yaw));
  const glm::quat lean =
      axis_angle(k_x, sym(rng, L.hips_lean)) * axis_angle(k_z, sym(rng, L.hips_lean));
  p[bone::hips] = hips_yaw * lean;
  if (L.coupled_deviation >= 0.f) {
    glm::quat bend = xyz_rotation(rng, L.spine);
    if (L.pelvis_share_max > 0.f) {
      // Lumbopelvic rhythm: the lean drawn above is the whole torso's; the pelvis takes a
      // share of it, the three spine bones a third of the rest each.
      const float share = uniform(rng, L.pelvis_share_min, L.pelvis_share_max);
      p[bone::hips] = hips_yaw * quat_fraction(lean, share);
      bend = axis_angle(k_y, sym(rng, L.spine)) * quat_fraction(lean, (1.f - share) / 3.f) *
             axis_angle(k_x, sym(rng, L.spine_free_lean)) *
             axis_angle(k_z, sym(rng, L.spine_free_lean));
    }
    for (bone b : {bone::spine, bone::chest, bone::upper_chest})
      p[b] = bend * xyz_rotation(rng, L.coupled_deviation);
    const glm::quat half_turn = quat_fraction(xyz_rotation(rng, L.head), 0.5f);
    for (bone b : {bone::neck, bone::head})
      p[b] = half_turn * xyz_rotation(rng, L.coupled_deviation);
  } else {
    for (bone b : {bone::spine, bone::chest, bone::upper_chest}) p[b] = xyz_rotation(rng, L.spine);
    p[bone::neck] = xyz_rotation(rng, L.neck);
    p[bone::head] = xyz_rotation(rng, L.head);
  }

  for (int side = 0; side < 2; ++side) {
    const bool right = side == 1;
    // Arm: shoulder, then a direction for the upper arm (in the shoulder's frame).
    glm::quat shoulder =
        axis_angle(k_y, sym(rng, L.shoulder)) * axis_angle(k_z, sym(rng, L.shoulder));
    set_side(p, bone::left_shoulder, shoulder, right);
    glm::vec3 dir;
    for (int tries = 0; tries < 64; ++tries) {
      float z = uniform(rng, -1.f, 1.f);
      float phi = uniform(rng, -k_pi, k_pi);
      float r = std::sqrt(1.f - z * z);
      dir = glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
      if (dir.z >= L.arm_min_forward && dir.x >= -L.arm_max_across) break;
    }
    glm::quat swing = rotation_between(k_x, dir);
    set_side(p, bone::left_upper_arm, swing * axis_angle(k_x, sym(rng, L.upper_arm_twist)), right);
    glm::quat elbow = axis_angle(-k_y, uniform(rng, 0.f, L.elbow_max) * k_deg) *
                      axis_angle(k_x, sym(rng, L.forearm_twist));
    set_side(p, bone::left_lower_arm, elbow, right);
    set_side(p, bone::left_hand, xyz_rotation(rng, L.hand), right);

    // Leg: forward swing (about -X), sideways (about +Z: left leg toward +X), twist.
    glm::quat leg = axis_angle(-k_x, uniform(rng, L.leg_forward_min, L.leg_forward_max) * k_deg) *
                    axis_angle(k_z, sym(rng, L.leg_side)) * axis_angle(k_y, sym(rng, L.leg_twist));
    set_side(p, bone::left_upper_leg, leg, right);
    set_side(p, bone::left_lower_leg, axis_angle(k_x, uniform(rng, 0.f, L.knee_max) * k_deg),
             right);
    set_side(p, bone::left_foot,
             axis_angle(k_x, sym(rng, L.foot)) * axis_angle(k_y, sym(rng, 0.5f * L.foot)) *
                 axis_angle(k_z, sym(rng, 0.5f * L.foot)),
             right);

    if (L.fingers) {
      for (int finger = 1; finger < 5; ++finger) {
        int b = idx(bone::left_thumb_metacarpal) + 3 * finger;
        glm::quat prox = finger_flex(uniform(rng, 0.f, L.finger_flex_max) * k_deg) *
                         axis_angle(k_y, sym(rng, L.finger_spread));
        set_side(p, static_cast<bone>(b), prox, right);
        for (int j = 1; j < 3; ++j) {
          glm::quat q = finger_flex(uniform(rng, 0.f, L.finger_flex_max) * k_deg);
          if (L.finger_side_bend > 0.f) q = q * axis_angle(k_y, sym(rng, L.finger_side_bend));
          set_side(p, static_cast<bone>(b + j), q, right);
        }
      }
      const glm::vec3 h = thumb_hinge();
      const glm::vec3 d = bone_rest_direction(bone::left_thumb_metacarpal);
      glm::quat meta = axis_angle(h, sym(rng, L.thumb_metacarpal)) *
                       axis_angle(k_y, sym(rng, L.thumb_metacarpal)) *
                       axis_angle(d, sym(rng, L.thumb_metacarpal));
      set_side(p, bone::left_thumb_metacarpal, meta, right);
      for (bone tb : {bone::left_thumb_proximal, bone::left_thumb_distal}) {
        glm::quat q = axis_angle(h, uniform(rng, 0.f, L.thumb_flex_max) * k_deg);
        if (L.finger_side_bend > 0.f) {
          const glm::vec3 side = glm::normalize(glm::cross(h, bone_rest_direction(tb)));
          q = q * axis_angle(side, sym(rng, L.finger_side_bend));
        }
        set_side(p, tb, q, right);
      }
    }
  }
  // Conjugate gaze: both eyes turn together.
  // Half the time at the camera (within 3 degrees), as a person at a screen or camera looks;
  // else anywhere in the limits.
  const bool at_camera = L.expressions && uniform(rng, 0.f, 1.f) < 0.5f;
  const float eye_yaw = at_camera ? std::min(3.f, L.eye_yaw) : L.eye_yaw;
  const float eye_pitch = at_camera ? std::min(3.f, L.eye_pitch) : L.eye_pitch;
  glm::quat eye = axis_angle(k_y, sym(rng, eye_yaw)) * axis_angle(k_x, sym(rng, eye_pitch));
  p[bone::left_eye] = eye;
  p[bone::right_eye] = eye;

  if (L.expressions) {
    // ARKit shapes (left/right the person's), in the combinations a face makes; the 21
    // expressions are derived from them and from the eyes (set_truth_expressions).
    auto& bs = p.blendshapes;
    auto set = [&](blendshape x, float v) { bs[idx(x)] = v; };
    auto pair = [&](blendshape left, float v, float asym) {
      const float other = std::min(1.f, std::max(0.f, v * uniform(rng, 1.f - asym, 1.f + asym)));
      const bool first = uniform(rng, 0.f, 1.f) < 0.5f;
      bs[idx(left)] = first ? v : other;
      bs[idx(left) + 1] = first ? other : v;
    };
    // Mostly open eyes and a face at rest, as in real takes: a blink in 15 % of the poses, a
    // wink in 5 %, wide eyes in 10 %; a mouth shape in 6 of 8; a brow move in 1 of 2.
    if (uniform(rng, 0.f, 1.f) < 0.15f)
      pair(blendshape::eye_blink_left, uniform(rng, 0.f, 1.f), 0.1f);
    if (uniform(rng, 0.f, 1.f) < 0.05f) {  // a wink
      const int side = uniform(rng, 0.f, 1.f) < 0.5f ? 0 : 1;
      bs[idx(blendshape::eye_blink_left) + side] = uniform(rng, 0.7f, 1.f);
    }
    if (uniform(rng, 0.f, 1.f) < 0.1f && bs[idx(blendshape::eye_blink_left)] == 0.f)
      pair(blendshape::eye_wide_left, uniform(rng, 0.f, 1.f), 0.15f);
    switch (static_cast<int>(uniform(rng, 0.f, 8.f))) {
      case 1:  // talking / jaw
        set(blendshape::jaw_open, uniform(rng, 0.f, 1.f));
        break;
      case 2:  // a smile, maybe with the cheeks and an open mouth
        pair(blendshape::mouth_smile_left, uniform(rng, 0.f, 1.f), 0.3f);
        pair(blendshape::cheek_squint_left,
             uniform(rng, 0.f, 1.f) * bs[idx(blendshape::mouth_smile_left)], 0.2f);
        set(blendshape::jaw_open, uniform(rng, 0.f, 0.5f));
        break;
      case 3:  // an O
        set(blendshape::mouth_funnel, uniform(rng, 0.f, 1.f));
        set(blendshape::jaw_open, uniform(rng, 0.f, 1.f));
        break;
      case 4:  // a kiss (the lips pushed together: the jaw nearly closed)
        set(blendshape::mouth_pucker, uniform(rng, 0.f, 1.f));
        set(blendshape::jaw_open, uniform(rng, 0.f, 0.15f));
        break;
      case 5:  // spread lips
        pair(blendshape::mouth_stretch_left, uniform(rng, 0.f, 1.f), 0.3f);
        set(blendshape::jaw_open, uniform(rng, 0.f, 0.6f));
        break;
      case 6:  // a frown
        pair(blendshape::mouth_frown_left, uniform(rng, 0.f, 1.f), 0.3f);
        break;
      default:
        break;
    }
    if (uniform(rng, 0.f, 1.f) < 0.15f)
      set(uniform(rng, 0.f, 1.f) < 0.5f ? blendshape::mouth_left : blendshape::mouth_right,
          uniform(rng, 0.f, 0.6f));
    switch (static_cast<int>(uniform(rng, 0.f, 6.f))) {
      case 1:
        set(blendshape::brow_inner_up, uniform(rng, 0.f, 1.f));
        pair(blendshape::brow_outer_up_left, uniform(rng, 0.f, 1.f), 0.3f);
        break;
      case 2:
        pair(blendshape::brow_outer_up_left, uniform(rng, 0.f, 1.f), 0.8f);
        break;
      case 3:
        pair(blendshape::brow_down_left, uniform(rng, 0.f, 1.f), 0.3f);
        break;
      default:
        break;
    }
    // The jaw sideways and the lips rolled in, drawn from a generator of their own seeded by
    // this pose's draws (the shared sequence, and so every other draw of a seed, is kept): the
    // jaw to one side in 10 % of the poses (with the mouth as drawn), the lips rolled in, one
    // or both, in 10 % (pressed in thought: the jaw then closed).
    std::uint32_t h = 2166136261u;
    for (float v : bs) {
      std::uint32_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 16777619u;
    }
    for (int k = 0; k < 4; ++k) {
      std::uint32_t bits;
      std::memcpy(&bits, &eye[k], sizeof bits);
      h = (h ^ bits) * 16777619u;
    }
    std::mt19937 own(h);
    if (uniform(own, 0.f, 1.f) < 0.1f)
      set(uniform(own, 0.f, 1.f) < 0.5f ? blendshape::jaw_left : blendshape::jaw_right,
          uniform(own, 0.f, 0.8f));
    if (uniform(own, 0.f, 1.f) < 0.1f) {
      const float which = uniform(own, 0.f, 3.f);
      if (which < 2.f) set(blendshape::mouth_roll_upper, uniform(own, 0.f, 1.f));
      if (which >= 1.f) set(blendshape::mouth_roll_lower, uniform(own, 0.f, 1.f));
      set(blendshape::jaw_open, std::min(bs[idx(blendshape::jaw_open)], 0.1f));
    }
    // Lips kept together with the jaw open (mumbling, an "m" or "b" on the way) in 20 % of the
    // poses whose jaw is open.
    if (bs[idx(blendshape::jaw_open)] > 0.2f && uniform(own, 0.f, 1.f) < 0.2f)
      set(blendshape::mouth_close, bs[idx(blendshape::jaw_open)] * uniform(own, 0.3f, 1.f));
    // A sneer (the nose's wings up, the upper lip's sides often with them) in 8 % of the poses;
    // the lower lip's sides pulled down (the lower teeth shown) in 8 %. Each side within half
    // of the other.
    auto own_pair = [&](blendshape left, float v) {
      const float other = std::min(1.f, v * uniform(own, 0.5f, 1.5f));
      const bool first = uniform(own, 0.f, 1.f) < 0.5f;
      bs[idx(left)] = first ? v : other;
      bs[idx(left) + 1] = first ? other : v;
    };
    if (uniform(own, 0.f, 1.f) < 0.08f) {
      own_pair(blendshape::nose_sneer_left, uniform(own, 0.f, 1.f));
      if (uniform(own, 0.f, 1.f) < 0.5f)
        own_pair(blendshape::mouth_upper_up_left, uniform(own, 0.f, 1.f));
    }
    if (uniform(own, 0.f, 1.f) < 0.08f)
      own_pair(blendshape::mouth_lower_down_left, uniform(own, 0.f, 1.f));
  }
  set_truth_expressions(p);
  return p;
}

namespace {
float smoothstep(float a, float b, float x) {
  float t = (x - a) / (b - a);
  t = t < 0.f ? 0.f : (t > 1.f ? 1.f : t);
  return t * t * (3.f - 2.f * t);
}
// 1 inside [a, b] with smooth ramps of length `ramp` at both ends.
float envelope(float a, float b, float ramp, float x) {
  return smoothstep(a, a + ramp, x) * (1.f - smoothstep(b - ramp, b, x));
}
float pulse(float centre, float half_width, float x) {
  float d = std::abs(x - centre) / half_width;
  return d >= 1.f ? 0.f : 1.f - d;
}
}  // namespace

proxy_pose demo_motion_pose(double t_seconds, const proxy_skeleton& skeleton) {
  proxy_pose p;
  p.t = t_seconds;
  p.confidence.fill(1.f);
  double wrapped = std::fmod(t_seconds, 10.0);
  if (wrapped < 0.0) wrapped += 10.0;
  const float t = static_cast<float>(wrapped);
  const float two_pi = 2.f * k_pi;

  // Squats (0-4 s): thighs forward, shins back, feet flat, torso leaning, arms forward.
  const float k = t < 4.f ? 0.5f * (1.f - std::cos(two_pi * t / 2.f)) : 0.f;
  // Yaw first, then lean in the yawed frame: both hip joints stay at the same height.
  const glm::quat yaw_only = axis_angle(k_y, 10.f * k_deg * std::sin(two_pi * t / 10.f));
  const glm::quat hips = yaw_only * axis_angle(k_x, 25.f * k_deg * k);
  const glm::quat thigh_world = axis_angle(-k_x, 75.f * k_deg * k);
  const glm::quat shin_world = axis_angle(k_x, 30.f * k_deg * k);
  p[bone::hips] = hips;
  p[bone::left_upper_leg] = glm::inverse(hips) * yaw_only * thigh_world;
  p[bone::right_upper_leg] = p[bone::left_upper_leg];
  p[bone::left_lower_leg] = glm::inverse(thigh_world) * shin_world;
  p[bone::right_lower_leg] = p[bone::left_lower_leg];
  p[bone::left_foot] = glm::inverse(shin_world);  // foot stays flat in the yawed frame
  p[bone::right_foot] = p[bone::left_foot];
  p[bone::spine] = axis_angle(k_x, -8.f * k_deg * k);
  const glm::quat arms_forward = axis_angle(-k_y, 75.f * k_deg * k);
  // Relaxed arms (about 65 degrees down) blended toward forward during the squats.
  const glm::quat relaxed = axis_angle(k_z, -65.f * k_deg * (1.f - k));
  const glm::quat left_arm = arms_forward * relaxed;
  p[bone::left_upper_arm] = left_arm;

  // Wave with the right hand (4-8 s): arm raised, twisted so the elbow bends upward and the
  // palm faces the camera; the elbow and hand swing.
  const float wave = envelope(4.f, 8.f, 0.6f, t);
  const float swing = std::sin(two_pi * 2.f * t);
  // Built as left-side rotations, mirrored onto the right side.
  const glm::quat raised = axis_angle(k_z, 20.f * k_deg) * axis_angle(k_x, -90.f * k_deg);
  const glm::quat right_upper = slerp_shortest(left_arm, raised, wave);
  p[bone::right_upper_arm] = mirror_x(right_upper);
  p[bone::right_lower_arm] = mirror_x(axis_angle(-k_y, wave * (90.f + 20.f * swing) * k_deg));
  p[bone::right_hand] = mirror_x(axis_angle(k_y, wave * 15.f * swing * k_deg));

  // Left-hand finger curls (5-9 s), two of them.
  const float curl = (t > 5.f && t < 9.f) ? 0.5f * (1.f - std::cos(two_pi * (t - 5.f) / 2.f)) : 0.f;
  curl_hand(p, false, curl * 75.f * k_deg);
  p[bone::left_lower_arm] = axis_angle(-k_y, 40.f * k_deg * curl);

  // Head and gaze.
  p[bone::neck] = axis_angle(k_y, 8.f * k_deg * std::sin(two_pi * t / 10.f));
  p[bone::head] = axis_angle(k_y, 12.f * k_deg * std::sin(two_pi * t / 5.f)) *
                  axis_angle(k_x, 6.f * k_deg * std::sin(two_pi * t / 2.5f));
  glm::quat eye = axis_angle(k_y, 12.f * k_deg * std::sin(two_pi * t / 3.3333333f));
  p[bone::left_eye] = eye;
  p[bone::right_eye] = eye;

  // Expressions: blinks, talking (6-9.5 s), brows up while waving.
  p[expression::blink] =
      pulse(1.0f, 0.15f, t) + pulse(3.3f, 0.15f, t) + pulse(5.6f, 0.15f, t) + pulse(8.2f, 0.15f, t);
  p[expression::blink_left] = pulse(9.5f, 0.2f, t);  // a wink
  const float talk = envelope(6.f, 9.5f, 0.3f, t);
  const float phase = (t - 6.f) / 0.35f;
  if (talk > 0.f) {
    int v = static_cast<int>(std::floor(phase));
    float frac = phase - std::floor(phase);
    float shape = std::sin(k_pi * frac);
    p.expressions[idx(expression::aa) + ((v % 5) + 5) % 5] = talk * shape;
  }
  p[expression::brow_up_left] = 0.7f * wave;
  p[expression::brow_up_right] = 0.7f * wave;

  // The generator draws ARKit shapes: the expressions above converted, then the truth
  // expressions derived back from them and from the eyes.
  blendshapes_from_expressions(p, p.blendshapes);
  set_truth_expressions(p);

  p.hips_position = glm::vec3(0.05f * std::sin(two_pi * t / 10.f), 0.f, 0.f);
  ground_pose(skeleton, p);
  return p;
}

proxy_pose demo_motion_pose(double t) {
  static const proxy_skeleton k_default = make_proxy_skeleton();
  return demo_motion_pose(t, k_default);
}

}  // namespace avatarmap
