#include "avatarmap/skeleton/leg_ik.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

// The component of `v` perpendicular to the unit vector `axis`, normalised; zero when `v`
// (nearly) lies along it.
glm::vec3 perpendicular_part(const glm::vec3& v, const glm::vec3& axis) {
  const glm::vec3 p = v - axis * glm::dot(v, axis);
  const float len = glm::length(p);
  return len > 1e-6f * std::max(1.f, glm::length(v)) && std::isfinite(len) ? p / len
                                                                           : glm::vec3(0.f);
}

}  // namespace

two_bone_ik_result solve_two_bone_ik(const glm::vec3& hip, float upper, float lower,
                                     const glm::vec3& target, const glm::vec3& pole,
                                     const glm::vec3& fallback_bend) {
  two_bone_ik_result r;
  r.knee = hip;
  r.ankle = hip;
  if (!is_finite(hip) || !is_finite(target) || !is_finite(pole) || !std::isfinite(upper) ||
      !std::isfinite(lower) || !(upper > 0.f) || !(lower > 0.f))
    return r;
  const glm::vec3 d = target - hip;
  const float dist = glm::length(d);
  // A target on the hip: any direction will do; straight down keeps the leg a leg.
  const glm::vec3 dir = dist > 1e-9f ? d / dist : glm::vec3(0.f, -1.f, 0.f);
  glm::vec3 bend = perpendicular_part(pole - hip, dir);
  if (bend == glm::vec3(0.f)) bend = perpendicular_part(fallback_bend, dir);
  if (bend == glm::vec3(0.f)) bend = perpendicular_part(glm::vec3(0.f, 0.f, 1.f), dir);
  if (bend == glm::vec3(0.f)) bend = perpendicular_part(glm::vec3(1.f, 0.f, 0.f), dir);
  const float reach = upper + lower;
  const float fold = std::abs(upper - lower);
  r.reached = dist <= reach && dist >= fold;
  if (dist >= reach) {
    // Too far: straight, pointing at the target.
    r.knee = hip + dir * upper;
    r.ankle = hip + dir * reach;
    return r;
  }
  const float c = std::max(dist, fold);
  // Law of cosines: the knee's distance along the hip-ankle line, then off it.
  const float a = c > 0.f ? (upper * upper - lower * lower + c * c) / (2.f * c) : 0.f;
  const float h = std::sqrt(std::max(0.f, upper * upper - a * a));
  r.knee = hip + dir * a + bend * h;
  // The ankle from the knee, so that the lower length holds exactly even where a == c.
  const glm::vec3 ka = hip + dir * c - r.knee;
  const float kal = glm::length(ka);
  r.ankle = kal > 0.f ? r.knee + ka * (lower / kal) : r.knee - bend * lower;
  return r;
}

float hip_drop_to_reach(const glm::vec3& hip, const glm::vec3& target, float reach,
                        const glm::vec3& up) {
  if (!is_finite(hip) || !is_finite(target) || !is_finite(up) || !std::isfinite(reach) ||
      !(reach > 0.f))
    return 0.f;
  const glm::vec3 d = target - hip;
  const float along = glm::dot(d, up);  // target above the hip: > 0
  const glm::vec3 across = d - up * along;
  const float h2 = glm::dot(across, across);
  if (h2 + along * along <= reach * reach) return 0.f;
  if (h2 >= reach * reach) return std::max(0.f, -along);
  // The hip at height y above the target reaches it when h2 + y^2 = reach^2.
  const float y = std::sqrt(reach * reach - h2);
  return std::max(0.f, -along - y);
}

}  // namespace avatarmap
