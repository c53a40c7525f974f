#include "avatarmap/time/offline_smoother.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/confidence_gate.hpp"

namespace avatarmap {

namespace {
// Kernels reach 3 sigma: the weight there is 1.1 % of the centre's.
constexpr double k_kernel_reach = 3.0;
constexpr int k_first_finger = static_cast<int>(bone::left_thumb_metacarpal);
// Hands and fingers seen with a low confidence are filled as gaps, not smoothed: a few
// millimetres of error turn a 2-4 cm finger bone, so a barely-seen hand's points say little.
constexpr bool hand_or_finger(int b) {
  return b >= k_first_finger || b == idx(bone::left_hand) || b == idx(bone::right_hand);
}
constexpr int k_fingers_per_hand = 15;
// Noise adaptation (offline_smoother_options::adapt_to_noise): the mean size of the observed
// bones' second differences (radians per sample) of the reference recordings the sigmas were
// tuned on (the synthetic noisy scenario without bursts, 30 fps, tuning seeds 1-3), per group
// (body, fingers); the running mean's time constant (seconds); the clamp of the factor.
constexpr double k_reference_noise[2] = {0.22, 0.93};
constexpr double k_reference_fps = 30.0;
constexpr double k_noise_seconds = 4.0;
constexpr double k_min_noise_factor = 0.25, k_max_noise_factor = 1.0;
// Longest hold, ease or gap accepted (a window of minutes would be a mistake, not a choice).
constexpr float k_max_gap_option_seconds = 60.f;
constexpr int k_min_capacity = 8;
constexpr int k_max_capacity = 65536;

bool finite_at_least(float v, float lo) { return std::isfinite(v) && v >= lo; }

float kernel(double dt, double sigma) {
  return static_cast<float>(std::exp(-0.5 * (dt * dt) / (sigma * sigma)));
}

glm::quat normalized_or(const glm::quat& sum, const glm::quat& fallback) {
  const float n2 = sum.x * sum.x + sum.y * sum.y + sum.z * sum.z + sum.w * sum.w;
  if (!(n2 > 1e-20f) || !std::isfinite(n2)) return fallback;
  const float k = 1.f / std::sqrt(n2);
  return glm::quat(sum.w * k, sum.x * k, sum.y * k, sum.z * k);
}
}  // namespace

status offline_smoother_options::validate() const {
  auto range = [](const char* name, const std::string& what) {
    return status::error(std::string("offline_smoother_options.") + name + " must be " + what);
  };
  if (!finite_at_least(strength, 0.f)) return range("strength", "finite and >= 0");
  if (!(finite_at_least(body_sigma_seconds, 0.f) && body_sigma_seconds > 0.f))
    return range("body_sigma_seconds", "finite and > 0");
  if (!(finite_at_least(finger_sigma_seconds, 0.f) && finger_sigma_seconds > 0.f))
    return range("finger_sigma_seconds", "finite and > 0");
  if (!(finite_at_least(position_sigma_seconds, 0.f) && position_sigma_seconds > 0.f))
    return range("position_sigma_seconds", "finite and > 0");
  if (!(finite_at_least(expression_sigma_seconds, 0.f) && expression_sigma_seconds > 0.f))
    return range("expression_sigma_seconds", "finite and > 0");
  // A window several seconds wide is a strength nobody means (and a large buffer).
  const float widest = strength * std::max({body_sigma_seconds, finger_sigma_seconds,
                                            position_sigma_seconds, expression_sigma_seconds});
  if (!(widest <= 2.f))
    return range("strength", "such that strength x the largest sigma is at most 2 s");
  if (!(finite_at_least(low_confidence_sigma_seconds, 0.f) &&
        strength * low_confidence_sigma_seconds <= 2.f))
    return range("low_confidence_sigma_seconds", "finite, >= 0 and at most 2 s x strength");
  if (!(min_sigma_frames >= 0.f && min_sigma_frames <= 10.f))
    return range("min_sigma_frames", "in [0, 10]");
  if (degree != 0 && degree != 2) return range("degree", "0 or 2");
  if (!(observed_above >= 0.f && observed_above <= 1.f))
    return range("observed_above", "in [0, 1]");
  if (!(finite_at_least(max_gap_seconds, 0.f) && max_gap_seconds <= k_max_gap_option_seconds))
    return range("max_gap_seconds", "in [0, 60]");
  if (!(finite_at_least(hold_seconds, 0.f) && hold_seconds <= k_max_gap_option_seconds))
    return range("hold_seconds", "in [0, 60]");
  if (!(finite_at_least(ease_seconds, 0.f) && ease_seconds <= k_max_gap_option_seconds))
    return range("ease_seconds", "in [0, 60]");
  if (capacity_frames < k_min_capacity || capacity_frames > k_max_capacity)
    return range("capacity_frames", "in [8, 65536]");
  return {};
}

struct offline_smoother::slot {
  proxy_pose pose;
  // Confidence that decides and weights (pose.confidence, with a hand and its fingers capped
  // by their lower arm under hands_follow_arms); pose.confidence is what is written out.
  std::array<float, k_bone_count> weight;
  int segment = 0;
  bool position_ok = true;
};

offline_smoother::offline_smoother(const offline_smoother_options& options) : options_(options) {
  assert(options.validate().ok());
  options_.capacity_frames = std::clamp(options.capacity_frames, k_min_capacity, k_max_capacity);
  if (!(options_.strength >= 0.f) || !std::isfinite(options_.strength)) options_.strength = 0.f;
  const double widest =
      options_.strength *
      std::max({options_.body_sigma_seconds, options_.finger_sigma_seconds,
                options_.position_sigma_seconds, options_.expression_sigma_seconds});
  past_seconds_ = std::isfinite(widest) ? k_kernel_reach * widest : 0.0;
  lookahead_ = std::max({past_seconds_, double(options_.max_gap_seconds),
                         double(options_.hold_seconds) + double(options_.ease_seconds)});
  if (!std::isfinite(lookahead_)) lookahead_ = 0.0;
  capacity_ = options_.capacity_frames;
  slots_.reset(new slot[static_cast<size_t>(capacity_)]);
  kernel_storage_.reset(new float[static_cast<size_t>(2 * k_table_count * capacity_)]);
  slot_storage_.reset(new const slot*[static_cast<size_t>(k_table_count * capacity_)]);
  for (int t = 0; t < k_table_count; ++t) {
    tables_[t].w = kernel_storage_.get() + 2 * t * capacity_;
    tables_[t].u = tables_[t].w + capacity_;
    tables_[t].slots = slot_storage_.get() + t * capacity_;
  }
  reset();
}

offline_smoother::~offline_smoother() = default;

void offline_smoother::reset() noexcept {
  head_ = count_ = centre_ = 0;
  segment_ = 0;
  finished_ = false;
  has_last_t_ = false;
  last_t_ = 0.0;
  sigma_floor_ = 0.0;
  sigma_widest_ = 0.0;
  noise_.fill(0.0);
  noise_dt_ = 0.0;
  noise_weight_ = 0.0;
  last_good_.fill(identity_quat());
  last_good_t_.fill(0.0);
  last_good_segment_.fill(-1);
}

offline_smoother::slot& offline_smoother::at(int i) const noexcept {
  int k = head_ + i;
  if (k >= capacity_) k -= capacity_;
  return slots_[static_cast<size_t>(k)];
}

bool offline_smoother::push(const proxy_pose& in) noexcept {
  if (count_ == capacity_) {
    if (centre_ == 0) return false;
    head_ = head_ + 1 == capacity_ ? 0 : head_ + 1;
    --count_;
    --centre_;
  }
  // A time that goes back or is not a number starts a new segment (nothing is mixed across).
  if (!has_last_t_ || !std::isfinite(in.t) || in.t < last_t_) ++segment_;
  has_last_t_ = std::isfinite(in.t);
  last_t_ = in.t;
  slot& s = at(count_++);
  s.pose = in;
  s.segment = segment_;
  for (int b = 0; b < k_bone_count; ++b) {
    if (!is_finite(s.pose.rotations[b])) {
      s.pose.rotations[b] = identity_quat();
      s.pose.confidence[b] = 0.f;
    } else if (!std::isfinite(s.pose.confidence[b])) {
      s.pose.confidence[b] = 0.f;
    }
  }
  s.weight = s.pose.confidence;
  if (options_.hands_follow_arms) {
    auto cap = [&](bone lower_arm, bone hand, bone first_finger) {
      const float arm = s.pose.confidence[idx(lower_arm)];
      s.weight[idx(hand)] = std::min(s.weight[idx(hand)], arm);
      for (int b = idx(first_finger); b < idx(first_finger) + k_fingers_per_hand; ++b)
        s.weight[b] = std::min(s.weight[b], arm);
    };
    cap(bone::left_lower_arm, bone::left_hand, bone::left_thumb_metacarpal);
    cap(bone::right_lower_arm, bone::right_hand, bone::right_thumb_metacarpal);
  }
  s.position_ok = is_finite(in.hips_position);
  if (options_.adapt_to_noise) observe_noise();
  return true;
}

// The newest three poses of one segment give, per bone observed in all three, the second
// difference of its rotation: the change of the per-frame turn, d = r(q1^-1 q2) - r(q0^-1 q1)
// with r the rotation vector (2 x the vector part, small angles), rescaled to the mean step
// when the steps differ. For noise of n radians per sample it is ~n * sqrt(6) per axis; real
// motion adds its acceleration x dt^2, small against noise at video rates.
void offline_smoother::observe_noise() noexcept {
  if (count_ < 3) return;
  const slot& a = at(count_ - 3);
  const slot& b = at(count_ - 2);
  const slot& c = at(count_ - 1);
  if (a.segment != c.segment || b.segment != c.segment) return;
  const double dt0 = b.pose.t - a.pose.t, dt1 = c.pose.t - b.pose.t;
  if (!(dt0 > 0.0) || !(dt1 > 0.0) || !std::isfinite(dt0 + dt1)) return;
  const double mean_dt = 0.5 * (dt0 + dt1);
  const float k0 = float(mean_dt / dt0), k1 = float(mean_dt / dt1);
  const float threshold = options_.observed_above;
  double sum[2] = {0.0, 0.0};
  int n[2] = {0, 0};
  for (int i = 0; i < k_bone_count; ++i) {
    if (!(a.weight[i] >= threshold && b.weight[i] >= threshold && c.weight[i] >= threshold))
      continue;
    const glm::quat d0 = glm::conjugate(a.pose.rotations[i]) * b.pose.rotations[i];
    const glm::quat d1 = glm::conjugate(b.pose.rotations[i]) * c.pose.rotations[i];
    const float s0 = d0.w < 0.f ? -2.f : 2.f, s1 = d1.w < 0.f ? -2.f : 2.f;
    const glm::vec3 v =
        (s1 * k1) * glm::vec3(d1.x, d1.y, d1.z) - (s0 * k0) * glm::vec3(d0.x, d0.y, d0.z);
    // Bones that do not change at all (set by a prior: toes, clavicles) tell nothing.
    const float len = glm::length(v);
    if (!(len > 1e-6f)) continue;
    const int g = i >= k_first_finger ? 1 : 0;
    sum[g] += len;
    ++n[g];
  }
  if (n[0] + n[1] == 0) return;
  // A running mean over about k_noise_seconds: plain while less than that has been seen.
  const double w = std::min(mean_dt, k_noise_seconds);
  const double total = std::min(noise_weight_ + w, k_noise_seconds);
  const double alpha = w / std::max(total, w);
  for (int g = 0; g < 2; ++g)
    if (n[g] > 0) noise_[g] += alpha * (sum[g] / n[g] - noise_[g]);
  noise_dt_ += alpha * (mean_dt - noise_dt_);
  noise_weight_ = total;
}

bool offline_smoother::ready() const noexcept {
  const int pending = count_ - centre_;
  if (pending <= 0) return false;
  if (finished_ || pending >= capacity_) return true;
  const slot& newest = at(count_ - 1);
  const slot& c = at(centre_);
  if (newest.segment != c.segment) return true;
  return newest.pose.t - c.pose.t >= lookahead_;
}

bool offline_smoother::pop(proxy_pose& out) noexcept {
  if (!ready()) return false;
  emit(out);
  // Drop history no kernel can reach any more (older than the widest reach behind the next
  // centre, or in an earlier segment).
  const int ref = std::min(centre_, count_ - 1);
  while (centre_ > 0 && ref >= 0) {
    const slot& oldest = at(0);
    const slot& r = at(std::min(centre_, count_ - 1));
    const double past =
        std::max({past_seconds_, k_kernel_reach * sigma_floor_, k_kernel_reach * sigma_widest_});
    if (oldest.segment == r.segment && !(r.pose.t - oldest.pose.t > past)) break;
    head_ = head_ + 1 == capacity_ ? 0 : head_ + 1;
    --count_;
    --centre_;
  }
  return true;
}

// The kernel around pose `centre` for `sigma`: the poses of its segment within reach, with
// their weight and u = dt / sigma. Computed once per centre and sigma (the table is kept
// while both stay the same), so that the 55 bones share the exponentials.
const offline_smoother::kernel_table& offline_smoother::kernel_for(int table, int centre,
                                                                   float sigma) noexcept {
  kernel_table& k = tables_[table];
  if (k.centre == centre && k.sigma == sigma && k.version == version_) return k;
  k.centre = centre;
  k.sigma = sigma;
  k.version = version_;
  const slot& c = at(centre);
  const double reach = k_kernel_reach * sigma;
  int lo = centre, hi = centre;
  if (sigma > 0.f) {
    auto within = [&](int j) {
      const slot& s = at(j);
      return s.segment == c.segment && std::abs(s.pose.t - c.pose.t) <= reach;
    };
    while (lo > 0 && within(lo - 1)) --lo;
    while (hi + 1 < count_ && within(hi + 1)) ++hi;
  }
  k.lo = lo;
  k.hi = hi;
  for (int j = lo; j <= hi; ++j) {
    k.slots[j - lo] = &at(j);
    const double dt = at(j).pose.t - c.pose.t;
    k.w[j - lo] = j == centre ? 1.f : kernel(dt, sigma);
    k.u[j - lo] = j == centre ? 0.f : float(dt / sigma);
  }
  return k;
}

// Gaussian-weighted estimate of bone b at the kernel's centre, over the poses the kernel
// reaches: all alike (uniform), the observed ones weighted by confidence (observed), or all
// weighted by confidence. Degree 0: the weighted mean. Degree 2: the value at the centre of a
// weighted least-squares quadratic in time (local quadratic regression), which follows the
// peaks of fast motion that a mean of the same width flattens; it falls back to the mean where
// the neighbours do not determine a quadratic (fewer than three distinct times).
void offline_smoother::smooth_rotation(const kernel_table& k, int b, weighting how,
                                       glm::quat& out) const noexcept {
  const glm::quat ref = at(k.centre).pose.rotations[b];
  if (k.lo == k.hi) {
    out = ref;
    return;
  }
  // Moments of the weights in u (|u| <= 3, so floats keep ~6 digits of the 3x3 system), and
  // the weighted sums of q, u q and u^2 q. The solve below is in double.
  float m0 = 0, m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  glm::vec4 q0(0.f), q1(0.f), q2(0.f);
  const float threshold = options_.observed_above;
  for (int j = k.lo; j <= k.hi; ++j) {
    const slot& s = *k.slots[j - k.lo];
    const float conf = s.weight[b];
    if (how == weighting::observed && !(conf >= threshold)) continue;
    const float w = k.w[j - k.lo] * (how == weighting::uniform ? 1.f : conf);
    if (!(w > 0.f)) continue;
    const glm::quat& q = s.pose.rotations[b];
    const float sign = ref.x * q.x + ref.y * q.y + ref.z * q.z + ref.w * q.w < 0.f ? -1.f : 1.f;
    const glm::vec4 v = sign * glm::vec4(q.w, q.x, q.y, q.z);
    const float u = k.u[j - k.lo], wu = w * u, wu2 = wu * u;
    m0 += w;
    m1 += wu;
    m2 += wu2;
    m3 += wu2 * u;
    m4 += wu2 * u * u;
    q0 += w * v;
    q1 += wu * v;
    q2 += wu2 * v;
  }
  double r[4];
  const double c00 = double(m2) * m4 - double(m3) * m3, c01 = double(m3) * m2 - double(m1) * m4,
               c02 = double(m1) * m3 - double(m2) * m2;
  const double det = m0 * c00 + m1 * c01 + m2 * c02;
  // Relative to the product of the diagonal: a nearly singular system (too few distinct times,
  // or all weight at one end) is solved as a mean instead.
  if (options_.degree == 2 && det > 1e-6 * m0 * m2 * m4 && det > 0.0) {
    for (int c = 0; c < 4; ++c) r[c] = (c00 * q0[c] + c01 * q1[c] + c02 * q2[c]) / det;
  } else {
    for (int c = 0; c < 4; ++c) r[c] = m0 > 0.0 ? q0[c] / m0 : 0.0;
  }
  out = normalized_or(glm::quat(float(r[0]), float(r[1]), float(r[2]), float(r[3])), ref);
}

void offline_smoother::emit(proxy_pose& out) noexcept {
  const int ci = centre_++;
  const slot& c = at(ci);
  out.t = c.pose.t;
  out.confidence = c.pose.confidence;
  const float k = options_.strength;
  // The frame interval around the centre (the mean of the steps to its neighbours in the same
  // segment) sets the least sigma: min_sigma_frames of it, within a third of the lookahead.
  {
    double steps = 0.0;
    int n = 0;
    if (ci > 0 && at(ci - 1).segment == c.segment) {
      steps += c.pose.t - at(ci - 1).pose.t;
      ++n;
    }
    if (ci + 1 < count_ && at(ci + 1).segment == c.segment) {
      steps += at(ci + 1).pose.t - c.pose.t;
      ++n;
    }
    const double floor = n > 0 ? options_.min_sigma_frames * steps / n : 0.0;
    sigma_floor_ = k > 0.f && std::isfinite(floor) && floor > 0.0
                       ? std::min(floor, lookahead_ / k_kernel_reach)
                       : 0.0;
  }
  const float floor = static_cast<float>(sigma_floor_);
  // Noise adaptation: width x (noise density / the reference's)^(1/7), within a third of the
  // lookahead (the kernel's reach must fit the window).
  float factor[2] = {1.f, 1.f};
  if (options_.adapt_to_noise && noise_weight_ > 0.0 && noise_dt_ > 0.0) {
    for (int g = 0; g < 2; ++g) {
      const double ratio = noise_[g] / k_reference_noise[g];
      const double density = ratio * ratio * (noise_dt_ * k_reference_fps);
      factor[g] =
          float(std::clamp(std::pow(density, 1.0 / 7.0), k_min_noise_factor, k_max_noise_factor));
    }
  }
  const float widest = float(lookahead_ / k_kernel_reach);
  const float sigma_body =
      std::max(std::min(k * options_.body_sigma_seconds * factor[0], widest), floor);
  const float sigma_finger =
      std::max(std::min(k * options_.finger_sigma_seconds * factor[1], widest), floor);
  sigma_widest_ = std::max(sigma_body, sigma_finger);
  const float sigma_low = std::max(k * options_.low_confidence_sigma_seconds, floor);
  ++version_;  // the ring moved: every kernel table is stale
  const double tc = c.pose.t;
  const float threshold = options_.observed_above;
  confidence_options ease;
  ease.hold_seconds = options_.hold_seconds;
  ease.ease_seconds = options_.ease_seconds;

  for (int b = 0; b < k_bone_count; ++b) {
    const int group = b >= k_first_finger ? k_finger_table : k_body_table;
    const float sigma = b >= k_first_finger ? sigma_finger : sigma_body;
    if (c.weight[b] >= threshold) {
      smooth_rotation(kernel_for(group, ci, sigma), b, weighting::observed, out.rotations[b]);
      last_good_[b] = out.rotations[b];
      last_good_t_[b] = tc;
      last_good_segment_[b] = c.segment;
      continue;
    }
    // Seen, but barely (its own confidence low and not zero): the measurement still says where
    // the bone went, so it is smoothed over a wider window with every frame weighted by its
    // confidence (observed neighbours dominate near the gap's ends).
    const float own = c.pose.confidence[b];
    if (options_.low_confidence_sigma_seconds > 0.f && own > 0.f && own == c.weight[b] &&
        !hand_or_finger(b)) {
      smooth_rotation(kernel_for(k_low_confidence_table, ci, sigma_low), b, weighting::confidence,
                      out.rotations[b]);
      continue;
    }
    // A gap: the sides are the last observed output before and the next observed pose within
    // the lookahead (same segment).
    const bool has_left = last_good_segment_[b] == c.segment && std::isfinite(tc);
    const double a = has_left ? tc - last_good_t_[b] : 0.0;
    int next = -1;
    for (int j = ci + 1; j < count_; ++j) {
      const slot& s = at(j);
      if (s.segment != c.segment || !(s.pose.t - tc <= lookahead_)) break;
      if (s.weight[b] >= threshold) {
        next = j;
        break;
      }
    }
    if (!has_left && next < 0) {
      // Observed nowhere within reach: what the input says (the solver's hold, ease or prior).
      smooth_rotation(kernel_for(group, ci, sigma), b, weighting::uniform, out.rotations[b]);
      continue;
    }
    glm::quat right{};
    double z = 0.0;
    if (next >= 0) {
      smooth_rotation(kernel_for(k_next_table, next, sigma), b, weighting::observed, right);
      z = at(next).pose.t - tc;
    }
    if (has_left && next >= 0 && a + z <= options_.max_gap_seconds) {
      const double span = a + z;
      out.rotations[b] =
          span > 0.0 ? slerp_shortest(last_good_[b], right, float(a / span)) : last_good_[b];
      continue;
    }
    glm::quat from_left{}, from_right{};
    if (has_left)
      from_left = slerp_shortest(last_good_[b], identity_quat(), hold_and_ease(a, ease).weight);
    if (next >= 0)
      from_right = slerp_shortest(right, identity_quat(), hold_and_ease(z, ease).weight);
    if (has_left && next >= 0) {
      // Each side weighted by how much of it is still held and by nearness: a side that has
      // eased fully to rest gives way to the other, and the blend is continuous everywhere.
      const double hold_left = 1.0 - hold_and_ease(a, ease).weight;
      const double hold_right = 1.0 - hold_and_ease(z, ease).weight;
      const double den = hold_left * z + hold_right * a;
      const float f = den > 1e-12 ? float(hold_right * a / den) : 0.5f;
      out.rotations[b] = slerp_shortest(from_left, from_right, f);
    } else
      out.rotations[b] = has_left ? from_left : from_right;
  }

  // Hips position and expressions: plain Gaussian means over the segment.
  const double sigma_pos = std::max(k * options_.position_sigma_seconds, floor);
  const double sigma_expr = std::max(k * options_.expression_sigma_seconds, floor);
  const double reach = k_kernel_reach * std::max(sigma_pos, sigma_expr);
  glm::vec3 pos_sum(0.f);
  float pos_w = 0.f;
  std::array<float, k_expression_count> expr_sum{}, expr_w{};
  auto add = [&](int j) {
    const slot& s = at(j);
    if (s.segment != c.segment) return false;
    const double dt = s.pose.t - tc;
    const bool is_centre = j == ci;
    if (!is_centre && !(std::abs(dt) <= reach)) return false;
    const float wp =
        sigma_pos > 0.0 ? (std::abs(dt) <= k_kernel_reach * sigma_pos ? kernel(dt, sigma_pos) : 0.f)
                        : (is_centre ? 1.f : 0.f);
    const float we =
        sigma_expr > 0.0
            ? (std::abs(dt) <= k_kernel_reach * sigma_expr ? kernel(dt, sigma_expr) : 0.f)
            : (is_centre ? 1.f : 0.f);
    if (s.position_ok && wp > 0.f) {
      pos_sum += wp * s.pose.hips_position;
      pos_w += wp;
    }
    if (we > 0.f)
      for (int e = 0; e < k_expression_count; ++e)
        if (std::isfinite(s.pose.expressions[e])) {
          expr_sum[e] += we * s.pose.expressions[e];
          expr_w[e] += we;
        }
    return true;
  };
  add(ci);
  for (int j = ci - 1; j >= 0 && add(j); --j) {
  }
  for (int j = ci + 1; j < count_ && add(j); ++j) {
  }
  out.hips_position = pos_w > 0.f ? pos_sum / pos_w : glm::vec3(0.f, k_default_hips_height, 0.f);
  for (int e = 0; e < k_expression_count; ++e)
    out.expressions[e] = expr_w[e] > 0.f ? expr_sum[e] / expr_w[e] : 0.f;
}

}  // namespace avatarmap
