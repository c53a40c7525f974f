#include "avatarmap/time/offline_smoother.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/confidence_gate.hpp"

// smooth_rotations works on 4 bones at once in the compilers' vector type where there is one
// (GCC, Clang: SSE2 on every x86-64 processor, NEON on ARM), else on plain arrays. Each lane
// does the same IEEE operations as scalar code would, so the results do not depend on it.
#if defined(__GNUC__) || defined(__clang__)
#define AVATARMAP_SMOOTHER_VECTORS 1
#else
#define AVATARMAP_SMOOTHER_VECTORS 0
#endif

namespace avatarmap {

namespace {
// Kernels reach 3 sigma: the weight there is 1.1 % of the centre's.
constexpr double k_kernel_reach = 3.0;
constexpr int k_first_finger = static_cast<int>(bone::left_thumb_metacarpal);
// The hand bones and fingers: a detection of them too short to believe is dropped
// (drop_flicker).
constexpr bool hand_or_finger(int b) {
  return b >= k_first_finger || b == idx(bone::left_hand) || b == idx(bone::right_hand);
}
constexpr int k_fingers_per_hand = 15;
// Groups for the worth of barely-seen measurements (low_informative_): the body without the
// hands, the fingers, the two hand bones. A hand bone spans the palm (~9 cm between six points)
// and keeps a usable direction under noise that leaves a 2-4 cm finger bone at random.
constexpr int k_low_body = 0, k_low_fingers = 1, k_low_hands = 2;
static_assert(k_low_body == 0 && k_low_fingers == 1, "the body and fingers share noise_'s groups");
constexpr int low_group_of(int b) {
  return b >= k_first_finger                                       ? k_low_fingers
         : b == idx(bone::left_hand) || b == idx(bone::right_hand) ? k_low_hands
                                                                   : k_low_body;
}
// Body bones (torso, head, limbs) and fingers: kernel tables 0 and 1, with their own sigmas.
constexpr int group_of(int b) { return b >= k_first_finger ? 1 : 0; }
// Index of the lowest set bit of x != 0.
inline int lowest_bit(std::uint64_t x) {
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(x);
#else
  int i = 0;
  while (!((x >> i) & 1u)) ++i;
  return i;
#endif
}
// Noise adaptation (offline_smoother_options::adapt_to_noise): the mean size of the observed
// bones' second differences (radians per sample) of the reference recordings the sigmas were
// tuned on (the synthetic noisy scenario without bursts, 30 fps, tuning seeds 1-3), per group
// (body, fingers); the running mean's time constant (seconds); the clamp of the factor.
constexpr double k_reference_noise[2] = {0.22, 0.93};
constexpr double k_reference_fps = 30.0;
constexpr double k_noise_seconds = 4.0;
constexpr double k_min_noise_factor = 0.25, k_max_noise_factor = 1.0;
// Low-confidence observations (0 < confidence < observed_above) of a group -- the body without
// the hands; the fingers; the hand bones -- are smoothed (low_confidence_sigma_seconds) while
// their measured noise (the same second differences, over the bones low in three frames
// running) is below k_low_noise_saturation radians per sample, where a bone's turn from frame
// to frame is mostly noise (a finger's 2-4 cm bone under 30 mm of noise measures ~2.0, under
// 10 mm ~1.65), and, for the body and the fingers, at most k_low_noise_ratio x the confident
// bones' of their kind (a hand bone under 30 mm measures ~1.2, 5-6 x the confident body's,
// and its smoothed direction still beats filling a 1 s burst); else they are filled as gaps
// from the observed frames around them. Until measured: the body's are smoothed, the hands'
// and fingers' filled.
constexpr double k_low_noise_ratio = 5.0;
constexpr double k_low_noise_saturation = 1.8;
// Shortest hand detection believed (drop_flicker): 0.25 s is 6 frames at 25 fps.
constexpr double k_min_detection_seconds = 0.25;
// Longest hold, ease or gap accepted (a window of minutes would be a mistake, not a choice).
constexpr float k_max_gap_option_seconds = 60.f;
constexpr int k_min_capacity = 8;
constexpr int k_max_capacity = 65536;
// smooth_rotations computes k_lanes bones at once. Their values are kept apart from the poses
// (offline_smoother::lanes_), by blocks of k_lanes bones: for block B and the pose in slot s,
// the rows of lane_row one after the other, k_lanes floats each, at ((B x capacity) + s) x
// k_block_floats, so that one block's rows of successive poses are next to each other in
// memory (the order smooth_rotations reads them in).
constexpr int k_lanes = 4;
constexpr int k_padded_bones = (k_bone_count + k_lanes - 1) / k_lanes * k_lanes;
constexpr int k_lane_blocks = k_padded_bones / k_lanes;
// The rotations' x, y, z, w (padding: identity), the weights and the weights where they count
// as observed (weight >= observed_above, else 0); padding 0.
enum lane_row { k_row_x, k_row_y, k_row_z, k_row_w, k_row_weight, k_row_observed, k_row_count };
constexpr int k_block_floats = k_row_count * k_lanes;
static_assert(k_bone_count <= 64, "slot::ones is one bit per bone");

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
  if (!(strength <= max_strength()))
    return range("strength", "such that strength x the largest sigma is at most 2 s");
  if (!(finite_at_least(low_confidence_sigma_seconds, 0.f) &&
        strength * low_confidence_sigma_seconds <= k_widest_sigma_seconds))
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
  int index = 0;                    // in slots_ (and in lanes_)
  std::uint64_t observed_bits = 0;  // bit b: weight[b] >= observed_above
  std::uint64_t ones = 0;           // bit b: weight[b] is exactly 1
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
  for (int i = 0; i < capacity_; ++i) slots_[static_cast<size_t>(i)].index = i;
  lanes_.reset(new float[static_cast<size_t>(k_lane_blocks) * static_cast<size_t>(capacity_) *
                         k_block_floats]);
  kernel_storage_.reset(new float[static_cast<size_t>(3 * k_table_count * capacity_)]);
  index_storage_.reset(new int[static_cast<size_t>(k_table_count * capacity_)]);
  for (int t = 0; t < k_table_count; ++t) {
    tables_[t].w = kernel_storage_.get() + 3 * t * capacity_;
    tables_[t].u = tables_[t].w + capacity_;
    tables_[t].coefficient = tables_[t].u + capacity_;
    tables_[t].index = index_storage_.get() + t * capacity_;
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
  low_noise_.fill(0.0);
  low_noise_weight_.fill(0.0);
  low_informative_ = {true, false, false};
  flicker_bits_ = 0;
  noise_dt_ = 0.0;
  noise_weight_ = 0.0;
  last_good_.fill(identity_quat());
  last_good_t_.fill(0.0);
  last_good_segment_.fill(-1);
}

float* offline_smoother::lanes_of_block(int block) const noexcept {
  return lanes_.get() + static_cast<size_t>(block) * static_cast<size_t>(capacity_) *
                            static_cast<size_t>(k_block_floats);
}

float* offline_smoother::lanes_of(const slot& s, int block) const noexcept {
  return lanes_of_block(block) + static_cast<size_t>(s.index) * k_block_floats;
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
  s.ones = s.observed_bits = 0;
  for (int b = 0; b < k_padded_bones; ++b) {
    const bool real = b < k_bone_count;
    const glm::quat q = real ? s.pose.rotations[b] : identity_quat();
    const float w = real ? s.weight[b] : 0.f;
    float* lane = lanes_of(s, b / k_lanes) + b % k_lanes;
    lane[k_row_x * k_lanes] = q.x;
    lane[k_row_y * k_lanes] = q.y;
    lane[k_row_z * k_lanes] = q.z;
    lane[k_row_w * k_lanes] = q.w;
    const bool observed = real && w >= options_.observed_above;
    lane[k_row_weight * k_lanes] = w;
    lane[k_row_observed * k_lanes] = observed ? w : 0.f;
    if (observed) s.observed_bits |= std::uint64_t{1} << b;
    if (real && w == 1.f) s.ones |= std::uint64_t{1} << b;
  }
  observe_noise();
  drop_flicker();
  return true;
}

// A hand seen for less than k_min_detection_seconds between frames where it was not detected
// at all (confidence 0, or a new segment of the take) is taken for a false detection: the hand
// landmark model also answers on a crop that holds no hand, or a hand turned the wrong way,
// and such answers rarely last. Its frames become gaps (filled from the frames around them)
// as long as none of them has been emitted. Checked when the hand is missed again, per bone.
void offline_smoother::drop_flicker() noexcept {
  if (count_ < 2) return;
  slot& s = at(count_ - 1);
  // A hand dropped before, still unseen: the input's hold of the false detection is replaced.
  for (std::uint64_t todo = flicker_bits_; todo != 0; todo &= todo - 1) {
    const int b = lowest_bit(todo);
    if (s.weight[b] > 0.f || s.segment != at(count_ - 2).segment) {
      flicker_bits_ &= ~(std::uint64_t{1} << b);
      continue;
    }
    s.pose.rotations[b] = flicker_fill_[b];
    float* lane = lanes_of(s, b / k_lanes) + b % k_lanes;
    lane[k_row_x * k_lanes] = flicker_fill_[b].x;
    lane[k_row_y * k_lanes] = flicker_fill_[b].y;
    lane[k_row_z * k_lanes] = flicker_fill_[b].z;
    lane[k_row_w * k_lanes] = flicker_fill_[b].w;
  }
  const slot& prev = at(count_ - 2);
  if (prev.segment != s.segment) return;
  std::uint64_t absent = 0;
  for (int b = 0; b < k_bone_count; ++b)
    if (hand_or_finger(b) && !(s.weight[b] > 0.f)) absent |= std::uint64_t{1} << b;
  for (std::uint64_t todo = absent & prev.observed_bits; todo != 0; todo &= todo - 1) {
    const int b = lowest_bit(todo);
    const std::uint64_t bit = std::uint64_t{1} << b;
    int first = count_ - 2;
    while (first > 0 && at(first - 1).segment == s.segment && (at(first - 1).observed_bits & bit))
      --first;
    if (first < centre_) continue;  // part of it already written out
    const bool bounded =
        first > 0 && (at(first - 1).segment != s.segment || !(at(first - 1).weight[b] > 0.f));
    if (!bounded || !(s.pose.t - at(first).pose.t < k_min_detection_seconds)) continue;
    // What the input showed before the detection stands for it (rest, or a hold), here and
    // in the frames after it while the hand stays unseen (the input holds the false detection).
    const slot& ahead = at(first - 1);
    const glm::quat before = ahead.segment == s.segment ? ahead.pose.rotations[b] : identity_quat();
    flicker_fill_[b] = before;
    flicker_bits_ |= bit;
    for (int i = first; i < count_; ++i) {
      slot& f = at(i);
      f.pose.rotations[b] = before;
      f.pose.confidence[b] = 0.f;
      f.weight[b] = 0.f;
      f.observed_bits &= ~bit;
      f.ones &= ~bit;
      float* lane = lanes_of(f, b / k_lanes) + b % k_lanes;
      lane[k_row_x * k_lanes] = before.x;
      lane[k_row_y * k_lanes] = before.y;
      lane[k_row_z * k_lanes] = before.z;
      lane[k_row_w * k_lanes] = before.w;
      lane[k_row_weight * k_lanes] = 0.f;
      lane[k_row_observed * k_lanes] = 0.f;
    }
  }
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
  // The size of every bone's second difference, in lanes: d0 = conj(a) b, d1 = conj(b) c
  // (glm's quaternion product, term for term), v = 2 (k1 d1 - k0 d0) in the vector parts.
  alignas(16) float size[k_padded_bones];
  for (int block = 0; block < k_lane_blocks; ++block) {
    const float* pa = lanes_of(a, block);
    const float* pb = lanes_of(b, block);
    const float* pc = lanes_of(c, block);
    for (int l = 0; l < k_lanes; ++l) {
      const float aw = pa[k_row_w * k_lanes + l], ax = -pa[k_row_x * k_lanes + l],
                  ay = -pa[k_row_y * k_lanes + l], az = -pa[k_row_z * k_lanes + l];
      const float bw = pb[k_row_w * k_lanes + l], bx = pb[k_row_x * k_lanes + l],
                  by = pb[k_row_y * k_lanes + l], bz = pb[k_row_z * k_lanes + l];
      const float cw = pc[k_row_w * k_lanes + l], cx = pc[k_row_x * k_lanes + l],
                  cy = pc[k_row_y * k_lanes + l], cz = pc[k_row_z * k_lanes + l];
      const float d0w = aw * bw - ax * bx - ay * by - az * bz;
      const float d0x = aw * bx + ax * bw + ay * bz - az * by;
      const float d0y = aw * by + ay * bw + az * bx - ax * bz;
      const float d0z = aw * bz + az * bw + ax * by - ay * bx;
      const float d1w = bw * cw + bx * cx + by * cy + bz * cz;
      const float d1x = bw * cx - bx * cw - by * cz + bz * cy;
      const float d1y = bw * cy - by * cw - bz * cx + bx * cz;
      const float d1z = bw * cz - bz * cw - bx * cy + by * cx;
      const float s0 = (d0w < 0.f ? -2.f : 2.f) * k0, s1 = (d1w < 0.f ? -2.f : 2.f) * k1;
      const float vx = s1 * d1x - s0 * d0x, vy = s1 * d1y - s0 * d0y, vz = s1 * d1z - s0 * d0z;
      size[block * k_lanes + l] = std::sqrt(vx * vx + vy * vy + vz * vz);
    }
  }
  double sum[2] = {0.0, 0.0}, low_sum[k_low_groups] = {0.0, 0.0, 0.0};
  int n[2] = {0, 0}, low_n[k_low_groups] = {0, 0, 0};
  auto low = [&](float w) { return w > 0.f && w < threshold; };
  for (int i = 0; i < k_bone_count; ++i) {
    if (low(a.weight[i]) && low(b.weight[i]) && low(c.weight[i]) && size[i] > 1e-6f) {
      low_sum[low_group_of(i)] += size[i];
      ++low_n[low_group_of(i)];
    }
    if (!(a.weight[i] >= threshold && b.weight[i] >= threshold && c.weight[i] >= threshold))
      continue;
    // Bones that do not change at all (set by a prior: toes, clavicles) tell nothing.
    const float len = size[i];
    if (!(len > 1e-6f)) continue;
    sum[group_of(i)] += len;
    ++n[group_of(i)];
  }
  // Running means as below, per group.
  for (int g = 0; g < k_low_groups; ++g) {
    if (low_n[g] == 0) continue;
    const double w = std::min(mean_dt, k_noise_seconds);
    const double total = std::min(low_noise_weight_[g] + w, k_noise_seconds);
    low_noise_[g] += w / std::max(total, w) * (low_sum[g] / low_n[g] - low_noise_[g]);
    low_noise_weight_[g] = total;
  }
  for (int g = 0; g < k_low_groups; ++g) {
    if (!(low_noise_weight_[g] > 0.0 && noise_weight_ > 0.0)) continue;
    // The body and the fingers also against their confident bones' noise (groups 0 and 1 of
    // noise_); the hand bones against the saturation alone.
    double limit = k_low_noise_saturation;
    if (g != k_low_hands) limit = std::min(limit, k_low_noise_ratio * noise_[g]);
    low_informative_[g] = low_noise_[g] <= limit;
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
  // At a steady frame rate the times around one centre repeat around the next: where u is the
  // same float as the previous table's at the same place, so is the weight (to ~1e-16 of its
  // value), and its exponential is skipped; when every u is, so are the moments.
  const bool same_shape =
      k.sigma == sigma && k.hi >= k.lo && k.lo - k.centre == lo - centre && k.hi - k.lo == hi - lo;
  bool same = same_shape;
  k.centre = centre;
  k.sigma = sigma;
  k.version = version_;
  k.lo = lo;
  k.hi = hi;
  k.ones = ~std::uint64_t{0};
  for (int j = lo; j <= hi; ++j) {
    const int i = j - lo;
    k.index[i] = at(j).index;
    k.ones &= at(j).ones;
    const double dt = at(j).pose.t - c.pose.t;
    const float u = j == centre ? 0.f : float(dt / sigma);
    if (same_shape && k.u[i] == u) continue;
    same = false;
    k.u[i] = u;
    k.w[i] = j == centre ? 1.f : kernel(dt, sigma);
  }
  if (!same) k.has_moments = false;
  return k;
}

namespace {
// k_lanes floats, one bone each, and the few operations smooth_rotations needs; each rounds as
// the scalar operation does, lane by lane.
struct lanes4 {
#if AVATARMAP_SMOOTHER_VECTORS
  typedef float f __attribute__((vector_size(16)));
  typedef std::int32_t i __attribute__((vector_size(16)));
  f v;
  static lanes4 load(const float* p) {
    lanes4 r;
    std::memcpy(&r.v, p, sizeof r.v);
    return r;
  }
  static lanes4 splat(float x) { return {f{x, x, x, x}}; }
  void store(float* p) const { std::memcpy(p, &v, sizeof v); }
  friend lanes4 operator+(lanes4 a, lanes4 b) { return {a.v + b.v}; }
  friend lanes4 operator*(lanes4 a, lanes4 b) { return {a.v * b.v}; }
  // x where x > 0, else 0.
  lanes4 positive() const { return {(f)((i)v & (v > f{}))}; }
  // -x where `sign` < 0, else x.
  lanes4 flipped_where_negative(lanes4 sign) const {
    return {(f)((i)v ^ ((sign.v < f{}) & (i{} + INT32_MIN)))};
  }
#else
  float v[4];
  static lanes4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static lanes4 splat(float x) { return {{x, x, x, x}}; }
  void store(float* p) const {
    for (int l = 0; l < 4; ++l) p[l] = v[l];
  }
  friend lanes4 operator+(lanes4 a, lanes4 b) {
    for (int l = 0; l < 4; ++l) a.v[l] += b.v[l];
    return a;
  }
  friend lanes4 operator*(lanes4 a, lanes4 b) {
    for (int l = 0; l < 4; ++l) a.v[l] *= b.v[l];
    return a;
  }
  lanes4 positive() const {
    lanes4 r;
    for (int l = 0; l < 4; ++l) r.v[l] = v[l] > 0.f ? v[l] : 0.f;
    return r;
  }
  lanes4 flipped_where_negative(lanes4 sign) const {
    lanes4 r;
    for (int l = 0; l < 4; ++l) r.v[l] = sign.v[l] < 0.f ? -v[l] : v[l];
    return r;
  }
#endif
};
static_assert(k_lanes == 4, "lanes4 holds one block");

// Moments of the weights in u (|u| <= 3, so floats keep ~6 digits of the 3x3 system) -> the
// estimate at the centre as a sum over the poses: the value at u = 0 of the weighted
// least-squares quadratic is sum_j (c00 + c01 u_j + c02 u_j^2) w_j / d q_j, with c0i the
// cofactors of the moments' matrix and d its determinant (in double); a nearly singular
// system (too few distinct times, or all weight at one end; d relative to the product of the
// diagonal) or degree 0 gives the weighted mean, sum_j w_j / m0 q_j. Returns a, b, c with
// each pose's factor = (a + b u_j + c u_j^2) w_j, formed as a w + b (w u) + c (w u) u.
void regression_coefficients(const float m[5], bool quadratic, float& a, float& b, float& c) {
  const float m0 = m[0], m1 = m[1], m2 = m[2], m3 = m[3], m4 = m[4];
  const double c00 = double(m2) * m4 - double(m3) * m3, c01 = double(m3) * m2 - double(m1) * m4,
               c02 = double(m1) * m3 - double(m2) * m2;
  const double det = m0 * c00 + m1 * c01 + m2 * c02;
  if (quadratic && det > 1e-6 * m0 * m2 * m4 && det > 0.0) {
    a = float(c00 / det);
    b = float(c01 / det);
    c = float(c02 / det);
  } else {
    a = m0 > 0.f ? float(1.0 / m0) : 0.f;
    b = c = 0.f;
  }
}

// One block of bones [b0, b0 + k_lanes) over one kernel's n poses.
struct lane_block {
  int n = 0;
  const float* lanes = nullptr;  // the block's lanes of slot 0
  const int* index = nullptr;    // per pose: its slot
  int centre = 0;                // the centre's slot
  const float* w = nullptr;      // kernel weights
  const float* u = nullptr;      // dt / sigma
  // Per pose, the factor shared by every lane (bones with weight 1 in every pose), or null:
  // then each lane's weight is w x (observed x by_observed + weight x by_weight + uniform),
  // exactly one selector 1 (0 where not positive: no pose counts with a weight <= 0).
  const float* shared = nullptr;
  const float* by_observed = nullptr;
  const float* by_weight = nullptr;
  const float* uniform = nullptr;
  bool quadratic = true;
};

// The block's sums sum_j factor_j q_j (each q_j flipped to the centre's hemisphere: the sign of
// the 4D dot product, summed x, y, z, w) into out[4][k_lanes] (x, y, z, w).
void smooth_block(const lane_block& in, float* out) {
  using L = lanes4;
  auto row = [&](int slot, int r) {
    return L::load(in.lanes + slot * k_block_floats + r * k_lanes);
  };
  const L rx = row(in.centre, k_row_x), ry = row(in.centre, k_row_y), rz = row(in.centre, k_row_z),
          rw = row(in.centre, k_row_w);
  L sx = L::splat(0.f), sy = sx, sz = sx, sw = sx;
  auto add = [&](int slot, L factor) {
    const L qx = row(slot, k_row_x), qy = row(slot, k_row_y), qz = row(slot, k_row_z),
            qw = row(slot, k_row_w);
    const L dot = rx * qx + ry * qy + rz * qz + rw * qw;
    factor = factor.flipped_where_negative(dot);
    sx = sx + factor * qx;
    sy = sy + factor * qy;
    sz = sz + factor * qz;
    sw = sw + factor * qw;
  };
  if (in.shared) {
    for (int j = 0; j < in.n; ++j) add(in.index[j], L::splat(in.shared[j]));
  } else {
    const L sel_observed = L::load(in.by_observed), sel_weight = L::load(in.by_weight),
            sel_uniform = L::load(in.uniform);
    auto weight_of = [&](int j) {
      const L observed = row(in.index[j], k_row_observed), weight = row(in.index[j], k_row_weight);
      return (L::splat(in.w[j]) * (observed * sel_observed + weight * sel_weight + sel_uniform))
          .positive();
    };
    L m0 = L::splat(0.f), m1 = m0, m2 = m0, m3 = m0, m4 = m0;
    for (int j = 0; j < in.n; ++j) {
      const L u = L::splat(in.u[j]), w = weight_of(j);
      const L wu = w * u, wu2 = wu * u;
      m0 = m0 + w;
      m1 = m1 + wu;
      m2 = m2 + wu2;
      m3 = m3 + wu2 * u;
      m4 = m4 + wu2 * u * u;
    }
    float m[5][k_lanes], ca[k_lanes], cb[k_lanes], cc[k_lanes];
    m0.store(m[0]);
    m1.store(m[1]);
    m2.store(m[2]);
    m3.store(m[3]);
    m4.store(m[4]);
    for (int l = 0; l < k_lanes; ++l) {
      const float ml[5] = {m[0][l], m[1][l], m[2][l], m[3][l], m[4][l]};
      regression_coefficients(ml, in.quadratic, ca[l], cb[l], cc[l]);
    }
    const L a = L::load(ca), b = L::load(cb), c = L::load(cc);
    for (int j = 0; j < in.n; ++j) {
      const L u = L::splat(in.u[j]), w = weight_of(j);
      const L wu = w * u, wu2 = wu * u;
      add(in.index[j], a * w + b * wu + c * wu2);
    }
  }
  sx.store(out);
  sy.store(out + k_lanes);
  sz.store(out + 2 * k_lanes);
  sw.store(out + 3 * k_lanes);
}

}  // namespace

// Gaussian-weighted estimate of each bone at the kernel's centre, over the poses the kernel
// reaches: all alike (uniform), the observed ones weighted by confidence (observed), or all
// weighted by confidence. Degree 0: the weighted mean. Degree 2: the value at the centre of a
// weighted least-squares quadratic in time (local quadratic regression), which follows the
// peaks of fast motion that a mean of the same width flattens; it falls back to the mean where
// the neighbours do not determine a quadratic (fewer than three distinct times). Each pose's
// rotation is first flipped to the centre's hemisphere.
//
// In blocks of bones (smooth_block): the moments per lane, then sum_j factor_j q_j. Where every
// bone of a block that counts confidence has weight 1 in every pose of the kernel, the
// kernel's own moments and factors serve them all (computed once per kernel).
void offline_smoother::smooth_rotations(kernel_table& k, int first, int end, const weighting* how,
                                        glm::quat* out) const noexcept {
  const int n = k.hi - k.lo + 1;
  const slot& centre = at(k.centre);
  if (n <= 1) {
    for (int b = first; b < end; ++b)
      if (how[b] != weighting::none) out[b] = centre.pose.rotations[b];
    return;
  }
  const bool quadratic = options_.degree == 2;
  lane_block in;
  in.n = n;
  in.index = k.index;
  in.centre = centre.index;
  in.w = k.w;
  in.u = k.u;
  in.quadratic = quadratic;
  for (int b0 = first / k_lanes * k_lanes; b0 < end; b0 += k_lanes) {
    float by_observed[k_lanes], by_weight[k_lanes], uniform[k_lanes];
    bool active = false, shared = true;
    for (int l = 0; l < k_lanes; ++l) {
      const int b = b0 + l;
      const weighting h = b >= first && b < end ? how[b] : weighting::none;
      active = active || h != weighting::none;
      by_observed[l] = h == weighting::observed || h == weighting::none ? 1.f : 0.f;
      by_weight[l] = h == weighting::confidence ? 1.f : 0.f;
      uniform[l] = h == weighting::uniform ? 1.f : 0.f;
      if ((h == weighting::observed && !((k.ones >> b) & 1u)) || h == weighting::confidence)
        shared = false;
    }
    if (!active) continue;
    if (shared && !k.has_moments) {
      float m[5] = {};
      for (int j = 0; j < n; ++j) {
        const float w = k.w[j] > 0.f ? k.w[j] : 0.f, u = k.u[j];
        const float wu = w * u, wu2 = wu * u;
        m[0] += w;
        m[1] += wu;
        m[2] += wu2;
        m[3] += wu2 * u;
        m[4] += wu2 * u * u;
      }
      float a, b, c;
      regression_coefficients(m, quadratic, a, b, c);
      for (int j = 0; j < n; ++j) {
        const float w = k.w[j] > 0.f ? k.w[j] : 0.f, u = k.u[j];
        const float wu = w * u, wu2 = wu * u;
        k.coefficient[j] = a * w + b * wu + c * wu2;
      }
      k.has_moments = true;
    }
    in.shared = shared ? k.coefficient : nullptr;
    in.by_observed = by_observed;
    in.by_weight = by_weight;
    in.uniform = uniform;
    in.lanes = lanes_of_block(b0 / k_lanes);
    float r[4 * k_lanes];
    smooth_block(in, r);
    for (int l = 0; l < k_lanes; ++l) {
      const int b = b0 + l;
      if (b < first || b >= end || how[b] == weighting::none) continue;
      out[b] =
          normalized_or(glm::quat(r[3 * k_lanes + l], r[l], r[k_lanes + l], r[2 * k_lanes + l]),
                        centre.pose.rotations[b]);
    }
  }
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

  // Which kernel each bone takes at the centre: its group's (observed, or observed nowhere
  // within reach: uniform) or the low-confidence one; the rest are gaps, filled below.
  std::array<weighting, k_padded_bones> how{}, how_low{};  // weighting::none
  bool group_used[2] = {false, false}, low_used = false;
  std::uint64_t gaps = 0;
  for (int b = 0; b < k_bone_count; ++b) {
    if (c.weight[b] >= threshold) {
      how[b] = weighting::observed;
      group_used[group_of(b)] = true;
      continue;
    }
    // Seen, but barely (its own confidence low and not zero): the measurement still says where
    // the bone went, so it is smoothed over a wider window with every frame weighted by its
    // confidence (observed neighbours dominate near the gap's ends).
    const float own = c.pose.confidence[b];
    if (options_.low_confidence_sigma_seconds > 0.f && own > 0.f && own == c.weight[b] &&
        low_informative_[low_group_of(b)]) {
      how_low[b] = weighting::confidence;
      low_used = true;
      continue;
    }
    gaps |= std::uint64_t{1} << b;
  }
  // A gap's sides: the last observed output before and the next observed pose within the
  // lookahead (same segment), found for every gap in one pass.
  std::array<int, k_bone_count> next;
  next.fill(-1);
  std::uint64_t pending = gaps;
  for (int j = ci + 1; j < count_ && pending != 0; ++j) {
    const slot& s = at(j);
    if (s.segment != c.segment || !(s.pose.t - tc <= lookahead_)) break;
    std::uint64_t found = pending & s.observed_bits;
    pending &= ~found;
    for (; found != 0; found &= found - 1) next[lowest_bit(found)] = j;
  }
  const bool has_time = std::isfinite(tc);
  for (std::uint64_t g = gaps; g != 0; g &= g - 1) {
    const int b = lowest_bit(g);
    if (!(last_good_segment_[b] == c.segment && has_time) && next[b] < 0) {
      // Observed nowhere within reach: what the input says (the solver's hold, ease or prior).
      how[b] = weighting::uniform;
      group_used[group_of(b)] = true;
      gaps &= ~(std::uint64_t{1} << b);
    }
  }
  static_assert(k_body_table == 0 && k_finger_table == 1, "a group's table is its number");
  const float group_sigma[2] = {sigma_body, sigma_finger};
  const int group_first[2] = {0, k_first_finger}, group_end[2] = {k_first_finger, k_bone_count};
  for (int g = 0; g < 2; ++g) {
    if (!group_used[g]) continue;
    kernel_for(g, ci, group_sigma[g]);
    smooth_rotations(tables_[g], group_first[g], group_end[g], how.data(), out.rotations.data());
  }
  if (low_used) {
    kernel_for(k_low_confidence_table, ci, sigma_low);
    smooth_rotations(tables_[k_low_confidence_table], 0, k_bone_count, how_low.data(),
                     out.rotations.data());
  }
  // The right side of each gap: the bone smoothed at its next observed pose, together for the
  // bones of one group with the same next pose (a hand and its fingers usually).
  std::array<glm::quat, k_bone_count> right;
  std::uint64_t todo = 0;
  for (std::uint64_t g = gaps; g != 0; g &= g - 1)
    if (next[lowest_bit(g)] >= 0) todo |= g & (~g + 1);
  while (todo != 0) {
    const int first_bone = lowest_bit(todo);
    const int g = group_of(first_bone), at_next = next[first_bone];
    std::array<weighting, k_padded_bones> how_next{};
    for (std::uint64_t t = todo; t != 0; t &= t - 1) {
      const int b = lowest_bit(t);
      if (group_of(b) != g || next[b] != at_next) continue;
      how_next[b] = weighting::observed;
      todo &= ~(std::uint64_t{1} << b);
    }
    kernel_for(k_next_table, at_next, group_sigma[g]);
    smooth_rotations(tables_[k_next_table], group_first[g], group_end[g], how_next.data(),
                     right.data());
  }
  for (; gaps != 0; gaps &= gaps - 1) {
    const int b = lowest_bit(gaps);
    const bool has_left = last_good_segment_[b] == c.segment && has_time;
    const double a = has_left ? tc - last_good_t_[b] : 0.0;
    const bool has_right = next[b] >= 0;
    const double z = has_right ? at(next[b]).pose.t - tc : 0.0;
    if (has_left && has_right && a + z <= options_.max_gap_seconds) {
      const double span = a + z;
      out.rotations[b] =
          span > 0.0 ? slerp_shortest(last_good_[b], right[b], float(a / span)) : last_good_[b];
      continue;
    }
    glm::quat from_left{}, from_right{};
    if (has_left)
      from_left = slerp_shortest(last_good_[b], identity_quat(), hold_and_ease(a, ease).weight);
    if (has_right)
      from_right = slerp_shortest(right[b], identity_quat(), hold_and_ease(z, ease).weight);
    if (has_left && has_right) {
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
  for (int b = 0; b < k_bone_count; ++b) {
    if (how[b] != weighting::observed) continue;
    last_good_[b] = out.rotations[b];
    last_good_t_[b] = tc;
    last_good_segment_[b] = c.segment;
  }

  // Hips position, expressions and blendshapes: plain Gaussian means over the segment (the
  // blendshapes with the expressions' sigma: both are face weights of the same signal).
  const double sigma_pos = std::max(k * options_.position_sigma_seconds, floor);
  const double sigma_expr = std::max(k * options_.expression_sigma_seconds, floor);
  const double reach = k_kernel_reach * std::max(sigma_pos, sigma_expr);
  glm::vec3 pos_sum(0.f);
  float pos_w = 0.f;
  std::array<float, k_expression_count> expr_sum{}, expr_w{};
  std::array<float, k_blendshape_count> shape_sum{}, shape_w{};
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
    if (we > 0.f)
      for (int b = 0; b < k_blendshape_count; ++b)
        if (std::isfinite(s.pose.blendshapes[b])) {
          shape_sum[b] += we * s.pose.blendshapes[b];
          shape_w[b] += we;
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
  for (int b = 0; b < k_blendshape_count; ++b)
    out.blendshapes[b] = shape_w[b] > 0.f ? shape_sum[b] / shape_w[b] : 0.f;
}

}  // namespace avatarmap
