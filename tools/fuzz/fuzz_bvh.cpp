// libFuzzer target: the BVH reader (export/bvh.hpp: read_bvh) on arbitrary bytes, written to a
// file in a private scratch folder (read_bvh takes a path). Checks that nothing crashes or
// throws, that a failure names the file and the line, and that a clip that loads is
// consistent: parents before children, channel offsets that add up, Frames x channels finite
// values, a positive frame time, and unit local rotations and finite positions in its first
// and last frames.
#include <cmath>
#include <cstdint>
#include <string>

#include "avatarmap/export/bvh.hpp"
#include "fuzz_support.hpp"

using namespace avatarmap;
using avatarmap::fuzz::check;

namespace {

bool unit(const glm::quat& q) {
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::isfinite(n) && std::abs(n - 1.f) < 1e-3f;
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_frame(const bvh_clip& clip, int f) {
  for (int j = 0; j < static_cast<int>(clip.joints.size()); ++j) {
    check(unit(clip.local_rotation(f, j)), "local rotations unit length");
    check(finite(clip.position(f, j)), "positions finite");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch("clip.bvh", data, size);
  bvh_clip clip;
  status s = read_bvh(path, clip);
  if (!s) {
    check(s.message().rfind(path + ":", 0) == 0, "errors start with the file's path");
    return 0;
  }
  check(!clip.joints.empty(), "a clip that loads has joints");
  check(clip.joints[0].parent == -1, "the first joint is a root");
  int channels = 0;
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const bvh_joint& joint = clip.joints[j];
    check(joint.parent >= -1 && joint.parent < static_cast<int>(j), "parents before children");
    check(joint.channels.size() <= 6, "at most 6 channels per joint");
    check(joint.first_channel == channels, "channel offsets add up");
    check(finite(joint.offset) && (!joint.has_end_site || finite(joint.end_site)),
          "offsets finite");
    channels += static_cast<int>(joint.channels.size());
  }
  check(clip.channel_count == channels, "channel_count is the sum of the joints' channels");
  check(clip.frame_count >= 0, "frame_count not negative");
  check(clip.values.size() ==
            static_cast<std::size_t>(clip.frame_count) * static_cast<std::size_t>(channels),
        "Frames x channels values");
  check(std::isfinite(clip.frame_time) && clip.frame_time > 0.0, "frame time positive, finite");
  for (float v : clip.values) check(std::isfinite(v), "motion values finite");
  if (clip.frame_count > 0) {
    check_frame(clip, 0);
    check_frame(clip, clip.frame_count - 1);
  }
  return 0;
}
