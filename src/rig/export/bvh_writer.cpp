// BVH writer for the proxy skeleton. Text goes through io_detail::text_output (atomic
// rename, std::to_chars numbers).
#include <cmath>
#include <cstdio>
#include <exception>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "avatarmap/export/bvh.hpp"
#include "common/text_output.hpp"
#include "rig/export/export_common.hpp"

namespace avatarmap {
namespace {

using export_detail::append_fixed;
using export_detail::append_vec;

bool has_children(int b) {
  for (int c = 0; c < k_bone_count; ++c)
    if (bone_parent(c) == b) return true;
  return false;
}

void write_joint(std::string& s, const proxy_skeleton& sk, int b, int depth, double scale) {
  std::string indent(static_cast<std::size_t>(depth), '\t');
  bool root = bone_parent(b) == k_no_parent;
  s += indent + (root ? "ROOT " : "JOINT ") + std::string(bone_name(static_cast<bone>(b))) + "\n" +
       indent + "{\n" + indent + "\tOFFSET ";
  append_vec(s, root ? glm::vec3(0.f) : sk.offsets[b], scale);
  s += "\n" + indent +
       (root ? "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
             : "\tCHANNELS 3 Zrotation Xrotation Yrotation\n");
  if (has_children(b)) {
    for (int c = 0; c < k_bone_count; ++c)
      if (bone_parent(c) == b) write_joint(s, sk, c, depth + 1, scale);
  } else {
    s += indent + "\tEnd Site\n" + indent + "\t{\n" + indent + "\t\tOFFSET ";
    append_vec(s, sk.lengths[b] * bone_rest_direction(static_cast<bone>(b)), scale);
    s += "\n" + indent + "\t}\n";
  }
  s += indent + "}\n";
}

// Angles (degrees) about Z, X, Y with R = Rz(z) * Rx(x) * Ry(y), in double so that the
// round trip stays well under 0.001 degree even near gimbal lock (|x| -> 90 degrees).
glm::dvec3 zxy_degrees(const glm::quat& qf) {
  glm::dquat q(qf.w, qf.x, qf.y, qf.z);
  glm::dmat3 m = glm::mat3_cast(glm::normalize(q));  // m[col][row]
  auto r = [&m](int row, int col) { return m[col][row]; };
  double c = std::sqrt(r(0, 1) * r(0, 1) + r(1, 1) * r(1, 1));  // |cos x|
  double x = std::atan2(r(2, 1), c), y, z;
  if (c > 1e-9) {
    z = std::atan2(-r(0, 1), r(1, 1));
    y = std::atan2(-r(2, 0), r(2, 2));
  } else {  // gimbal lock: the remaining rotation goes to Z
    y = 0.0;
    z = std::atan2(r(1, 0), r(0, 0));
  }
  constexpr double k_deg = 180.0 / 3.14159265358979323846;
  return glm::dvec3(z, x, y) * k_deg;
}

// Order in which write_joint visits the bones (= the channel order of a frame line).
void joint_order(int b, std::vector<int>& out) {
  out.push_back(b);
  for (int c = 0; c < k_bone_count; ++c)
    if (bone_parent(c) == b) joint_order(c, out);
}

status write_impl(const std::string& path, const std::vector<proxy_pose>& frames,
                  const bvh_write_options& options) {
  if (status s = export_detail::check_frames(path, frames, options.fps); !s) return s;
  if (!std::isfinite(options.height) || options.height <= 0.f)
    return status::error(path + ": height must be positive, got " + std::to_string(options.height));
  std::vector<proxy_pose> keys;
  if (status s = export_detail::frames_to_write(path, frames, options.fps, true, keys); !s)
    return s;
  double frame_time = 1.0 / 30.0;
  if (options.fps > 0.0)
    frame_time = 1.0 / options.fps;
  else if (frames.size() > 1)
    frame_time = (frames.back().t - frames.front().t) / static_cast<double>(frames.size() - 1);
  const double scale = options.units == bvh_units::centimetres ? 100.0 : 1.0;
  const proxy_skeleton sk = make_proxy_skeleton(options.height);

  io_detail::text_output out;
  if (status s = out.open(path); !s) return s;
  std::string text = "HIERARCHY\n";
  write_joint(text, sk, idx(bone::hips), 0, scale);
  text += "MOTION\nFrames: " + std::to_string(keys.size()) + "\nFrame Time: ";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", frame_time);
  text += buf;
  text += "\n";
  std::vector<int> order;
  joint_order(idx(bone::hips), order);
  for (const proxy_pose& p : keys) {
    append_vec(text, p.hips_position, scale);
    for (int b : order) {
      glm::dvec3 zxy = zxy_degrees(p.rotations[b]);
      for (int i = 0; i < 3; ++i) {
        text.push_back(' ');
        append_fixed(text, zxy[i]);
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

status write_bvh(const std::string& path, const std::vector<proxy_pose>& frames,
                 const bvh_write_options& options) {
  try {
    return write_impl(path, frames, options);
  } catch (const std::exception& e) {
    return status::internal(path + ": " + e.what());
  }
}

}  // namespace avatarmap
