// Internal: how the measuring stages (body, hands, face) write a bone's measurement into a
// frame_measurement, and the confidence of a group of pose points.
#pragma once

#include <algorithm>
#include <initializer_list>

#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// Lowest confidence among the pose points `ids` (1 for none).
inline float min_conf(const body_points& b, std::initializer_list<int> ids) {
  float c = 1.f;
  for (int i : ids) c = std::min(c, b.c[i]);
  return c;
}

/// A bone measured as a world rotation.
inline void set(frame_measurement& m, bone b, const glm::quat& world, float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = world;
  bm.confidence = c;
  bm.has_local = false;
}

/// A bone measured only relative to its (measured) parent: `world` stays unset (identity);
/// use it for bones whose children are all measured relative to them too.
inline void set_local(frame_measurement& m, bone b, const glm::quat& local, float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = identity_quat();
  bm.local = local;
  bm.confidence = c;
  bm.has_local = true;
}

/// Same, with the world rotation known too.
inline void set(frame_measurement& m, bone b, const glm::quat& world, const glm::quat& local,
                float c) {
  bone_measurement& bm = m.bones[idx(b)];
  bm.world = world;
  bm.local = local;
  bm.confidence = c;
  bm.has_local = true;
}

}  // namespace avatarmap::solve_detail
