// The animated .glb writer: the avatar's own JSON (opened and checked by gltf_detail) with every
// buffer and image gathered into one BIN chunk, the animation appended, and the GLB container
// made by export_detail::make_glb (no glTF library re-encodes anything: textures pass through
// byte for byte, whatever their format). Written atomically (io_detail::write_file_atomically).
#include "avatarmap/export/animated_glb.hpp"

#include <cmath>
#include <cstdint>
#include <exception>
#include <new>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/rotation.hpp"
#include "common/atomic_file.hpp"
#include "rig/export/glb_builder.hpp"
#include "rig/gltf_document.hpp"

namespace avatarmap {
namespace {

using json = nlohmann::json;

using export_detail::glb_builder;

// Moves every buffer of the avatar into the BIN chunk (buffer 0 of the output): the GLB's own
// BIN chunk, data: URIs and external files alike, and rewrites the bufferViews (and extension
// bufferViews such as EXT_meshopt_compression's) to point into it.
status gather_buffers(const gltf_detail::gltf_document& doc, json& j, glb_builder& bin,
                      std::uint64_t& total_read) {
  const std::string& p = doc.path;
  std::vector<std::size_t> offset;
  if (j.contains("buffers")) {
    const json& buffers = j["buffers"];
    if (!buffers.is_array()) return status::parse_error(p + ": buffers is not an array");
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const json& b = buffers[i];
      const std::string where = "buffers[" + std::to_string(i) + "]";
      if (!b.is_object() || !b.contains("byteLength") || !b["byteLength"].is_number_integer() ||
          b["byteLength"].get<std::int64_t>() < 0)
        return status::parse_error(p + ": " + where + " has no valid byteLength");
      const auto length = static_cast<std::uint64_t>(b["byteLength"].get<std::int64_t>());
      std::string bytes;
      if (b.contains("uri")) {
        if (!b["uri"].is_string())
          return status::parse_error(p + ": " + where + ".uri is not a string");
        if (status s = gltf_detail::read_gltf_uri(doc, b["uri"].get<std::string>(), where + ".uri",
                                                  total_read, bytes);
            !s)
          return s;
      } else if (doc.binary && i == 0) {
        bytes.assign(doc.bin());
      } else {
        return status::parse_error(
            p + ": " + where +
            " has no uri and is not the GLB's binary chunk; its data is nowhere");
      }
      if (bytes.size() < length)
        return status::parse_error(p + ": " + where + " declares " + std::to_string(length) +
                                   " bytes but its data has " + std::to_string(bytes.size()));
      bytes.resize(static_cast<std::size_t>(length));
      offset.push_back(bin.append(bytes));
    }
  }
  // Points a {buffer, byteOffset} object into the BIN chunk.
  auto rebase = [&](json& view, const std::string& where) -> status {
    if (!view.contains("buffer") || !view["buffer"].is_number_integer())
      return status::parse_error(p + ": " + where + " has no valid buffer index");
    const std::int64_t b = view["buffer"].get<std::int64_t>();
    if (b < 0 || b >= static_cast<std::int64_t>(offset.size()))
      return status::parse_error(p + ": " + where + " names buffer " + std::to_string(b) +
                                 ", out of range (the file has " + std::to_string(offset.size()) +
                                 " buffers)");
    std::uint64_t start = 0;
    if (view.contains("byteOffset")) {
      if (!view["byteOffset"].is_number_integer() || view["byteOffset"].get<std::int64_t>() < 0)
        return status::parse_error(p + ": " + where + ".byteOffset is not a non-negative integer");
      start = static_cast<std::uint64_t>(view["byteOffset"].get<std::int64_t>());
    }
    view["buffer"] = 0;
    view["byteOffset"] = start + offset[static_cast<std::size_t>(b)];
    return {};
  };
  if (j.contains("bufferViews")) {
    json& views = j["bufferViews"];
    if (!views.is_array()) return status::parse_error(p + ": bufferViews is not an array");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "bufferViews[" + std::to_string(i) + "]";
      json& v = views[i];
      if (!v.is_object()) return status::parse_error(p + ": " + where + " is not an object");
      if (status s = rebase(v, where); !s) return s;
      if (v.contains("extensions") && v["extensions"].is_object())
        for (auto it = v["extensions"].begin(); it != v["extensions"].end(); ++it)
          if (it.value().is_object() && it.value().contains("buffer"))
            if (status s = rebase(it.value(), where + ".extensions." + it.key()); !s) return s;
    }
  }
  j["buffers"] = json::array();  // replaced by the BIN chunk in write_animated_glb
  return {};
}

// Moves every image given by a URI (file or data:) into the BIN chunk as a bufferView, bytes
// unchanged, with its media type. An image file that does not exist (but that our rules would
// read) is left named as the avatar names it: the avatar already lacked it, and a viewer
// then misses the same texture; nothing is read.
status gather_images(const gltf_detail::gltf_document& doc, json& j, glb_builder& bin,
                     std::uint64_t& total_read) {
  if (!j.contains("images")) return {};
  json& images = j["images"];
  if (!images.is_array()) return status::parse_error(doc.path + ": images is not an array");
  for (std::size_t i = 0; i < images.size(); ++i) {
    json& image = images[i];
    if (!image.is_object() || !image.contains("uri")) continue;
    const std::string where = "images[" + std::to_string(i) + "].uri";
    if (!image["uri"].is_string())
      return status::parse_error(doc.path + ": " + where + " is not a string");
    std::string bytes;
    bool missing = false;
    if (status s = gltf_detail::read_gltf_uri(doc, image["uri"].get<std::string>(), where,
                                              total_read, bytes, &missing);
        !s) {
      if (missing) continue;
      return s;
    }
    std::string mime = gltf_detail::sniff_image_mime_type(bytes);
    if (mime.empty() && image.contains("mimeType") && image["mimeType"].is_string())
      mime = image["mimeType"].get<std::string>();
    if (mime.empty())
      return status::parse_error(
          doc.path + ": " + where +
          ": cannot tell the image's format (not PNG, JPEG, WebP, KTX2, AVIF "
          "or DDS, and no mimeType given)");
    image.erase("uri");
    image["bufferView"] = bin.add_view(bytes);
    image["mimeType"] = mime;
  }
  return {};
}

// Appends the animation (time accessor, one rotation channel per joint that moves, the hips'
// translation). Refuses non-finite values: no writer emits nan.
status add_animation(const rig& r, const std::vector<rig_pose>& frames,
                     const animated_glb_options& options, const std::string& out_path, json& j,
                     glb_builder& bin) {
  const std::size_t n = frames.size();
  for (std::size_t f = 0; f < n; ++f) {
    const rig_pose& pose = frames[f];
    if (pose.local_rotations.size() < static_cast<std::size_t>(r.joint_count()))
      return status::error(out_path + ": frame " + std::to_string(f) +
                           " has fewer rotations than the rig has joints");
    for (int k = 0; k < r.joint_count(); ++k)
      if (!is_finite(pose.local_rotations[static_cast<std::size_t>(k)]))
        return status::error(out_path + ": frame " + std::to_string(f) + " joint '" + r.names[k] +
                             "' has a non-finite rotation; nothing written");
    if (pose.hips_joint >= 0 && !is_finite(pose.hips_translation))
      return status::error(out_path + ": frame " + std::to_string(f) +
                           " has a non-finite hips translation; nothing written");
  }
  std::vector<float> times(n);
  for (std::size_t i = 0; i < n; ++i) times[i] = static_cast<float>(double(i) / options.fps);
  json anim = {
      {"name", options.animation_name}, {"samplers", json::array()}, {"channels", json::array()}};
  const std::size_t time_acc = bin.add_floats(times, "SCALAR", 1, true);
  auto add_channel = [&](int node, const char* path, const std::vector<float>& values,
                         const char* type, int comps) {
    json sampler = {{"input", time_acc},
                    {"output", bin.add_floats(values, type, comps, false)},
                    {"interpolation", "LINEAR"}};
    anim["samplers"].push_back(std::move(sampler));
    json channel = {{"sampler", anim["samplers"].size() - 1},
                    {"target", {{"node", node}, {"path", path}}}};
    anim["channels"].push_back(std::move(channel));
  };
  std::vector<float> values;
  for (int k = 0; k < r.joint_count(); ++k) {
    bool moves = false;
    for (const rig_pose& f : frames)
      if (angle_between(f.local_rotations[static_cast<size_t>(k)], r.rest_local[k].rotation) >
          1e-6f)
        moves = true;
    if (!moves) continue;
    values.clear();
    glm::quat prev = frames[0].local_rotations[static_cast<size_t>(k)];
    for (const rig_pose& f : frames) {
      glm::quat q = f.local_rotations[static_cast<size_t>(k)];
      // Keep consecutive keys in one hemisphere so LINEAR interpolation takes the short way.
      if (q.x * prev.x + q.y * prev.y + q.z * prev.z + q.w * prev.w < 0.f) q = -q;
      prev = q;
      values.insert(values.end(), {q.x, q.y, q.z, q.w});
    }
    add_channel(r.source_index[k], "rotation", values, "VEC4", 4);
  }
  const int hips = frames[0].hips_joint;
  if (hips >= 0 && hips < r.joint_count()) {
    values.clear();
    for (const rig_pose& f : frames)
      values.insert(values.end(),
                    {f.hips_translation.x, f.hips_translation.y, f.hips_translation.z});
    add_channel(r.source_index[hips], "translation", values, "VEC3", 3);
  }
  if (!j.contains("animations") || !j["animations"].is_array()) j["animations"] = json::array();
  j["animations"].push_back(std::move(anim));
  return {};
}

status write_impl(const std::string& avatar_path, const rig& r, const std::vector<rig_pose>& frames,
                  const animated_glb_options& options, const std::string& out_path) {
  if (frames.empty()) return status::error(out_path + ": no frames to write");
  if (!(options.fps > 0.0 && options.fps <= k_max_fps))
    return status::error(out_path + ": fps must be in (0, " + limit_text(k_max_fps) + "]");
  gltf_detail::gltf_document doc;
  if (status s = gltf_detail::open_gltf_document(avatar_path, doc); !s) return s;
  json j = std::move(doc.json);
  const std::size_t nodes = j.contains("nodes") && j["nodes"].is_array() ? j["nodes"].size() : 0;
  for (int k = 0; k < r.joint_count(); ++k)
    if (r.source_index[k] < 0 || static_cast<std::size_t>(r.source_index[k]) >= nodes)
      return status::invalid_argument(
          avatar_path + ": the rig does not belong to this file (joint '" + r.names[k] + "')");

  glb_builder bin(j);
  std::uint64_t total_read = 0;
  if (status s = gather_buffers(doc, j, bin, total_read); !s) return s;
  if (status s = gather_images(doc, j, bin, total_read); !s) return s;
  if (status s = add_animation(r, frames, options, out_path, j, bin); !s) return s;
  if (!j.contains("asset") || !j["asset"].is_object()) j["asset"] = {{"version", "2.0"}};
  j["asset"]["generator"] = "avatarmap";
  std::string glb;
  if (status s = export_detail::make_glb(j, bin.bytes(), out_path, glb); !s)
    return s.with_message(s.message() + "; use a shorter clip");
  return io_detail::write_file_atomically(out_path, glb);
}

}  // namespace

status write_animated_glb(const std::string& avatar_path, const rig& r,
                          const std::vector<rig_pose>& frames, const animated_glb_options& options,
                          const std::string& out_path) {
  try {
    return write_impl(avatar_path, r, frames, options, out_path);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(out_path + ": not enough memory to write the animated avatar");
  } catch (const std::exception&) {
    return status::internal(out_path +
                            ": cannot write the animated avatar (unexpected internal "
                            "error)");
  }
}

}  // namespace avatarmap
