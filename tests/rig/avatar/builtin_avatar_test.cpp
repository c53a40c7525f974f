// The built-in avatar (include/avatarmap/avatar/builtin_avatar.hpp): it loads as an avatar with
// every humanoid bone, its joints are the proxy skeleton's (known answers), its skin is sane
// (weights sum to 1, inverse bind matrices invert the joints' rest matrices, closed parts face
// outward), its expressions move only the head, retargeting a pose onto it and skinning moves
// every vertex where the proxy's forward kinematics says, and the file reads back (tinygltf) to
// exactly what was built.
#include "avatarmap/avatar/builtin_avatar.hpp"

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig_binding.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

builtin_avatar make(float height = k_proxy_reference_height) {
  builtin_avatar a;
  builtin_avatar_options o;
  o.height = height;
  const status s = make_builtin_avatar(o, a);
  EXPECT_TRUE(s.ok()) << s.message();
  return a;
}

// The avatar written to a file and loaded as any avatar is.
struct loaded {
  raw_rig raw;
  rig r;
};

void load(const std::string& path, loaded& out) {
  status s = load_avatar(path, out.raw);
  ASSERT_TRUE(s.ok()) << s.message();
  s = build_rig(out.raw, out.r);
  ASSERT_TRUE(s.ok()) << s.message();
}

TEST(BuiltinAvatar, OptionsOutOfRangeAreRefusedNamingTheField) {
  for (float h : {0.f, 0.49f, 3.01f, std::nanf(""), INFINITY}) {
    builtin_avatar_options o;
    o.height = h;
    const status s = o.validate();
    EXPECT_FALSE(s.ok()) << h;
    EXPECT_NE(s.message().find("height must be in [0.50, 3.00] metres"), std::string::npos)
        << s.message();
    builtin_avatar a;
    EXPECT_FALSE(make_builtin_avatar(o, a).ok());
  }
  builtin_avatar_options o;
  o.name.clear();
  EXPECT_NE(o.validate().message().find("name"), std::string::npos);
  test::temp_dir dir("builtin_avatar");
  o = builtin_avatar_options{};
  o.height = 7.f;
  const status s = write_builtin_avatar(dir.file("a.vrm"), o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("a.vrm"), std::string::npos) << s.message();
  EXPECT_TRUE(dir.entries().empty());
}

TEST(BuiltinAvatar, UnwritablePathFailsNamingItAndLeavesNothing) {
  test::temp_dir dir("builtin_avatar");
  const std::string path = dir.file("no-such-folder/a.vrm");
  const status s = write_builtin_avatar(path);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
  EXPECT_TRUE(dir.entries().empty());
}

TEST(BuiltinAvatar, LoadsAsAVrm1AvatarWithEveryHumanoidBoneAndExpression) {
  test::temp_dir dir("builtin_avatar");
  const std::string path = dir.file("avatar.vrm");
  ASSERT_TRUE(write_builtin_avatar(path).ok());
  EXPECT_EQ(dir.entries().size(), 1u);  // no temporary file left
  loaded l;
  load(path, l);
  EXPECT_EQ(l.raw.source, rig_source::vrm1);
  for (int b = 0; b < k_bone_count; ++b) {
    EXPECT_GE(l.r.declared_humanoid[b], 0) << bone_name(static_cast<bone>(b));
    if (l.r.declared_humanoid[b] >= 0)
      EXPECT_EQ(l.r.names[l.r.declared_humanoid[b]], bone_name(static_cast<bone>(b)));
  }
  for (const char* e : {"blink", "blinkLeft", "blinkRight", "aa", "ih", "ou", "ee", "oh", "happy",
                        "angry", "sad", "relaxed", "surprised", "browUpLeft", "browDownRight"})
    EXPECT_NE(std::find(l.r.expressions.begin(), l.r.expressions.end(), e), l.r.expressions.end())
        << e;
  rig_binding_choice choice;
  const status s = select_binding(l.r, "auto", "", choice);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(choice.uses_table);
  EXPECT_EQ(choice.bound, k_bone_count);
  retargeter rt;
  EXPECT_TRUE(rt.build(l.r, choice.binding).ok());
}

// Joint world positions at rest are the proxy skeleton's, for two heights; and a few known
// answers of the 1.70 m table worked out by hand (hips above the soles, the left hand joint).
TEST(BuiltinAvatar, JointsAreTheProxySkeletonsAtRest) {
  for (float h : {1.70f, 1.50f}) {
    test::temp_dir dir("builtin_avatar");
    builtin_avatar_options o;
    o.height = h;
    ASSERT_TRUE(write_builtin_avatar(dir.file("a.vrm"), o).ok());
    loaded l;
    load(dir.file("a.vrm"), l);
    const proxy_skeleton sk = make_proxy_skeleton(h);
    proxy_pose rest;
    rest.hips_position = glm::vec3(0.f, standing_hips_height(sk), 0.f);
    std::array<glm::vec3, k_bone_count> expected;
    joint_world_positions(sk, rest, expected);
    for (int b = 0; b < k_bone_count; ++b) {
      const int j = l.r.declared_humanoid[b];
      ASSERT_GE(j, 0);
      const glm::vec3 got(l.r.rest_world[j][3]);
      EXPECT_NEAR(glm::length(got - expected[b]), 0.f, 1e-5f) << bone_name(static_cast<bone>(b));
      EXPECT_NEAR(angle_between(l.r.rest_world_rotation[j], identity_quat()), 0.f, 1e-6f);
    }
    const float k = h / 1.70f;
    // hips: thigh 0.42 + shin 0.40 + the toe tip's drop below the ankle, (0.117 + 0.04) / sqrt(5)
    // (the foot and toes point (0, -1, 2) / sqrt(5)): the toe tip is the lowest point.
    const float hips_y = 0.82f + 0.157f / std::sqrt(5.f);
    const glm::vec3 hips(l.r.rest_world[l.r.declared_humanoid[idx(bone::hips)]][3]);
    EXPECT_NEAR(hips.y, hips_y * k, 1e-5f);
    // left hand: x = 0.02 + 0.15 + 0.28 + 0.25, y = hips + 0.08 + 0.12 + 0.12 + 0.15.
    const glm::vec3 hand(l.r.rest_world[l.r.declared_humanoid[idx(bone::left_hand)]][3]);
    EXPECT_NEAR(glm::length(hand - k * glm::vec3(0.70f, hips_y + 0.47f, 0.f)), 0.f, 1e-5f);
  }
}

TEST(BuiltinAvatar, MeshStandsOnTheFloorAndIsAsTallAsAsked) {
  for (float h : {1.70f, 0.9f, 2.2f}) {
    const builtin_avatar a = make(h);
    float lo = 1e9f, hi = -1e9f, left = -1e9f;
    for (const avatar_mesh& m : a.meshes)
      for (const avatar_primitive& p : m.primitives)
        for (const glm::vec3& v : p.positions) {
          lo = std::min(lo, v.y);
          hi = std::max(hi, v.y);
          left = std::max(left, v.x);
        }
    EXPECT_NEAR(lo, 0.f, 5e-4f * h) << h;  // soles on Y = 0 (half a millimetre)
    EXPECT_NEAR(hi, h, 0.01f * h) << h;    // top of the head
    // The tip of the left middle finger: 0.70 + 0.095 + 0.045 + 0.028 + 0.022 (1.70 m table).
    EXPECT_NEAR(left, 0.89f * h / 1.70f, 1e-3f * h) << h;
  }
}

// Skin: every vertex bound, weights non-negative and summing to 1, joints in range; normals
// unit; every closed part (each connected component whose edges all have two triangles) has a
// positive signed volume, i.e. its triangles face outward.
TEST(BuiltinAvatar, SkinWeightsNormalsAndWindingAreSane) {
  const builtin_avatar a = make();
  ASSERT_EQ(a.meshes.size(), 2u);
  int closed_parts = 0;
  for (const avatar_mesh& m : a.meshes)
    for (const avatar_primitive& p : m.primitives) {
      const std::size_t n = p.positions.size();
      ASSERT_GT(n, 0u);
      ASSERT_EQ(p.normals.size(), n);
      ASSERT_EQ(p.joints.size(), n);
      ASSERT_EQ(p.weights.size(), n);
      ASSERT_EQ(p.indices.size() % 3, 0u);
      for (std::size_t v = 0; v < n; ++v) {
        float sum = 0.f;
        for (int k = 0; k < 4; ++k) {
          EXPECT_GE(p.weights[v][k], 0.f);
          EXPECT_LT(p.joints[v][k], k_bone_count);
          if (p.weights[v][k] == 0.f) EXPECT_EQ(p.joints[v][k], 0);
          sum += p.weights[v][k];
        }
        ASSERT_NEAR(sum, 1.f, 1e-6f) << m.name << " vertex " << v;
        ASSERT_NEAR(glm::length(p.normals[v]), 1.f, 1e-5f);
      }
      for (std::uint32_t i : p.indices) ASSERT_LT(i, n);
      // Connected components (union-find over triangle edges).
      std::vector<std::size_t> parent(n);
      for (std::size_t v = 0; v < n; ++v) parent[v] = v;
      auto find = [&](std::size_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
      };
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
      for (std::size_t t = 0; t < p.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
          const std::uint32_t u = p.indices[t + e], w = p.indices[t + (e + 1) % 3];
          parent[find(u)] = find(w);
          ++edges[{std::min(u, w), std::max(u, w)}];
        }
      std::map<std::size_t, double> volume;
      std::map<std::size_t, bool> closed;
      for (const auto& [e, count] : edges) {
        const std::size_t c = find(e.first);
        if (!closed.count(c)) closed[c] = true;
        if (count != 2) closed[c] = false;
      }
      for (std::size_t t = 0; t < p.indices.size(); t += 3) {
        const glm::dvec3 x(p.positions[p.indices[t]]), y(p.positions[p.indices[t + 1]]),
            z(p.positions[p.indices[t + 2]]);
        volume[find(p.indices[t])] += glm::dot(x, glm::cross(y, z)) / 6.0;
      }
      for (const auto& [c, vol] : volume) {
        if (!closed[c]) continue;
        ++closed_parts;
        EXPECT_GT(vol, 0.0) << m.name << " primitive of material " << p.material;
      }
    }
  // Torso 2, neck, 2 x (arm, palm, 5 fingers, leg, foot), head, nose, 2 x (eye, iris, brow),
  // mouth, tongue: every part but the eyelids (open sheets) is closed.
  EXPECT_EQ(closed_parts, 3 + 2 * 9 + 2 + 2 * 3 + 2);
}

// What the file holds: tinygltf reads it without errors or warnings and gives back exactly the
// built positions, weights, morph targets and indices; the skin's inverse bind matrices invert
// each joint's rest world matrix; VRMC_vrm names every bone's node and binds the expressions.
TEST(BuiltinAvatar, FileReadsBackToWhatWasBuilt) {
  const builtin_avatar a = make();
  std::string glb;
  ASSERT_TRUE(encode_builtin_avatar(a, glb).ok());
  std::string again;
  ASSERT_TRUE(builtin_avatar_glb({}, again).ok());
  EXPECT_EQ(glb, again);  // reproducible byte for byte

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromMemory(&model, &err, &warn,
                                          reinterpret_cast<const unsigned char*>(glb.data()),
                                          static_cast<unsigned>(glb.size())))
      << err;
  EXPECT_TRUE(err.empty()) << err;
  EXPECT_TRUE(warn.empty()) << warn;
  auto bytes = [&](int accessor) {
    const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(accessor)];
    const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(acc.bufferView)];
    return model.buffers[0].data.data() + view.byteOffset + acc.byteOffset;
  };
  auto floats = [&](int accessor, int comps) {
    const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(accessor)];
    EXPECT_EQ(acc.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
    std::vector<float> out(acc.count * static_cast<std::size_t>(comps));
    std::memcpy(out.data(), bytes(accessor), out.size() * 4);
    return out;
  };

  ASSERT_EQ(model.meshes.size(), 2u);
  for (std::size_t m = 0; m < 2; ++m) {
    ASSERT_EQ(model.meshes[m].primitives.size(), a.meshes[m].primitives.size());
    for (std::size_t k = 0; k < a.meshes[m].primitives.size(); ++k) {
      const tinygltf::Primitive& gp = model.meshes[m].primitives[k];
      const avatar_primitive& p = a.meshes[m].primitives[k];
      const std::vector<float> pos = floats(gp.attributes.at("POSITION"), 3);
      ASSERT_EQ(pos.size(), p.positions.size() * 3);
      for (std::size_t v = 0; v < p.positions.size(); ++v)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(pos[v * 3 + c], p.positions[v][c]);
      const std::vector<float> w = floats(gp.attributes.at("WEIGHTS_0"), 4);
      const tinygltf::Accessor& ja = model.accessors[gp.attributes.at("JOINTS_0")];
      ASSERT_EQ(ja.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE);
      const unsigned char* jb = bytes(gp.attributes.at("JOINTS_0"));
      for (std::size_t v = 0; v < p.positions.size(); ++v)
        for (int c = 0; c < 4; ++c) {
          ASSERT_EQ(w[v * 4 + c], p.weights[v][c]);
          ASSERT_EQ(jb[v * 4 + c], p.joints[v][c]);
        }
      const tinygltf::Accessor& ia = model.accessors[static_cast<std::size_t>(gp.indices)];
      ASSERT_EQ(ia.count, p.indices.size());
      ASSERT_EQ(ia.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
      const unsigned char* ib = bytes(gp.indices);
      for (std::size_t i = 0; i < p.indices.size(); ++i)
        ASSERT_EQ(ib[2 * i] | (ib[2 * i + 1] << 8), static_cast<int>(p.indices[i]));
      ASSERT_EQ(gp.targets.size(), p.targets.size());
      for (std::size_t t = 0; t < p.targets.size(); ++t) {
        const std::vector<float> d = floats(gp.targets[t].at("POSITION"), 3);
        for (std::size_t v = 0; v < p.positions.size(); ++v)
          for (int c = 0; c < 3; ++c) ASSERT_EQ(d[v * 3 + c], p.targets[t][v][c]);
      }
    }
  }

  ASSERT_EQ(model.skins.size(), 1u);
  const tinygltf::Skin& skin = model.skins[0];
  ASSERT_EQ(skin.joints.size(), static_cast<std::size_t>(k_bone_count));
  const std::vector<float> ibm = floats(skin.inverseBindMatrices, 16);
  for (int b = 0; b < k_bone_count; ++b) {
    ASSERT_EQ(skin.joints[b], b);
    EXPECT_EQ(model.nodes[b].name, bone_name(static_cast<bone>(b)));
    // The joint's rest world matrix from the node tree (translations only, no rotations).
    glm::mat4 world(1.f);
    for (int n = b; n >= 0; n = bone_parent(n)) {
      const std::vector<double>& t = model.nodes[n].translation;
      world = glm::translate(glm::mat4(1.f), glm::vec3(t[0], t[1], t[2])) * world;
      EXPECT_TRUE(model.nodes[n].rotation.empty());
    }
    glm::mat4 inv;
    std::memcpy(&inv[0][0], &ibm[static_cast<std::size_t>(b) * 16], 64);
    const glm::mat4 product = inv * world;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(product[c][r], c == r ? 1.f : 0.f, 1e-6f);
    EXPECT_NEAR(glm::length(glm::vec3(world[3]) - a.joints[b]), 0.f, 1e-6f);
  }

  const tinygltf::Value& vrm = model.extensions.at("VRMC_vrm");
  EXPECT_EQ(vrm.Get("specVersion").Get<std::string>(), "1.0");
  const tinygltf::Value& meta = vrm.Get("meta");
  EXPECT_EQ(meta.Get("licenseUrl").Get<std::string>(), "https://vrm.dev/licenses/1.0/");
  EXPECT_GE(meta.Get("authors").ArrayLen(), 1u);
  EXPECT_EQ(meta.Get("name").Get<std::string>(), "avatarmap mannequin");
  const tinygltf::Value& bones = vrm.Get("humanoid").Get("humanBones");
  for (int b = 0; b < k_bone_count; ++b)
    EXPECT_EQ(bones.Get(std::string(bone_name(static_cast<bone>(b)))).Get("node").Get<int>(), b);
  const tinygltf::Value& blink = vrm.Get("expressions").Get("preset").Get("blink");
  ASSERT_EQ(blink.Get("morphTargetBinds").ArrayLen(), 2u);
  const int face_node = blink.Get("morphTargetBinds").Get(0).Get("node").Get<int>();
  EXPECT_EQ(model.nodes[static_cast<std::size_t>(face_node)].mesh, 1);
  EXPECT_EQ(model.nodes[static_cast<std::size_t>(face_node)].skin, 0);
}

// The face's morph targets are ARKit's 52 (Perfect Sync), named as Apple names them, in ARKit's
// order; each moves only vertices bound to the head or the eyes, by millimetres to centimetres,
// a one-sided shape mostly on its side (the person's left = the avatar's left = +X); the
// eyeLook* ones move nothing (the gaze turns the eye bones); the body has no morph targets.
TEST(BuiltinAvatar, FaceHasArkitsBlendshapesAsMorphTargets) {
  const builtin_avatar a = make();
  for (const avatar_primitive& p : a.meshes[0].primitives) EXPECT_TRUE(p.targets.empty());
  const avatar_mesh& face = a.meshes[1];
  ASSERT_EQ(face.primitives.size(), 1u);
  const avatar_primitive& p = face.primitives[0];
  ASSERT_EQ(face.target_names.size(), 52u);
  ASSERT_EQ(p.targets.size(), 52u);
  // Spot checks against Apple's list (ARFaceAnchor.BlendShapeLocation, alphabetical).
  EXPECT_EQ(face.target_names[0], "browDownLeft");
  EXPECT_EQ(face.target_names[8], "eyeBlinkLeft");
  EXPECT_EQ(face.target_names[24], "jawOpen");
  EXPECT_EQ(face.target_names[43], "mouthSmileLeft");
  EXPECT_EQ(face.target_names[51], "tongueOut");
  EXPECT_TRUE(std::is_sorted(face.target_names.begin(), face.target_names.end()));
  const std::set<int> head_bones = {idx(bone::head), idx(bone::left_eye), idx(bone::right_eye),
                                    idx(bone::jaw)};
  for (std::size_t t = 0; t < 52; ++t) {
    const std::string& name = face.target_names[t];
    ASSERT_EQ(p.targets[t].size(), p.positions.size()) << name;
    int moved = 0;
    float largest = 0.f, side = 0.f;
    for (std::size_t v = 0; v < p.positions.size(); ++v) {
      const float d = glm::length(p.targets[t][v]);
      if (d == 0.f) continue;
      ++moved;
      largest = std::max(largest, d);
      side += d * p.positions[v].x;
      for (int k = 0; k < 4; ++k)
        if (p.weights[v][k] > 0.f) EXPECT_TRUE(head_bones.count(p.joints[v][k])) << name;
    }
    if (name.rfind("eyeLook", 0) == 0) {
      EXPECT_EQ(moved, 0) << name;
      continue;
    }
    EXPECT_GT(moved, 10) << name;
    EXPECT_GT(largest, 0.0015f) << name;  // visibly: millimetres
    EXPECT_LT(largest, 0.05f) << name;    // and within the face
    const bool one_sided =
        name != "jawLeft" && name != "jawRight" && name != "mouthLeft" && name != "mouthRight";
    if (one_sided && name.find("Left") != std::string::npos) EXPECT_GT(side, 0.f) << name;
    if (one_sided && name.find("Right") != std::string::npos) EXPECT_LT(side, 0.f) << name;
  }
}

// Each shape moves the face the way Apple's reference describes it: the parts are told apart by
// their vertex colours (mouth, tongue, lids, hair = brows) and the displacement of the part is
// measured (mean, or at its extreme vertex).
TEST(BuiltinAvatar, ArkitShapesMoveAsApplesDefinitionsSay) {
  const builtin_avatar a = make();
  const avatar_mesh& face = a.meshes[1];
  const avatar_primitive& p = face.primitives[0];
  ASSERT_EQ(p.colors.size(), p.positions.size());
  auto target = [&](const char* name) -> const std::vector<glm::vec3>& {
    const auto it = std::find(face.target_names.begin(), face.target_names.end(), name);
    EXPECT_NE(it, face.target_names.end()) << name;
    return p.targets[static_cast<std::size_t>(it - face.target_names.begin())];
  };
  auto is = [&](std::size_t v, glm::vec3 c) { return glm::length(p.colors[v] - c) < 1e-3f; };
  const glm::vec3 mouth(0.32f, 0.05f, 0.06f), tongue(0.80f, 0.36f, 0.38f), lid(0.74f, 0.50f, 0.39f),
      hair(0.07f, 0.04f, 0.025f);
  const float eye_y = a.joints[idx(bone::left_eye)].y;
  // Mean displacement of the vertices of one colour that pass `where`.
  auto mean = [&](const char* name, glm::vec3 colour, auto where) {
    const std::vector<glm::vec3>& d = target(name);
    glm::vec3 sum(0.f);
    int n = 0;
    for (std::size_t v = 0; v < d.size(); ++v)
      if (is(v, colour) && where(p.positions[v])) {
        sum += d[v];
        ++n;
      }
    EXPECT_GT(n, 0) << name;
    return n ? sum / float(n) : sum;
  };
  auto any = [](const glm::vec3&) { return true; };
  auto left = [](const glm::vec3& q) { return q.x > 0.01f; };
  auto right = [](const glm::vec3& q) { return q.x < -0.01f; };
  auto brows = [&](const glm::vec3& q) { return q.y > eye_y && q.y < eye_y + 0.05f && q.z > 0.f; };
  auto inner = [&](const glm::vec3& q) { return brows(q) && std::fabs(q.x) < 0.03f; };
  // The lower half of the mouth (below its centre) and its corners.
  float mouth_y = 0.f, mouth_x = 0.f;
  int mouth_n = 0;
  for (std::size_t v = 0; v < p.positions.size(); ++v)
    if (is(v, mouth)) {
      mouth_y += p.positions[v].y;
      mouth_x = std::max(mouth_x, p.positions[v].x);
      ++mouth_n;
    }
  ASSERT_GT(mouth_n, 0);
  mouth_y /= float(mouth_n);
  auto lower = [&](const glm::vec3& q) { return q.y < mouth_y - 0.002f; };
  auto upper = [&](const glm::vec3& q) { return q.y > mouth_y + 0.002f; };
  auto left_corner = [&](const glm::vec3& q) { return q.x > 0.8f * mouth_x; };
  auto right_corner = [&](const glm::vec3& q) { return q.x < -0.8f * mouth_x; };
  const float mm = 0.001f;

  EXPECT_LT(mean("jawOpen", mouth, lower).y, -10 * mm);   // the jaw drops the lower lip
  EXPECT_GT(mean("jawForward", mouth, lower).z, 3 * mm);  // and pushes it forward
  EXPECT_GT(mean("jawLeft", mouth, lower).x, 3 * mm);     // to the person's left, +X
  EXPECT_LT(mean("jawRight", mouth, lower).x, -3 * mm);
  EXPECT_GT(mean("mouthClose", mouth, lower).y, 5 * mm);            // lips close over an open jaw
  EXPECT_GT(mean("mouthSmileLeft", mouth, left_corner).y, 4 * mm);  // left corner up
  EXPECT_NEAR(mean("mouthSmileLeft", mouth, right_corner).y, 0.f, 0.5f * mm);
  EXPECT_GT(mean("mouthSmileRight", mouth, right_corner).y, 4 * mm);
  EXPECT_LT(mean("mouthFrownLeft", mouth, left_corner).y, -3 * mm);  // left corner down
  EXPECT_LT(mean("mouthFrownRight", mouth, right_corner).y, -3 * mm);
  EXPECT_GT(mean("mouthStretchLeft", mouth, left_corner).x, 3 * mm);  // pulled outward
  EXPECT_LT(mean("mouthStretchRight", mouth, right_corner).x, -3 * mm);
  EXPECT_GT(mean("mouthLeft", mouth, any).x, 5 * mm);  // the whole mouth to the left
  EXPECT_LT(mean("mouthRight", mouth, any).x, -5 * mm);
  EXPECT_LT(mean("mouthPucker", mouth, left_corner).x, -5 * mm);  // narrower
  EXPECT_GT(mean("mouthPucker", mouth, any).z, 4 * mm);           // and forward
  EXPECT_GT(mean("mouthFunnel", mouth, any).z, 3 * mm);
  EXPECT_GT(mean("mouthUpperUpLeft", mouth, upper).y, 1 * mm);
  EXPECT_LT(mean("mouthLowerDownLeft", mouth, lower).y, -1 * mm);
  EXPECT_GT(mean("mouthShrugLower", mouth, lower).y, 1 * mm);
  EXPECT_LT(mean("mouthRollUpper", mouth, upper).y, -1 * mm);
  EXPECT_GT(mean("tongueOut", tongue, any).z, 15 * mm);      // the tongue comes out
  EXPECT_LT(mean("eyeBlinkLeft", lid, left).y, -1.5f * mm);  // lids close (down on average)
  EXPECT_NEAR(glm::length(mean("eyeBlinkLeft", lid, right)), 0.f, 1e-6f);
  EXPECT_LT(mean("eyeBlinkRight", lid, right).y, -1.5f * mm);
  EXPECT_GT(mean("eyeWideLeft", lid, [&](const glm::vec3& q) { return left(q) && q.y > eye_y; }).y,
            0.5f * mm);  // the upper lid goes up
  EXPECT_GT(mean("browInnerUp", hair, inner).y, 2 * mm);
  EXPECT_LT(mean("browDownLeft", hair, [&](const glm::vec3& q) { return brows(q) && left(q); }).y,
            -2 * mm);
  EXPECT_GT(
      mean("browOuterUpRight", hair, [&](const glm::vec3& q) { return brows(q) && right(q); }).y,
      1 * mm);
  // cheekPuff: the skin of the cheeks goes outward from the head's centre.
  const std::vector<glm::vec3>& puff = target("cheekPuff");
  const glm::vec3 head = a.joints[idx(bone::head)];
  float outward = 0.f;
  for (std::size_t v = 0; v < puff.size(); ++v)
    if (glm::length(puff[v]) > 0.f) outward += glm::dot(puff[v], p.positions[v] - head);
  EXPECT_GT(outward, 0.f);
}

// The VRM expressions bind combinations of the ARKit targets (nothing else), with weights in
// (0, 1]: blink = eyeBlinkLeft + eyeBlinkRight; the five emotions are presets built from the
// shapes their faces show.
TEST(BuiltinAvatar, ExpressionsBindArkitTargets) {
  const builtin_avatar a = make();
  const avatar_mesh& face = a.meshes[1];
  std::map<std::string, std::set<std::string>> binds;
  std::map<std::string, bool> preset;
  for (const avatar_expression& e : a.expressions) {
    preset[e.name] = e.preset;
    for (const avatar_expression::bind& b : e.binds) {
      ASSERT_EQ(b.mesh, 1) << e.name;
      ASSERT_GE(b.target, 0);
      ASSERT_LT(b.target, 52);
      EXPECT_GT(b.weight, 0.f) << e.name;
      EXPECT_LE(b.weight, 1.f) << e.name;
      binds[e.name].insert(face.target_names[static_cast<std::size_t>(b.target)]);
    }
  }
  for (const char* name :
       {"blink", "blinkLeft", "blinkRight", "aa", "ih", "ou", "ee", "oh", "happy", "angry", "sad",
        "relaxed", "surprised", "browUpLeft", "browUpRight", "browDownLeft", "browDownRight"}) {
    ASSERT_TRUE(binds.count(name)) << name;
    EXPECT_EQ(preset[name], std::string(name).rfind("brow", 0) != 0) << name;
  }
  EXPECT_EQ(binds["blink"], (std::set<std::string>{"eyeBlinkLeft", "eyeBlinkRight"}));
  EXPECT_EQ(binds["blinkLeft"], (std::set<std::string>{"eyeBlinkLeft"}));
  EXPECT_TRUE(binds["aa"].count("jawOpen"));
  EXPECT_TRUE(binds["happy"].count("mouthSmileLeft") && binds["happy"].count("mouthSmileRight"));
  EXPECT_TRUE(binds["angry"].count("browDownLeft") && binds["angry"].count("browDownRight"));
  EXPECT_TRUE(binds["sad"].count("browInnerUp") && binds["sad"].count("mouthFrownLeft"));
  EXPECT_TRUE(binds["relaxed"].count("mouthSmileLeft"));
  EXPECT_TRUE(binds["surprised"].count("eyeWideLeft") && binds["surprised"].count("jawOpen"));
  EXPECT_EQ(binds["browDownLeft"], (std::set<std::string>{"browDownLeft"}));
}

// Retargeting poses onto the loaded avatar and skinning every vertex with the rig's posed
// joints (linear blend skinning, the file's inverse bind matrices = the inverse rest matrices)
// puts each vertex where the proxy's own forward kinematics says; plus one pose by hand.
TEST(BuiltinAvatar, RetargetedPoseSkinsVerticesWhereProxyFkSays) {
  test::temp_dir dir("builtin_avatar");
  ASSERT_TRUE(write_builtin_avatar(dir.file("a.vrm")).ok());
  loaded l;
  load(dir.file("a.vrm"), l);
  const builtin_avatar a = make();
  retargeter rt;
  retarget_options ro;
  ro.root_motion = false;  // the hips stay at their rest place: compare rotations only
  ASSERT_TRUE(rt.build(l.r, l.r.declared_humanoid, ro).ok());
  rig_pose rp;
  rt.prepare(rp);

  auto rig_world = [&](std::vector<glm::mat4>& world) {
    world.resize(static_cast<std::size_t>(l.r.joint_count()));
    for (int j = 0; j < l.r.joint_count(); ++j) {
      const glm::mat4 m = glm::translate(glm::mat4(1.f), l.r.rest_local[j].translation) *
                          glm::mat4_cast(rp.local_rotations[j]);
      world[j] = l.r.parents[j] < 0 ? m : world[l.r.parents[j]] * m;
    }
  };

  // By hand: the left forearm turned 90 degrees about +Y carries the hand joint from
  // (0.70, y, 0) to (0.45, y, -0.25) (+X turns to -Z; y = the hand's rest height).
  proxy_pose hand_pose;
  hand_pose.hips_position = a.joints[idx(bone::hips)];
  hand_pose.rotations[idx(bone::left_lower_arm)] = axis_angle(glm::vec3(0, 1, 0), 0.5f * k_pi);
  rt.apply(hand_pose, rp);
  std::vector<glm::mat4> world;
  rig_world(world);
  const glm::vec3 hand(world[l.r.declared_humanoid[idx(bone::left_hand)]][3]);
  const float y = a.joints[idx(bone::left_hand)].y;
  EXPECT_NEAR(glm::length(hand - glm::vec3(0.45f, y, -0.25f)), 0.f, 1e-5f);

  std::mt19937 rng(5);
  double worst = 0.0;
  for (int i = 0; i < 20; ++i) {
    proxy_pose pose = i == 0 ? hand_pose : random_pose(rng);
    pose.hips_position = a.joints[idx(bone::hips)];
    rt.apply(pose, rp);
    rig_world(world);
    proxy_fk fk;
    compute_proxy_fk(a.skeleton, pose, fk);
    for (const avatar_mesh& m : a.meshes)
      for (const avatar_primitive& p : m.primitives)
        for (std::size_t v = 0; v < p.positions.size(); ++v) {
          const glm::vec3 x = p.positions[v];
          glm::vec3 by_rig(0.f), by_fk(0.f);
          for (int k = 0; k < 4; ++k) {
            const float w = p.weights[v][k];
            if (w == 0.f) continue;
            const int b = p.joints[v][k];
            const int j = l.r.declared_humanoid[b];
            // The skin's inverse bind matrix of joint b is a translation by -joints[b].
            by_rig += w * glm::vec3(world[j] * glm::vec4(x - a.joints[b], 1.f));
            by_fk += w * (fk.joints[b] + fk.world[b] * (x - a.joints[b]));
          }
          worst = std::max(worst, double(glm::length(by_rig - by_fk)));
        }
  }
  EXPECT_LT(worst, 1e-4) << "metres";
}

}  // namespace
}  // namespace avatarmap
