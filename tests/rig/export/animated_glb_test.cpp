// The animated .glb writer (include/avatarmap/export/animated_glb.hpp): a well-formed GLB with
// everything in one BIN chunk, textures byte for byte, the animation readable back; hostile
// avatars (URIs leaving the folder, symbolic links) refused with no output written and no
// secret copied; non-finite poses refused; written atomically; the face's morph weights from
// expressions and ARKit blendshapes (known weights, the precedence, hostile names).
#include "avatarmap/export/animated_glb.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "rig/gltf_document.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using nlohmann::json;
using test::contains;
using test::u32_at;

// A GLB written by us, taken apart with the spec's rules (independently of the writer).
struct parsed_glb {
  json j;
  std::string bin;
  std::string error;  // empty when the container is well-formed
};

parsed_glb parse_glb(const std::string& b) {
  parsed_glb out;
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0) return out.error = "no header", out;
  if (u32_at(b, 4) != 2) return out.error = "version", out;
  if (u32_at(b, 8) != b.size()) return out.error = "total length", out;
  const std::uint32_t jl = u32_at(b, 12);
  if (u32_at(b, 16) != 0x4E4F534A || jl % 4 != 0 || 20 + std::size_t{jl} > b.size())
    return out.error = "JSON chunk", out;
  const std::string text = b.substr(20, jl);
  if (text.find_first_not_of(' ', text.find_last_not_of(' ') + 1) != std::string::npos)
    return out.error = "JSON padding", out;
  out.j = json::parse(text, nullptr, false);
  if (out.j.is_discarded()) return out.error = "JSON text", out;
  std::size_t at = 20 + std::size_t{jl};
  if (at < b.size()) {
    const std::uint32_t bl = u32_at(b, at);
    if (u32_at(b, at + 4) != 0x004E4942 || bl % 4 != 0 || at + 8 + std::size_t{bl} != b.size())
      return out.error = "BIN chunk", out;
    out.bin = b.substr(at + 8, bl);
  }
  return out;
}

// The bytes of bufferView `v` of a parsed GLB.
std::string view_bytes(const parsed_glb& g, std::size_t v) {
  const json& view = g.j["bufferViews"][v];
  const std::size_t offset = view.value("byteOffset", std::size_t{0});
  return g.bin.substr(offset, view["byteLength"].get<std::size_t>());
}

// Frames that bend the spine and move the hips (the rig of test::minimal_vrm1).
std::vector<rig_pose> bending_frames(const rig& r, int count) {
  const int hips = r.find("hips"), spine = r.find("spine");
  std::vector<rig_pose> frames(static_cast<std::size_t>(count));
  for (int f = 0; f < count; ++f) {
    rig_pose& p = frames[static_cast<std::size_t>(f)];
    p.local_rotations.resize(static_cast<std::size_t>(r.joint_count()));
    for (int k = 0; k < r.joint_count(); ++k) p.local_rotations[k] = r.rest_local[k].rotation;
    p.local_rotations[spine] = glm::angleAxis(0.1f * float(f), glm::vec3(1, 0, 0));
    p.hips_joint = hips;
    p.hips_translation = glm::vec3(0.f, 1.f, 0.01f * float(f));
  }
  return frames;
}

// Loads and builds the rig of `path` (which must succeed).
rig rig_of(const std::string& path) {
  raw_rig raw;
  rig r;
  status s = load_avatar(path, raw);
  EXPECT_TRUE(s.ok()) << s.message();
  if (s) s = build_rig(raw, r);
  EXPECT_TRUE(s.ok()) << s.message();
  return r;
}

// Random bytes behind a format's magic (never decodable: proves nothing decodes them).
std::string fake_image(const std::string& magic, std::size_t size, unsigned seed) {
  std::mt19937 rng(seed);
  std::string b = magic;
  while (b.size() < size) b += static_cast<char>(rng());
  return b;
}

// A PNG whose header claims 16384 x 16384 pixels, followed by garbage: a decoder would try to
// allocate a gigabyte or fail; a copier copies it.
std::string png_16k() {
  std::string b = "\x89PNG\r\n\x1a\n";
  test::append_u32_le(b, 0);  // the length field's bytes (big-endian 13): 0 0 0 13
  b.replace(8, 4, std::string("\0\0\0\x0d", 4));
  b += "IHDR";
  b += std::string("\0\0\x40\0\0\0\x40\0\x08\x06\0\0\0", 13);
  return b + fake_image("", 5000, 16);
}

class animated_glb_writer : public ::testing::Test {
 protected:
  test::temp_dir dir{"glb"};
  std::string folder = dir.file("avatar");
  std::string out = dir.file("out.glb");
  void SetUp() override { std::filesystem::create_directories(folder + "/tex"); }
  std::string write_json(const std::string& name, const json& j) {
    test::write_text(folder + "/" + name, j.dump());
    return folder + "/" + name;
  }
};

TEST_F(animated_glb_writer, textures_pass_through_byte_for_byte) {
  const std::string png = png_16k();
  const std::string webp = fake_image(std::string("RIFF\x10\x27\0\0WEBPVP8 ", 16), 10000, 2);
  const std::string jpeg = fake_image("\xFF\xD8\xFF\xE0", 3000, 3);
  const std::string geometry = fake_image("", 64, 4);
  test::write_text(folder + "/tex/skin.png", png);
  test::write_text(folder + "/tex/cloth.webp", webp);
  test::write_text(folder + "/geometry.bin", geometry);
  json j = test::minimal_vrm1();
  j["buffers"] = json::array({{{"uri", "geometry.bin"}, {"byteLength", 64}}});
  j["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 16}, {"byteLength", 48}}});
  j["images"] = json::array({{{"uri", "tex/skin.png"}},
                             {{"uri", "tex/cloth.webp"}},
                             {{"uri", "data:image/jpeg;base64," + std::string()}},  // filled below
                             {{"bufferView", 0}, {"mimeType", "image/png"}}});
  // base64 of `jpeg`.
  static const char* k_b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < jpeg.size(); i += 3) {
    std::uint32_t v = static_cast<unsigned char>(jpeg[i]) << 16;
    if (i + 1 < jpeg.size()) v |= static_cast<unsigned char>(jpeg[i + 1]) << 8;
    if (i + 2 < jpeg.size()) v |= static_cast<unsigned char>(jpeg[i + 2]);
    b64 += k_b64[(v >> 18) & 63];
    b64 += k_b64[(v >> 12) & 63];
    b64 += i + 1 < jpeg.size() ? k_b64[(v >> 6) & 63] : '=';
    b64 += i + 2 < jpeg.size() ? k_b64[v & 63] : '=';
  }
  j["images"][2]["uri"] = "data:image/jpeg;base64," + b64;
  j["extensionsUsed"].push_back("EXT_texture_webp");
  const std::string avatar = write_json("avatar.gltf", j);
  const rig r = rig_of(avatar);
  ASSERT_GT(r.joint_count(), 0);
  status s = write_animated_glb(avatar, r, bending_frames(r, 5), {}, out);
  ASSERT_TRUE(s.ok()) << s.message();

  const parsed_glb g = parse_glb(test::read_text(out));
  ASSERT_EQ(g.error, "");
  // One buffer, the BIN chunk; no URI left anywhere.
  ASSERT_EQ(g.j["buffers"].size(), 1u);
  EXPECT_EQ(g.j["buffers"][0]["byteLength"].get<std::size_t>(), g.bin.size());
  EXPECT_FALSE(g.j["buffers"][0].contains("uri"));
  const json& images = g.j["images"];
  ASSERT_EQ(images.size(), 4u);
  const std::string expected[] = {png, webp, jpeg, geometry.substr(16, 48)};
  const char* mime[] = {"image/png", "image/webp", "image/jpeg", "image/png"};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_FALSE(images[i].contains("uri")) << i;
    ASSERT_TRUE(images[i].contains("bufferView")) << i;
    EXPECT_EQ(view_bytes(g, images[i]["bufferView"].get<std::size_t>()), expected[i]) << i;
    EXPECT_EQ(images[i]["mimeType"], mime[i]) << i;
  }
  // The original bufferView still points at the same bytes of the geometry.
  EXPECT_EQ(view_bytes(g, 0), geometry.substr(16, 48));
  // Every bufferView lies inside the BIN chunk and is 4-byte aligned.
  for (const json& v : g.j["bufferViews"]) {
    EXPECT_EQ(v["buffer"], 0);
    EXPECT_LE(v.value("byteOffset", std::size_t{0}) + v["byteLength"].get<std::size_t>(),
              g.bin.size());
    EXPECT_EQ(v.value("byteOffset", std::size_t{0}) % 4, 0u);
  }
  EXPECT_EQ(g.j["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]["hips"]["node"], 1);
}

TEST_F(animated_glb_writer, the_animation_reads_back) {
  const std::string avatar = dir.file("avatar/a.vrm");
  test::write_text(avatar, test::make_glb(test::minimal_vrm1()));
  const rig r = rig_of(avatar);
  const std::vector<rig_pose> frames = bending_frames(r, 4);
  animated_glb_options o;
  o.fps = 20.0;
  ASSERT_TRUE(write_animated_glb(avatar, r, frames, o, out).ok());
  // Through the guarded loader and tinygltf: a valid glTF whose rig is the avatar's.
  raw_rig raw;
  status s = load_avatar(out, raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.nodes.size(), 3u);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 1);
  gltf_detail::gltf_document doc;
  ASSERT_TRUE(gltf_detail::open_gltf_document(out, doc).ok());
  tinygltf::Model model;
  ASSERT_TRUE(gltf_detail::parse_gltf_model(doc, model).ok());
  ASSERT_EQ(model.animations.size(), 1u);
  const tinygltf::Animation& anim = model.animations[0];
  EXPECT_EQ(anim.name, "avatarmap");
  ASSERT_EQ(anim.channels.size(), 2u);  // the spine's rotation, the hips' translation
  EXPECT_EQ(anim.channels[0].target_node, 2);
  EXPECT_EQ(anim.channels[0].target_path, "rotation");
  EXPECT_EQ(anim.channels[1].target_node, 1);
  EXPECT_EQ(anim.channels[1].target_path, "translation");
  const tinygltf::Accessor& times = model.accessors[anim.samplers[0].input];
  EXPECT_EQ(times.count, 4u);
  ASSERT_EQ(times.maxValues.size(), 1u);
  EXPECT_NEAR(times.maxValues[0], 3.0 / 20.0, 1e-7);
  const tinygltf::Accessor& rot = model.accessors[anim.samplers[0].output];
  const tinygltf::BufferView& view = model.bufferViews[rot.bufferView];
  float q[4];
  std::memcpy(q, model.buffers[0].data.data() + view.byteOffset + rot.byteOffset + 3 * 16, 16);
  const glm::quat expected = frames[3].local_rotations[r.find("spine")];
  EXPECT_NEAR(q[0], expected.x, 1e-7f);
  EXPECT_NEAR(q[3], expected.w, 1e-7f);
}

TEST_F(animated_glb_writer, hostile_uris_write_nothing_and_leak_nothing) {
  const std::string secret = "TOP-SECRET-0123456789";
  test::write_text(dir.file("secret.txt"), secret);
  ASSERT_EQ(::symlink(dir.file("secret.txt").c_str(), (folder + "/link.bin").c_str()), 0);
  // The rig comes from a clean copy (a hostile avatar cannot be loaded at all).
  const rig r = rig_of(write_json("clean.gltf", test::minimal_vrm1()));
  test::write_text(out, "the user's old file");
  for (const std::string uri :
       {std::string("../secret.txt"), dir.file("secret.txt"), "file://" + dir.file("secret.txt"),
        std::string("link.bin"), std::string("%2e%2e/secret.txt")}) {
    for (const char* array : {"buffers", "images"}) {
      json j = test::minimal_vrm1();
      j[array] = json::array({{{"uri", uri}}});
      if (std::string(array) == "buffers") j[array][0]["byteLength"] = secret.size();
      const std::string avatar = write_json("hostile.gltf", j);
      status s = write_animated_glb(avatar, r, bending_frames(r, 3), {}, out);
      ASSERT_FALSE(s.ok()) << uri;
      EXPECT_TRUE(contains(s.message(), avatar)) << s.message();
      EXPECT_TRUE(contains(s.message(), std::string(array) + "[0].uri")) << s.message();
      EXPECT_EQ(test::read_text(out), "the user's old file");
    }
  }
  // No temporary file left beside the output.
  for (const std::string& e : dir.entries())
    EXPECT_TRUE(e == "avatar" || e == "secret.txt" || e == "out.glb") << e;
  // A texture the avatar names but lacks stays named (the output misses it as the avatar
  // did); nothing is read for it.
  json j = test::minimal_vrm1();
  j["images"] = json::array({{{"uri", "tex/missing.png"}}, {{"uri", "../missing.png"}}});
  status s = write_animated_glb(write_json("missing.gltf", j), r, bending_frames(r, 3), {}, out);
  ASSERT_FALSE(s.ok());  // the second one leaves the folder
  EXPECT_TRUE(contains(s.message(), "images[1].uri")) << s.message();
  j["images"].erase(1);
  s = write_animated_glb(write_json("missing.gltf", j), r, bending_frames(r, 3), {}, out);
  ASSERT_TRUE(s.ok()) << s.message();
  const parsed_glb g = parse_glb(test::read_text(out));
  ASSERT_EQ(g.error, "");
  EXPECT_EQ(g.j["images"][0]["uri"], "tex/missing.png");
}

TEST_F(animated_glb_writer, refuses_non_finite_poses_and_foreign_rigs) {
  const std::string avatar = write_json("a.gltf", test::minimal_vrm1());
  const rig r = rig_of(avatar);
  std::vector<rig_pose> frames = bending_frames(r, 3);
  frames[1].local_rotations[r.find("spine")].x = NAN;
  status s = write_animated_glb(avatar, r, frames, {}, out);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "frame 1") && contains(s.message(), "'spine'")) << s.message();
  frames = bending_frames(r, 3);
  frames[2].hips_translation.y = INFINITY;
  EXPECT_FALSE(write_animated_glb(avatar, r, frames, {}, out).ok());
  EXPECT_FALSE(std::filesystem::exists(out));
  // A rig with more joints than the file has nodes.
  rig bigger = r;
  bigger.names.push_back("extra");
  bigger.source_index.push_back(7);
  s = write_animated_glb(avatar, bigger, bending_frames(r, 3), {}, out);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "does not belong")) << s.message();
}

// The face (docs/export.md): the weights written for known expressions (the independent
// read-back over three definition kinds is tests/convert/face_glb_test.py); frames whose count
// or values are wrong refused; hostile or absent definitions give joints only, never a crash.
TEST_F(animated_glb_writer, the_face_drives_morph_weights_and_bad_faces_are_refused) {
  const std::string avatar = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(avatar).ok());
  const rig r = rig_of(avatar);
  const std::vector<rig_pose> frames = bending_frames(r, 3);
  std::vector<proxy_pose> faces(3);
  faces[1][expression::aa] = 0.5f;
  animated_glb_options o;
  o.expressions = &faces;
  ASSERT_TRUE(write_animated_glb(avatar, r, frames, o, out).ok());
  const parsed_glb g = parse_glb(test::read_text(out));
  ASSERT_TRUE(g.error.empty()) << g.error;
  // The built-in avatar binds aa to its face's ARKit target jawOpen, weight 0.75 (the clip has
  // no blendshapes: the expressions drive).
  int channels = 0;
  for (const json& c : g.j["animations"][0]["channels"]) {
    if (c["target"]["path"] != "weights") continue;
    ++channels;
    const json& node = g.j["nodes"][c["target"]["node"].get<std::size_t>()];
    const json& names = g.j["meshes"][node["mesh"].get<std::size_t>()]["extras"]["targetNames"];
    const json& acc =
        g.j["accessors"][g.j["animations"][0]["samplers"][c["sampler"].get<std::size_t>()]["output"]
                             .get<std::size_t>()];
    ASSERT_EQ(acc["count"].get<std::size_t>(), 3 * names.size());
    const std::string bytes = view_bytes(g, acc["bufferView"].get<std::size_t>());
    for (std::size_t f = 0; f < 3; ++f)
      for (std::size_t t = 0; t < names.size(); ++t) {
        float v = 0.f;
        std::memcpy(
            &v, bytes.data() + acc.value("byteOffset", std::size_t{0}) + 4 * (f * names.size() + t),
            4);
        EXPECT_FLOAT_EQ(v, f == 1 && names[t] == "jawOpen" ? 0.375f : 0.f)
            << names[t] << " frame " << f;
      }
  }
  EXPECT_EQ(channels, 1);

  faces.pop_back();
  status s = write_animated_glb(avatar, r, frames, o, dir.file("short.glb"));
  EXPECT_EQ(s.code(), status_code::invalid_argument);
  EXPECT_TRUE(contains(s.message(), "2 expression frames for 3")) << s.message();
  faces.resize(3);
  faces[2][expression::blink] = NAN;
  s = write_animated_glb(avatar, r, frames, o, dir.file("nan.glb"));
  EXPECT_TRUE(contains(s.message(), "frame 2 expression 'blink'")) << s.message();
  EXPECT_FALSE(std::filesystem::exists(dir.file("nan.glb")));
  faces[2][expression::blink] = 0.f;
  faces[1][blendshape::tongue_out] = INFINITY;
  s = write_animated_glb(avatar, r, frames, o, dir.file("inf.glb"));
  EXPECT_TRUE(contains(s.message(), "frame 1 blendshape 'tongueOut'")) << s.message();
  EXPECT_FALSE(std::filesystem::exists(dir.file("inf.glb")));
  faces[1][blendshape::tongue_out] = 0.f;

  // Hostile definitions: binds to a node without a mesh, out-of-range indices, wrong types.
  json j = test::minimal_vrm1();
  j["extensions"]["VRMC_vrm"]["expressions"] = {
      {"preset",
       {{"blink",
         {{"morphTargetBinds",
           {{{"node", 1}, {"index", 0}, {"weight", 1.0}},
            {{"node", 99}, {"index", -1}, {"weight", "x"}},
            {{"node", "a"}, {"index", 1e30}}}}}},
        {"aa", {{"morphTargetBinds", 7}}}}},
      {"custom", "not an object"}};
  const std::string hostile = write_json("hostile.gltf", j);
  const rig hr = rig_of(hostile);
  faces[2][expression::blink] = 1.f;
  const std::vector<rig_pose> hframes = bending_frames(hr, 3);
  ASSERT_TRUE(write_animated_glb(hostile, hr, hframes, o, out).ok());
  const json written = parse_glb(test::read_text(out)).j;  // kept: the loop reads into it
  for (const json& c : written["animations"][0]["channels"])
    EXPECT_NE(c["target"]["path"], "weights");
}

// The weights channel of a written GLB: per frame, target name -> weight (the first channel on
// a node whose mesh names its targets).
std::vector<std::map<std::string, float>> face_weights(const parsed_glb& g) {
  std::vector<std::map<std::string, float>> out;
  for (const json& c : g.j["animations"][0]["channels"]) {
    if (c["target"]["path"] != "weights") continue;
    const json& node = g.j["nodes"][c["target"]["node"].get<std::size_t>()];
    const json& names = g.j["meshes"][node["mesh"].get<std::size_t>()]["extras"]["targetNames"];
    const json& acc =
        g.j["accessors"][g.j["animations"][0]["samplers"][c["sampler"].get<std::size_t>()]["output"]
                             .get<std::size_t>()];
    const std::string bytes = view_bytes(g, acc["bufferView"].get<std::size_t>());
    const std::size_t frames = acc["count"].get<std::size_t>() / names.size();
    out.resize(frames);
    for (std::size_t f = 0; f < frames; ++f)
      for (std::size_t t = 0; t < names.size(); ++t) {
        float v = 0.f;
        std::memcpy(
            &v, bytes.data() + acc.value("byteOffset", std::size_t{0}) + 4 * (f * names.size() + t),
            4);
        out[f][names[t].get<std::string>()] = v;
      }
    break;
  }
  return out;
}

// Perfect Sync: the proxy's ARKit blendshapes drive the morph targets named after them; where
// the clip carries blendshapes, a target an ARKit shape drives is not driven again by the VRM
// expressions bound to it (aa binds jawOpen x 0.75: jawOpen is the blendshape's value alone),
// and the expressions drive nothing else here (every face target of the built-in avatar is an
// ARKit shape).
TEST_F(animated_glb_writer, arkit_blendshapes_drive_their_targets_without_double_driving) {
  const std::string avatar = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(avatar).ok());
  const rig r = rig_of(avatar);
  const std::vector<rig_pose> frames = bending_frames(r, 3);
  std::vector<proxy_pose> faces(3);
  faces[1][blendshape::eye_blink_left] = 0.8f;
  faces[1][blendshape::mouth_smile_right] = 0.3f;
  faces[1][blendshape::tongue_out] = 1.7f;  // clamped
  faces[2][blendshape::jaw_open] = 0.2f;
  faces[2][expression::aa] = 0.9f;    // would add 0.675 to jawOpen
  faces[2][expression::happy] = 1.f;  // would add to mouthSmile*, cheekSquint*...
  faces[2][expression::blink] = 1.f;  // would close both eyes
  animated_glb_options o;
  o.expressions = &faces;
  ASSERT_TRUE(write_animated_glb(avatar, r, frames, o, out).ok());
  const auto w = face_weights(parse_glb(test::read_text(out)));
  ASSERT_EQ(w.size(), 3u);
  ASSERT_EQ(w[0].size(), 52u);
  for (const auto& [name, v] : w[0]) EXPECT_EQ(v, 0.f) << name;
  EXPECT_FLOAT_EQ(w[1].at("eyeBlinkLeft"), 0.8f);
  EXPECT_FLOAT_EQ(w[1].at("mouthSmileRight"), 0.3f);
  EXPECT_FLOAT_EQ(w[1].at("tongueOut"), 1.f);
  EXPECT_FLOAT_EQ(w[1].at("eyeBlinkRight"), 0.f);
  EXPECT_FLOAT_EQ(w[2].at("jawOpen"), 0.2f);
  for (const auto& [name, v] : w[2])
    if (name != "jawOpen") EXPECT_EQ(v, 0.f) << name;
}

// Names that are no expression and no ARKit shape, prefixes with nothing after them, targets
// named by non-strings, more names than targets: documented results, no crash. A custom
// expression "ARKIT_JAWOPEN" (any case, prefix) claims jawOpen and drives the target it binds,
// so the target named jawOpen is not driven again; targets without a string name are not
// driven; mouthSmileLeft is driven by its target's name.
TEST_F(animated_glb_writer, unknown_and_hostile_face_names_are_ignored) {
  const std::string builtin = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(builtin).ok());
  const parsed_glb g = parse_glb(test::read_text(builtin));
  ASSERT_TRUE(g.error.empty()) << g.error;
  json j = g.j;
  int face = -1;
  for (std::size_t n = 0; n < j["nodes"].size(); ++n)
    if (j["nodes"][n].value("name", "") == "Face") face = static_cast<int>(n);
  ASSERT_GE(face, 0);
  const json bind = {{{"node", face}, {"index", 0}, {"weight", 1.0}}};
  json custom = json::object();
  for (const std::string name :
       {std::string(""), std::string("."), std::string("ARKit_"), std::string("blendShape1."),
        std::string("x.y.z."), std::string("smirk"),
        std::string("\xc3\xbc"
                    "n\xc3\xaf"
                    "c"),
        std::string(10000, 'a')})
    custom[name] = {{"morphTargetBinds", bind}};
  custom["ARKIT_JAWOPEN"] = {
      {"morphTargetBinds", {{{"node", face}, {"index", 24}, {"weight", 0.5}}}}};
  j["extensions"]["VRMC_vrm"]["expressions"] = {{"preset", json::object()}, {"custom", custom}};
  json& names = j["meshes"][j["nodes"][face]["mesh"].get<std::size_t>()]["extras"]["targetNames"];
  ASSERT_EQ(names.size(), 52u);
  names[8] = 42;  // eyeBlinkLeft
  names[9] = nullptr;
  names.push_back("tongueOut");  // a 53rd name for 52 targets
  const std::string avatar = dir.file("hostile_names.glb");
  test::write_text(avatar, test::make_glb(j, g.bin));
  const rig r = rig_of(avatar);
  const std::vector<rig_pose> frames = bending_frames(r, 2);
  std::vector<proxy_pose> faces(2);
  faces[1][blendshape::jaw_open] = 0.5f;
  faces[1][blendshape::eye_blink_left] = 1.f;
  faces[1][blendshape::eye_blink_right] = 1.f;
  faces[1][blendshape::mouth_smile_left] = 0.4f;
  faces[1][expression::blink] = 1.f;
  animated_glb_options o;
  o.expressions = &faces;
  ASSERT_TRUE(write_animated_glb(avatar, r, frames, o, out).ok());
  const parsed_glb w = parse_glb(test::read_text(out));
  ASSERT_TRUE(w.error.empty()) << w.error;
  int channels = 0;
  for (const json& c : w.j["animations"][0]["channels"]) {
    if (c["target"]["path"] != "weights") continue;
    ++channels;
    EXPECT_EQ(c["target"]["node"].get<int>(), face);
    const json& acc =
        w.j["accessors"][w.j["animations"][0]["samplers"][c["sampler"].get<std::size_t>()]["output"]
                             .get<std::size_t>()];
    ASSERT_EQ(acc["count"].get<std::size_t>(), 2u * 52u);
    const std::string bytes = view_bytes(w, acc["bufferView"].get<std::size_t>());
    for (std::size_t t = 0; t < 52; ++t) {
      float v = 0.f;
      std::memcpy(&v, bytes.data() + acc.value("byteOffset", std::size_t{0}) + 4 * (52 + t), 4);
      const float want = t == 24 ? 0.25f : t == 43 ? 0.4f : 0.f;
      EXPECT_FLOAT_EQ(v, want) << "target " << t;
    }
  }
  EXPECT_EQ(channels, 1);
}

TEST_F(animated_glb_writer, keeps_the_mode_of_the_replaced_file_and_follows_no_symlink) {
  const std::string avatar = write_json("a.gltf", test::minimal_vrm1());
  const rig r = rig_of(avatar);
  test::write_text(dir.file("elsewhere.txt"), "not yours");
  // A symbolic link where the writer used to put its fixed temporary name.
  ASSERT_EQ(::symlink(dir.file("elsewhere.txt").c_str(), (out + ".tmp").c_str()), 0);
  test::write_text(out, "old");
  ASSERT_EQ(::chmod(out.c_str(), 0600), 0);
  ASSERT_TRUE(write_animated_glb(avatar, r, bending_frames(r, 3), {}, out).ok());
  EXPECT_EQ(test::read_text(dir.file("elsewhere.txt")), "not yours");
  EXPECT_EQ(parse_glb(test::read_text(out)).error, "");
  struct stat st {};
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  // A missing folder: an error naming it; nothing created.
  status s = write_animated_glb(avatar, r, bending_frames(r, 3), {}, dir.file("no/such/o.glb"));
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "no/such")) << s.message();
}

TEST_F(animated_glb_writer, shared_avatars_round_trip_with_their_textures) {
  for (const char* name : {"vrm1_debug_robot.vrm", "vrm0_sphere.vrm", "gltf_cesium_man.glb"}) {
    const std::string path = test::test_data_path(std::string("avatars/") + name);
    if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
    const rig r = rig_of(path);
    const int hips =
        r.declared_humanoid[idx(bone::hips)] >= 0 ? r.declared_humanoid[idx(bone::hips)] : 0;
    std::vector<rig_pose> frames(3);
    for (std::size_t f = 0; f < frames.size(); ++f) {
      frames[f].local_rotations.resize(static_cast<std::size_t>(r.joint_count()));
      for (int k = 0; k < r.joint_count(); ++k)
        frames[f].local_rotations[k] =
            glm::angleAxis(0.05f * float(f), glm::vec3(0, 1, 0)) * r.rest_local[k].rotation;
      frames[f].hips_joint = hips;
      frames[f].hips_translation = r.rest_local[hips].translation;
    }
    status s = write_animated_glb(path, r, frames, {}, out);
    ASSERT_TRUE(s.ok()) << name << ": " << s.message();
    const parsed_glb in = parse_glb(test::read_text(path));
    const parsed_glb g = parse_glb(test::read_text(out));
    ASSERT_EQ(in.error, "") << name;
    ASSERT_EQ(g.error, "") << name;
    const json images_in = in.j.value("images", json::array());
    const json images_out = g.j.value("images", json::array());
    ASSERT_EQ(images_out.size(), images_in.size()) << name;
    for (std::size_t i = 0; i < images_out.size(); ++i) {
      if (images_in[i].contains("uri"))  // CesiumMan.jpg is not in the folder: kept as named
        EXPECT_EQ(images_out[i].value("uri", ""), images_in[i]["uri"]) << name;
      else
        EXPECT_EQ(view_bytes(g, images_out[i]["bufferView"]),
                  view_bytes(in, images_in[i]["bufferView"]))
            << name << " image " << i;
    }
    EXPECT_EQ(g.j["animations"].size(), in.j.value("animations", json::array()).size() + 1);
    EXPECT_EQ(rig_of(out).joint_count(), r.joint_count()) << name;
  }
}

TEST(rig_bvh_non_finite, a_rig_with_a_zero_scale_writes_no_nan) {
  test::temp_dir dir("glb");
  const std::string avatar = dir.file("a.gltf");
  test::write_text(avatar, test::minimal_vrm1().dump());
  rig r = rig_of(avatar);
  // A rig that skipped build_rig's checks (a hand-made one).
  r.rest_local[r.find("hips")].scale = glm::vec3(0.f, 1.f, 1.f);
  std::vector<rig_pose> frames = bending_frames(r, 3);
  const std::string out = dir.file("o.bvh");
  status s = write_rig_bvh(out, r, frames, {});
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'hips'")) << s.message();
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace avatarmap
