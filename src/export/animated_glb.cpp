#include "avatarmap/export/animated_glb.hpp"

#include <tiny_gltf.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

// Appends raw little-endian floats to buffer 0 and returns the accessor index.
int add_float_accessor(tinygltf::Model& m, const std::vector<float>& values, int type,
                       int components, bool with_bounds) {
  tinygltf::Buffer& buf = m.buffers[0];
  while (buf.data.size() % 4) buf.data.push_back(0);
  const size_t offset = buf.data.size();
  buf.data.resize(offset + values.size() * sizeof(float));
  std::memcpy(buf.data.data() + offset, values.data(), values.size() * sizeof(float));
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = values.size() * sizeof(float);
  m.bufferViews.push_back(view);
  tinygltf::Accessor acc;
  acc.bufferView = static_cast<int>(m.bufferViews.size()) - 1;
  acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  acc.count = values.size() / static_cast<size_t>(components);
  acc.type = type;
  if (with_bounds && !values.empty()) {
    acc.minValues.assign(static_cast<size_t>(components), 1e300);
    acc.maxValues.assign(static_cast<size_t>(components), -1e300);
    for (size_t i = 0; i < values.size(); ++i) {
      size_t c = i % static_cast<size_t>(components);
      acc.minValues[c] = std::min(acc.minValues[c], double(values[i]));
      acc.maxValues[c] = std::max(acc.maxValues[c], double(values[i]));
    }
  }
  m.accessors.push_back(acc);
  return static_cast<int>(m.accessors.size()) - 1;
}

}  // namespace

status write_animated_glb(const std::string& avatar_path, const rig& r,
                          const std::vector<rig_pose>& frames, const animated_glb_options& options,
                          const std::string& out_path) {
  if (frames.empty()) return status::error(out_path + ": no frames to write");
  if (!(options.fps > 0.0 && options.fps <= 1000.0))
    return status::error(out_path + ": fps must be in (0, 1000]");
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  std::ifstream probe(avatar_path, std::ios::binary);
  char magic[4] = {};
  probe.read(magic, 4);
  const bool binary = probe.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
  probe.close();
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, avatar_path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, avatar_path);
  if (!ok) return status::error(avatar_path + ": cannot read the avatar: " + err);
  const int nodes = static_cast<int>(model.nodes.size());
  for (int j = 0; j < r.joint_count(); ++j)
    if (r.source_index[j] < 0 || r.source_index[j] >= nodes)
      return status::error(avatar_path + ": the rig does not belong to this file (joint '" +
                           r.names[j] + "')");
  if (model.buffers.empty()) model.buffers.emplace_back();
  if (!model.buffers[0].uri.empty())
    return status::error(avatar_path +
                         ": buffer 0 is an external file; only self-contained .glb/.vrm avatars "
                         "can be written with their animation");

  const size_t n = frames.size();
  std::vector<float> times(n);
  for (size_t i = 0; i < n; ++i) times[i] = static_cast<float>(double(i) / options.fps);
  tinygltf::Animation anim;
  anim.name = options.animation_name;
  const int time_acc = add_float_accessor(model, times, TINYGLTF_TYPE_SCALAR, 1, true);
  auto add_channel = [&](int node, const char* path, const std::vector<float>& values, int type,
                         int comps) {
    tinygltf::AnimationSampler sampler;
    sampler.input = time_acc;
    sampler.output = add_float_accessor(model, values, type, comps, false);
    sampler.interpolation = "LINEAR";
    anim.samplers.push_back(sampler);
    tinygltf::AnimationChannel ch;
    ch.sampler = static_cast<int>(anim.samplers.size()) - 1;
    ch.target_node = node;
    ch.target_path = path;
    anim.channels.push_back(ch);
  };
  std::vector<float> values;
  for (int j = 0; j < r.joint_count(); ++j) {
    bool moves = false;
    for (const rig_pose& f : frames)
      if (angle_between(f.local_rotations[static_cast<size_t>(j)], r.rest_local[j].rotation) >
          1e-6f)
        moves = true;
    if (!moves) continue;
    values.clear();
    glm::quat prev = frames[0].local_rotations[static_cast<size_t>(j)];
    for (const rig_pose& f : frames) {
      glm::quat q = f.local_rotations[static_cast<size_t>(j)];
      // Keep consecutive keys in one hemisphere so LINEAR interpolation takes the short way.
      if (q.x * prev.x + q.y * prev.y + q.z * prev.z + q.w * prev.w < 0.f) q = -q;
      prev = q;
      values.insert(values.end(), {q.x, q.y, q.z, q.w});
    }
    add_channel(r.source_index[j], "rotation", values, TINYGLTF_TYPE_VEC4, 4);
  }
  const int hips = frames[0].hips_joint;
  if (hips >= 0) {
    values.clear();
    for (const rig_pose& f : frames)
      values.insert(values.end(),
                    {f.hips_translation.x, f.hips_translation.y, f.hips_translation.z});
    add_channel(r.source_index[hips], "translation", values, TINYGLTF_TYPE_VEC3, 3);
  }
  model.buffers[0].uri.clear();
  model.animations.push_back(anim);
  model.asset.generator = "avatarmap";

  const std::string tmp = out_path + ".tmp";
  if (!loader.WriteGltfSceneToFile(&model, tmp, true, true, false, true)) {
    std::remove(tmp.c_str());
    return status::error(out_path + ": cannot write the file");
  }
  if (std::rename(tmp.c_str(), out_path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return status::error(out_path + ": cannot replace the file");
  }
  return {};
}

}  // namespace avatarmap
