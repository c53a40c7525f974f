// Validates every shipped mapping table against mappings/schema.json with a small validator
// for exactly the JSON Schema (draft 2020-12) keywords the schema uses. A keyword the
// validator does not know fails the test, so the schema cannot silently outgrow it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using json = nlohmann::json;

namespace {

std::string source_dir() {
  const char* d = std::getenv("AVATARMAP_SOURCE_DIR");
  if (d && *d) return d;
  // Run outside ctest: this file is <source>/tests/rig/mapping_schema_test.cpp.
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string();
}

json read_json(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return json::parse(ss.str());
}

class validator {
 public:
  explicit validator(json schema) : root_(std::move(schema)) {}

  // Appends "path: problem" lines to `errors`.
  void validate(const json& s, const json& v, const std::string& path,
                std::vector<std::string>& errors) const {
    if (s.is_boolean()) {
      if (!s.get<bool>()) errors.push_back(path + ": not allowed");
      return;
    }
    static const std::set<std::string> k_known = {"$schema",
                                                  "$id",
                                                  "title",
                                                  "description",
                                                  "type",
                                                  "const",
                                                  "enum",
                                                  "required",
                                                  "properties",
                                                  "patternProperties",
                                                  "additionalProperties",
                                                  "propertyNames",
                                                  "items",
                                                  "minItems",
                                                  "maxItems",
                                                  "uniqueItems",
                                                  "minLength",
                                                  "exclusiveMinimum",
                                                  "pattern",
                                                  "oneOf",
                                                  "anyOf",
                                                  "$ref",
                                                  "$defs"};
    for (auto it = s.begin(); it != s.end(); ++it)
      if (!k_known.count(it.key())) errors.push_back("schema uses unsupported keyword " + it.key());
    if (s.contains("$ref")) {
      std::string ref = s["$ref"];
      const std::string pre = "#/$defs/";
      if (ref.rfind(pre, 0) != 0) {
        errors.push_back("unsupported $ref " + ref);
      } else {
        validate(root_["$defs"][ref.substr(pre.size())], v, path, errors);
      }
    }
    if (s.contains("type")) {
      std::string t = s["type"];
      bool ok = (t == "object" && v.is_object()) || (t == "array" && v.is_array()) ||
                (t == "string" && v.is_string()) || (t == "number" && v.is_number()) ||
                (t == "integer" && v.is_number_integer()) || (t == "boolean" && v.is_boolean());
      if (!ok) {
        errors.push_back(path + ": expected " + t);
        return;
      }
    }
    if (s.contains("const") && v != s["const"])
      errors.push_back(path + ": must be " + s["const"].dump());
    if (s.contains("enum")) {
      bool found = false;
      for (const json& e : s["enum"]) found = found || e == v;
      if (!found) errors.push_back(path + ": " + v.dump() + " is not one of the allowed values");
    }
    if (v.is_string()) {
      const std::string str = v.get<std::string>();
      if (s.contains("minLength") && str.size() < s["minLength"].get<std::size_t>())
        errors.push_back(path + ": too short");
      if (s.contains("pattern") &&
          !std::regex_search(str, std::regex(s["pattern"].get<std::string>())))
        errors.push_back(path + ": does not match " + s["pattern"].get<std::string>());
    }
    if (v.is_number() && s.contains("exclusiveMinimum") &&
        !(v.get<double>() > s["exclusiveMinimum"].get<double>()))
      errors.push_back(path + ": must be > " + s["exclusiveMinimum"].dump());
    if (v.is_array()) {
      if (s.contains("minItems") && v.size() < s["minItems"].get<std::size_t>())
        errors.push_back(path + ": too few items");
      if (s.contains("maxItems") && v.size() > s["maxItems"].get<std::size_t>())
        errors.push_back(path + ": too many items");
      if (s.value("uniqueItems", false))
        for (std::size_t i = 0; i < v.size(); ++i)
          for (std::size_t j = i + 1; j < v.size(); ++j)
            if (v[i] == v[j]) errors.push_back(path + ": duplicate item " + v[i].dump());
      if (s.contains("items"))
        for (std::size_t i = 0; i < v.size(); ++i)
          validate(s["items"], v[i], path + "[" + std::to_string(i) + "]", errors);
    }
    if (v.is_object()) {
      if (s.contains("required"))
        for (const json& r : s["required"])
          if (!v.contains(r.get<std::string>())) errors.push_back(path + ": missing " + r.dump());
      for (auto it = v.begin(); it != v.end(); ++it) {
        const std::string key = it.key(), sub = path + "." + key;
        if (s.contains("propertyNames"))
          validate(s["propertyNames"], json(key), sub + " (name)", errors);
        bool covered = false;
        if (s.contains("properties") && s["properties"].contains(key)) {
          covered = true;
          validate(s["properties"][key], it.value(), sub, errors);
        }
        if (s.contains("patternProperties"))
          for (auto p = s["patternProperties"].begin(); p != s["patternProperties"].end(); ++p)
            if (std::regex_search(key, std::regex(p.key()))) {
              covered = true;
              validate(p.value(), it.value(), sub, errors);
            }
        if (!covered && s.contains("additionalProperties"))
          validate(s["additionalProperties"], it.value(), sub, errors);
      }
    }
    if (s.contains("oneOf")) {
      int n = 0;
      for (const json& alt : s["oneOf"]) {
        std::vector<std::string> e;
        validate(alt, v, path, e);
        n += e.empty() ? 1 : 0;
      }
      if (n != 1) errors.push_back(path + ": matches " + std::to_string(n) + " of oneOf");
    }
    if (s.contains("anyOf")) {
      bool any = false;
      for (const json& alt : s["anyOf"]) {
        std::vector<std::string> e;
        validate(alt, v, path, e);
        any = any || e.empty();
      }
      if (!any) errors.push_back(path + ": matches none of anyOf");
    }
  }

  std::vector<std::string> check(const json& doc) const {
    std::vector<std::string> errors;
    validate(root_, doc, "$", errors);
    return errors;
  }

 private:
  json root_;
};

std::vector<std::string> shipped_tables() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(source_dir() + "/mappings"))
    if (e.path().extension() == ".json" && e.path().filename() != "schema.json")
      files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

TEST(mapping_schema, every_shipped_table_validates) {
  validator v(read_json(source_dir() + "/mappings/schema.json"));
  auto files = shipped_tables();
  ASSERT_GE(files.size(), 7u);
  for (const std::string& f : files) {
    auto errors = v.check(read_json(f));
    std::string all;
    for (const auto& e : errors) all += "\n  " + e;
    EXPECT_TRUE(errors.empty()) << f << all;
  }
}

TEST(mapping_schema, validator_rejects_broken_tables) {
  validator v(read_json(source_dir() + "/mappings/schema.json"));
  json good = read_json(source_dir() + "/mappings/mixamo.json");
  ASSERT_TRUE(v.check(good).empty());
  auto broken = [&](auto edit) {
    json d = good;
    edit(d);
    return !v.check(d).empty();
  };
  EXPECT_TRUE(broken([](json& d) { d.erase("format_version"); }));
  EXPECT_TRUE(broken([](json& d) { d["format_version"] = 2; }));
  EXPECT_TRUE(broken([](json& d) { d["bones"]["tail"] = {{"rig", "Tail"}}; }));
  EXPECT_TRUE(broken([](json& d) { d["bones"]["hips"] = {{"name", "Hips"}}; }));
  EXPECT_TRUE(broken([](json& d) { d["bones"]["hips"]["f"] = {"x", "y"}; }));
  EXPECT_TRUE(broken([](json& d) { d["bones"]["hips"]["order"] = "XYX"; }));
  EXPECT_TRUE(broken([](json& d) { d["rest_pose"] = "y_pose"; }));
  EXPECT_TRUE(broken([](json& d) { d["units_scale"] = 0; }));
  EXPECT_TRUE(broken([](json& d) { d["unknown"] = 1; }));
  EXPECT_TRUE(broken([](json& d) { d["recognize"]["required"].push_back("hips"); }));
  EXPECT_TRUE(broken([](json& d) { d["expressions"] = {{"smile", "Smile"}}; }));
  EXPECT_FALSE(broken([](json& d) { d["bones"]["hips"]["f"] = {"-x", "y", "-z"}; }));
  EXPECT_FALSE(broken([](json& d) { d["$comment"] = "ok"; }));
}
