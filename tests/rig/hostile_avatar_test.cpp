// Hostile avatars (issue 8): files built to crash the loader, to make it read files outside
// the avatar's folder, or to slip a wrong rig through. Each must give an error naming the
// file and what is wrong, never a crash; the legitimate neighbours of each case still load.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/rig.hpp"
#include "rig/gltf_document.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using nlohmann::json;
using test::contains;
using test::u32_at;

// Words of the libraries we use, which must not reach a user.
void expect_our_words(const std::string& message) {
  for (const char* foreign : {"json.exception", "tinygltf failed", "Invalid glTF binary",
                              "Invalid magic", "File not found :", "\x01"})
    EXPECT_FALSE(contains(message, foreign)) << message;
}

status load_bytes(const test::temp_dir& dir, const std::string& name, const std::string& bytes,
                  raw_rig& raw) {
  test::write_text(dir.file(name), bytes);
  return load_avatar(dir.file(name), raw);
}

// Loads and builds; the message of the first failure, or "" when both succeed.
std::string load_and_build(const std::string& path) {
  raw_rig raw;
  status s = load_avatar(path, raw);
  if (!s) return s.message();
  rig r;
  s = build_rig(raw, r);
  return s ? std::string() : s.message();
}

// ---- deep nesting --------------------------------------------------------------------------

TEST(hostile_avatar, deep_extras_in_text_gltf_is_an_error_not_a_crash) {
  test::temp_dir dir("hostile");
  json j = test::minimal_vrm1();
  j["nodes"][1]["extras"] = "@RAW@";
  raw_rig raw;
  status s =
      load_bytes(dir, "deep.gltf", test::dump_with_raw(j, test::deep_json_array(20000)), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), dir.file("deep.gltf"))) << s.message();
  EXPECT_TRUE(contains(s.message(), "deeper than 128 levels")) << s.message();
  EXPECT_TRUE(raw.nodes.empty());
  // Deep but within the limit (nodes > node > extras: 3 levels used) still loads.
  s = load_bytes(dir, "ok.gltf", test::dump_with_raw(j, test::deep_json_array(100)), raw);
  EXPECT_TRUE(s.ok()) << s.message();
}

TEST(hostile_avatar, deep_vrmc_vrm_extension_in_glb_is_an_error_not_a_crash) {
  test::temp_dir dir("hostile");
  json j = test::minimal_vrm1();
  j["extensions"]["VRMC_vrm"]["meta"] = "@RAW@";
  const std::string deep = "{\"a\":" + test::deep_json_array(20000) + "}";
  raw_rig raw;
  test::glb_parts parts;
  parts.json = test::dump_with_raw(j, deep);
  status s = load_bytes(dir, "deep.vrm", test::make_glb(parts), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), dir.file("deep.vrm"))) << s.message();
  EXPECT_TRUE(contains(s.message(), "deeper than")) << s.message();
  // Root-level extras, objects instead of arrays.
  std::string objects;
  for (int i = 0; i < 20000; ++i) objects += "{\"a\":";
  objects += "1" + std::string(20000, '}');
  j = test::minimal_vrm1();
  j["extras"] = "@RAW@";
  s = load_bytes(dir, "deep_objects.gltf", test::dump_with_raw(j, objects), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "deeper than")) << s.message();
}

// ---- the GLB container ---------------------------------------------------------------------

TEST(hostile_avatar, glb_container_is_checked_in_our_words) {
  test::temp_dir dir("hostile");
  const json j = test::minimal_vrm1();
  raw_rig raw;
  test::glb_parts good;
  good.json = j.dump();
  good.bin = std::string(8, '\x7f');
  ASSERT_TRUE(load_bytes(dir, "good.vrm", test::make_glb(good), raw).ok());

  struct bad_case {
    const char* name;
    std::string bytes;
    const char* words;
  };
  auto with = [&](auto change) {
    test::glb_parts p = good;
    change(p);
    return test::make_glb(p);
  };
  const std::string full = test::make_glb(good);
  const bad_case cases[] = {
      {"short.vrm", "glTF\x02\0\0", "truncated"},
      {"version1.vrm", with([](test::glb_parts& p) { p.version = 1; }), "version 1"},
      {"longer.vrm", with([](test::glb_parts& p) { p.total_length = 1 << 20; }), "truncated"},
      {"cut.vrm", full.substr(0, full.size() - 4), "truncated"},
      {"trailing.vrm", full + std::string(8, '\0'), "damaged"},
      {"json_len.vrm", with([](test::glb_parts& p) { p.json_length = 0x7FFFFFF0; }),
       "JSON chunk declares"},
      {"json_type.vrm", with([](test::glb_parts& p) { p.json_type = 0x004E4942; }), "first chunk"},
      {"bin_len.vrm", with([](test::glb_parts& p) { p.bin_length = 0xFFFFFFF0; }),
       "BIN chunk declares"},
      // tinygltf alone reads 8 bytes past the end here (it forgets the chunk header).
      {"bin_len_by_8.vrm", with([](test::glb_parts& p) { p.bin_length = 16; }),
       "BIN chunk declares"},
      {"bin_odd.vrm", with([](test::glb_parts& p) {
         p.bin_length = 6;
         p.bin_type = 0x004E4942;
       }),
       "multiple of 4"},
      {"bin_type.vrm", with([](test::glb_parts& p) { p.bin_type = 0x12345678; }), "not BIN"},
      {"empty_json.vrm", with([](test::glb_parts& p) {
         p.json.clear();
         p.json_length = 0;
       }),
       "JSON"},
  };
  for (const bad_case& c : cases) {
    status s = load_bytes(dir, c.name, c.bytes, raw);
    ASSERT_FALSE(s.ok()) << c.name;
    EXPECT_TRUE(contains(s.message(), dir.file(c.name))) << s.message();
    EXPECT_TRUE(contains(s.message(), c.words)) << c.name << ": " << s.message();
    expect_our_words(s.message());
    EXPECT_TRUE(raw.nodes.empty());
  }
}

TEST(hostile_avatar, malformed_json_and_bad_numbers_are_reported_in_our_words) {
  test::temp_dir dir("hostile");
  raw_rig raw;
  status s = load_bytes(dir, "bad.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "malformed at byte")) << s.message();
  expect_our_words(s.message());
  s = load_bytes(dir, "huge.gltf",
                 R"({"asset": {"version": "2.0"}, "nodes": [{"scale": [1e400, 1, 1]}]})", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "too large")) << s.message();
  expect_our_words(s.message());
  s = load_bytes(dir, "noasset.gltf", R"({"nodes": []})", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "asset.version")) << s.message();
  // A schema error tinygltf finds (an accessor without componentType) keeps its detail but
  // not its voice.
  s = load_bytes(dir, "schema.gltf",
                 R"({"asset": {"version": "2.0"}, "accessors": [{"count": 1, "type": "SCALAR"}]})",
                 raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "not valid glTF 2.0")) << s.message();
  EXPECT_TRUE(contains(s.message(), "componentType")) << s.message();
  expect_our_words(s.message());
}

// ---- URIs ----------------------------------------------------------------------------------

// <dir>/secret.txt beside <dir>/avatar/, where the avatar lives.
struct uri_fixture {
  test::temp_dir dir{"hostile_uri"};
  std::string secret_path;
  std::string folder;
  const std::string secret = "TOP-SECRET-0123456789";
  uri_fixture() {
    folder = dir.file("avatar");
    std::filesystem::create_directories(folder + "/sub");
    secret_path = dir.file("secret.txt");
    test::write_text(secret_path, secret);
  }
  // An avatar whose buffer 0 (byteLength = the secret's length) has `uri`.
  std::string write_buffer_avatar(const std::string& name, const std::string& uri) const {
    json j = test::minimal_vrm1();
    j["buffers"] = json::array({{{"uri", uri}, {"byteLength", secret.size()}}});
    const std::string path = folder + "/" + name;
    test::write_text(path, j.dump());
    return path;
  }
  std::string write_image_avatar(const std::string& name, const std::string& uri) const {
    json j = test::minimal_vrm1();
    j["images"] = json::array({{{"uri", uri}}});
    const std::string path = folder + "/" + name;
    test::write_text(path, j.dump());
    return path;
  }
};

TEST(hostile_avatar, uris_leaving_the_folder_are_refused) {
  uri_fixture f;
  ASSERT_EQ(::symlink(f.secret_path.c_str(), (f.folder + "/link.bin").c_str()), 0);
  ASSERT_EQ(::symlink(f.dir.path().c_str(), (f.folder + "/up").c_str()), 0);
  struct bad_case {
    std::string uri;
    const char* words;
  };
  const bad_case cases[] = {
      {"../secret.txt", "leaves the avatar's folder"},
      {"sub/../../secret.txt", "leaves the avatar's folder"},
      {"%2e%2e/secret.txt", "leaves the avatar's folder"},
      {"..%2Fsecret.txt", "leaves the avatar's folder"},
      {f.secret_path, "absolute path"},
      {"%2F" + f.secret_path.substr(1), "absolute path"},
      {"file://" + f.secret_path, "scheme (file:)"},
      {"FILE:" + f.secret_path, "scheme (FILE:)"},
      {"http://example.com/x.bin", "scheme (http:)"},
      {"link.bin", "symbolic link"},
      {"up/secret.txt", "symbolic link"},
      {"a%00b.bin", "NUL"},
      {"a%zzb.bin", "%-escape"},
  };
  int n = 0;
  for (const bad_case& c : cases) {
    for (bool image : {false, true}) {
      const std::string name = "a" + std::to_string(n++) + ".gltf";
      const std::string path =
          image ? f.write_image_avatar(name, c.uri) : f.write_buffer_avatar(name, c.uri);
      const std::string message = load_and_build(path);
      ASSERT_FALSE(message.empty()) << c.uri;
      EXPECT_TRUE(contains(message, path)) << message;
      EXPECT_TRUE(contains(message, image ? "images[0].uri" : "buffers[0].uri")) << message;
      EXPECT_TRUE(contains(message, c.words)) << c.uri << ": " << message;
      EXPECT_FALSE(contains(message, f.secret)) << message;
      expect_our_words(message);
    }
  }
}

TEST(hostile_avatar, files_inside_the_folder_still_load) {
  uri_fixture f;
  test::write_text(f.folder + "/sub/data.bin", f.secret);
  test::write_text(f.folder + "/my file+1.bin", f.secret);
  ASSERT_EQ(::symlink("sub/data.bin", (f.folder + "/inner_link.bin").c_str()), 0);
  for (const char* uri : {"sub/data.bin", "./sub/data.bin", "sub/../sub/data.bin", "sub%2Fdata.bin",
                          "inner_link.bin", "my%20file+1.bin"}) {
    const std::string path = f.write_buffer_avatar("ok.gltf", uri);
    // tinygltf decodes '+' as a space: the file named with '+' is then not found, an error in
    // our words; every other form loads.
    const std::string message = load_and_build(path);
    if (std::string(uri) == "my%20file+1.bin") {
      if (!message.empty()) EXPECT_TRUE(contains(message, "no such file")) << message;
      continue;
    }
    EXPECT_EQ(message, "") << uri;
  }
  // A data: URI buffer.
  EXPECT_EQ(load_and_build(f.write_buffer_avatar(
                "data.gltf", "data:application/octet-stream;base64,VE9QLVNFQ1JFVC0wMTIzNDU2Nzg5")),
            "");
  // A buffer's data: URI of another media type (tinygltf would look for it as a file).
  std::string m = load_and_build(f.write_buffer_avatar("text.gltf", "data:text/x;base64,AAAA"));
  EXPECT_TRUE(contains(m, "application/octet-stream")) << m;
  expect_our_words(m);
  // A missing image is no reason to refuse the skeleton; a missing buffer is.
  EXPECT_EQ(load_and_build(f.write_image_avatar("img.gltf", "missing.png")), "");
  const std::string message = load_and_build(f.write_buffer_avatar("buf.gltf", "missing.bin"));
  EXPECT_TRUE(contains(message, "missing.bin") && contains(message, "no such file")) << message;
}

TEST(hostile_avatar, the_current_directory_is_not_searched) {
  // tinygltf looks for a URI in the current directory when the avatar's folder lacks it.
  uri_fixture f;
  const std::string cwd = std::filesystem::current_path().string();
  std::filesystem::current_path(f.dir.path());  // secret.txt is now ./secret.txt
  const std::string message = load_and_build(f.write_buffer_avatar("cwd.gltf", "secret.txt"));
  std::filesystem::current_path(cwd);
  EXPECT_TRUE(contains(message, "no such file")) << message;
}

TEST(hostile_avatar, data_uris_and_files_are_bounded) {
  uri_fixture f;
  gltf_detail::gltf_limits limits;
  limits.max_data_uri_bytes = 64;
  gltf_detail::gltf_document doc;
  const std::string big = "data:application/octet-stream;base64," + std::string(100, 'A');
  json j = test::minimal_vrm1();
  j["buffers"] = json::array({{{"uri", big}, {"byteLength", 75}}});
  test::write_text(f.folder + "/big.gltf", j.dump());
  status s = gltf_detail::open_gltf_document(f.folder + "/big.gltf", doc, limits);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "data: URI") && contains(s.message(), "limit")) << s.message();
  // The file itself.
  limits = {};
  limits.max_file_bytes = 100;
  s = gltf_detail::open_gltf_document(f.folder + "/big.gltf", doc, limits);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "more than the limit of 100 bytes")) << s.message();
  // An external file over the per-file limit, read by tinygltf through our resolver.
  test::write_text(f.folder + "/sub/big.bin", std::string(4096, 'x'));
  j = test::minimal_vrm1();
  j["buffers"] = json::array({{{"uri", "sub/big.bin"}, {"byteLength", 4096}}});
  test::write_text(f.folder + "/ext.gltf", j.dump());
  limits = {};
  limits.max_resource_bytes = 1000;
  ASSERT_TRUE(gltf_detail::open_gltf_document(f.folder + "/ext.gltf", doc, limits).ok());
  tinygltf::Model model;
  s = gltf_detail::parse_gltf_model(doc, model);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "big.bin") && contains(s.message(), "limit")) << s.message();
  // Not a regular file: a folder named as the avatar, a FIFO (no writer: must not block).
  raw_rig raw;
  s = load_avatar(f.folder, raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "not a regular file")) << s.message();
  ASSERT_EQ(::mkfifo((f.folder + "/fifo.vrm").c_str(), 0600), 0);
  s = load_avatar(f.folder + "/fifo.vrm", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "not a regular file")) << s.message();
}

// ---- indices and transforms ----------------------------------------------------------------

constexpr std::int64_t k_two_to_40 = std::int64_t{1} << 40;

TEST(hostile_avatar, hips_node_two_to_the_40_is_an_error_not_node_0) {
  test::temp_dir dir("hostile");
  raw_rig raw;
  // VRM 1.0 (text and binary).
  json j = test::minimal_vrm1();
  j["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]["hips"]["node"] = k_two_to_40;
  for (const bool binary : {false, true}) {
    const std::string name = binary ? "big.vrm" : "big.gltf";
    status s = load_bytes(dir, name, binary ? test::make_glb(j) : j.dump(), raw);
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_TRUE(contains(s.message(), "'hips'")) << s.message();
    EXPECT_TRUE(contains(s.message(), "1099511627776")) << s.message();
    EXPECT_TRUE(contains(s.message(), "out of range")) << s.message();
    EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], -1);
  }
  // 2^32 (would wrap to 0 in 32 bits as well) and 2^32 + 1 (to 1).
  for (std::int64_t v : {std::int64_t{1} << 32, (std::int64_t{1} << 32) + 1}) {
    j["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]["hips"]["node"] = v;
    status s = load_bytes(dir, "wrap.vrm", test::make_glb(j), raw);
    EXPECT_FALSE(s.ok()) << v;
  }
  // VRM 0.x.
  j = test::minimal_vrm1();
  j["extensions"].erase("VRMC_vrm");
  j["extensions"]["VRM"] = {
      {"humanoid", {{"humanBones", json::array({{{"bone", "hips"}, {"node", k_two_to_40}}})}}}};
  status s = load_bytes(dir, "vrm0.vrm", test::make_glb(j), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "1099511627776") && contains(s.message(), "'hips'"))
      << s.message();
  // VRMA's extension read as an avatar.
  j = test::minimal_vrm1();
  j["extensions"].erase("VRMC_vrm");
  j["extensions"]["VRMC_vrm_animation"] = {
      {"specVersion", "1.0"}, {"humanoid", {{"humanBones", {{"hips", {{"node", k_two_to_40}}}}}}}};
  s = load_bytes(dir, "anim.vrma", test::make_glb(j), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "1099511627776")) << s.message();
}

TEST(hostile_avatar, core_indices_beyond_int_are_refused_with_their_path) {
  test::temp_dir dir("hostile");
  raw_rig raw;
  json j = test::minimal_vrm1();
  j["nodes"][0]["children"] = {k_two_to_40 + 1};  // tinygltf alone reads child 1
  status s = load_bytes(dir, "child.gltf", j.dump(), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "nodes[0].children[0]")) << s.message();
  EXPECT_TRUE(contains(s.message(), "1099511627777")) << s.message();
  j = test::minimal_vrm1();
  j["scenes"][0]["nodes"] = {-k_two_to_40};
  s = load_bytes(dir, "scene.gltf", j.dump(), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "scenes[0].nodes[0]")) << s.message();
  // Big numbers in extras are nobody's index: allowed.
  j = test::minimal_vrm1();
  j["nodes"][0]["extras"] = {{"timestamp", k_two_to_40}};
  s = load_bytes(dir, "extras.gltf", j.dump(), raw);
  EXPECT_TRUE(s.ok()) << s.message();
}

TEST(hostile_avatar, buffer_views_outside_their_buffer_are_refused) {
  test::temp_dir dir("hostile");
  raw_rig raw;
  json j = test::minimal_vrm1();
  j["buffers"] = json::array({{{"byteLength", 8}}});
  j["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 4}, {"byteLength", 4}}});
  j["images"] = json::array({{{"bufferView", 0}, {"mimeType", "image/png"}}});
  ASSERT_TRUE(load_bytes(dir, "ok.vrm", test::make_glb(j, std::string(8, 'x')), raw).ok());
  // An image's bytes at offset 2^31 - 1 of an 8-byte buffer (tinygltf takes their address).
  j["bufferViews"][0]["byteOffset"] = 2147483647;
  status s = load_bytes(dir, "offset.vrm", test::make_glb(j, std::string(8, 'x')), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "bufferViews[0]") && contains(s.message(), "outside"))
      << s.message();
  j["bufferViews"][0]["byteOffset"] = 0;
  j["bufferViews"][0]["buffer"] = 3;
  s = load_bytes(dir, "buffer.vrm", test::make_glb(j, std::string(8, 'x')), raw);
  EXPECT_TRUE(!s.ok() && contains(s.message(), "names no buffer")) << s.message();
  j["bufferViews"][0]["buffer"] = 0;
  j["images"][0]["bufferView"] = 1;
  s = load_bytes(dir, "view.vrm", test::make_glb(j, std::string(8, 'x')), raw);
  EXPECT_TRUE(!s.ok() && contains(s.message(), "images[0].bufferView")) << s.message();
}

TEST(hostile_avatar, zero_scale_and_singular_matrices_are_refused_naming_the_node) {
  test::temp_dir dir("hostile");
  auto message_for = [&](const std::string& name, const json& j) {
    test::write_text(dir.file(name), j.dump());
    return load_and_build(dir.file(name));
  };
  json j = test::minimal_vrm1();
  j["nodes"][1]["scale"] = {0.0, 1.0, 1.0};
  std::string m = message_for("zero.gltf", j);
  EXPECT_TRUE(contains(m, "'hips'") && contains(m, "zero")) << m;
  EXPECT_TRUE(contains(m, dir.file("zero.gltf"))) << m;
  j["nodes"][1]["scale"] = {1.0, 1e-9, 1.0};
  m = message_for("tiny.gltf", j);
  EXPECT_TRUE(contains(m, "'hips'") && contains(m, "near-zero")) << m;
  j["nodes"][1]["scale"] = {0.01, 0.01, 0.01};  // a centimetre rig: fine
  EXPECT_EQ(message_for("cm.gltf", j), "");
  j["nodes"][1]["scale"] = {-1.0, 1.0, 1.0};  // a mirror: fine
  EXPECT_EQ(message_for("mirror.gltf", j), "");

  j = test::minimal_vrm1();
  j["nodes"][2].erase("translation");
  j["nodes"][2]["matrix"] = {1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // x = y
  m = message_for("singular.gltf", j);
  EXPECT_TRUE(contains(m, "'spine'") && contains(m, "singular")) << m;
  j["nodes"][2]["matrix"] = {0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // zero column
  m = message_for("zero_column.gltf", j);
  EXPECT_TRUE(contains(m, "'spine'") && contains(m, "zero")) << m;
  j["nodes"][2]["matrix"] = {1e38, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  j["nodes"][1]["scale"] = {1e38, 1.0, 1.0};  // the product overflows float
  m = message_for("overflow.gltf", j);
  EXPECT_TRUE(contains(m, "'spine'") && contains(m, "non-finite")) << m;
}

TEST(hostile_avatar, build_rig_refuses_an_out_of_range_declared_bone) {
  raw_rig raw;
  raw.nodes.resize(2);
  raw.nodes[0].name = "a";
  raw.nodes[1].name = "b";
  raw.nodes[1].parent = 0;
  raw.declared_humanoid[idx(bone::hips)] = 5;
  rig r;
  status s = build_rig(raw, r);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'hips'") && contains(s.message(), "5")) << s.message();
  raw.declared_humanoid[idx(bone::hips)] = 1;
  EXPECT_TRUE(build_rig(raw, r).ok());
  EXPECT_EQ(r.declared_humanoid[idx(bone::hips)], 1);
}

TEST(hostile_avatar, shared_avatars_still_load) {
  for (const char* name :
       {"vrm0_sphere.vrm", "vrm1_debug_robot.vrm", "vrm1_spec_53bones.vrm",
        "vrm1_spec_expressions.vrm", "gltf_cesium_man.glb", "gltf_rigged_figure.glb",
        "gltf_rigged_simple.glb", "clip_idle_loop.vrma"}) {
    const std::string path = test::test_data_path(std::string("avatars/") + name);
    if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
    EXPECT_EQ(load_and_build(path), "") << name;
  }
}

}  // namespace
}  // namespace avatarmap
