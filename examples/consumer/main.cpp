// Consumer of the C++ library: solve one empty frame (nothing seen) and print the hips.
#include <avatarmap/core/rotation.hpp>
#include <avatarmap/solve/frame_solver.hpp>
#include <avatarmap/version.hpp>
#include <cstdio>
#include <memory>

int main() {
  namespace am = avatarmap;
  auto frame = std::make_unique<am::landmark_frame>();
  auto pose = std::make_unique<am::proxy_pose>();
  am::frame_solver solver;
  solver.solve(*frame, *pose);
  float q[4];
  am::store_xyzw((*pose)[am::bone::hips], q);
  std::printf("avatarmap %s: hips [%g %g %g %g]\n", AVATARMAP_VERSION_STRING, q[0], q[1], q[2],
              q[3]);
  return q[3] > 0.999f ? 0 : 1;  // nothing seen: the hips stay at rest
}
