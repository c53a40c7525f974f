// libFuzzer target: the time resamplers. The bytes become a few proxy-pose frames with
// arbitrary times (ordered, equal, reversed, far apart, non-finite), rotations (unit, or
// arbitrary bits), hips positions, expression and blendshape weights, and a frame rate.
//  - resample_clip (time/resample_clip.hpp), the batch resampler of the exporters: must not
//    crash or allocate without bound, must refuse exactly the clips its documented rules
//    refuse (times not finite or out of order, span or frame count over the limits), and
//    must return floor(span * fps + 1e-3) + 1 frames in time order within the clip, unit
//    rotations staying unit.
//  - pose_resampler (time/pose_resampler.hpp), the live one: its documented promise is that
//    sample() never produces non-finite values whatever was pushed; checked at every pushed
//    time, between them and past the newest.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "avatarmap/time/pose_resampler.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "fuzz_support.hpp"

using namespace avatarmap;
using avatarmap::fuzz::check;

namespace {

constexpr int k_max_frames = 12;

bool unit(const glm::quat& q) {
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::isfinite(n) && std::abs(n - 1.f) < 1e-3f;
}

double raw_double(FuzzedDataProvider& in) {
  const std::uint64_t bits = in.ConsumeIntegral<std::uint64_t>();
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

float raw_float(FuzzedDataProvider& in) {
  const std::uint32_t bits = in.ConsumeIntegral<std::uint32_t>();
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// A time after `prev`: mostly a plausible step, sometimes anything at all.
double next_time(FuzzedDataProvider& in, double prev) {
  switch (in.ConsumeIntegralInRange(0, 5)) {
    case 0:
      return prev + 1.0 / 30.0;
    case 1:
      return prev + in.ConsumeFloatingPointInRange(0.0, 0.5);
    case 2:
      return prev;  // a repeated time
    case 3:
      return prev - in.ConsumeProbability<double>();  // going back
    case 4:
      return in.ConsumeFloatingPoint<double>();  // anywhere, finite
    default:
      return raw_double(in);  // NaN and infinities too
  }
}

// A rotation: mostly a unit quaternion, sometimes whatever the bits say. (Components are read
// one by one: the order of a constructor's arguments is unspecified.)
glm::quat rotation(FuzzedDataProvider& in, bool& out_unit) {
  float c[4];
  if (in.ConsumeIntegralInRange(0, 7) == 0) {
    for (float& x : c) x = raw_float(in);
    const glm::quat q(c[3], c[0], c[1], c[2]);
    out_unit = unit(q);
    return q;
  }
  for (float& x : c) x = in.ConsumeFloatingPointInRange(-1.f, 1.f);
  glm::quat u(c[3], c[0], c[1], c[2]);
  if (!(glm::dot(u, u) > 1e-6f)) u = glm::quat(1.f, 0.f, 0.f, 0.f);
  out_unit = true;
  return glm::normalize(u);
}

// True when resample_clip must accept `frames` at `fps` (its documented rules, checked here
// independently): fps positive and finite, times finite and not decreasing, the span within
// k_max_clip_seconds and the frame count within k_max_resampled_frames.
bool acceptable(const std::vector<proxy_pose>& frames, double fps, double& out_count) {
  out_count = 0.0;
  if (!(fps > 0.0) || !std::isfinite(fps)) return false;
  if (frames.empty()) return true;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!std::isfinite(frames[i].t)) return false;
    if (i > 0 && frames[i].t < frames[i - 1].t) return false;
  }
  const double span = frames.back().t - frames.front().t;
  if (!(span <= k_max_clip_seconds)) return false;
  out_count = std::floor(span * fps + 1e-3) + 1.0;
  return out_count <= static_cast<double>(k_max_resampled_frames);
}

void check_batch(const std::vector<proxy_pose>& frames, double fps, bool rebase,
                 bool rotations_unit) {
  double count = 0.0;
  const bool ok = acceptable(frames, fps, count);
  // The documented limit allows ~5 GB of output; the fuzzer runs under -rss_limit_mb=2048, so
  // large accepted clips are only counted (resampled_frame_count), not resampled.
  if (ok && count > 65536.0) {
    std::size_t n = 0;
    check(resampled_frame_count(frames.front().t, frames.back().t, fps, "clip", n).ok() &&
              static_cast<double>(n) == count,
          "resampled_frame_count agrees with the documented formula");
    return;
  }
  std::vector<proxy_pose> out;
  const status s = resample_clip(frames, fps, rebase, out, "clip");
  check(s.ok() == ok, "resample_clip refuses exactly the clips its rules refuse");
  if (!s) {
    check(s.message().rfind("clip: ", 0) == 0, "errors start with the clip's name");
    check(out.empty(), "a refused clip gives no frames");
    return;
  }
  check(static_cast<double>(out.size()) == count, "floor(span * fps + 1e-3) + 1 frames");
  check(out.size() <= k_max_resampled_frames, "output bounded");
  for (std::size_t k = 0; k < out.size(); ++k) {
    const proxy_pose& p = out[k];
    check(std::isfinite(p.t), "output times finite");
    // Far from 0 (t0 = 1e17 s) consecutive samples may round to the same double.
    if (k > 0) check(p.t >= out[k - 1].t, "output times do not decrease");
    if (k > 0 && rebase) check(p.t > out[k - 1].t, "rebased output times increase");
    if (rotations_unit)
      for (const glm::quat& q : p.rotations) check(unit(q), "unit rotations stay unit");
  }
  if (!out.empty()) {
    check(out.front().t == (rebase ? 0.0 : frames.front().t), "output starts at the first frame");
    const double end = rebase ? frames.back().t - frames.front().t : frames.back().t;
    const double rounding = 1e-12 * (std::abs(frames.front().t) + std::abs(end) + 1.0);
    check(out.back().t <= end + 1e-3 / fps + rounding, "output ends within the clip");
  }
}

void check_sample(const pose_resampler& r, double t) {
  proxy_pose out;
  if (!r.sample(t, out)) {
    check(r.empty() || !std::isfinite(t), "sample fails only when empty or t not finite");
    return;
  }
  check(out.t == t, "sample sets t");
  for (int b = 0; b < k_bone_count; ++b) {
    if (!unit(out.rotations[b])) {  // what the crash report needs to be read
      std::fprintf(stderr, "sample(%.17g) bone %d: (%g %g %g %g); kept frames at", t, b,
                   out.rotations[b].w, out.rotations[b].x, out.rotations[b].y, out.rotations[b].z);
      for (int k = 0; k < r.size(); ++k) {
        const glm::quat& q = r.frame(k).rotations[b];
        std::fprintf(stderr, " %.17g (%g %g %g %g)", r.frame(k).t, q.w, q.x, q.y, q.z);
      }
      std::fprintf(stderr, "; max_extrapolation_seconds %g\n",
                   r.options().max_extrapolation_seconds);
    }
    check(unit(out.rotations[b]), "sampled rotations unit length");
    check(out.confidence[b] >= 0.f && out.confidence[b] <= 1.f, "confidence in [0, 1]");
  }
  for (int k = 0; k < 3; ++k) check(std::isfinite(out.hips_position[k]), "sampled hips finite");
  for (float e : out.expressions) check(e >= 0.f && e <= 1.f, "sampled expressions in [0, 1]");
  for (float w : out.blendshapes) check(w >= 0.f && w <= 1.f, "sampled blendshapes in [0, 1]");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  double fps;
  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 0:
      fps = 30.0;
      break;
    case 1:
      fps = in.ConsumeFloatingPointInRange(0.1, 240.0);
      break;
    case 2:
      fps = in.ConsumeFloatingPoint<double>();
      break;
    default:
      fps = raw_double(in);
      break;
  }
  const bool rebase = in.ConsumeBool();
  const int n = in.ConsumeIntegralInRange(0, k_max_frames);
  std::vector<proxy_pose> frames(static_cast<std::size_t>(n));
  bool rotations_unit = true;
  double t = in.ConsumeFloatingPointInRange(-10.0, 10.0);
  for (proxy_pose& p : frames) {
    p.t = t;
    t = next_time(in, t);
    const int moved = in.ConsumeIntegralInRange(0, 3);  // a few bones, to keep inputs short
    for (int k = 0; k < moved; ++k) {
      bool u = true;
      p.rotations[static_cast<std::size_t>(in.ConsumeIntegralInRange(0, k_bone_count - 1))] =
          rotation(in, u);
      rotations_unit = rotations_unit && u;
    }
    for (int k = 0; k < 3; ++k) p.hips_position[k] = raw_float(in);
    p.expressions[static_cast<std::size_t>(in.ConsumeIntegralInRange(0, k_expression_count - 1))] =
        raw_float(in);
    p.confidence[0] = raw_float(in);
    p.blendshapes[static_cast<std::size_t>(in.ConsumeIntegralInRange(0, k_blendshape_count - 1))] =
        raw_float(in);
  }

  check_batch(frames, fps, rebase, rotations_unit);

  pose_resampler_options options;
  options.max_extrapolation_seconds = in.ConsumeBool() ? 0.1 : raw_double(in);
  pose_resampler live(options);
  for (const proxy_pose& p : frames) {
    live.push(p);
    check(live.size() <= k_pose_resampler_capacity, "at most 4 frames kept");
    check_sample(live, p.t);
    check_sample(live, p.t - 0.01);
    check_sample(live, p.t + 0.05);
    check_sample(live, p.t + 10.0);
  }
  if (!live.empty()) {
    check_sample(live, live.frame(0).t + 0.5 * (live.frame(live.size() - 1).t - live.frame(0).t));
    check_sample(live, in.ConsumeFloatingPoint<double>());
  }
  return 0;
}
