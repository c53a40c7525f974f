// The kinds of failure (status_code) of the avatar side, given where each failure happens:
// an avatar, mapping table or clip file that cannot be read is io; malformed content (or a
// table that does not fit the rig) is parse; a bad argument is invalid_argument. Through the
// real loaders, binders, readers and the clip-output job, on real files.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "avatarmap/export/bvh.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig_binding.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

std::string mappings_dir() {
  const char* d = std::getenv("AVATARMAP_SOURCE_DIR");
  const std::string root =
      d && *d ? d
              : std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string();
  return root + "/mappings";
}

// A rig whose joint names no shipped table knows (Pelvis > Spine0), no declared humanoid.
rig unknown_rig() {
  raw_rig raw;
  raw.file = "figure.gltf";
  raw.nodes.resize(2);
  raw.nodes[0].name = "Pelvis";
  raw.nodes[0].rest.translation = {0.f, 1.f, 0.f};
  raw.nodes[1].name = "Spine0";
  raw.nodes[1].parent = 0;
  raw.nodes[1].rest.translation = {0.f, 0.2f, 0.f};
  rig r;
  EXPECT_TRUE(build_rig(raw, r).ok());
  return r;
}

TEST(rig_error_codes, avatar_missing_is_io_malformed_is_parse) {
  test::temp_dir dir("rig_codes");
  raw_rig raw;
  const std::string missing = dir.file("none.vrm");
  const status a = load_avatar(missing, raw);
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  EXPECT_NE(a.message().find(missing), std::string::npos) << a.message();
  const status folder = load_avatar(dir.path().string(), raw);
  EXPECT_EQ(folder.code(), status_code::io) << folder.message();

  const std::string text = dir.file("text.glb");
  test::write_text(text, "hello, not an avatar");
  const status b = load_avatar(text, raw);
  EXPECT_EQ(b.code(), status_code::parse) << b.message();
  const std::string truncated = dir.file("truncated.vrm");
  test::write_text(truncated, test::make_glb(test::minimal_vrm1()).substr(0, 30));
  const status c = load_avatar(truncated, raw);
  EXPECT_EQ(c.code(), status_code::parse) << c.message();
  // A buffer the file names but its folder lacks: the file is fine, a file it needs is not.
  nlohmann::json j = test::minimal_vrm1();
  j["buffers"] = nlohmann::json::array({{{"uri", "gone.bin"}, {"byteLength", 4}}});
  const std::string gltf = dir.file("buffer.gltf");
  test::write_text(gltf, j.dump());
  const status d = load_avatar(gltf, raw);
  EXPECT_EQ(d.code(), status_code::io) << d.message();
}

TEST(rig_error_codes, a_malformed_skeleton_is_parse) {
  raw_rig raw;
  raw.file = "cycle.gltf";
  raw.nodes.resize(2);
  raw.nodes[0].name = "a";
  raw.nodes[0].parent = 1;
  raw.nodes[1].name = "b";
  raw.nodes[1].parent = 0;
  rig r;
  const status st = build_rig(raw, r);
  EXPECT_EQ(st.code(), status_code::parse) << st.message();
}

TEST(rig_error_codes, mapping_table_missing_is_io_malformed_is_parse) {
  test::temp_dir dir("rig_codes");
  mapping_table t;
  const status a = load_mapping(dir.file("none.json"), t);
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  const std::string broken = dir.file("broken.json");
  test::write_text(broken, "{\"format_version\": 1,");
  const status b = load_mapping(broken, t);
  EXPECT_EQ(b.code(), status_code::parse) << b.message();
  const std::string wrong = dir.file("wrong.json");
  test::write_text(wrong, "{\"format_version\": 1, \"name\": \"x\", \"bones\": 3}");
  const status c = load_mapping(wrong, t);
  EXPECT_EQ(c.code(), status_code::parse) << c.message();
  EXPECT_NE(c.message().find("bones"), std::string::npos) << c.message();
  std::vector<mapping_table> all;
  const status d = load_mapping_folder(dir.file("no-such-folder"), all);
  EXPECT_EQ(d.code(), status_code::io) << d.message();
}

TEST(rig_error_codes, binding_tells_unreadable_malformed_unfit_and_unknown_apart) {
  test::temp_dir dir("rig_codes");
  const rig r = unknown_rig();
  rig_binding_choice choice;
  // A table that does not fit this rig (Mixamo's names on Pelvis/Spine0), and no table at all.
  const status no_fit = select_binding(r, "mixamo", mappings_dir(), choice);
  EXPECT_EQ(no_fit.code(), status_code::parse) << no_fit.message();
  EXPECT_NE(no_fit.message().find("does not fit"), std::string::npos) << no_fit.message();
  const status none_fits = select_binding(r, "auto", mappings_dir(), choice);
  EXPECT_EQ(none_fits.code(), status_code::parse) << none_fits.message();
  const status unknown = select_binding(r, "no-such-table", mappings_dir(), choice);
  EXPECT_EQ(unknown.code(), status_code::invalid_argument) << unknown.message();
  const status unreadable = select_binding(r, dir.file("none.json"), mappings_dir(), choice);
  EXPECT_EQ(unreadable.code(), status_code::io) << unreadable.message();
  const std::string broken = dir.file("broken.json");
  test::write_text(broken, "{oops");
  const status malformed = select_binding(r, broken, mappings_dir(), choice);
  EXPECT_EQ(malformed.code(), status_code::parse) << malformed.message();
  const status no_folder = select_binding(r, "mixamo", "", choice);
  EXPECT_EQ(no_folder.code(), status_code::io) << no_folder.message();
  const status bad_folder = select_binding(r, "mixamo", dir.file("no-such-folder"), choice);
  EXPECT_EQ(bad_folder.code(), status_code::io) << bad_folder.message();
  // A folder with a malformed table: the table's parse error, naming it.
  const std::string tables = dir.file("tables");
  std::filesystem::create_directories(tables);
  test::write_text(tables + "/bad.json", "[1,");
  const status bad_table = select_binding(r, "mixamo", tables, choice);
  EXPECT_EQ(bad_table.code(), status_code::parse) << bad_table.message();
  EXPECT_NE(bad_table.message().find("bad.json"), std::string::npos) << bad_table.message();
  // A binding the retargeter refuses (no hips) does not fit the rig: parse.
  bone_binding none;
  none.fill(-1);
  retargeter rt;
  const status no_hips = rt.build(r, none);
  EXPECT_EQ(no_hips.code(), status_code::parse) << no_hips.message();
}

TEST(rig_error_codes, clip_readers_missing_is_io_malformed_is_parse_bad_option_invalid) {
  test::temp_dir dir("rig_codes");
  bvh_clip bvh;
  EXPECT_EQ(read_bvh(dir.file("none.bvh"), bvh).code(), status_code::io);
  const std::string bad_bvh = dir.file("bad.bvh");
  test::write_text(bad_bvh, "HIERARCHY\nROOT\n");
  const status b = read_bvh(bad_bvh, bvh);
  EXPECT_EQ(b.code(), status_code::parse) << b.message();

  vrma_clip vrma;
  EXPECT_EQ(read_vrma(dir.file("none.vrma"), vrma).code(), status_code::io);
  const std::string not_vrma = dir.file("plain.vrma");
  test::write_text(not_vrma, test::make_glb(test::minimal_vrm1()));  // no animation extension
  const status v = read_vrma(not_vrma, vrma);
  EXPECT_EQ(v.code(), status_code::parse) << v.message();
  vrma_read_options o;
  o.fps = -1.0;
  EXPECT_EQ(read_vrma(not_vrma, vrma, o).code(), status_code::invalid_argument);
}

TEST(rig_error_codes, clip_output_bad_option_is_invalid_unwritable_output_is_io) {
  test::temp_dir dir("rig_codes");
  std::vector<proxy_pose> frames(3);
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].t = 0.1 * static_cast<double>(i);
  clip_output_job job;
  job.frames = &frames;
  job.path = dir.file("x.vrma");
  job.fps = -5.0;
  clip_output_summary s;
  EXPECT_EQ(job.run(s).code(), status_code::invalid_argument);
  job.fps = 0.0;
  job.path = dir.file("x.txt");  // no format of that name
  EXPECT_EQ(job.run(s).code(), status_code::invalid_argument);
  job.path = dir.file("no-such-folder/x.bvh");
  const status st = job.run(s);
  EXPECT_EQ(st.code(), status_code::io) << st.message();
  EXPECT_NE(st.message().find("no-such-folder/x.bvh"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace avatarmap
