// BVH writer for an avatar's own rig (write_rig_bvh in include/avatarmap/export/bvh.hpp).
// BVH has no rest rotations, so the written rest pose has world-aligned joint frames: OFFSETs
// are world rest offsets and each joint's channels carry its world rotation away from rest,
// relative to its parent's. Forward kinematics runs in double so that long chains under a
// 0.01 scale node stay exact to the printed digits. Text goes through io_detail::text_output.
#include <cmath>
#include <cstdio>
#include <exception>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <unordered_set>
#include <vector>

#include "avatarmap/core/euler.hpp"
#include "avatarmap/export/bvh.hpp"
#include "common/text_output.hpp"
#include "rig/export/export_common.hpp"

namespace avatarmap {
namespace {

using export_detail::append_fixed;
using export_detail::append_vec;

glm::dmat4 local_matrix(const glm::vec3& translation, const glm::quat& rotation,
                        const glm::vec3& scale) {
  glm::dquat q(rotation.w, rotation.x, rotation.y, rotation.z);
  glm::dmat4 m = glm::mat4_cast(glm::normalize(q));
  m[0] *= double(scale.x);
  m[1] *= double(scale.y);
  m[2] *= double(scale.z);
  m[3] = glm::dvec4(glm::dvec3(translation), 1.0);
  return m;
}

// Rotation part of a linear map that is a rotation times a uniform scale (columns normalised;
// for anything else, the nearest this simple projection gets).
glm::dquat rotation_of(const glm::dmat3& m) {
  glm::dmat3 n(glm::normalize(m[0]), glm::normalize(m[1]), glm::normalize(m[2]));
  return glm::normalize(glm::quat_cast(n));
}

bool is_finite_quat(const glm::quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w) &&
         glm::dot(q, q) > 1e-20f;
}

// BVH joint names: one token (Blender and most readers split the line on whitespace), unique.
std::vector<std::string> bvh_names(const rig& r, const std::vector<int>& joints) {
  std::vector<std::string> out;
  std::unordered_set<std::string> used;
  for (int j : joints) {
    std::string n = r.names[j];
    for (char& c : n)
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '{' || c == '}') c = '_';
    if (n.empty()) n = "joint" + std::to_string(j);
    if (used.count(n)) n += "_" + std::to_string(j);
    used.insert(n);
    out.push_back(n);
  }
  return out;
}

struct rig_bvh_layout {
  std::vector<int> joints;         // rig joints written, rig order (hips first)
  std::vector<int> bvh_parent;     // index into joints, -1 for the root
  std::vector<bool> has_children;  // per written joint
  std::vector<std::string> names;
};

rig_bvh_layout make_layout(const rig& r, int hips) {
  rig_bvh_layout l;
  std::vector<int> slot(static_cast<std::size_t>(r.joint_count()), -1);
  for (int j = hips; j < r.joint_count(); ++j) {
    int p = j == hips ? -1 : r.parents[j];
    if (j != hips && (p < 0 || slot[p] < 0)) continue;  // not below the hips
    slot[j] = static_cast<int>(l.joints.size());
    l.joints.push_back(j);
    l.bvh_parent.push_back(p < 0 ? -1 : slot[p]);
    l.has_children.push_back(false);
    if (p >= 0) l.has_children[slot[p]] = true;
  }
  l.names = bvh_names(r, l.joints);
  return l;
}

void write_hierarchy(std::string& s, const rig_bvh_layout& l, const std::vector<glm::dvec3>& rest,
                     const std::vector<glm::dvec3>& tips, int k, int depth, double scale) {
  const std::string indent(static_cast<std::size_t>(depth), '\t');
  const bool root = k == 0;
  s += indent + (root ? "ROOT " : "JOINT ") + l.names[k] + "\n" + indent + "{\n" + indent +
       "\tOFFSET ";
  // The root's rest position lives in its position channels only (see write_rig_bvh).
  const glm::dvec3 offset =
      root ? glm::dvec3(0.0) : rest[l.joints[k]] - rest[l.joints[l.bvh_parent[k]]];
  append_vec(s, offset, scale);
  s += "\n" + indent +
       (root ? "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
             : "\tCHANNELS 3 Zrotation Xrotation Yrotation\n");
  if (l.has_children[k]) {
    // Rig order is parent-first and children of one parent keep their relative order, so a
    // depth-first walk over increasing indices matches joint_order below.
    for (std::size_t c = static_cast<std::size_t>(k) + 1; c < l.joints.size(); ++c)
      if (l.bvh_parent[c] == k)
        write_hierarchy(s, l, rest, tips, static_cast<int>(c), depth + 1, scale);
  } else {
    s += indent + "\tEnd Site\n" + indent + "\t{\n" + indent + "\t\tOFFSET ";
    // The rig's own end (a BVH avatar's End Site), else half the joint's own offset.
    const glm::dvec3& tip = tips[l.joints[k]];
    const bool known = std::isfinite(tip.x) && std::isfinite(tip.y) && std::isfinite(tip.z);
    append_vec(s, known ? tip : 0.5 * offset, scale);
    s += "\n" + indent + "\t}\n";
  }
  s += indent + "}\n";
}

void joint_order(const rig_bvh_layout& l, int k, std::vector<int>& out) {
  out.push_back(k);
  for (std::size_t c = static_cast<std::size_t>(k) + 1; c < l.joints.size(); ++c)
    if (l.bvh_parent[c] == k) joint_order(l, static_cast<int>(c), out);
}

status write_impl(const std::string& path, const rig& r, const std::vector<rig_pose>& frames,
                  const rig_bvh_options& options) {
  if (frames.empty()) return status::error(path + ": no frames to write");
  if (!std::isfinite(options.fps) || options.fps <= 0.0)
    return status::error(path + ": fps must be positive, got " + std::to_string(options.fps));
  const int n = r.joint_count();
  const int hips = frames[0].hips_joint;
  if (hips < 0 || hips >= n)
    return status::error(path + ": the frames' hips joint " + std::to_string(hips) +
                         " is not a joint of the rig (" + std::to_string(n) + " joints)");
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].hips_joint != hips)
      return status::error(path + ": frame " + std::to_string(f) + " has hips joint " +
                           std::to_string(frames[f].hips_joint) + ", frame 0 has " +
                           std::to_string(hips));
    if (frames[f].local_rotations.size() != static_cast<std::size_t>(n))
      return status::error(path + ": frame " + std::to_string(f) + " has " +
                           std::to_string(frames[f].local_rotations.size()) +
                           " rotations for a rig of " + std::to_string(n) + " joints");
  }
  const double scale = options.units == bvh_units::centimetres ? 100.0 : 1.0;
  const rig_bvh_layout layout = make_layout(r, hips);

  // Rest world transforms, recomputed in double from the locals (posed ones use the same code,
  // so a rest frame gives D = identity exactly).
  std::vector<glm::dmat4> rest_world(static_cast<std::size_t>(n));
  std::vector<glm::dvec3> rest_pos(rest_world.size());
  std::vector<glm::dmat3> rest_inverse(rest_world.size());
  for (int j = 0; j < n; ++j) {
    const transform& t = r.rest_local[j];
    glm::dmat4 m = local_matrix(t.translation, t.rotation, t.scale);
    rest_world[j] = r.parents[j] < 0 ? m : rest_world[r.parents[j]] * m;
    rest_pos[j] = glm::dvec3(rest_world[j][3]);
    rest_inverse[j] = glm::inverse(glm::dmat3(rest_world[j]));
  }
  // No writer emits nan: a rest transform with no inverse (a zero scale) is refused before
  // anything is written (build_rig refuses it too; a hand-made rig may not have been built).
  for (int j : layout.joints) {
    const glm::dmat3& inv = rest_inverse[j];
    bool finite = std::isfinite(rest_pos[j].x) && std::isfinite(rest_pos[j].y) &&
                  std::isfinite(rest_pos[j].z);
    for (int c = 0; c < 3; ++c)
      finite =
          finite && std::isfinite(inv[c].x) && std::isfinite(inv[c].y) && std::isfinite(inv[c].z);
    if (!finite)
      return status::error(path + ": joint '" + r.names[j] +
                           "' has a singular or non-finite rest transform (a zero scale?); "
                           "nothing written");
  }

  io_detail::text_output out;
  if (status s = out.open(path); !s) return s;
  std::string text = "HIERARCHY\n";
  // The rig's segment ends (End Sites) turned into world axes as the offsets are.
  std::vector<glm::dvec3> tips(rest_world.size(), glm::dvec3(std::nan("")));
  for (int j = 0; j < n && static_cast<std::size_t>(j) < r.tips.size(); ++j)
    tips[j] = glm::dmat3(rest_world[j]) * glm::dvec3(r.tips[j]);
  write_hierarchy(text, layout, rest_pos, tips, 0, 0, scale);
  text += "MOTION\nFrames: " + std::to_string(frames.size()) + "\nFrame Time: ";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", 1.0 / options.fps);
  text += buf;
  text += "\n";
  std::vector<int> order;
  joint_order(layout, 0, order);

  std::vector<glm::quat> rotations(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) rotations[j] = r.rest_local[j].rotation;
  glm::vec3 hips_translation = r.rest_local[hips].translation;
  std::vector<glm::dmat4> world(static_cast<std::size_t>(n));
  std::vector<glm::dquat> delta(layout.joints.size());
  for (const rig_pose& p : frames) {
    for (int j = 0; j < n; ++j)
      if (is_finite_quat(p.local_rotations[j])) rotations[j] = p.local_rotations[j];
    const glm::vec3& ht = p.hips_translation;
    if (std::isfinite(ht.x) && std::isfinite(ht.y) && std::isfinite(ht.z)) hips_translation = ht;
    for (int j = 0; j < n; ++j) {
      const transform& t = r.rest_local[j];
      glm::dmat4 m =
          local_matrix(j == hips ? hips_translation : t.translation, rotations[j], t.scale);
      world[j] = r.parents[j] < 0 ? m : world[r.parents[j]] * m;
    }
    for (std::size_t k = 0; k < layout.joints.size(); ++k) {
      const int j = layout.joints[k];
      delta[k] = rotation_of(glm::dmat3(world[j]) * rest_inverse[j]);
    }
    const glm::dvec3 hips_position(world[hips][3]);
    if (!std::isfinite(hips_position.x) || !std::isfinite(hips_position.y) ||
        !std::isfinite(hips_position.z))
      return status::error(path + ": frame " + std::to_string(&p - frames.data()) +
                           ": the hips position is not finite; nothing written");
    append_vec(text, hips_position, scale);
    for (int k : order) {
      const int parent = layout.bvh_parent[k];
      const glm::dquat local = parent < 0 ? delta[k] : glm::conjugate(delta[parent]) * delta[k];
      const glm::vec3 xyz = euler_from_quat(
          glm::normalize(glm::quat(float(local.w), float(local.x), float(local.y), float(local.z))),
          euler_order::zxy);
      constexpr double k_deg = 180.0 / 3.14159265358979323846;
      const double zxy[3] = {xyz.z * k_deg, xyz.x * k_deg, xyz.y * k_deg};
      for (double a : zxy) {
        if (!std::isfinite(a))
          return status::error(path + ": frame " + std::to_string(&p - frames.data()) +
                               ": joint '" + r.names[layout.joints[k]] +
                               "' has a non-finite rotation; nothing written");
        text.push_back(' ');
        append_fixed(text, a);
      }
    }
    text.push_back('\n');
    if (text.size() > 1 << 16) {
      if (!out.write(text)) return out.error_status();
      text.clear();
    }
  }
  if (!out.write(text)) return out.error_status();
  return out.commit();
}

}  // namespace

status write_rig_bvh(const std::string& path, const rig& r, const std::vector<rig_pose>& frames,
                     const rig_bvh_options& options) {
  try {
    return write_impl(path, r, frames, options);
  } catch (const std::exception& e) {
    return status::internal(path + ": " + e.what());
  }
}

}  // namespace avatarmap
