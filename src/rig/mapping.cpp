#include "avatarmap/rig/mapping.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "avatarmap/skeleton/expression.hpp"
#include "common/json_text.hpp"

namespace avatarmap {

namespace {

using json = nlohmann::json;

// VRM 1.0 preset expressions (docs/conventions.md); the project's custom brow expressions come from
// expression.hpp.
constexpr std::array<std::string_view, 18> k_vrm1_expressions = {
    "happy",      "angry",  "sad",      "relaxed",  "surprised", "aa",
    "ih",         "ou",     "ee",       "oh",       "blink",     "blinkLeft",
    "blinkRight", "lookUp", "lookDown", "lookLeft", "lookRight", "neutral"};

bool known_expression(std::string_view name) {
  for (std::string_view e : k_vrm1_expressions)
    if (e == name) return true;
  return expression_from_name(name).has_value();
}

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

// '*' matches any run (possibly empty); everything else literally.
bool glob_match(std::string_view pattern, std::string_view text) {
  std::size_t p = 0, t = 0, star = std::string_view::npos, mark = 0;
  while (t < text.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = t;
    } else if (p < pattern.size() && pattern[p] == text[t]) {
      ++p, ++t;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      t = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

std::string quote(std::string_view s) { return "'" + std::string(s) + "'"; }

// A JSON number as a float; false when it is not finite as a float (a double such as 1e300
// must not be cast to float: that is undefined behaviour).
bool finite_float(const json& v, float& out) {
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > static_cast<double>(std::numeric_limits<float>::max()))
    return false;
  out = static_cast<float>(d);
  return true;
}

// Error builder: "<file>: <key>: <message>".
struct context {
  std::string file;
  status error(const std::string& key, const std::string& message) const {
    return status::parse_error(file + ": " + (key.empty() ? "" : key + ": ") + message);
  }
};

status check_keys(const context& c, const std::string& key, const json& object,
                  std::initializer_list<std::string_view> allowed) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    const std::string& k = it.key();
    if (!k.empty() && k[0] == '$') continue;
    bool ok = false;
    for (std::string_view a : allowed) ok = ok || a == k;
    if (!ok) {
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      return c.error(key.empty() ? k : key + "." + k, "unknown key (allowed: " + list + ")");
    }
  }
  return {};
}

status get_string(const context& c, const std::string& key, const json& v, std::string& out,
                  bool allow_empty = false) {
  if (!v.is_string())
    return c.error(key, std::string("expected a string, got ") + io_detail::json_type_text(v));
  out = v.get<std::string>();
  if (out.empty() && !allow_empty) return c.error(key, "must not be empty");
  return {};
}

status get_string_list(const context& c, const std::string& key, const json& v,
                       std::vector<std::string>& out, bool allow_empty_strings = false) {
  out.clear();
  if (!v.is_array())
    return c.error(
        key, std::string("expected an array of strings, got ") + io_detail::json_type_text(v));
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::string s;
    if (status st =
            get_string(c, key + "[" + std::to_string(i) + "]", v[i], s, allow_empty_strings);
        !st)
      return st;
    out.push_back(std::move(s));
  }
  return {};
}

status parse_order(const context& c, const std::string& key, const json& v, euler_order& out) {
  if (!v.is_string())
    return c.error(key, std::string("expected an Euler order string such as \"ZXY\", got ") +
                            io_detail::json_type_text(v));
  auto o = euler_order_from_name(v.get<std::string>());
  if (!o)
    return c.error(key, "bad Euler order " + quote(v.get<std::string>()) +
                            " (expected one of XYZ, XZY, YXZ, YZX, ZXY, ZYX)");
  out = *o;
  return {};
}

// Compiles fx, fy, fz into `b`; `keys` names each formula for messages.
status set_formulas(const context& c, const std::array<std::string, 3>& keys,
                    const std::array<std::string, 3>& texts, mapping_bone& b) {
  for (int i = 0; i < 3; ++i) {
    formula f;
    if (status s = compile_formula(texts[i], f); !s)
      return c.error(keys[i], s.message() + " in " + quote(texts[i]));
    b.f[i] = f;
    b.f_text[i] = texts[i];
  }
  b.has_formulas = true;
  return {};
}

// Every rig name may serve one bone only.
status check_duplicates(const context& c, const std::string& bones_key, const mapping_table& t) {
  std::map<std::string, int> owner;
  for (int b = 0; b < k_bone_count; ++b) {
    for (const std::string& n : t.bones[b].rig_names) {
      auto [it, inserted] = owner.emplace(n, b);
      if (!inserted && it->second != b)
        return c.error(bones_key + "." + std::string(bone_name(static_cast<bone>(b))),
                       "rig name " + quote(n) + " is already used by " +
                           std::string(bone_name(static_cast<bone>(it->second))));
      if (!inserted)
        return c.error(bones_key + "." + std::string(bone_name(static_cast<bone>(b))),
                       "rig name " + quote(n) + " is listed twice");
    }
  }
  return {};
}

status parse_bone(const context& c, const std::string& key, const json& v, mapping_bone& out) {
  if (!v.is_object())
    return c.error(
        key, std::string("expected an object {\"rig\": ...}, got ") + io_detail::json_type_text(v));
  if (status s = check_keys(c, key, v, {"rig", "order", "target_order", "f", "rest"}); !s) return s;
  auto rig_it = v.find("rig");
  if (rig_it == v.end()) return c.error(key, "missing \"rig\" (the rig joint name)");
  if (rig_it->is_string()) {
    std::string n;
    if (status s = get_string(c, key + ".rig", *rig_it, n); !s) return s;
    out.rig_names = {n};
  } else if (rig_it->is_array()) {
    if (status s = get_string_list(c, key + ".rig", *rig_it, out.rig_names); !s) return s;
    if (out.rig_names.empty()) return c.error(key + ".rig", "must list at least one name");
  } else {
    return c.error(key + ".rig", "expected a joint name or an array of alternatives");
  }
  if (auto it = v.find("order"); it != v.end())
    if (status s = parse_order(c, key + ".order", *it, out.order); !s) return s;
  out.target_order = out.order;
  if (auto it = v.find("target_order"); it != v.end())
    if (status s = parse_order(c, key + ".target_order", *it, out.target_order); !s) return s;
  if (auto it = v.find("f"); it != v.end()) {
    if (!it->is_array() || it->size() != 3)
      return c.error(key + ".f", "expected three formulas [fx, fy, fz]");
    std::array<std::string, 3> texts, keys;
    for (int i = 0; i < 3; ++i) {
      keys[i] = key + ".f[" + std::to_string(i) + "]";
      if (status s = get_string(c, keys[i], (*it)[i], texts[i], true); !s) return s;
    }
    if (status s = set_formulas(c, keys, texts, out); !s) return s;
  }
  if (auto it = v.find("rest"); it != v.end()) {
    if (!it->is_array() || it->size() != 3 || !(*it)[0].is_number() || !(*it)[1].is_number() ||
        !(*it)[2].is_number())
      return c.error(key + ".rest", "expected three numbers [x, y, z] (radians)");
    for (int i = 0; i < 3; ++i)
      if (!finite_float((*it)[i], out.rest[i])) return c.error(key + ".rest", "must be finite");
    out.has_rest = true;
  }
  return {};
}

status parse_table(const context& c, const json& doc, mapping_table& t) {
  if (!doc.is_object())
    return c.error("", std::string("expected a JSON object (a mapping table), got ") +
                           io_detail::json_type_text(doc));
  auto ver = doc.find("format_version");
  if (ver == doc.end())
    return c.error("", "missing \"format_version\" (this reader reads version " +
                           std::to_string(k_mapping_format_version) + ")");
  if (!ver->is_number_integer())
    return c.error("format_version",
                   std::string("expected an integer, got ") + io_detail::json_type_text(*ver));
  const long long version = ver->get<long long>();
  if (version > k_mapping_format_version)
    return c.error("format_version",
                   "version " + std::to_string(version) + " is newer than this reader (" +
                       std::to_string(k_mapping_format_version) + "): update avatarmap");
  if (version < 1) return c.error("format_version", "must be >= 1");
  if (status s = check_keys(c, "", doc,
                            {"format_version", "name", "description", "recognize", "rest_pose",
                             "units_scale", "bones", "expressions"});
      !s)
    return s;

  auto name = doc.find("name");
  if (name == doc.end()) return c.error("", "missing \"name\"");
  if (status s = get_string(c, "name", *name, t.name); !s) return s;
  if (auto it = doc.find("description"); it != doc.end())
    if (status s = get_string(c, "description", *it, t.description, true); !s) return s;

  if (auto it = doc.find("rest_pose"); it != doc.end()) {
    std::string r;
    if (status s = get_string(c, "rest_pose", *it, r); !s) return s;
    if (r == "t_pose")
      t.rest_pose = mapping_rest_pose::t_pose;
    else if (r == "a_pose")
      t.rest_pose = mapping_rest_pose::a_pose;
    else if (r == "file")
      t.rest_pose = mapping_rest_pose::file;
    else
      return c.error("rest_pose", "expected \"t_pose\", \"a_pose\" or \"file\", got " + quote(r));
  }
  if (auto it = doc.find("units_scale"); it != doc.end()) {
    if (!it->is_number())
      return c.error("units_scale",
                     std::string("expected a number, got ") + io_detail::json_type_text(*it));
    if (!finite_float(*it, t.units_scale) || !(t.units_scale > 0.f))
      return c.error("units_scale", "must be a positive finite number");
    t.has_units_scale = true;
  }

  auto bones = doc.find("bones");
  if (bones == doc.end()) return c.error("", "missing \"bones\"");
  if (!bones->is_object())
    return c.error("bones", "expected an object keyed by VRM 1.0 bone names");
  for (auto it = bones->begin(); it != bones->end(); ++it) {
    const std::string key = "bones." + it.key();
    if (!it.key().empty() && it.key()[0] == '$') continue;
    auto b = bone_from_name(it.key());
    if (!b)
      return c.error(key,
                     "unknown VRM 1.0 bone name (e.g. \"hips\", \"leftUpperArm\", "
                     "\"leftThumbMetacarpal\")");
    if (status s = parse_bone(c, key, it.value(), t.bones[idx(*b)]); !s) return s;
  }
  if (status s = check_duplicates(c, "bones", t); !s) return s;

  if (auto rec = doc.find("recognize"); rec != doc.end()) {
    if (!rec->is_object()) return c.error("recognize", "expected an object");
    if (status s =
            check_keys(c, "recognize", *rec, {"prefixes", "required", "patterns", "humanoid"});
        !s)
      return s;
    if (auto it = rec->find("prefixes"); it != rec->end()) {
      if (status s = get_string_list(c, "recognize.prefixes", *it, t.prefixes, true); !s) return s;
      t.prefixes.erase(std::remove(t.prefixes.begin(), t.prefixes.end(), std::string()),
                       t.prefixes.end());
      std::stable_sort(
          t.prefixes.begin(), t.prefixes.end(),
          [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
    }
    if (auto it = rec->find("patterns"); it != rec->end())
      if (status s = get_string_list(c, "recognize.patterns", *it, t.patterns); !s) return s;
    if (auto it = rec->find("humanoid"); it != rec->end()) {
      std::string h;
      if (status s = get_string(c, "recognize.humanoid", *it, h); !s) return s;
      if (h == "vrm0")
        t.humanoid = mapping_humanoid::vrm0;
      else if (h == "vrm1")
        t.humanoid = mapping_humanoid::vrm1;
      else
        return c.error("recognize.humanoid", "expected \"vrm0\" or \"vrm1\", got " + quote(h));
    }
    if (auto it = rec->find("required"); it != rec->end()) {
      std::vector<std::string> names;
      if (status s = get_string_list(c, "recognize.required", *it, names); !s) return s;
      for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string key = "recognize.required[" + std::to_string(i) + "]";
        auto b = bone_from_name(names[i]);
        if (!b) return c.error(key, "unknown VRM 1.0 bone name " + quote(names[i]));
        if (!t.bones[idx(*b)].mapped())
          return c.error(key, quote(names[i]) + " is required but \"bones\" does not map it");
        if (std::find(t.required.begin(), t.required.end(), idx(*b)) != t.required.end())
          return c.error(key, quote(names[i]) + " is listed twice");
        t.required.push_back(idx(*b));
      }
      std::sort(t.required.begin(), t.required.end());
    }
  }

  if (auto ex = doc.find("expressions"); ex != doc.end()) {
    if (!ex->is_object())
      return c.error("expressions", "expected an object {\"<VRM expression>\": \"<rig name>\"}");
    for (auto it = ex->begin(); it != ex->end(); ++it) {
      if (!it.key().empty() && it.key()[0] == '$') continue;
      const std::string key = "expressions." + it.key();
      if (!known_expression(it.key()))
        return c.error(key, "unknown VRM 1.0 expression (e.g. \"blink\", \"aa\", \"happy\")");
      std::string target;
      if (status s = get_string(c, key, it.value(), target); !s) return s;
      t.expressions.emplace_back(it.key(), std::move(target));
    }
  }
  return {};
}

// The table in `doc` into `out` (left empty on failure); `name` is recorded as its file.
status table_from_json(const context& c, const json& doc, const std::string& name,
                       mapping_table& out) {
  mapping_table t;
  t.file = name;
  if (status s = parse_table(c, doc, t); !s) return s;
  out = std::move(t);
  return {};
}

// SysMocap binding key -> bone. PascalCase keys are VRM 0.x humanoid names (three-vrm 0.x's
// HumanoidBoneName), whose thumb joints are Proximal/Intermediate/Distal; camelCase keys are
// VRM 1.0 names.
std::optional<bone> sysmocap_bone(const std::string& key) {
  if (key.empty()) return std::nullopt;
  if (key[0] >= 'A' && key[0] <= 'Z') {
    std::string camel = key;
    camel[0] = lower(camel[0]);
    for (const char* side : {"left", "right"}) {
      const std::string thumb = std::string(side) + "Thumb";
      if (camel == thumb + "Proximal") return bone_from_name(thumb + "Metacarpal");
      if (camel == thumb + "Intermediate") return bone_from_name(thumb + "Proximal");
      if (camel == thumb + "Metacarpal") return std::nullopt;  // not a VRM 0.x name
    }
    return bone_from_name(camel);
  }
  return bone_from_name(key);
}

}  // namespace

int mapping_table::mapped_count() const {
  int n = 0;
  for (const mapping_bone& b : bones) n += b.mapped() ? 1 : 0;
  return n;
}

status load_mapping_json(std::string_view text, const std::string& name, mapping_table& out) {
  out = mapping_table{};
  context c{name.empty() ? std::string("<mapping>") : name};
  // Depth and size limits first, then the parse, errors in our words (common/json_text.hpp).
  json doc;
  if (status s = io_detail::parse_json_text(text, c.file, doc); !s) return s;
  return table_from_json(c, doc, name, out);
}

status load_mapping(const std::string& path, mapping_table& out) {
  out = mapping_table{};
  json doc;
  if (status s = io_detail::read_json_file(path, doc); !s) return s;
  return table_from_json(context{path}, doc, path, out);
}

status load_mapping_folder(const std::string& folder, std::vector<mapping_table>& out) {
  out.clear();
  std::error_code ec;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    if (!e.is_regular_file() || e.path().extension() != ".json") continue;
    if (e.path().filename() == "schema.json") continue;
    files.push_back(e.path().string());
  }
  if (ec) return status::io_error(folder + ": cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end());
  for (const std::string& f : files) {
    mapping_table t;
    if (status s = load_mapping(f, t); !s) return s;
    out.push_back(std::move(t));
  }
  return {};
}

std::string mapping_match::summary() const {
  std::string s = "matched " + std::to_string(matched) + "/" + std::to_string(needed) + " bones";
  if (!prefix.empty()) s += " (prefix " + quote(prefix) + ")";
  if (!missing_required.empty()) {
    s += "; missing required:";
    for (int b : missing_required) s += " " + std::string(bone_name(static_cast<bone>(b)));
  }
  return s;
}

int match_score(const mapping_table& table, const rig& r, mapping_match& out) {
  out = mapping_match{};
  const int n = r.joint_count();
  for (const mapping_bone& b : table.bones) out.needed += b.mapped() ? 1 : 0;

  auto finish = [&](int per_bone_weight) {
    for (int b = 0; b < k_bone_count; ++b) {
      if (!table.bones[b].mapped() || out.joint[b] >= 0) continue;
      out.missing.push_back(b);
      if (std::binary_search(table.required.begin(), table.required.end(), b))
        out.missing_required.push_back(b);
    }
    for (const std::string& p : table.patterns) {
      bool any = false;
      for (int j = 0; j < n && !any; ++j) any = glob_match(p, r.names[j]);
      out.patterns_matched += any ? 1 : 0;
    }
    if (!out.usable()) return 0;
    return 1 + per_bone_weight * out.exact + out.folded + 4 * out.patterns_matched;
  };

  const bool declared =
      (table.humanoid == mapping_humanoid::vrm0 && r.source == rig_source::vrm0) ||
      (table.humanoid == mapping_humanoid::vrm1 && r.source == rig_source::vrm1);
  if (table.humanoid != mapping_humanoid::none && !declared &&
      (r.source == rig_source::vrm0 || r.source == rig_source::vrm1)) {
    finish(0);
    return 0;  // a VRM file of the other version: its declaration is what counts
  }
  if (declared) {
    // The file's own humanoid declaration beats any name match (3 per bone vs 2).
    for (int b = 0; b < k_bone_count; ++b) {
      const int j = r.declared_humanoid[b];
      if (!table.bones[b].mapped() || j < 0 || j >= n) continue;
      out.joint[b] = j;
      ++out.matched;
      ++out.exact;
    }
    return finish(3);
  }

  // Strip the longest matching prefix of each joint name once.
  std::vector<std::string_view> stripped(static_cast<std::size_t>(n));
  std::vector<int> prefix_of(static_cast<std::size_t>(n), -1);
  for (int j = 0; j < n; ++j) {
    std::string_view name = r.names[j];
    stripped[j] = name;
    for (std::size_t p = 0; p < table.prefixes.size(); ++p) {
      const std::string& pre = table.prefixes[p];
      if (name.size() > pre.size() && name.compare(0, pre.size(), pre) == 0) {
        stripped[j] = name.substr(pre.size());
        prefix_of[j] = static_cast<int>(p);
        break;  // prefixes are sorted longest first
      }
    }
  }
  std::vector<char> taken(static_cast<std::size_t>(n), 0);
  auto find = [&](std::string_view want, bool fold) {
    for (int j = 0; j < n; ++j)
      if (!taken[j] && (fold ? iequals(stripped[j], want) : stripped[j] == want)) return j;
    return -1;
  };
  // Exact names first for every bone, so that a case-folded match never steals a joint
  // another bone names exactly.
  for (int pass = 0; pass < 2; ++pass) {
    for (int b = 0; b < k_bone_count; ++b) {
      if (out.joint[b] >= 0) continue;
      for (const std::string& want : table.bones[b].rig_names) {
        int j = find(want, pass == 1);
        if (j < 0) continue;
        out.joint[b] = j;
        taken[j] = 1;
        ++out.matched;
        ++(pass == 0 ? out.exact : out.folded);
        break;
      }
    }
  }
  std::vector<int> prefix_count(table.prefixes.size() + 1, 0);
  for (int b = 0; b < k_bone_count; ++b)
    if (out.joint[b] >= 0) ++prefix_count[static_cast<std::size_t>(prefix_of[out.joint[b]] + 1)];
  const auto best =
      std::max_element(prefix_count.begin(), prefix_count.end()) - prefix_count.begin();
  if (best > 0) out.prefix = table.prefixes[static_cast<std::size_t>(best - 1)];
  return finish(2);
}

status auto_detect(const std::vector<mapping_table>& tables, const rig& r, int& out_best,
                   mapping_match& out_match) {
  out_best = -1;
  out_match = mapping_match{};
  const std::string what = r.file.empty() ? std::string("the rig") : r.file;
  if (tables.empty()) return status::parse_error(what + ": no mapping tables to choose from");
  int best_score = 0;
  std::string report;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    mapping_match m;
    const int score = match_score(tables[i], r, m);
    if (score > best_score) {
      best_score = score;
      out_best = static_cast<int>(i);
      out_match = m;
    }
    if (score == 0) {
      report += "\n  " + tables[i].name + ": " + m.summary();
      if (m.matched == 0) report += " (no bone name matched)";
    }
  }
  if (out_best < 0)
    return status::parse_error(what + ": no mapping table fits (" +
                               std::to_string(r.joint_count()) + " joints)" + report);
  return {};
}

status import_sysmocap_binding(std::string_view text, mapping_table& out) {
  out = mapping_table{};
  context c{"SysMocap binding"};
  json doc;
  if (status s = io_detail::parse_json_text(text, c.file, doc); !s) return s;
  const json* model = nullptr;
  std::string key_base = "binding";
  if (doc.is_array()) {
    int count = 0;
    std::string names;
    for (std::size_t i = 0; i < doc.size(); ++i) {
      if (!doc[i].is_object() || !doc[i].contains("binding")) continue;
      ++count;
      model = &doc[i];
      key_base = "[" + std::to_string(i) + "].binding";
      if (doc[i].contains("name") && doc[i]["name"].is_string())
        names += " " + quote(doc[i]["name"].get<std::string>());
    }
    if (count != 1)
      return c.error("", std::to_string(count) +
                             " model entries have a \"binding\"; pass exactly one entry" +
                             (names.empty() ? std::string() : " (found" + names + ")"));
  } else if (doc.is_object() && doc.contains("binding")) {
    model = &doc;
  } else if (!doc.is_object()) {
    return c.error("", "expected a binding object, a model entry or the models.json array");
  }
  const json& binding = model ? (*model)["binding"] : doc;
  if (!binding.is_object()) return c.error(key_base, "expected an object keyed by bone names");

  mapping_table t;
  t.name = "sysmocap";
  t.rest_pose = mapping_rest_pose::file;
  if (model && model->contains("name") && (*model)["name"].is_string())
    t.name = (*model)["name"].get<std::string>();
  t.description = "Imported from a SysMocap binding table";
  for (auto it = binding.begin(); it != binding.end(); ++it) {
    const std::string key = key_base + "." + it.key();
    auto b = sysmocap_bone(it.key());
    if (!b)
      return c.error(key,
                     "unknown bone name (expected SysMocap/VRM 0.x names such as "
                     "\"Hips\", \"LeftUpperArm\" or VRM 1.0 names such as \"leftUpperArm\")");
    const json& e = it.value();
    if (!e.is_object()) return c.error(key, "expected an object {\"name\", \"func\"}");
    auto name = e.find("name");
    if (name == e.end()) return c.error(key, "missing \"name\" (the rig bone, or \"None\")");
    std::string rig_name;
    if (status s = get_string(c, key + ".name", *name, rig_name); !s) return s;
    if (rig_name == "None") continue;
    mapping_bone& mb = t.bones[idx(*b)];
    if (mb.mapped()) return c.error(key, "bone " + std::string(bone_name(*b)) + " is bound twice");
    mb.rig_names = {rig_name};
    if (auto o = e.find("order"); o != e.end())
      if (status s = parse_order(c, key + ".order", *o, mb.order); !s) return s;
    if (auto f = e.find("func"); f != e.end()) {
      if (!f->is_object()) return c.error(key + ".func", "expected {\"fx\", \"fy\", \"fz\"}");
      std::array<std::string, 3> texts, keys;
      const char* names3[3] = {"fx", "fy", "fz"};
      for (int i = 0; i < 3; ++i) {
        keys[i] = key + ".func." + names3[i];
        auto fi = f->find(names3[i]);
        if (fi == f->end())
          return c.error(key + ".func", std::string("missing \"") + names3[i] + "\"");
        if (status s = get_string(c, keys[i], *fi, texts[i], true); !s) return s;
      }
      if (status s = set_formulas(c, keys, texts, mb); !s) return s;
    }
  }
  if (status s = check_duplicates(c, key_base, t); !s) return s;
  if (model && model->contains("init")) {
    const json& init = (*model)["init"];
    if (!init.is_object()) return c.error("init", "expected an object keyed by bone names");
    for (auto it = init.begin(); it != init.end(); ++it) {
      const std::string key = "init." + it.key();
      auto b = sysmocap_bone(it.key());
      if (!b) return c.error(key, "unknown bone name");
      const json& v = it.value();
      mapping_bone& mb = t.bones[idx(*b)];
      if (!mb.mapped()) continue;  // SysMocap ignores it too
      for (int i = 0; i < 3; ++i) {
        const char* axis = i == 0 ? "x" : i == 1 ? "y" : "z";
        if (!v.is_object() || !v.contains(axis) || !v[axis].is_number() ||
            !finite_float(v[axis], mb.rest[i]))
          return c.error(key, "expected {\"x\", \"y\", \"z\"} finite numbers (radians)");
      }
      mb.has_rest = true;
    }
  }
  out = std::move(t);
  return {};
}

std::string mapping_to_json(const mapping_table& t) {
  nlohmann::ordered_json doc;
  doc["format_version"] = k_mapping_format_version;
  doc["name"] = t.name;
  if (!t.description.empty()) doc["description"] = t.description;
  nlohmann::ordered_json rec = nlohmann::ordered_json::object();
  if (!t.prefixes.empty()) rec["prefixes"] = t.prefixes;
  if (!t.required.empty()) {
    std::vector<std::string> req;
    for (int b : t.required) req.emplace_back(bone_name(static_cast<bone>(b)));
    rec["required"] = req;
  }
  if (!t.patterns.empty()) rec["patterns"] = t.patterns;
  if (t.humanoid != mapping_humanoid::none)
    rec["humanoid"] = t.humanoid == mapping_humanoid::vrm0 ? "vrm0" : "vrm1";
  if (!rec.empty()) doc["recognize"] = rec;
  doc["rest_pose"] = t.rest_pose == mapping_rest_pose::t_pose   ? "t_pose"
                     : t.rest_pose == mapping_rest_pose::a_pose ? "a_pose"
                                                                : "file";
  if (t.has_units_scale) doc["units_scale"] = t.units_scale;
  nlohmann::ordered_json bones = nlohmann::ordered_json::object();
  for (int b = 0; b < k_bone_count; ++b) {
    const mapping_bone& mb = t.bones[b];
    if (!mb.mapped()) continue;
    nlohmann::ordered_json e;
    if (mb.rig_names.size() == 1)
      e["rig"] = mb.rig_names[0];
    else
      e["rig"] = mb.rig_names;
    if (mb.has_formulas || mb.order != euler_order::xyz)
      e["order"] = std::string(euler_order_name(mb.order));
    if (mb.target_order != mb.order)
      e["target_order"] = std::string(euler_order_name(mb.target_order));
    if (mb.has_formulas) e["f"] = {mb.f_text[0], mb.f_text[1], mb.f_text[2]};
    if (mb.has_rest) e["rest"] = {mb.rest.x, mb.rest.y, mb.rest.z};
    bones[std::string(bone_name(static_cast<bone>(b)))] = e;
  }
  doc["bones"] = bones;
  if (!t.expressions.empty()) {
    nlohmann::ordered_json ex = nlohmann::ordered_json::object();
    for (const auto& [k, v] : t.expressions) ex[k] = v;
    doc["expressions"] = ex;
  }
  return doc.dump(2) + "\n";
}

}  // namespace avatarmap
