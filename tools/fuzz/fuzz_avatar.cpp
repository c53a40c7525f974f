// libFuzzer target: avatar loading (rig/avatar_loader.hpp: load_avatar of glTF, GLB, VRM 0.x
// and 1.0, VRMA), then build_rig, then binding and retargeting as `convert --rig auto` does.
// The bytes are written to a file in a private scratch folder (load_avatar takes a path, and
// relative buffer URIs resolve against that folder). Checks that nothing crashes or throws,
// that a failure names the file and leaves the raw rig empty, that a loaded raw rig is
// consistent (parents and humanoid nodes in range, no node on two bones), that a built rig
// is parent-first with finite world transforms and unit rotations, that retargeting the rest
// pose (and a bent one) of a bound rig gives finite, unit-length rotations and a finite hips
// translation, and that the two poses written as the animated avatar (.glb) and as a rig .bvh
// read back, or fail with a message while keeping the existing output and leaking no file.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "avatarmap/export/animated_glb.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "fuzz_support.hpp"

using namespace avatarmap;
using avatarmap::fuzz::check;

namespace {

// The shipped mapping tables, loaded once (select_binding would reread the folder per input).
const std::vector<mapping_table>& tables() {
  static const std::vector<mapping_table> t = [] {
    std::vector<mapping_table> out;
    status s = load_mapping_folder(AVATARMAP_FUZZ_MAPPINGS_DIR, out);
    if (!s) {
      std::fprintf(stderr, "fuzz_avatar: %s\n", s.message().c_str());
      std::abort();
    }
    return out;
  }();
  return t;
}

bool unit(const glm::quat& q) {
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::isfinite(n) && std::abs(n - 1.f) < 1e-3f;
}

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

void check_raw(const raw_rig& raw, const std::string& path) {
  check(raw.file == path, "raw.file is the path");
  const int n = static_cast<int>(raw.nodes.size());
  std::vector<int> bone_of_node(raw.nodes.size(), -1);
  for (const raw_rig::node& node : raw.nodes) {
    check(node.parent >= -1 && node.parent < n, "raw parents in range");
    check(!node.name.empty(), "every node has a name");
  }
  for (int b = 0; b < k_bone_count; ++b) {
    const int i = raw.declared_humanoid[b];
    check(i >= -1 && i < n, "declared humanoid node in range");
    if (i < 0) continue;
    check(bone_of_node[static_cast<std::size_t>(i)] < 0, "no node declared for two bones");
    bone_of_node[static_cast<std::size_t>(i)] = b;
  }
  if (raw.source == rig_source::gltf)
    for (int i : raw.declared_humanoid) check(i < 0, "plain glTF declares no humanoid");
}

void check_rig(const rig& r, const raw_rig& raw) {
  const int n = r.joint_count();
  check(n == static_cast<int>(raw.nodes.size()), "the rig keeps every node");
  check(r.parents.size() == r.names.size() && r.rest_local.size() == r.names.size() &&
            r.rest_world.size() == r.names.size() &&
            r.rest_world_rotation.size() == r.names.size() &&
            r.source_index.size() == r.names.size(),
        "the rig's arrays have one entry per joint");
  for (int i = 0; i < n; ++i) {
    check(r.parents[i] >= -1 && r.parents[i] < i, "joints are parent-first");
    check(finite(r.rest_world[i]), "rest world matrices are finite");
    check(unit(r.rest_world_rotation[i]), "rest world rotations are unit length");
    check(unit(r.rest_local[i].rotation), "rest local rotations are unit length");
  }
  for (int j : r.declared_humanoid) check(j >= -1 && j < n, "declared humanoid joint in range");
  check(r.file == raw.file && r.source == raw.source, "the rig keeps the file and the source");
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

constexpr const char* k_previous = "an existing output file\n";

// Writes `frames` as the animated avatar (.glb) and as a rig .bvh over existing files in the
// scratch folder. A write that succeeds must read back (the .glb as an avatar with the same
// nodes, the .bvh with one frame per pose); one that fails must name a file, keep the
// existing output and leave no temporary file behind.
void write_outputs(const std::string& avatar, const rig& r, const std::vector<rig_pose>& frames) {
  const std::string glb = fuzz::scratch_dir() + "/out.glb";
  const std::string bvh = fuzz::scratch_dir() + "/out.bvh";
  for (const char* name : {"out.glb", "out.bvh"})
    fuzz::write_scratch(name, reinterpret_cast<const std::uint8_t*>(k_previous),
                        std::char_traits<char>::length(k_previous));
  const int entries = fuzz::scratch_entries();

  status s = write_animated_glb(avatar, r, frames, {}, glb);
  check(fuzz::scratch_entries() == entries, "writing the .glb leaves no temporary file");
  if (!s) {
    check(s.message().rfind(avatar, 0) == 0 || s.message().rfind(glb, 0) == 0,
          "the .glb writer's errors name a file");
    check(read_all(glb) == k_previous, "a failed .glb write keeps the existing file");
  } else {
    raw_rig back;
    status b = load_avatar(glb, back);
    if (!b) std::fprintf(stderr, "%s\n", b.message().c_str());
    check(b.ok(), "the written .glb loads back as an avatar");
    check(back.nodes.size() == r.names.size(), "the written .glb keeps every node");
  }

  s = write_rig_bvh(bvh, r, frames);
  check(fuzz::scratch_entries() == entries, "writing the .bvh leaves no temporary file");
  if (!s) {
    check(s.message().rfind(bvh, 0) == 0 || s.message().rfind(r.file, 0) == 0,
          "the .bvh writer's errors name a file");
    check(read_all(bvh) == k_previous, "a failed .bvh write keeps the existing file");
  } else {
    bvh_clip clip;
    status b = read_bvh(bvh, clip);
    if (!b) std::fprintf(stderr, "%s\n", b.message().c_str());
    check(b.ok(), "the written .bvh reads back");
    check(clip.frame_count == static_cast<int>(frames.size()), "one BVH frame per pose");
    for (float v : clip.values) check(std::isfinite(v), "the written .bvh has finite values");
  }
}

// Binds `r` as select_binding(r, "auto", ...) does, retargets the rest pose and a bent pose,
// and writes them.
void retarget_and_write(const std::string& avatar, const rig& r) {
  bone_binding binding;
  binding.fill(-1);
  const mapping_table* table = nullptr;
  if (r.declared_humanoid[idx(bone::hips)] >= 0) {
    binding = r.declared_humanoid;
  } else {
    int best = -1;
    mapping_match m;
    if (!auto_detect(tables(), r, best, m)) return;
    check(best >= 0 && best < static_cast<int>(tables().size()), "auto_detect's index in range");
    table = &tables()[static_cast<std::size_t>(best)];
    binding = m.joint;
  }
  for (int j : binding) check(j >= -1 && j < r.joint_count(), "bound joints in range");
  retargeter rt;
  if (status s = rt.build(r, binding, {}, table); !s) {
    check(!s.message().empty(), "a failed retargeter build says why");
    return;
  }
  rig_pose out;
  rt.prepare(out);
  check(static_cast<int>(out.local_rotations.size()) == r.joint_count(), "one rotation per joint");
  proxy_pose pose;  // identity rotations: the VRM rest pose
  std::vector<rig_pose> frames;
  for (int f = 0; f < 2; ++f) {
    rt.apply(pose, out);
    for (const glm::quat& q : out.local_rotations) check(unit(q), "retargeted rotations are unit");
    for (int k = 0; k < 3; ++k)
      check(std::isfinite(out.hips_translation[k]), "hips translation finite");
    check(out.hips_joint >= 0 && out.hips_joint < r.joint_count(), "hips joint in range");
    frames.push_back(out);
    // Then a pose that turns every bone (and moves the hips) a little.
    for (glm::quat& q : pose.rotations)
      q = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1.f, 2.f, 3.f)));
    pose.hips_position += glm::vec3(0.1f, -0.2f, 0.3f);
  }
  write_outputs(avatar, r, frames);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  (void)tables();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::clear_scratch();  // outputs of the previous input must not be readable as buffers
  const std::string path = fuzz::write_scratch("avatar.vrm", data, size);
  raw_rig raw;
  status s = load_avatar(path, raw);
  if (!s) {
    check(s.message().rfind(path, 0) == 0, "errors start with the file's path");
    check(raw.nodes.empty() && raw.file == path, "a failed load leaves the rig empty");
    return 0;
  }
  check_raw(raw, path);
  rig r;
  s = build_rig(raw, r);
  if (!s) {
    check(s.message().rfind(path, 0) == 0, "build_rig's errors start with the file's path");
    return 0;
  }
  check_rig(r, raw);
  retarget_and_write(path, r);
  return 0;
}
