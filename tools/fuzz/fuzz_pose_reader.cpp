// libFuzzer target: the *.pose.jsonl reader on arbitrary bytes. Checks that it never
// crashes and that every pose it returns has unit quaternions and finite values.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "avatarmap/io/pose_file.hpp"

using namespace avatarmap;

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "invariant failed: %s\n", what);
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pose_reader r;
  if (!r.open_memory(reinterpret_cast<const char*>(data), size, "<fuzz>")) return 0;
  proxy_pose p;
  for (;;) {
    read_result res = r.next(p);
    if (res == read_result::end) break;
    if (res == read_result::error) {
      check(r.error().rfind("<fuzz>:", 0) == 0, "error names the file");
      continue;
    }
    check(std::isfinite(p.t), "t finite");
    for (int k = 0; k < 3; ++k) check(std::isfinite(p.hips_position[k]), "hips finite");
    for (const glm::quat& q : p.rotations) {
      float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
      check(std::isfinite(n) && std::abs(n - 1.f) < 1e-5f, "unit quaternion");
    }
    for (float e : p.expressions) check(std::isfinite(e), "expression finite");
    for (float c : p.confidence) check(std::isfinite(c), "confidence finite");
  }
  return 0;
}
