// `avatarmap convert IN -o OUT [--avatar AVATAR] [--rig auto|NAME|FILE.json] [--fps N]`:
// landmarks, proxy poses or VRM Animation in; VRMA, animated GLB, BVH or proxy poses out.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/filter_option.hpp"
#include "cli/rig_select.hpp"
#include "cli/solve_job.hpp"
#include "common/atomic_file.hpp"

namespace avatarmap::cli {
namespace {

const char* k_convert_help =
    "Usage: avatarmap convert IN -o OUT [options]\n"
    "\n"
    "IN:  *.landmarks.jsonl (solved as by `avatarmap solve`), *.pose.jsonl or *.vrma\n"
    "OUT: *.vrma (VRM Animation), *.glb (the avatar with the motion; needs --avatar),\n"
    "     *.bvh (centimetres, ZXY: the avatar's own rig with --avatar, else the proxy\n"
    "     skeleton), *.pose.jsonl\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     output file (required; written atomically)\n"
    "  --avatar FILE         the avatar (.vrm, .glb, .gltf) to drive (required for .glb;\n"
    "                        with .bvh: write its rig instead of the proxy skeleton)\n"
    "  --rig auto|NAME|FILE.json\n"
    "                        how the avatar's joints map to the proxy: auto (default) uses a\n"
    "                        VRM's own humanoid map, else the best shipped table (mixamo,\n"
    "                        unity_humanoid, ue4_mannequin, ue5_mannequin, character_creator,\n"
    "                        ...); NAME picks a shipped table; FILE.json a table of yours\n"
    "  --fps N               output frame rate (default 30; .pose.jsonl: the input's frames)\n"
    "  --bind BONE=JOINT     bind a proxy bone (VRM 1.0 name) to an avatar joint, or to\n"
    "                        none; repeatable; overrides --rig, and alone drives a rig no\n"
    "                        table fits\n"
    "  --ground              keep the avatar's lowest foot on the floor every frame\n"
    "  --no-root-motion      keep the hips where they are at rest\n"
    "  --mirror, --image-size WxH, --filter offline|live|none, --smoothing S\n"
    "                        as for `avatarmap solve` (landmark input only)\n"
    "  --quiet               no summary\n";

// Whether `s` ends with the lower-case `suffix`, ignoring ASCII case (as output names are).
bool ends_with_nocase(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i) {
    char c = s[s.size() - suffix.size() + i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != suffix[i]) return false;
  }
  return true;
}

status load_motion(const std::string& in, const solve_file_job& solve, std::vector<proxy_pose>& out,
                   double& source_fps) {
  out.clear();
  source_fps = 0.0;
  if (ends_with_nocase(in, ".vrma")) {
    vrma_clip clip;
    status st = read_vrma(in, clip);
    if (!st.ok()) return st;
    out = std::move(clip.frames);
    return {};
  }
  if (ends_with_nocase(in, ".pose.jsonl")) {
    pose_reader reader;
    status st = reader.open(in);
    if (!st.ok()) return st;
    source_fps = reader.header().fps;
    proxy_pose p;
    for (;;) {
      read_result r = reader.next(p);
      if (r == read_result::end) break;
      if (r == read_result::error) return status::error(reader.error());
      out.push_back(p);
    }
    return {};
  }
  if (ends_with_nocase(in, ".jsonl") || in == "-") {
    solve_file_job job = solve;
    job.input = in;
    job.sink = [&](const proxy_pose& p) {
      out.push_back(p);
      return status{};
    };
    solve_file_summary summary;
    // A progress line on a terminal.
    status st = run_solve_job(job, progress_mode::automatic, summary);
    source_fps = summary.fps;  // the landmarks' nominal rate, as `avatarmap solve` writes it
    return st;
  }
  return status::error(in +
                       ": unknown input type (give *.landmarks.jsonl, *.pose.jsonl or *.vrma)");
}

void append_position(std::string& s, const std::string& name, glm::dvec3 p, bool first) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "\":[%.7g,%.7g,%.7g]", p.x, p.y, p.z);
  s += first ? "\"" : ",\"";
  s += name;
  s += buf;
}

// Diagnostic (--dump-positions, used by tools/interop/check_blender.sh): every joint's world
// position (metres, the output's world axes) per written frame, as JSON
// {"unit":"m","fps":F,"frames":[{"name":[x,y,z],...},...]}. Rig output: every rig joint, rig
// FK of the retargeted poses; otherwise the proxy bones on the proxy skeleton written to
// BVH. Joint names must need no JSON escaping (interop files only).
status dump_positions(const std::string& path, double fps, const std::vector<proxy_pose>& sampled,
                      const rig* r, const std::vector<rig_pose>& poses) {
  std::string s = "{\"unit\":\"m\",\"fps\":" + std::to_string(fps) + ",\"frames\":[";
  if (r) {
    std::vector<glm::dmat4> world(static_cast<size_t>(r->joint_count()));
    for (size_t f = 0; f < poses.size(); ++f) {
      s += f ? ",{" : "{";
      for (int j = 0; j < r->joint_count(); ++j) {
        const transform& t = r->rest_local[j];
        const glm::quat& q = poses[f].local_rotations[j];
        glm::dmat4 m = glm::mat4_cast(glm::normalize(glm::dquat(q.w, q.x, q.y, q.z)));
        m[0] *= double(t.scale.x);
        m[1] *= double(t.scale.y);
        m[2] *= double(t.scale.z);
        m[3] = glm::dvec4(
            glm::dvec3(j == poses[f].hips_joint ? poses[f].hips_translation : t.translation), 1.0);
        world[j] = r->parents[j] < 0 ? m : world[r->parents[j]] * m;
        append_position(s, r->names[j], glm::dvec3(world[j][3]), j == 0);
      }
      s += "}";
    }
  } else {
    const proxy_skeleton sk = make_proxy_skeleton();
    std::array<glm::vec3, k_bone_count> joints;
    for (size_t f = 0; f < sampled.size(); ++f) {
      s += f ? ",{" : "{";
      joint_world_positions(sk, sampled[f], joints);
      for (int b = 0; b < k_bone_count; ++b)
        append_position(s, std::string(bone_name(static_cast<bone>(b))), glm::dvec3(joints[b]),
                        b == 0);
      s += "}";
    }
  }
  s += "]}\n";
  return io_detail::write_file_atomically(path, s);
}

}  // namespace

int run_convert(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_convert_help, stdout);
    return 0;
  }
  std::string out_path, avatar, rig_option = "auto", value;
  a.value("--output", out_path, "-o");
  a.value("--avatar", avatar);
  a.value("--rig", rig_option);
  std::vector<std::string> binds;  // --bind BONE=JOINT, repeatable
  while (a.value("--bind", value)) binds.push_back(value);
  std::string dump_path;  // hidden diagnostic option, see dump_positions()
  a.value("--dump-positions", dump_path);
  double fps = 0.0;
  const bool fps_given = a.number("--fps", fps);
  const bool ground = a.flag("--ground");
  const bool root_motion = !a.flag("--no-root-motion");
  const bool quiet = a.flag("--quiet");
  solve_file_job solve = make_cli_solve_job();
  solve.options.mirror = a.flag("--mirror");
  if (a.value("--image-size", value)) {
    int w = 0, h = 0;
    if (!parse_image_size(value, w, h)) {
      std::fprintf(stderr, "avatarmap convert: --image-size wants WxH in pixels, e.g. 1280x720\n");
      return 2;
    }
    solve.image_width = float(w);
    solve.image_height = float(h);
  }
  if (a.value("--filter", value) && !apply_filter_option(value, solve)) {
    std::fprintf(stderr, "avatarmap convert: --filter is %s, got '%s'\n", k_filter_names,
                 value.c_str());
    return 2;
  }
  double smoothing = 1.0;
  if (a.number("--smoothing", smoothing) && !apply_smoothing_option(smoothing, solve)) {
    std::fprintf(stderr, "avatarmap convert: --smoothing is a scale in [0, 10] (1 = default)\n");
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1 || out_path.empty()) {
    std::fprintf(stderr, "avatarmap convert: %s\n",
                 !a.error().empty()     ? a.error().c_str()
                 : a.rest().size() != 1 ? "give exactly one input file (see --help)"
                                        : "give the output with -o OUT (see --help)");
    return 2;
  }
  if (fps_given && !(fps > 0.0 && fps <= 1000.0)) {
    std::fprintf(stderr, "avatarmap convert: --fps must be in (0, 1000]\n");
    return 2;
  }
  const clip_format_info* format = nullptr;
  if (status st = clip_format_for(out_path, format); !st.ok()) {
    std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
    return 2;
  }
  const bool to_pose = format->format == clip_format::pose_jsonl;
  if (format->needs_avatar && avatar.empty()) {
    std::fprintf(stderr,
                 "avatarmap convert: .glb output needs --avatar AVATAR (the model to animate)\n");
    return 2;
  }
  const auto t_start = std::chrono::steady_clock::now();

  // The avatar first, so that a bad avatar fails before any long work.
  raw_rig raw;
  rig r;
  rig_selection selection;
  if (!avatar.empty()) {
    status st = load_avatar(avatar, raw);
    if (st.ok()) st = build_rig(raw, r);
    if (st.ok()) {
      st = select_rig_binding(r, rig_option, selection);
      // A rig no table fits can still be driven by explicit --bind options alone.
      if (!st.ok() && !binds.empty() && rig_option == "auto") {
        selection.table = nullptr;
        selection.binding.fill(-1);
        selection.description = "bound by --bind only (no table fits)";
        st = status{};
      }
    }
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
      return 1;
    }
    for (const std::string& b : binds) {
      const size_t eq = b.find('=');
      const auto bone_id = eq == std::string::npos ? std::nullopt : bone_from_name(b.substr(0, eq));
      if (!bone_id) {
        std::fprintf(stderr,
                     "avatarmap convert: --bind wants BONE=JOINT with a VRM 1.0 bone name "
                     "(hips, leftUpperArm, ...), got '%s'\n",
                     b.c_str());
        return 2;
      }
      const std::string joint_name = b.substr(eq + 1);
      const int joint = joint_name == "none" ? -1 : r.find(joint_name);
      if (joint_name != "none" && joint < 0) {
        std::fprintf(stderr,
                     "avatarmap convert: --bind %s: the avatar has no joint '%s' (see `avatarmap "
                     "inspect %s`)\n",
                     b.c_str(), joint_name.c_str(), avatar.c_str());
        return 1;
      }
      // A joint drives one bone: taking it from another bone unbinds that one.
      for (int& j : selection.binding)
        if (joint >= 0 && j == joint) j = -1;
      selection.binding[idx(*bone_id)] = joint;
    }
    if (!binds.empty())
      selection.description += "; " + std::to_string(binds.size()) + " binding(s) from --bind";
  }

  std::vector<proxy_pose> frames;
  double source_fps = 0.0;
  status st = load_motion(a.rest()[0], solve, frames, source_fps);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
    return 1;
  }
  if (frames.empty()) {
    std::fprintf(stderr, "avatarmap convert: %s has no frames\n", a.rest()[0].c_str());
    return 1;
  }
  const double out_fps = fps_given ? fps : k_default_rig_fps;
  // Resampling needs the frames in time order; landmark and pose files need not be (a capture
  // may end with a frame stamped before its first). Sorted here (stably, so at equal times the
  // later line wins), with a warning; .pose.jsonl without --fps passes them through as read.
  const bool pass_through = to_pose && !fps_given;
  if (!pass_through) {
    if (const std::size_t moved = sort_clip_by_time(frames); moved > 0)
      std::fprintf(stderr,
                   "avatarmap convert: warning: %zu frame(s) of %s were out of time order; "
                   "sorted by time before resampling\n",
                   moved, a.rest()[0].c_str());
  }
  // The library writes every format (clip_output_job): resampling bounded by resample_clip,
  // avatar outputs (.glb, and .bvh with --avatar) retargeted onto the rig.
  clip_output_job out;
  out.path = out_path;
  out.frames = &frames;
  out.fps = pass_through ? 0.0 : out_fps;
  out.source_fps = source_fps;
  out.what = a.rest()[0];
  if (!avatar.empty()) {
    out.avatar_path = avatar;
    out.avatar_rig = &r;
    out.avatar_binding = selection.binding;
    out.avatar_table = selection.table;
  }
  out.keep_feet_on_ground = ground;
  out.root_motion = root_motion;
  const bool to_rig = format->uses_avatar && !avatar.empty();
  const bool dump = !dump_path.empty() && format->uses_avatar;  // .glb and .bvh
  std::vector<proxy_pose> sampled;
  std::vector<rig_pose> poses;
  if (dump) {
    out.out_frames = &sampled;
    out.out_rig_poses = &poses;
  }
  clip_output_summary written;
  st = out.run(written);
  if (st.ok() && dump)
    st = dump_positions(dump_path, out_fps, sampled, to_rig ? &r : nullptr, poses);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
    return 1;
  }
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (!quiet) {
    char fps_text[48];  // --fps is within (0, 1000]: "%g" stays short
    std::snprintf(fps_text, sizeof fps_text, " at %g fps", out_fps);
    std::fprintf(stderr, "converted %zu input frames (%s s) into %zu frames%s in %.3f s\n",
                 frames.size(), seconds_text(frames.back().t - frames.front().t, 2).c_str(),
                 written.frames_written, pass_through ? "" : fps_text, secs);
    if (!avatar.empty())
      std::fprintf(stderr, "avatar %s: %d joints; %s\n", avatar.c_str(), r.joint_count(),
                   selection.description.c_str());
    std::fprintf(stderr, "wrote %s\n", out_path.c_str());
  }
  return 0;
}

}  // namespace avatarmap::cli
