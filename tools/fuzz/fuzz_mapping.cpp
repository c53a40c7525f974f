// libFuzzer target: the mapping-table loader (rig/mapping.hpp: load_mapping_json) on arbitrary
// bytes. Checks that it never crashes or throws, that a failure names the table and leaves
// `out` empty, that a loaded table is well formed (required bones mapped, prefixes longest
// first, finite numbers), that matching it against a small rig works, and that
// mapping_to_json gives text that loads back to the same table (the same text again).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/rig.hpp"

using namespace avatarmap;

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "invariant failed: %s\n", what);
    std::abort();
  }
}

// A few joints with Mixamo-style and plain names (only names matter to match_score).
const rig& test_rig() {
  static const rig r = [] {
    rig x;
    x.names = {"mixamorig:Hips", "mixamorig:Spine", "Head", "LeftArm",
               "leftUpperArm",   "spine_05",        "",     "*"};
    for (std::size_t i = 0; i < x.names.size(); ++i) x.parents.push_back(int(i) - 1);
    x.declared_humanoid.fill(-1);
    x.file = "fuzz-rig";
    return x;
  }();
  return r;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  mapping_table t;
  status s = load_mapping_json(text, "fuzz.json", t);
  if (!s.ok()) {
    check(s.message().rfind("fuzz.json: ", 0) == 0, "errors start with the table's name");
    check(t.name.empty() && t.mapped_count() == 0, "a failed load leaves the table empty");
    return 0;
  }
  check(!t.name.empty(), "a loaded table has a name");
  check(t.file == "fuzz.json", "file is the name given");
  check(std::isfinite(t.units_scale) && t.units_scale > 0.f, "units_scale positive and finite");
  for (int b : t.required) {
    check(b >= 0 && b < k_bone_count, "required bone in range");
    check(t.bones[b].mapped(), "required bones are mapped");
  }
  for (std::size_t i = 1; i < t.prefixes.size(); ++i)
    check(t.prefixes[i - 1].size() >= t.prefixes[i].size(), "prefixes longest first");
  for (const mapping_bone& b : t.bones) {
    for (const std::string& n : b.rig_names) check(!n.empty(), "rig names are not empty");
    check(std::isfinite(b.rest.x) && std::isfinite(b.rest.y) && std::isfinite(b.rest.z),
          "rest angles finite");
    if (b.has_formulas)
      for (const formula& f : b.f) {
        volatile float v = f.eval(0.1f, -0.2f, 0.3f);
        (void)v;
      }
  }

  mapping_match m;
  const int score = match_score(t, test_rig(), m);
  check(score >= 0, "score not negative");
  check(m.matched <= m.needed && m.matched == m.exact + m.folded, "match counts add up");
  if (score > 0) check(m.usable(), "a positive score is usable");

  const std::string json = mapping_to_json(t);
  mapping_table back;
  status s2 = load_mapping_json(json, "fuzz.json", back);
  if (!s2.ok()) std::fprintf(stderr, "%s\n--- dumped:\n%s\n", s2.message().c_str(), json.c_str());
  check(s2.ok(), "mapping_to_json output loads back");
  check(back.name == t.name && back.mapped_count() == t.mapped_count() &&
            back.required == t.required && back.prefixes == t.prefixes &&
            back.patterns == t.patterns && back.expressions == t.expressions,
        "the reloaded table equals the original");
  check(mapping_to_json(back) == json, "dumping the reloaded table gives the same text");
  return 0;
}
