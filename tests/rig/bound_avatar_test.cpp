// Loading, building and binding an avatar in one call (include/avatarmap/rig/bound_avatar.hpp):
// against the steps it stands for (load_avatar, build_rig, select_binding), the overrides'
// rules (a joint drives one bone; "none" unbinds; overrides alone bind a rig no table fits),
// and each failing step with its code and the step named.
#include "avatarmap/rig/bound_avatar.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

std::string source_dir() {
  const char* d = std::getenv("AVATARMAP_SOURCE_DIR");
  if (d && *d) return d;
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string();
}

int count_bound(const bone_binding& b) {
  int n = 0;
  for (int j : b) n += j >= 0;
  return n;
}

// A plain glTF (no VRM humanoid) whose joint names no shipped table knows.
std::string write_unknown_rig(const test::temp_dir& dir) {
  nlohmann::json j;
  j["asset"] = {{"version", "2.0"}};
  j["nodes"] = nlohmann::json::array(
      {{{"name", "Pelvis"}, {"children", {1}}, {"translation", {0.0, 1.0, 0.0}}},
       {{"name", "Spine0"}, {"translation", {0.0, 0.2, 0.0}}}});
  j["scenes"] = nlohmann::json::array({{{"nodes", {0}}}});
  j["scene"] = 0;
  const std::string path = dir.file("figure.gltf");
  test::write_text(path, j.dump());
  return path;
}

bind_avatar_options with_shipped_tables() {
  bind_avatar_options o;
  o.mappings_folder = source_dir() + "/mappings";
  return o;
}

TEST(bound_avatar, a_vrm_is_bound_by_its_declared_humanoid_as_the_steps_would_bind_it) {
  test::temp_dir dir("bound_avatar");
  const std::string path = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(path).ok());
  bound_avatar b;
  const status st = bind_avatar(path, with_shipped_tables(), b);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(b.failed_step, bind_avatar_step::none);
  // The reference: the three steps by hand.
  raw_rig raw;
  ASSERT_TRUE(load_avatar(path, raw).ok());
  rig r;
  ASSERT_TRUE(build_rig(raw, r).ok());
  rig_binding_choice choice;
  ASSERT_TRUE(select_binding(r, "auto", "", choice).ok());
  EXPECT_EQ(b.rig.names, r.names);
  EXPECT_EQ(b.binding, choice.binding);
  EXPECT_EQ(b.binding, r.declared_humanoid);
  EXPECT_EQ(b.bound, count_bound(r.declared_humanoid));
  EXPECT_EQ(b.description, choice.description);
  EXPECT_NE(b.description.find("VRM 1.0 humanoid declared by the file"), std::string::npos);
  EXPECT_EQ(b.table(), nullptr);
  EXPECT_EQ(b.path, path);
}

TEST(bound_avatar, overrides_rebind_take_joints_from_other_bones_and_unbind) {
  test::temp_dir dir("bound_avatar");
  const std::string path = dir.file("avatar.vrm");
  test::write_text(path, test::make_glb(test::minimal_vrm1()));  // root > hips > spine
  bind_avatar_options o;
  for (const char* text : {"chest=spine", "hips=none"}) {
    bone_override ov;
    ASSERT_TRUE(parse_bone_override(text, ov).ok()) << text;
    o.overrides.push_back(ov);
  }
  o.overrides_name = "--bind";
  bound_avatar b;
  const status st = bind_avatar(path, o, b);
  ASSERT_TRUE(st.ok()) << st.message();
  const int spine = b.rig.find("spine");
  ASSERT_GE(spine, 0);
  EXPECT_EQ(b.binding[idx(bone::chest)], spine);
  EXPECT_EQ(b.binding[idx(bone::spine)], -1);  // its joint went to chest
  EXPECT_EQ(b.binding[idx(bone::hips)], -1);   // "none"
  EXPECT_EQ(b.bound, 1);
  EXPECT_EQ(b.description,
            "VRM 1.0 humanoid declared by the file (2 bones); 2 binding(s) from --bind");
  // A joint the rig lacks: the override step fails, naming the file, override and joint.
  bone_override nope;
  ASSERT_TRUE(parse_bone_override("hips=nope", nope).ok());
  o.overrides = {nope};
  const status bad = bind_avatar(path, o, b);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.code(), status_code::invalid_argument);
  EXPECT_EQ(b.failed_step, bind_avatar_step::overrides);
  EXPECT_NE(bad.message().find(path + ": --bind hips=nope: the avatar has no joint 'nope'"),
            std::string::npos)
      << bad.message();
}

TEST(bound_avatar, a_rig_no_table_fits_fails_at_the_binding_unless_overrides_bind_it) {
  test::temp_dir dir("bound_avatar");
  const std::string path = write_unknown_rig(dir);
  bound_avatar b;
  status st = bind_avatar(path, with_shipped_tables(), b);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::parse);
  EXPECT_EQ(b.failed_step, bind_avatar_step::select);
  EXPECT_NE(st.message().find("no mapping table fits"), std::string::npos) << st.message();
  EXPECT_EQ(b.rig.joint_count(), 2);  // built before the binding failed (what inspect lists)
  EXPECT_EQ(b.mappings_folder, source_dir() + "/mappings");

  bind_avatar_options o = with_shipped_tables();
  bone_override ov;
  ASSERT_TRUE(parse_bone_override("hips=Pelvis", ov).ok());
  o.overrides = {ov};
  st = bind_avatar(path, o, b);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(b.binding[idx(bone::hips)], b.rig.find("Pelvis"));
  EXPECT_EQ(b.bound, 1);
  EXPECT_EQ(b.description, "bound by overrides only (no table fits); 1 binding(s) from overrides");
  // Overrides do not rescue a named table that does not exist: the option was a mistake.
  o.rig = "no_such_table";
  st = bind_avatar(path, o, b);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_EQ(b.failed_step, bind_avatar_step::select);
  EXPECT_NE(st.message().find("unknown rig table 'no_such_table'"), std::string::npos);
}

TEST(bound_avatar, a_json_table_of_ones_own_binds_with_its_table) {
  test::temp_dir dir("bound_avatar");
  const std::string path = write_unknown_rig(dir);
  const std::string table = dir.file("figure.json");
  test::write_text(table,
                   R"({"format_version": 1, "name": "figure", "recognize": {"prefixes": [],
                       "required": ["hips"]}, "rest_pose": "t_pose",
                       "bones": {"hips": {"rig": "Pelvis"}, "spine": {"rig": "Spine0"}}})");
  bind_avatar_options o;
  o.rig = table;
  bound_avatar b;
  const status st = bind_avatar(path, o, b);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_NE(b.table(), nullptr);
  EXPECT_EQ(b.table()->name, "figure");
  EXPECT_EQ(b.binding[idx(bone::hips)], b.rig.find("Pelvis"));
  EXPECT_EQ(b.binding[idx(bone::spine)], b.rig.find("Spine0"));
  EXPECT_EQ(b.bound, 2);
  EXPECT_EQ(b.description.rfind("table figure (" + table + "): ", 0), 0u) << b.description;
}

TEST(bound_avatar, each_step_that_fails_says_which_with_its_code) {
  test::temp_dir dir("bound_avatar");
  bound_avatar b;
  status st = bind_avatar(dir.file("missing.vrm"), {}, b);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::io);
  EXPECT_EQ(b.failed_step, bind_avatar_step::load);
  EXPECT_NE(st.message().find("missing.vrm"), std::string::npos);

  const std::string garbage = dir.file("garbage.vrm");
  test::write_text(garbage, "not a model");
  st = bind_avatar(garbage, {}, b);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::parse);
  EXPECT_EQ(b.failed_step, bind_avatar_step::load);
}

TEST(bound_avatar, override_text_is_bone_equals_joint) {
  bone_override o;
  ASSERT_TRUE(parse_bone_override("leftUpperArm=arm_L", o).ok());
  EXPECT_EQ(o.proxy_bone, bone::left_upper_arm);
  EXPECT_EQ(o.joint, "arm_L");
  ASSERT_TRUE(parse_bone_override("hips=a=b", o).ok());  // the first '=' splits
  EXPECT_EQ(o.joint, "a=b");
  for (const char* bad : {"tail=x", "hips", "", "=x", "Hips=x"}) {
    const status st = parse_bone_override(bad, o);
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_EQ(st.code(), status_code::invalid_argument);
    EXPECT_NE(st.message().find("VRM 1.0 bone name"), std::string::npos);
    EXPECT_NE(st.message().find(std::string("'") + bad + "'"), std::string::npos);
  }
}

}  // namespace
}  // namespace avatarmap
