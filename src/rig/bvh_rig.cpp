#include "avatarmap/rig/bvh_rig.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <utility>

#include "avatarmap/io/resources.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/retarget_inverse.hpp"
#include "avatarmap/rig/rig_binding.hpp"

namespace avatarmap {
namespace {

// Rest world positions (file units, OFFSETs summed; no rotations at rest) of every joint.
std::vector<glm::vec3> rest_positions(const bvh_clip& clip) {
  std::vector<glm::vec3> p(clip.joints.size());
  for (std::size_t i = 0; i < clip.joints.size(); ++i) {
    const bvh_joint& j = clip.joints[i];
    p[i] = j.offset + (j.parent < 0 ? glm::vec3(0.f) : p[static_cast<std::size_t>(j.parent)]);
  }
  return p;
}

}  // namespace

float bvh_rest_height(const bvh_clip& clip) {
  if (clip.joints.empty()) return 0.f;
  const std::vector<glm::vec3> p = rest_positions(clip);
  float lo = p[0].y, hi = p[0].y;
  for (std::size_t i = 0; i < p.size(); ++i) {
    lo = std::min(lo, p[i].y);
    hi = std::max(hi, p[i].y);
    if (clip.joints[i].has_end_site) {
      const float e = p[i].y + clip.joints[i].end_site.y;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
  }
  return hi - lo;
}

bvh_length_unit detect_bvh_units(const bvh_clip& clip) {
  static const bvh_length_unit k_units[] = {{1.f, "metres"},
                                            {k_cmu_metres_per_unit, "CMU units (0.056444 m)"},
                                            {0.01f, "centimetres"},
                                            {0.001f, "millimetres"}};
  const float h = bvh_rest_height(clip);
  bvh_length_unit best = k_units[0];
  if (!(std::isfinite(h) && h > 0.f)) return best;
  double best_error = 1e300;
  for (const bvh_length_unit& u : k_units) {
    const double e = std::fabs(std::log(static_cast<double>(h) * u.metres_per_unit /
                                        static_cast<double>(k_bvh_reference_height)));
    if (e < best_error) {
      best_error = e;
      best = u;
    }
  }
  return best;
}

status bvh_rig_from_clip(const bvh_clip& clip, const std::string& file,
                         const bvh_rig_options& options, raw_rig& out, bvh_length_unit* out_unit) {
  out = raw_rig{};
  out.file = file;
  if (clip.joints.empty()) return status::parse_error(file + ": the BVH has no joints");
  if (!(std::isfinite(options.metres_per_unit) && options.metres_per_unit >= 0.f))
    return status::parse_error(file + ": metres per BVH unit must be > 0 (or 0: detect), got " +
                               std::to_string(options.metres_per_unit));
  bvh_length_unit unit = options.metres_per_unit > 0.f
                             ? bvh_length_unit{options.metres_per_unit, "as given"}
                             : detect_bvh_units(clip);
  const float s = unit.metres_per_unit;
  // Lift every root by the same height so that the lowest joint or End Site (the toes' tips,
  // below the toe joints) stands on Y = 0: the floor of the rest pose.
  const std::vector<glm::vec3> p = rest_positions(clip);
  float lowest = p[0].y;
  for (std::size_t i = 0; i < p.size(); ++i) {
    lowest = std::min(lowest, p[i].y);
    if (clip.joints[i].has_end_site) lowest = std::min(lowest, p[i].y + clip.joints[i].end_site.y);
  }
  out.nodes.resize(clip.joints.size());
  for (std::size_t i = 0; i < clip.joints.size(); ++i) {
    const bvh_joint& j = clip.joints[i];
    raw_rig::node& n = out.nodes[i];
    n.name = j.name;
    n.parent = j.parent;
    n.rest.translation = j.offset * s;
    if (j.has_end_site) n.tip = j.end_site * s;
    if (j.parent < 0) n.rest.translation.y -= lowest * s;
  }
  out.source = rig_source::unknown;
  out.floor_y = 0.f;
  if (out_unit != nullptr) *out_unit = unit;
  return {};
}

status load_bvh_avatar(const std::string& path, raw_rig& out, const bvh_rig_options& options) {
  out = raw_rig{};
  out.file = path;
  bvh_clip clip;
  if (status st = read_bvh(path, clip); !st.ok()) return st;
  return bvh_rig_from_clip(clip, path, options, out);
}

status read_bvh_motion(const std::string& path, const bvh_motion_options& options,
                       std::vector<proxy_pose>& out, bvh_motion_summary* out_summary) {
  out.clear();
  try {
    bvh_clip clip;
    if (status st = read_bvh(path, clip); !st.ok()) return st;
    raw_rig raw;
    bvh_length_unit unit;
    if (status st = bvh_rig_from_clip(clip, path, {options.metres_per_unit}, raw, &unit); !st.ok())
      return st;
    rig r;
    if (status st = build_rig(raw, r); !st.ok()) return st;
    const resource_lookup tables = find_resource(resource::mappings, options.mappings_folder);
    rig_binding_choice choice;
    if (status st = select_binding(r, options.rig, tables.folder, choice); !st.ok()) {
      if (tables.folder.empty() && st.code() == status_code::io)
        return st.with_message(path + ": reading a BVH's motion needs the mapping tables, and no " +
                               "folder of them was found; set " +
                               resource_environment(resource::mappings));
      return st;
    }
    for (bone b : {bone::left_upper_leg, bone::left_lower_leg, bone::left_foot,
                   bone::right_upper_leg, bone::right_lower_leg, bone::right_foot})
      if (choice.binding[idx(b)] < 0)
        return status::parse_error(path + ": the skeleton has no " + std::string(bone_name(b)) +
                                   " (" + choice.description +
                                   "): its motion needs both legs (upper leg, lower leg, foot) " +
                                   "for the floor and the hips height");
    // The performer's own skeleton: hips height = the rig's, so hips_position is the root's
    // position in metres (scale 1).
    retarget_options ro;
    retargeter forward;
    if (status st = forward.build(r, choice.binding, ro); !st.ok()) return st;
    ro.performer_hips_height = forward.rig_hips_height();
    if (status st = forward.build(r, choice.binding, ro); !st.ok()) return st;
    inverse_retargeter inverse;
    if (status st = inverse.build(forward, ro); !st.ok()) return st;

    rig_pose in;
    forward.prepare(in);
    const int hips = in.hips_joint;
    const int hips_source = r.source_index[static_cast<std::size_t>(hips)];
    const bool hips_is_root = r.parents[static_cast<std::size_t>(hips)] < 0;
    const bvh_joint& hips_joint = clip.joints[static_cast<std::size_t>(hips_source)];
    // Frame Time is often printed short (.0083333 for 1/120 s): a rate within 1e-4 of a whole
    // number of frames per second is taken as that number.
    double frame_time = clip.frame_time;
    const double rate = std::round(1.0 / frame_time);
    if (rate >= 1.0 && std::fabs(1.0 / frame_time - rate) < 1e-4 * rate) frame_time = 1.0 / rate;
    out.reserve(static_cast<std::size_t>(clip.frame_count));
    for (int f = 0; f < clip.frame_count; ++f) {
      for (int j = 0; j < r.joint_count(); ++j)
        in.local_rotations[static_cast<std::size_t>(j)] =
            clip.local_rotation(f, r.source_index[static_cast<std::size_t>(j)]);
      in.hips_translation = r.rest_local[static_cast<std::size_t>(hips)].translation;
      if (hips_is_root) {
        for (int c = 0; c < static_cast<int>(hips_joint.channels.size()); ++c) {
          const int axis = static_cast<int>(hips_joint.channels[static_cast<std::size_t>(c)]);
          if (axis <= static_cast<int>(bvh_channel::z_position))
            in.hips_translation[axis] = clip.value(f, hips_source, c) * unit.metres_per_unit;
        }
      }
      proxy_pose p;
      inverse.apply(in, p);
      p.t = f * frame_time;
      out.push_back(p);
    }
    if (out_summary != nullptr) {
      out_summary->unit = unit;
      out_summary->binding = choice.description;
      out_summary->bound = choice.bound;
      out_summary->frame_time = frame_time;
    }
    return {};
  } catch (const std::bad_alloc&) {
    out.clear();
    return status::out_of_memory(path + ": not enough memory to read the motion");
  }
}

}  // namespace avatarmap
