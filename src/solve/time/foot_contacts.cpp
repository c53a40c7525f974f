#include "avatarmap/time/foot_contacts.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace avatarmap {

namespace {

// Time steps longer than this (or not positive) break a take: no speed across them, and the
// root motion starts again from the filtered hips.
constexpr double k_max_step_seconds = 0.5;

bool finite3(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

bool good_step(double t0, double t1) {
  const double dt = t1 - t0;
  return std::isfinite(dt) && dt > 0.0 && dt <= k_max_step_seconds;
}

constexpr bone k_leg_bones[2][3] = {{bone::left_lower_leg, bone::left_foot, bone::left_toes},
                                    {bone::right_lower_leg, bone::right_foot, bone::right_toes}};
constexpr bone k_toes[2] = {bone::left_toes, bone::right_toes};

// The measured hips' drift under a person standing still (m/s): both feet carried together
// slower than this since a plant are not a step (docs/contacts.md).
constexpr float k_drift_speed = 0.05f;
// A foot lifted by release_distance plants again once slower than this share of plant_speed.
constexpr float k_settled = 0.5f;

}  // namespace

status foot_contact_options::validate() const {
  if (status st = check_options(k_foot_contact_option_table, *this, "foot_contacts."); !st.ok())
    return st;
  if (!(release_speed >= plant_speed))
    return status::error("foot_contacts.contact_release_speed must be >= contact_plant_speed");
  if (!(release_height >= plant_height))
    return status::error("foot_contacts.contact_release_height must be >= contact_plant_height");
  return {};
}

void measure_feet(const proxy_skeleton& skeleton, const proxy_pose& pose, float min_confidence,
                  std::array<foot_measure, 2>& out) {
  // The legs' bones only (compute_proxy_fk's heels and toe tips, bit for bit).
  proxy_feet feet;
  compute_proxy_feet(skeleton, pose, feet);
  float floor = std::numeric_limits<float>::infinity();
  glm::vec3 heel[2], toe[2];
  bool finite[2];
  for (int s = 0; s < 2; ++s) {
    heel[s] = feet.heels[s];
    toe[s] = feet.toe_tips[s];
    finite[s] = finite3(heel[s]) && finite3(toe[s]);
    if (finite[s]) floor = std::min(floor, std::min(heel[s].y, toe[s].y));
  }
  for (int s = 0; s < 2; ++s) {
    foot_measure& m = out[s];
    float c = 1.f;
    for (bone b : k_leg_bones[s]) c = std::min(c, pose.confidence[idx(b)]);
    m.usable = finite[s] && c >= min_confidence && c > 0.f;  // NaN confidence: not usable
    if (!finite[s]) {
      m.point = glm::vec3(0.f);
      m.height = 0.f;
      continue;
    }
    m.point = 0.5f * (heel[s] + toe[s]);
    m.height = std::min(heel[s].y, toe[s].y) - floor;
  }
}

struct foot_contact_stage::slot {
  proxy_pose pose;
  std::array<foot_measure, 2> feet;
  bool ok = false;  // hips and feet finite
};

foot_contact_stage::foot_contact_stage(const foot_contact_options& options, bool both_sided,
                                       const proxy_skeleton& skeleton)
    : options_(options), both_sided_(both_sided), base_skeleton_(skeleton), skeleton_(skeleton) {
  assert(options.validate().ok());
  const int w = std::clamp(options.window_frames, 1, k_max_contact_window_frames);
  // Causal mode keeps the newest and the one before (the speed over the last frame).
  capacity_ = both_sided ? 2 * w + 1 : 2;
  ring_.reset(new slot[static_cast<std::size_t>(capacity_)]);
}

foot_contact_stage::~foot_contact_stage() = default;

void foot_contact_stage::set_leg_length(float leg_length) noexcept {
  const float base = base_skeleton_.lengths[idx(bone::left_upper_leg)] +
                     base_skeleton_.lengths[idx(bone::left_lower_leg)];
  if (!(std::isfinite(leg_length) && leg_length > 0.f && base > 0.f)) {
    if (leg_length_ != 0.f) skeleton_ = base_skeleton_;
    leg_length_ = 0.f;
    return;
  }
  if (leg_length_ > 0.f && std::fabs(leg_length - leg_length_) < 0.01f * leg_length_) return;
  leg_length_ = leg_length;
  const float k = leg_length / base;
  skeleton_ = base_skeleton_;
  skeleton_.height *= k;
  skeleton_.scale *= k;
  for (glm::vec3& o : skeleton_.offsets) o *= k;
  for (float& l : skeleton_.lengths) l *= k;
  skeleton_.heel_offset *= k;
}

foot_contact_stage::slot& foot_contact_stage::at(long i) noexcept {
  return ring_[static_cast<std::size_t>(i % capacity_)];
}

void foot_contact_stage::reset() noexcept {
  pushed_ = emitted_ = 0;
  planted_.fill(false);
  stepped_.fill(false);
  contact_.fill(0.f);
  anchored_.fill(false);
  have_root_ = false;
}

bool foot_contact_stage::push(const proxy_pose& in, proxy_pose& out) noexcept {
  if (!options_.enabled) {
    out = in;
    return true;
  }
  slot& s = at(pushed_);
  s.pose = in;
  measure_feet(skeleton_, in, options_.min_confidence, s.feet);
  s.ok = std::isfinite(in.t) && finite3(in.hips_position) && finite3(s.feet[0].point) &&
         finite3(s.feet[1].point);
  ++pushed_;
  const long delay = both_sided_ ? (capacity_ - 1) / 2 : 0;
  if (pushed_ - emitted_ <= delay) return false;
  emit(static_cast<int>(emitted_ % capacity_), out);
  ++emitted_;
  return true;
}

bool foot_contact_stage::flush(proxy_pose& out) noexcept {
  if (!options_.enabled || emitted_ >= pushed_) {
    reset();
    return false;
  }
  emit(static_cast<int>(emitted_ % capacity_), out);
  ++emitted_;
  return true;
}

void foot_contact_stage::emit(int k, proxy_pose& out) noexcept {
  const slot& cur = ring_[static_cast<std::size_t>(k)];
  out = cur.pose;
  out.foot_contact = {0.f, 0.f};
  const double t = cur.pose.t;
  if (!cur.ok) {
    // Nothing to plant; hips that are not finite keep the last output's (never NaN out of a
    // stage that had a finite pose).
    if (have_root_ && !finite3(out.hips_position)) out.hips_position = root_prev_;
    planted_.fill(false);
    stepped_.fill(false);
    contact_.fill(0.f);
    anchored_.fill(false);
    return;
  }
  // Time backwards is a new take: the root motion starts again from the filtered hips. A gap
  // (or a pose without finite points before) restarts the contacts only, so the hips go on
  // from where they were.
  const bool root_continues = have_root_ && std::isfinite(t_prev_) && t > t_prev_;
  const bool continues = root_continues && good_step(t_prev_, t);
  if (!continues) {
    planted_.fill(false);
    stepped_.fill(false);
    contact_.fill(0.f);
    anchored_.fill(false);
  }
  const float dt = continues ? static_cast<float>(t - t_prev_) : 0.f;

  // Speeds: causal, over the last frame; both-sided, the smaller of the backward and forward
  // differences over up to window_frames frames (a foot that has just landed or is about to
  // lift is still over one of them).
  const long self = emitted_;
  const long w = both_sided_ ? (capacity_ - 1) / 2 : 1;
  // The farthest neighbour on each side still within the take (self: none).
  long far[2] = {self, self};
  for (int side = 0; side < 2; ++side) {
    const int dir = side == 0 ? -1 : 1;
    if (dir > 0 && !both_sided_) continue;
    for (long j = 1; j <= w; ++j) {
      const long i = self + dir * j;
      if (i < 0 || i >= pushed_ || i < pushed_ - capacity_) break;
      const slot& a = at(dir < 0 ? i : i - 1);
      const slot& b = at(dir < 0 ? i + 1 : i);
      if (!a.ok || !b.ok || !good_step(a.pose.t, b.pose.t)) break;
      far[side] = i;
    }
  }
  // The smaller of the two sides' speeds of a point of the feet; 0 with no neighbour (the
  // first pose of a take: no evidence of motion; a foot that is low may plant, a take that
  // starts standing).
  auto window_speed = [&](auto&& point) {
    float best = std::numeric_limits<float>::infinity();
    for (long o_index : far) {
      if (o_index == self) continue;
      const slot& o = at(o_index);
      const double span = std::fabs(o.pose.t - t);
      const float v = glm::length(point(o) - point(cur)) / static_cast<float>(span);
      if (std::isfinite(v)) best = std::min(best, v);
    }
    return std::isfinite(best) ? best : 0.f;
  };
  std::array<float, 2> speed;
  for (int f = 0; f < 2; ++f)
    speed[f] = window_speed([f](const slot& x) { return x.feet[f].point; });
  // The feet's speed relative to each other: the hips' (and the camera's) motion cancels. A
  // walk's swing foot moves against the stance foot; standing or in double support the feet
  // keep their distance. When they part faster than release_speed, the faster foot is not
  // planted, whatever its own speed says (a slow walk's swing foot, measured against noisy
  // hips, can stay under release_speed: holding both feet held the body back by half its
  // path on the benchmark's slow walk and bent the rig's legs to reach both anchors).
  const float apart = window_speed([](const slot& x) { return x.feet[0].point - x.feet[1].point; });
  const int swinging = apart > options_.release_speed ? (speed[0] > speed[1] ? 0 : 1) : -1;

  // Hysteresis, then the blend towards the state.
  const float step = dt / options_.blend_seconds;
  for (int f = 0; f < 2; ++f) {
    const foot_measure& m = cur.feet[f];
    if (!m.usable || f == swinging) {
      planted_[f] = false;
    } else if (planted_[f]) {
      // A planted foot that has left where it was planted by more than release_distance has
      // moved, however slowly: a slow walk's swing foot stays under release_speed. Unless the
      // other foot moved with it, slower than k_drift_speed on average since the plant: that
      // is the hips' measurement drifting under a person standing still. (Both feet carried
      // faster, the body travelling on legs the capture barely shows swing, are let go: held,
      // they pulled the rig's hips 28 cm down to reach anchors left behind.) It plants again
      // only once settled, not at once a little further on.
      const glm::vec3 moved = m.point - plant_point_[f];
      const glm::vec3 parted = (m.point - cur.feet[1 - f].point) - plant_apart_[f];
      const float own = std::sqrt(moved.x * moved.x + moved.z * moved.z);
      const float own_apart = std::sqrt(parted.x * parted.x + parted.z * parted.z);
      const float drift = k_drift_speed * static_cast<float>(t - plant_t_[f]);
      if (speed[f] > options_.release_speed || m.height > options_.release_height) {
        planted_[f] = false;
      } else if (own > options_.release_distance && (own_apart > options_.release_distance ||
                                                     own > options_.release_distance + drift)) {
        planted_[f] = false;
        stepped_[f] = true;
      }
    } else if (speed[f] < (stepped_[f] ? k_settled : 1.f) * options_.plant_speed &&
               m.height < options_.plant_height) {
      planted_[f] = true;
      stepped_[f] = false;
      plant_point_[f] = m.point;
      plant_apart_[f] = m.point - cur.feet[1 - f].point;
      plant_t_[f] = t;
    }
    if (!continues) {
      // A take's first pose: a planted foot starts planted (standing still from frame 0).
      contact_[f] = planted_[f] ? 1.f : 0.f;
    } else if (planted_[f]) {
      contact_[f] = std::min(1.f, contact_[f] + step);
    } else {
      contact_[f] = std::max(0.f, contact_[f] - step);
    }
    if (!m.usable) contact_[f] = 0.f;  // locking off for that leg, at once
    out.foot_contact[f] = contact_[f];
  }

  const glm::vec3 measured = cur.pose.hips_position;
  glm::vec3 root = measured;
  if (options_.root_follows_contacts) {
    // Where the hips would be without contacts: the previous output moved by the filtered
    // hips' motion (X/Z). Y stays the filtered one: the solver already holds the lowest foot
    // point on the floor, and lowering the hips to put a planted foot that is not the lowest
    // on it would push the lower foot through the floor.
    glm::vec3 free = measured;
    if (root_continues) {
      free.x = root_prev_.x + (measured.x - measured_prev_.x);
      free.z = root_prev_.z + (measured.z - measured_prev_.z);
    }
    // How firmly each foot holds the hips: its contact, less (both-sided) as the foot is
    // faster than half plant_speed, none at plant_speed (a foot may stay planted up to
    // release_speed: the rig's foot lock holds it, but the body is not held back by it). A
    // planted foot that still moves (a slow step in a slow walk: both feet low and slow, both
    // planted) must not hold the body back.
    std::array<float, 2> hold;
    for (int f = 0; f < 2; ++f) {
      // 1 - (speed - plant/2) / (plant/2), clamped (plant_speed > 0: validated). Causal: one
      // frame's speed is landmark noise more than motion; a planted foot holds.
      const float h =
          both_sided_ ? std::clamp(2.f - 2.f * speed[f] / options_.plant_speed, 0.f, 1.f) : 1.f;
      hold[f] = contact_[f] * h;
    }
    // The hips each anchored foot asks for (its offset from the hips is the FK's).
    auto blend_root = [&](bool only_anchored) {
      // The feet share the firmest hold between them by their holds; the rest is free motion
      // (two feet that each hold 40 % pin the body 40 %, not 80 %).
      glm::vec2 sum(0.f);
      float wsum = 0.f, firm = 0.f;
      for (int f = 0; f < 2; ++f) {
        if (hold[f] <= 0.f || (only_anchored && !anchored_[f])) continue;
        const glm::vec3 offset = cur.feet[f].point - measured;
        sum += hold[f] * glm::vec2(anchor_[f].x - offset.x, anchor_[f].z - offset.z);
        wsum += hold[f];
        firm = std::max(firm, hold[f]);
      }
      glm::vec3 r = free;
      if (wsum > 0.f) {
        r.x = firm * sum.x / wsum + (1.f - firm) * free.x;
        r.z = firm * sum.y / wsum + (1.f - firm) * free.z;
      }
      r.y = measured.y;
      return r;
    };
    root = blend_root(true);
    // New contacts are anchored where the foot is under the hips as held by the others.
    for (int f = 0; f < 2; ++f) {
      if (contact_[f] > 0.f && !anchored_[f]) {
        anchor_[f] = root + (cur.feet[f].point - measured);
        anchor_[f].y = 0.f;
        anchored_[f] = true;
      }
    }
    root = blend_root(false);
    if (!finite3(root)) root = measured;
    // A foot that holds only partly slides its anchor along with it by the rest.
    for (int f = 0; f < 2; ++f) {
      if (!anchored_[f] || contact_[f] <= 0.f) continue;
      const float follow = 1.f - hold[f] / contact_[f];
      if (follow > 0.f) {
        glm::vec3 here = root + (cur.feet[f].point - measured);
        here.y = 0.f;
        anchor_[f] += follow * (here - anchor_[f]);
      }
    }
    out.hips_position = root;
  }
  for (int f = 0; f < 2; ++f)
    if (contact_[f] <= 0.f) anchored_[f] = false;
  root_prev_ = root;
  measured_prev_ = measured;
  t_prev_ = t;
  have_root_ = true;
}

}  // namespace avatarmap
