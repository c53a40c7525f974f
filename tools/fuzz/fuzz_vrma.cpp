// libFuzzer target: the VRM Animation reader (export/vrma.hpp: read_vrma) on arbitrary bytes,
// written to a file in a private scratch folder (read_vrma takes a path). Each input is read
// at its key times (fps 0) and, when that succeeds, again resampled at 30 fps with hips
// scaling, the two paths a user takes (`convert in.vrma`, `convert --fps 30`). Checks that
// nothing crashes or throws, that a failure names the file, and that a clip that loads keeps
// the documented promises: frames in increasing time order, finite times within the key range,
// unit rotations, finite hips positions, expression and blendshape weights in [0, 1] (0 for
// those the file lacks), confidence 0 or 1 (1 exactly for the bones the file maps, and the eyes
// when it has a lookAt), eyes at rest without a lookAt, and that resampling gives the
// documented number of frames.
#include <cmath>
#include <cstdint>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "fuzz_support.hpp"

using namespace avatarmap;
using avatarmap::fuzz::check;

namespace {

bool unit(const glm::quat& q) {
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::isfinite(n) && std::abs(n - 1.f) < 1e-3f;
}

void check_clip(const vrma_clip& clip) {
  check(!clip.frames.empty(), "a clip that loads has frames");
  check(std::isfinite(clip.duration) && clip.duration >= 0.0, "duration finite, not negative");
  check(clip.has_bone[idx(bone::hips)], "a clip that loads maps the hips");
  check(std::isfinite(clip.rest_hips_height), "rest hips height finite");
  for (std::size_t f = 0; f < clip.frames.size(); ++f) {
    const proxy_pose& p = clip.frames[f];
    check(std::isfinite(p.t) && p.t >= 0.0 && p.t <= clip.duration + 1e-6,
          "frame times finite and within the keys");
    if (f > 0) check(p.t > clip.frames[f - 1].t, "frame times increase");
    for (int b = 0; b < k_bone_count; ++b) {
      check(unit(p.rotations[b]), "rotations unit length");
      const bool eye = b == idx(bone::left_eye) || b == idx(bone::right_eye);
      check(p.confidence[b] == (clip.has_bone[b] || (eye && clip.has_look_at) ? 1.f : 0.f),
            "confidence 1 for mapped bones (and the eyes with a lookAt)");
    }
    for (int k = 0; k < 3; ++k) check(std::isfinite(p.hips_position[k]), "hips position finite");
    for (int e = 0; e < k_expression_count; ++e) {
      const float w = p.expressions[e];
      check(w >= 0.f && w <= 1.f, "expressions in [0, 1]");
      if (!clip.has_expression[e]) check(w == 0.f, "expressions the file lacks are 0");
    }
    for (int sh = 0; sh < k_blendshape_count; ++sh) {
      const float w = p.blendshapes[sh];
      check(w >= 0.f && w <= 1.f, "blendshapes in [0, 1]");
      if (!clip.has_blendshape[sh]) check(w == 0.f, "blendshapes the file lacks are 0");
    }
    if (!clip.has_look_at)
      check(p[bone::left_eye] == identity_quat() && p[bone::right_eye] == identity_quat(),
            "eyes at rest without a lookAt");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // read_vrma reads text glTF when the name ends in .gltf: let the content pick, so that both
  // of tinygltf's parsers are explored.
  const bool text = size > 0 && data[0] == '{';
  const std::string path = fuzz::write_scratch(text ? "clip.gltf" : "clip.vrma", data, size);
  vrma_clip clip;
  status s = read_vrma(path, clip);
  if (!s) {
    check(s.message().rfind(path, 0) == 0, "errors start with the file's path");
    return 0;
  }
  check_clip(clip);

  constexpr double k_fps = 30.0;
  const double t0 = clip.frames.front().t;
  const double span = clip.frames.back().t - t0;
  // The documented limit (k_max_resampled_frames) allows ~5 GB of frames; the fuzzer runs
  // under -rss_limit_mb=2048, so long clips are only counted, not resampled.
  if (span * k_fps > 65536.0) {
    std::size_t count = 0;
    const status c = resampled_frame_count(t0, clip.frames.back().t, k_fps, path, count);
    check(!c.ok() || static_cast<double>(count) == std::floor(span * k_fps + 1e-3) + 1.0,
          "resampled_frame_count agrees with the documented formula");
    return 0;
  }
  vrma_read_options options;
  options.fps = k_fps;
  options.hips_height = 1.f;
  vrma_clip resampled;
  s = read_vrma(path, resampled, options);
  if (!s) {  // e.g. a span too long to resample: allowed, with a message
    check(s.message().rfind(path, 0) == 0, "errors start with the file's path");
    return 0;
  }
  check_clip(resampled);
  check(static_cast<double>(resampled.frames.size()) == std::floor(span * k_fps + 1e-3) + 1.0,
        "resampling gives floor(span * fps + 1e-3) + 1 frames");
  check(resampled.frames.front().t == t0, "resampling starts at the first key");
  return 0;
}
