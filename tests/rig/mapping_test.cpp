#include "avatarmap/rig/mapping.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace avatarmap;

namespace {

std::string source_dir() {
  const char* d = std::getenv("AVATARMAP_SOURCE_DIR");
  if (d && *d) return d;
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string();
}

std::vector<mapping_table> shipped() {
  std::vector<mapping_table> t;
  status s = load_mapping_folder(source_dir() + "/mappings", t);
  EXPECT_TRUE(s.ok()) << s.message();
  return t;
}

const mapping_table* by_name(const std::vector<mapping_table>& tables, const std::string& n) {
  for (const auto& t : tables)
    if (t.name == n) return &t;
  return nullptr;
}

// A flat test rig with the given joint names.
rig make_rig(const std::vector<std::string>& names, rig_source source = rig_source::test) {
  raw_rig raw;
  for (const auto& n : names) raw.nodes.push_back({n, -1, {}});
  raw.source = source;
  raw.file = "test-rig";
  rig r;
  status s = build_rig(raw, r);
  EXPECT_TRUE(s.ok()) << s.message();
  return r;
}

// The rig a table describes: every mapped bone's first name, with `prefix`.
rig rig_of(const mapping_table& t, const std::string& prefix = "") {
  std::vector<std::string> names = {"root"};
  for (const auto& b : t.bones)
    if (b.mapped()) names.push_back(prefix + b.rig_names[0]);
  return make_rig(names);
}

status load(const std::string& json, mapping_table& t) {
  return load_mapping_json(json, "test.json", t);
}

std::string error_of(const std::string& json) {
  mapping_table t;
  status s = load(json, t);
  EXPECT_FALSE(s.ok()) << json;
  return s.message();
}

#define EXPECT_CONTAINS(haystack, needle)                          \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "'" << (haystack) << "' lacks '" << (needle) << "'"

const char* k_minimal = R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "Hips"}}})";

}  // namespace

TEST(mapping, every_shipped_table_loads) {
  auto tables = shipped();
  ASSERT_EQ(tables.size(), 8u);
  // CMU's mocap skeleton (a BVH): one finger segment a hand, no thumbs bound.
  ASSERT_NE(by_name(tables, "cmu"), nullptr);
  EXPECT_EQ(by_name(tables, "cmu")->mapped_count(), 24);
  for (const char* n : {"vrm1", "vrm0", "mixamo", "unity_humanoid", "ue4_mannequin",
                        "ue5_mannequin", "character_creator"}) {
    const mapping_table* t = by_name(tables, n);
    ASSERT_NE(t, nullptr) << n;
    EXPECT_GE(t->mapped_count(), 49) << n << ": fingers included";
    EXPECT_FALSE(t->required.empty()) << n;
  }
  EXPECT_EQ(by_name(tables, "vrm1")->mapped_count(), 55);
  EXPECT_EQ(by_name(tables, "vrm0")->mapped_count(), 55);
  EXPECT_EQ(by_name(tables, "vrm0")->humanoid, mapping_humanoid::vrm0);
  // VRM 0.x requires chest and neck too.
  EXPECT_EQ(by_name(tables, "vrm0")->required.size(), by_name(tables, "vrm1")->required.size() + 2);
  EXPECT_EQ(by_name(tables, "ue5_mannequin")->rest_pose, mapping_rest_pose::a_pose);
  const mapping_table* mix = by_name(tables, "mixamo");
  EXPECT_EQ(mix->bones[idx(bone::chest)].rig_names[0], "Spine1");
  EXPECT_EQ(mix->bones[idx(bone::left_thumb_metacarpal)].rig_names[0], "LeftHandThumb1");
  EXPECT_EQ(mix->bones[idx(bone::left_toes)].rig_names[0], "LeftToeBase");
  EXPECT_EQ(by_name(tables, "vrm0")->bones[idx(bone::left_thumb_metacarpal)].rig_names[0],
            "leftThumbProximal");
}

TEST(mapping, every_required_bone_is_in_its_own_bone_list) {
  for (const mapping_table& t : shipped())
    for (int b : t.required)
      EXPECT_TRUE(t.bones[b].mapped()) << t.name << ": " << bone_name(static_cast<bone>(b));
  // And the loader enforces it.
  EXPECT_CONTAINS(
      error_of(R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H"}},
                            "recognize": {"required": ["hips", "head"]}})"),
      "test.json: recognize.required[1]: 'head' is required but \"bones\" does not map it");
}

TEST(mapping, shipped_tables_round_trip_through_json) {
  for (const mapping_table& t : shipped()) {
    mapping_table back;
    status s = load_mapping_json(mapping_to_json(t), t.name, back);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(back.name, t.name);
    EXPECT_EQ(back.required, t.required);
    EXPECT_EQ(back.prefixes, t.prefixes);
    EXPECT_EQ(back.expressions, t.expressions);
    for (int b = 0; b < k_bone_count; ++b) EXPECT_EQ(back.bones[b].rig_names, t.bones[b].rig_names);
  }
}

TEST(mapping, formulas_order_alternatives_and_rest) {
  mapping_table t;
  status s = load(R"({"format_version": 1, "name": "t", "description": "d",
    "rest_pose": "file", "units_scale": 0.01,
    "recognize": {"prefixes": ["a:", "", "abc:"], "patterns": ["a:*"]},
    "bones": {
      "hips": {"rig": "Hips", "order": "ZXY", "f": ["-z", "x", "Math.PI/2 - y"], "rest": [0, 1.5, 0]},
      "spine": {"rig": ["Spine", "Spine01"]},
      "$comment": "ignored"},
    "expressions": {"blink": "Blink", "happy": "Joy", "browUpLeft": "BrowUp_L"}})",
                  t);
  ASSERT_TRUE(s.ok()) << s.message();
  const mapping_bone& h = t.bones[idx(bone::hips)];
  EXPECT_EQ(h.order, euler_order::zxy);
  ASSERT_TRUE(h.has_formulas);
  EXPECT_FLOAT_EQ(h.f[0].eval(1.f, 2.f, 3.f), -3.f);
  EXPECT_FLOAT_EQ(h.f[1].eval(1.f, 2.f, 3.f), 1.f);
  EXPECT_FLOAT_EQ(h.f[2].eval(1.f, 2.f, 3.f), 3.14159265f / 2 - 2.f);
  EXPECT_EQ(h.f_text[2], "Math.PI/2 - y");
  EXPECT_TRUE(h.has_rest);
  EXPECT_FLOAT_EQ(h.rest.y, 1.5f);
  EXPECT_FALSE(t.bones[idx(bone::spine)].has_formulas);
  EXPECT_EQ(t.bones[idx(bone::spine)].rig_names.size(), 2u);
  EXPECT_EQ(t.rest_pose, mapping_rest_pose::file);
  EXPECT_TRUE(t.has_units_scale);
  EXPECT_FLOAT_EQ(t.units_scale, 0.01f);
  EXPECT_EQ(t.prefixes, (std::vector<std::string>{"abc:", "a:"}));  // longest first, "" dropped
  ASSERT_EQ(t.expressions.size(), 3u);
  EXPECT_EQ(t.expressions[2].second, "Joy");  // sorted by VRM name
  EXPECT_EQ(t.file, "test.json");
}

TEST(mapping, errors_name_file_key_and_column) {
  EXPECT_CONTAINS(error_of(R"({"name": "t", "bones": {}})"),
                  "test.json: missing \"format_version\" (this reader reads version 1)");
  EXPECT_CONTAINS(error_of(R"({"format_version": 2, "name": "t", "bones": {}})"),
                  "test.json: format_version: version 2 is newer than this reader (1)");
  EXPECT_CONTAINS(error_of(R"({"format_version": "1", "name": "t", "bones": {}})"),
                  "format_version: expected an integer");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "bones": {}})"), "missing \"name\"");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "name": "t"})"), "missing \"bones\"");
  EXPECT_CONTAINS(
      error_of(R"({"format_version": 1, "name": "t", "bones": {"Hips": {"rig": "H"}}})"),
      "test.json: bones.Hips: unknown VRM 1.0 bone name");
  EXPECT_CONTAINS(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H"}, "spine": {"rig": "H"}}})"),
      "bones.spine: rig name 'H' is already used by hips");
  EXPECT_CONTAINS(
      error_of(R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": ["H", "H"]}}})"),
      "bones.hips: rig name 'H' is listed twice");
  EXPECT_CONTAINS(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H", "order": "XYX"}}})"),
      "bones.hips.order: bad Euler order 'XYX'");
  EXPECT_CONTAINS(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {"leftHand": {"rig": "H", "f": ["x", "y + ", "z"]}}})"),
      "test.json: bones.leftHand.f[1]: column 5: expected a number, a name or '(', found the end "
      "of the formula in 'y + '");
  EXPECT_CONTAINS(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H", "f": ["x", "y"]}}})"),
      "bones.hips.f: expected three formulas");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": ""}}})"),
                  "bones.hips.rig: must not be empty");
  EXPECT_CONTAINS(
      error_of(R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H", "foo": 1}}})"),
      "bones.hips.foo: unknown key");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "name": "t", "bones": {}, "rest_pose": "y"})"),
                  "rest_pose: expected \"t_pose\", \"a_pose\" or \"file\"");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "name": "t", "bones": {}, "units_scale": -1})"),
                  "units_scale: must be a positive finite number");
  EXPECT_CONTAINS(
      error_of(R"({"format_version": 1, "name": "t", "bones": {}, "expressions": {"smile": "S"}})"),
      "expressions.smile: unknown VRM 1.0 expression");
  EXPECT_CONTAINS(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {}, "recognize": {"humanoid": "vrm2"}})"),
      "recognize.humanoid: expected \"vrm0\" or \"vrm1\"");
  EXPECT_CONTAINS(error_of(R"({"format_version": 1, "name": "t", "bones": {}, "extra": 1})"),
                  "test.json: extra: unknown key");
  EXPECT_CONTAINS(error_of("{\"format_version\": 1,"), "test.json: invalid JSON");
  mapping_table t;
  status s = load_mapping(source_dir() + "/mappings/none.json", t);
  EXPECT_CONTAINS(s.message(), "none.json: cannot read the file");
}

// Errors in our words, never nlohmann's ("[json.exception.out_of_range.406] ..."): what is
// wrong, where (line and column, or the key) and what was found.
TEST(mapping, json_errors_are_in_our_words) {
  auto check = [](const std::string& message, const std::string& words) {
    EXPECT_CONTAINS(message, words);
    EXPECT_EQ(message.find("json.exception"), std::string::npos) << message;
    EXPECT_EQ(message.find("[json"), std::string::npos) << message;
  };
  // A number beyond a double (nlohmann's out_of_range.406), on line 2.
  check(error_of("{\"format_version\": 1,\n \"units_scale\": 1e400, \"name\": \"t\"}"),
        "test.json: invalid JSON at line 2, column");
  check(error_of("{\"format_version\": 1, \"units_scale\": -1e400}"),
        "the number -1e400 is too large");
  check(error_of("{\"format_version\": 1, \"name\": \"t\" \"bones\": {}}"),
        "invalid JSON at line 1, column 35: unexpected \"bones\"");
  check(error_of("{\"format_version\": 1,"), "test.json: invalid JSON at line 1");
  check(error_of("{\"format_version\": 1,"), "ends too early");
  check(error_of("{\"name\": \"\\uZZZZ\"}"), "bad \\u escape");
  // Types: what was expected and what was found.
  check(
      error_of(
          R"({"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H", "f": [1, "y", "z"]}}})"),
      "test.json: bones.hips.f[0]: expected a string, got a number");
  check(error_of(R"({"format_version": 1, "name": 7, "bones": {}})"),
        "name: expected a string, got a number");
  check(error_of(R"({"format_version": 1.5, "name": "t", "bones": {}})"),
        "format_version: expected an integer, got a number");
  check(error_of(R"([1, 2])"), "test.json: expected a JSON object (a mapping table), got an array");
  check(error_of(R"({"format_version": 1, "name": "t", "bones": {"hips": "H"}})"),
        "bones.hips: expected an object {\"rig\": ...}, got a string");
  // Nesting beyond the limit is refused before nlohmann builds (and recurses through) a tree.
  check(error_of("{\"x\":" + std::string(5000, '[') + std::string(5000, ']') + "}"),
        "test.json: JSON nests deeper than 128 levels");
  mapping_table t;
  status s = import_sysmocap_binding("{\"Hips\": {\"name\": 1e999}}", t);
  check(s.message(), "SysMocap binding: invalid JSON at line 1");
}

TEST(mapping, match_strips_prefixes_and_falls_back_to_case_insensitive) {
  auto tables = shipped();
  const mapping_table& mix = *by_name(tables, "mixamo");
  for (const std::string prefix : {"mixamorig:", "mixamorig1:", "mixamorig2:", "mixamorig", ""}) {
    mapping_match m;
    const int score = match_score(mix, rig_of(mix, prefix), m);
    EXPECT_GT(score, 0) << prefix;
    EXPECT_EQ(m.matched, mix.mapped_count()) << prefix;
    EXPECT_EQ(m.needed, mix.mapped_count());
    EXPECT_EQ(m.exact, m.matched);
    EXPECT_EQ(m.prefix, prefix);
    EXPECT_TRUE(m.missing.empty());
    EXPECT_TRUE(m.usable());
  }
  // Lower-case names still resolve, but score below exact ones.
  std::vector<std::string> lower = {"mixamorig:hips", "mixamorig:spine", "mixamorig:head"};
  rig exact_rig = rig_of(mix, "mixamorig:");
  mapping_match exact_m;
  const int exact_score = match_score(mix, exact_rig, exact_m);
  std::vector<std::string> names;
  for (const auto& n : exact_rig.names) {
    std::string l = n;
    std::transform(l.begin(), l.end(), l.begin(), [](char c) { return std::tolower(c); });
    names.push_back(l);
  }
  mapping_match folded_m;
  const int folded_score = match_score(mix, make_rig(names), folded_m);
  EXPECT_EQ(folded_m.matched, exact_m.matched);
  EXPECT_EQ(folded_m.folded, folded_m.matched);
  EXPECT_GT(folded_score, 0);
  EXPECT_LT(folded_score, exact_score);
  // Joint indices point at the right names.
  EXPECT_EQ(exact_rig.names[exact_m.joint[idx(bone::left_lower_arm)]], "mixamorig:LeftForeArm");
}

TEST(mapping, missing_required_bones_are_listed) {
  auto tables = shipped();
  const mapping_table& mix = *by_name(tables, "mixamo");
  rig r = make_rig({"mixamorig:Hips", "mixamorig:Spine", "mixamorig:LeftArm", "Cube"});
  mapping_match m;
  EXPECT_EQ(match_score(mix, r, m), 0);
  EXPECT_EQ(m.matched, 3);
  EXPECT_FALSE(m.usable());
  EXPECT_EQ(std::count(m.missing_required.begin(), m.missing_required.end(), idx(bone::head)), 1);
  EXPECT_EQ(std::count(m.missing_required.begin(), m.missing_required.end(), idx(bone::hips)), 0);
  EXPECT_CONTAINS(m.summary(), "matched 3/");
  EXPECT_CONTAINS(m.summary(), "missing required: head");
  int best = 0;
  mapping_match bm;
  status s = auto_detect(tables, r, best, bm);
  EXPECT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "test-rig: no mapping table fits");
  EXPECT_CONTAINS(s.message(), "mixamo: matched 3/");
  EXPECT_EQ(best, -1);
}

TEST(mapping, auto_detect_picks_each_shipped_family) {
  auto tables = shipped();
  for (const char* n :
       {"mixamo", "unity_humanoid", "ue4_mannequin", "ue5_mannequin", "character_creator"}) {
    const mapping_table& t = *by_name(tables, n);
    const std::string prefix = t.prefixes.empty() ? "" : t.prefixes.back();
    int best = -1;
    mapping_match m;
    status s = auto_detect(tables, rig_of(t, prefix), best, m);
    ASSERT_TRUE(s.ok()) << n << ": " << s.message();
    EXPECT_EQ(tables[best].name, n);
    EXPECT_EQ(m.matched, t.mapped_count()) << n;
  }
  // CC_Base_ names need the prefix stripped.
  mapping_match m;
  EXPECT_GT(match_score(*by_name(tables, "character_creator"),
                        rig_of(*by_name(tables, "character_creator"), "CC_Base_"), m),
            0);
}

TEST(mapping, vrm_tables_use_the_declared_humanoid) {
  auto tables = shipped();
  // Node names that no table knows; only the declaration tells the bones.
  raw_rig raw;
  for (int b = 0; b < k_bone_count; ++b) {
    raw.nodes.push_back({"J_Bip_" + std::to_string(b), -1, {}});
    raw.declared_humanoid[b] = b;
  }
  for (rig_source src : {rig_source::vrm1, rig_source::vrm0}) {
    raw.source = src;
    rig r;
    ASSERT_TRUE(build_rig(raw, r).ok());
    int best = -1;
    mapping_match m;
    status s = auto_detect(tables, r, best, m);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(tables[best].name, src == rig_source::vrm1 ? "vrm1" : "vrm0");
    EXPECT_EQ(m.matched, 55);
    EXPECT_EQ(r.names[m.joint[idx(bone::left_hand)]],
              "J_Bip_" + std::to_string(idx(bone::left_hand)));
    // The other VRM version's table does not apply.
    mapping_match other;
    EXPECT_EQ(match_score(*by_name(tables, src == rig_source::vrm1 ? "vrm0" : "vrm1"), r, other),
              0);
  }
}

TEST(mapping, a_joint_serves_one_bone) {
  mapping_table t;
  ASSERT_TRUE(load(R"({"format_version": 1, "name": "t", "bones": {
      "hips": {"rig": "hips"}, "spine": {"rig": "HIPS"}}})",
                   t)
                  .ok());
  mapping_match m;
  match_score(t, make_rig({"hips"}), m);
  EXPECT_EQ(m.joint[idx(bone::hips)], 0);
  EXPECT_EQ(m.joint[idx(bone::spine)], -1);  // exact match first: no stealing by folding
}

TEST(mapping, patterns_break_ties_between_ue4_and_ue5) {
  auto tables = shipped();
  const mapping_table& ue4 = *by_name(tables, "ue4_mannequin");
  const mapping_table& ue5 = *by_name(tables, "ue5_mannequin");
  rig r5 = rig_of(ue5);
  // A UE5 rig also has spine_02 (unmapped by ue5) so the UE4 table resolves as many bones.
  std::vector<std::string> names = r5.names;
  names.push_back("spine_02");
  names.push_back("spine_04");
  names.push_back("neck_02");
  rig full5 = make_rig(names);
  mapping_match m4, m5;
  const int s4 = match_score(ue4, full5, m4), s5 = match_score(ue5, full5, m5);
  EXPECT_EQ(m4.matched, m5.matched);
  EXPECT_GT(s5, s4);
  EXPECT_EQ(m5.patterns_matched, 4);
}

TEST(mapping, sysmocap_binding_import) {
  // The shape of SysMocap's models.json entry (binding keyed by three-vrm 0.x bone names).
  const char* entry = R"({
    "name": "Robot", "type": "fbx", "path": "./models/robot.fbx",
    "init": {"LeftUpperArm": {"x": 0.1, "y": 0.2, "z": -1.5}},
    "binding": {
      "Hips": {"name": "mixamorigHips", "func": {"fx": "-x", "fy": "y", "fz": "-z"}},
      "Chest": {"name": "None"},
      "LeftUpperArm": {"name": "mixamorigLeftArm", "order": "ZXY",
                       "func": {"fx": "z", "fy": "-x", "fz": "-y"}},
      "LeftThumbProximal": {"name": "mixamorigLeftHandThumb1"},
      "rightThumbProximal": {"name": "mixamorigRightHandThumb2"}
    }})";
  mapping_table t;
  status s = import_sysmocap_binding(entry, t);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(t.name, "Robot");
  EXPECT_EQ(t.rest_pose, mapping_rest_pose::file);
  EXPECT_EQ(t.mapped_count(), 4);
  EXPECT_FALSE(t.bones[idx(bone::chest)].mapped());
  const mapping_bone& arm = t.bones[idx(bone::left_upper_arm)];
  EXPECT_EQ(arm.rig_names[0], "mixamorigLeftArm");
  EXPECT_EQ(arm.order, euler_order::zxy);
  EXPECT_FLOAT_EQ(arm.f[1].eval(0.5f, 0.f, 0.f), -0.5f);
  EXPECT_TRUE(arm.has_rest);
  EXPECT_FLOAT_EQ(arm.rest.z, -1.5f);
  EXPECT_EQ(t.bones[idx(bone::hips)].order, euler_order::xyz);  // SysMocap's default
  // PascalCase = VRM 0.x thumb naming; camelCase = VRM 1.0.
  EXPECT_EQ(t.bones[idx(bone::left_thumb_metacarpal)].rig_names[0], "mixamorigLeftHandThumb1");
  EXPECT_EQ(t.bones[idx(bone::right_thumb_proximal)].rig_names[0], "mixamorigRightHandThumb2");
  EXPECT_FALSE(t.bones[idx(bone::left_thumb_metacarpal)].has_formulas);

  // The bare binding object and the models.json array work too.
  mapping_table t2;
  ASSERT_TRUE(import_sysmocap_binding(
                  R"({"Neck": {"name": "Head", "func": {"fx": "-x", "fy": "y", "fz": "-z"}}})", t2)
                  .ok());
  EXPECT_EQ(t2.bones[idx(bone::neck)].rig_names[0], "Head");
  mapping_table t3;
  ASSERT_TRUE(import_sysmocap_binding(
                  std::string("[{\"name\": \"vrm\", \"type\": \"vrm\"}, ") + entry + "]", t3)
                  .ok());
  EXPECT_EQ(t3.name, "Robot");
  // Saved as a mapping file, it loads back.
  mapping_table back;
  status sb = load_mapping_json(mapping_to_json(t), "saved.json", back);
  ASSERT_TRUE(sb.ok()) << sb.message();
  EXPECT_EQ(back.bones[idx(bone::left_upper_arm)].f_text[0], "z");
  EXPECT_FLOAT_EQ(back.bones[idx(bone::left_upper_arm)].rest.x, 0.1f);
  // Matching by the full names SysMocap stores.
  mapping_match m;
  EXPECT_GT(match_score(t, make_rig({"mixamorigHips", "mixamorigLeftArm"}), m), 0);
  EXPECT_EQ(m.matched, 2);
}

TEST(mapping, sysmocap_binding_errors) {
  mapping_table t;
  status s = import_sysmocap_binding(R"({"Tail": {"name": "T"}})", t);
  EXPECT_CONTAINS(s.message(), "SysMocap binding: binding.Tail: unknown bone name");
  s = import_sysmocap_binding(R"({"Hips": {"name": "H", "func": {"fx": "-x", "fy": "y"}}})", t);
  EXPECT_CONTAINS(s.message(), "binding.Hips.func: missing \"fz\"");
  s = import_sysmocap_binding(
      R"j({"Hips": {"name": "H", "func": {"fx": "-x", "fy": "alert(1)", "fz": "z"}}})j", t);
  EXPECT_CONTAINS(s.message(), "binding.Hips.func.fy: column 1: unknown name 'alert'");
  s = import_sysmocap_binding(R"({"Hips": {"name": "H"}, "Spine": {"name": "H"}})", t);
  EXPECT_CONTAINS(s.message(), "rig name 'H' is already used by hips");
  s = import_sysmocap_binding(R"({"Hips": {"name": "H", "order": "QQQ"}})", t);
  EXPECT_CONTAINS(s.message(), "binding.Hips.order: bad Euler order");
  s = import_sysmocap_binding(R"([{"binding": {}}, {"binding": {}}])", t);
  EXPECT_CONTAINS(s.message(), "2 model entries have a \"binding\"");
  s = import_sysmocap_binding("[1,", t);
  EXPECT_CONTAINS(s.message(), "invalid JSON");
}
