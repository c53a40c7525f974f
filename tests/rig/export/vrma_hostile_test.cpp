// Hostile .vrma files (issue 8): read_vrma goes through the guarded glTF loader. A valid clip
// written by write_vrma is taken apart and broken one way at a time: deep JSON, huge node
// indices in the extension and in the animation, a URI leaving the folder, a lying GLB header.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "avatarmap/export/vrma.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using nlohmann::json;
using test::contains;
using test::u32_at;

class vrma_hostile : public ::testing::Test {
 protected:
  test::temp_dir dir{"vrma_hostile"};
  json doc;
  std::string bin;

  void SetUp() override {
    std::vector<proxy_pose> frames(4);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      frames[i].set_rest();
      frames[i].t = 0.1 * double(i);
      frames[i][bone::spine] = glm::angleAxis(0.1f * float(i), glm::vec3(1, 0, 0));
    }
    const std::string path = dir.file("good.vrma");
    ASSERT_TRUE(write_vrma(path, frames).ok());
    const std::string glb = test::read_text(path);
    const std::uint32_t jl = u32_at(glb, 12);
    doc = json::parse(glb.substr(20, jl));
    bin = glb.substr(20 + jl + 8);
    vrma_clip clip;
    status s = read_vrma(path, clip);  // the unbroken file reads
    ASSERT_TRUE(s.ok()) << s.message();
  }

  // Writes `bytes` as NAME and reads it: the message ("" when it reads).
  std::string read(const std::string& name, const std::string& bytes) {
    test::write_text(dir.file(name), bytes);
    vrma_clip clip;
    status s = read_vrma(dir.file(name), clip);
    if (s) return "";
    EXPECT_TRUE(contains(s.message(), dir.file(name))) << s.message();
    EXPECT_TRUE(clip.frames.empty());
    return s.message();
  }
};

TEST_F(vrma_hostile, hips_node_two_to_the_40_is_an_error_not_node_0) {
  json j = doc;
  j["extensions"]["VRMC_vrm_animation"]["humanoid"]["humanBones"]["hips"]["node"] = std::int64_t{1}
                                                                                    << 40;
  const std::string m = read("hips.vrma", test::make_glb(j, bin));
  EXPECT_TRUE(contains(m, "humanoid.humanBones.hips")) << m;
  EXPECT_TRUE(contains(m, "valid node")) << m;
  // The same for an expression's node.
  j = doc;
  j["extensions"]["VRMC_vrm_animation"]["expressions"]["preset"]["happy"]["node"] =
      (std::int64_t{1} << 32) + 1;
  EXPECT_TRUE(contains(read("expr.vrma", test::make_glb(j, bin)), "expressions.preset.happy"));
}

TEST_F(vrma_hostile, animation_indices_beyond_int_are_refused) {
  json j = doc;
  j["animations"][0]["channels"][0]["target"]["node"] = (std::int64_t{1} << 40) + 1;
  std::string m = read("target.vrma", test::make_glb(j, bin));
  EXPECT_TRUE(contains(m, "animations[0].channels[0].target.node")) << m;
  j = doc;
  j["accessors"][0]["bufferView"] = std::int64_t{1} << 33;
  m = read("view.vrma", test::make_glb(j, bin));
  EXPECT_TRUE(contains(m, "accessors[0].bufferView")) << m;
}

TEST_F(vrma_hostile, deep_json_is_an_error_not_a_crash) {
  json j = doc;
  j["extensions"]["VRMC_vrm_animation"]["extras"] = "@RAW@";
  test::glb_parts p;
  p.json = test::dump_with_raw(j, test::deep_json_array(20000));
  p.bin = bin;
  EXPECT_TRUE(contains(read("deep.vrma", test::make_glb(p)), "deeper than 128 levels"));
  j = doc;
  j["animations"][0]["extras"] = "@RAW@";
  EXPECT_TRUE(contains(read("deep.gltf", test::dump_with_raw(j, test::deep_json_array(5000))),
                       "deeper than"));
}

TEST_F(vrma_hostile, external_buffers_stay_in_the_folder) {
  test::write_text(dir.file("outside.bin"), bin);
  test::write_text(dir.file("inside.bin"), bin);
  json j = doc;
  j["buffers"][0]["uri"] = "../" + dir.path().filename().string() + "/outside.bin";
  // ../<this folder>/outside.bin leaves the folder by name, even if it comes back.
  EXPECT_TRUE(contains(read("escape.gltf", j.dump()), "leaves the avatar's folder"));
  j["buffers"][0]["uri"] = "inside.bin";
  EXPECT_EQ(read("inside.gltf", j.dump()), "");
}

TEST_F(vrma_hostile, lying_glb_headers_are_reported_in_our_words) {
  test::glb_parts p;
  p.json = doc.dump();
  p.bin = bin;
  p.bin_length = static_cast<std::int64_t>(bin.size() + 8);
  std::string m = read("bin.vrma", test::make_glb(p));
  EXPECT_TRUE(contains(m, "BIN chunk declares")) << m;
  p = test::glb_parts{};
  p.json = doc.dump();
  p.bin = bin;
  p.total_length = 12;
  m = read("total.vrma", test::make_glb(p));
  EXPECT_TRUE(contains(m, "the GLB header declares 12 bytes")) << m;
  EXPECT_FALSE(contains(m, "Invalid")) << m;
}

}  // namespace
}  // namespace avatarmap
