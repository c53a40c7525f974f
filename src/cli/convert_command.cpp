// `avatarmap convert IN -o OUT [--avatar AVATAR] [--rig auto|NAME|FILE.json] [--fps N]`:
// landmarks, proxy poses or VRM Animation in; VRMA, animated GLB, BVH or proxy poses out.
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/core/limits.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "avatarmap/jobs/people.hpp"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/filter_option.hpp"
#include "cli/option_flags.hpp"
#include "cli/solve_job.hpp"
#include "common/atomic_file.hpp"

namespace avatarmap::cli {
namespace {

const char* k_convert_help =
    "Usage: avatarmap convert IN -o OUT [options]\n"
    "\n"
    "IN:  *.landmarks.jsonl (solved as by `avatarmap solve`), *.pose.jsonl, *.vrma or *.bvh\n"
    "     (mocap on its own skeleton, bound by the mapping tables)\n"
    "OUT: *.vrma (VRM Animation), *.glb (the avatar with the motion; the built-in avatar\n"
    "     unless --avatar),\n"
    "     *.bvh (centimetres, ZXY: the avatar's own rig with --avatar, else the proxy\n"
    "     skeleton), *.pose.jsonl\n"
    "\n"
    "Options:\n";

// convert's own flags; the landmark solve's come from the solver and solve-file tables
// (k_convert_solve_flags).
const cli_flag k_convert_flags[] = {
    {"--output", "-o", "PATH", "output file (required; written atomically)"},
    {"--avatar", nullptr, "FILE",
     "the avatar (.vrm, .glb, .gltf, or a .bvh's skeleton) to drive (.glb: the built-in avatar "
     "when not given, as `avatarmap avatar` writes it; with .bvh: write its rig instead of "
     "the proxy skeleton). Repeat it for a file of several people: person i (in id order) "
     "drives the i-th avatar, cycling"},
    {"--rig", nullptr, "auto|NAME|FILE.json",
     "how the avatar's joints map to the proxy: auto (default) uses a VRM's own humanoid map, "
     "else the best shipped table (mixamo, unity_humanoid, ue4_mannequin, ue5_mannequin, "
     "character_creator, ...); NAME picks a shipped table; FILE.json a table of yours"},
    {"--bind", nullptr, "BONE=JOINT",
     "bind a proxy bone (VRM 1.0 name) to an avatar joint, or to none; repeatable; overrides "
     "--rig, and alone drives a rig no table fits"},
    {"--fps", nullptr, "N",
     "output frame rate (default 30; .pose.jsonl: the input's frames; 0: the frames' own "
     "times; at most 1000)"},
    {"--ground", nullptr, nullptr, "keep the avatar's lowest foot on the floor every frame"},
    {"--no-root-motion", nullptr, nullptr, "keep the hips where they are at rest"},
    {"--no-foot-lock", nullptr, nullptr,
     "let planted feet slide: no foot locking, no hips lowering, no floor clamp (see "
     "docs/foot-locking.md)"},
    {"--image-size", nullptr, "WxH", "landmark input: image size in pixels, as for solve"},
    {"--filter", nullptr, "offline|live|none", "landmark input: the filter, as for solve"},
    {"--parts", nullptr, "LIST", k_parts_flag_help},
    {"--quiet", nullptr, nullptr, "no summary"},
};
// The solve-file table's flags convert takes for a landmark input (its --fps is the output's).
#define AVATARMAP_CONVERT_SOLVE_FLAGS                                           \
  {                                                                             \
    "--smoothing", "--min-cutoff", "--beta", "--threads", "--skip-bad-lines",   \
        "--no-foot-contacts", "--no-root-follow", "--person", "--origin-person" \
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

// The built-in avatar (avatar/builtin_avatar.hpp) in a private temporary file
// ($TMPDIR/avatarmap-builtin-XXXXXX.vrm) for as long as this object lives; registered for
// removal on a signal.
class builtin_avatar_file {
 public:
  builtin_avatar_file() = default;
  builtin_avatar_file(const builtin_avatar_file&) = delete;
  builtin_avatar_file& operator=(const builtin_avatar_file&) = delete;
  ~builtin_avatar_file() {
    if (!path_.empty()) std::remove(path_.c_str());
  }
  status write() {
    std::string glb;
    if (status st = builtin_avatar_glb(builtin_avatar_options{}, glb); !st.ok()) return st;
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    if (ec) dir = ".";
    std::string name = (dir / "avatarmap-builtin-XXXXXX.vrm").string();
    const int fd = ::mkstemps(name.data(), 4);
    if (fd < 0)
      return status::error("cannot create a temporary file in " + dir.string() + ": " +
                           std::strerror(errno));
    path_ = name;
    registration_ = std::make_unique<io_detail::temp_file_registration>(path_);
    const int err = io_detail::write_all(fd, glb.data(), glb.size());
    ::close(fd);
    if (err != 0) return status::error("cannot write " + path_ + ": " + std::strerror(err));
    return {};
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::unique_ptr<io_detail::temp_file_registration> registration_;
};

// What to do when the avatar's binding failed on its tables (parse: the table, or every
// table, lacks bones the rig needs, or a table is malformed): the library says what did not
// fit, the command line says which options change it.
std::string binding_hint(const convert_file_job& job, const convert_file_summary& done,
                         const status& st) {
  if (!done.avatar || done.avatar->failed_step != bind_avatar_step::select ||
      st.code() != status_code::parse)
    return {};
  const std::string& folder = done.avatar->mappings_folder;
  return "\nTo drive this rig with convert or animate: name a table that fits with --rig NAME (" +
         (folder.empty() ? std::string("a shipped table") : "a table in " + folder) +
         ") or --rig FILE.json (your own, see docs/mappings.md), or bind the bones yourself with "
         "--bind BONE=JOINT (repeatable, e.g. --bind hips=Pelvis; `avatarmap inspect " +
         job.avatar + "` lists the joints)";
}

// One conversion: the avatar (the built-in one for a .glb without --avatar), the rate, the run.
int convert_one(convert_file_job& job, bool fps_given, double fps, bool quiet,
                const std::string& dump_path) {
  // A .glb without --avatar carries the built-in avatar (as `view` shows it): written to a
  // private temporary file that the binding and the writer read, removed at the end (or by
  // the signal handlers, main.cpp).
  const clip_format_info* glb = find_clip_format(job.output);
  builtin_avatar_file builtin;
  if (glb != nullptr && glb->needs_avatar && job.avatar.empty()) {
    if (status st = builtin.write(); !st.ok()) {
      std::fprintf(stderr, "avatarmap convert: the built-in avatar: %s\n", st.message().c_str());
      return 1;
    }
    job.avatar = builtin.path();
  }
  // Without --fps: 30 frames/s, except .pose.jsonl, which keeps the frames' own times.
  const clip_format_info* format = find_clip_format(job.output);
  job.fps = fps_given                                                        ? fps
            : format != nullptr && format->format == clip_format::pose_jsonl ? 0.0
                                                                             : k_default_rig_fps;
  if (status st = job.validate(); !st.ok()) {
    std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
    return 2;
  }
  const bool show_progress = shows_progress(progress_mode::automatic);
  if (show_progress) job.solve.progress = print_solve_progress;
  job.warning = [](const std::string& w) {
    std::fprintf(stderr, "avatarmap convert: warning: %s\n", w.c_str());
  };
  const bool dump = !dump_path.empty() && format->uses_avatar;  // .glb and .bvh
  std::vector<proxy_pose> sampled;
  std::vector<rig_pose> poses;
  if (dump) {
    job.out_frames = &sampled;
    job.out_rig_poses = &poses;
  }
  convert_file_summary done;
  status st = job.run(done);
  if (show_progress && done.solve.frames > 0) std::fputs("\r", stderr);
  if (st.ok() && dump)
    st = dump_positions(dump_path, done.output.fps, sampled,
                        done.avatar ? &done.avatar->rig : nullptr, poses);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap convert: %s%s\n", st.message().c_str(),
                 binding_hint(job, done, st).c_str());
    return 1;
  }
  if (!quiet) {
    char fps_text[48];  // --fps is within (0, 1000]: "%g" stays short
    std::snprintf(fps_text, sizeof fps_text, " at %g fps", done.output.fps);
    std::fprintf(stderr, "converted %zu input frames (%s s) into %zu frames%s in %.3f s\n",
                 done.frames_read, seconds_text(done.t_last - done.t_first, 2).c_str(),
                 done.output.frames_written, done.output.fps > 0.0 ? fps_text : "", done.seconds);
    if (done.avatar)
      std::fprintf(stderr, "avatar %s: %d joints; %s\n",
                   builtin.path().empty() ? job.avatar.c_str() : "(built-in)",
                   done.avatar->rig.joint_count(), done.avatar->description.c_str());
    std::fprintf(stderr, "wrote %s\n", job.output.c_str());
  }
  return 0;
}

}  // namespace

void add_convert_command_flag_specs(std::vector<flag_spec>& out) {
  const solve_file_job start = make_cli_solve_job();
  add_flag_specs(k_convert_flags, out);
  add_flag_specs(k_solver_option_table, start.options, out);
  add_flag_specs(k_solve_file_option_table, start, out, AVATARMAP_CONVERT_SOLVE_FLAGS);
}

int run_convert(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    const solve_file_job start = make_cli_solve_job();
    std::fputs(k_convert_help, stdout);
    std::fputs(cli_flags_help(k_convert_flags).c_str(), stdout);
    std::fputs("\nLandmark input (solved as by `avatarmap solve`):\n", stdout);
    std::fputs(option_flags_help(k_solver_option_table, start.options).c_str(), stdout);
    std::fputs(
        option_flags_help(k_solve_file_option_table, start, AVATARMAP_CONVERT_SOLVE_FLAGS).c_str(),
        stdout);
    return 0;
  }
  convert_file_job job;
  job.avatar_name = "--avatar AVATAR";
  job.binding.overrides_name = "--bind";
  std::string value;
  a.value("--output", job.output, "-o");
  std::vector<std::string> avatars;  // --avatar A, repeatable: person i gets avatar i mod n
  while (a.value("--avatar", value)) avatars.push_back(value);
  if (!avatars.empty()) job.avatar = avatars.front();
  a.value("--rig", job.binding.rig);
  while (a.value("--bind", value)) {  // --bind BONE=JOINT, repeatable
    bone_override o;
    if (status st = parse_bone_override(value, o); !st.ok()) {
      std::fprintf(stderr, "avatarmap convert: --bind %s\n", st.message().c_str());
      return 2;
    }
    job.binding.overrides.push_back(o);
  }
  std::string dump_path;  // hidden diagnostic option, see dump_positions()
  a.value("--dump-positions", dump_path);
  double fps = 0.0;
  const bool fps_given = a.number("--fps", fps);
  job.keep_feet_on_ground = a.flag("--ground");
  job.root_motion = !a.flag("--no-root-motion");
  job.foot_lock.enabled = !a.flag("--no-foot-lock");
  const bool quiet = a.flag("--quiet");
  job.solve = make_cli_solve_job();
  std::string error;
  if (!parse_option_flags(a, k_solver_option_table, job.solve.options, error) ||
      !parse_option_flags(a, k_solve_file_option_table, job.solve, error,
                          AVATARMAP_CONVERT_SOLVE_FLAGS)) {
    std::fprintf(stderr, "avatarmap convert: %s\n", error.c_str());
    return 2;
  }
  if (!parse_parts_flag(a, job.solve.options.parts, error)) {
    std::fprintf(stderr, "avatarmap convert: landmark input: %s\n", error.c_str());
    return 2;
  }
  if (a.value("--image-size", value)) {
    int w = 0, h = 0;
    if (!parse_image_size(value, w, h)) {
      std::fprintf(stderr, "avatarmap convert: --image-size wants WxH in pixels, e.g. 1280x720\n");
      return 2;
    }
    job.solve.image_width = float(w);
    job.solve.image_height = float(h);
  }
  if (a.value("--filter", value) && !apply_filter_option(value, job.solve)) {
    std::fprintf(stderr, "avatarmap convert: --filter is %s, got '%s'\n", k_filter_names,
                 value.c_str());
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1 || job.output.empty()) {
    std::fprintf(stderr, "avatarmap convert: %s\n",
                 !a.error().empty()     ? a.error().c_str()
                 : a.rest().size() != 1 ? "give exactly one input file (see --help)"
                                        : "give the output with -o OUT (see --help)");
    return 2;
  }
  if (fps_given && !(fps >= 0.0 && fps <= k_max_fps)) {
    std::fprintf(stderr, "avatarmap convert: --fps must be 0 or in (0, %s], got %s\n",
                 limit_text(k_max_fps).c_str(), limit_text(fps).c_str());
    return 2;
  }
  job.input = a.rest()[0];
  // A landmark file of several people: one run per person (jobs/people.hpp).
  std::vector<person_run> runs;
  const motion_input_info* kind = nullptr;
  if (find_motion_input(job.input, kind).ok() && kind->kind == motion_input::landmarks) {
    if (status st = plan_person_runs(job.input, job.solve.person, job.output, runs); !st.ok()) {
      std::fprintf(stderr, "avatarmap convert: %s\n", st.message().c_str());
      return st.code() == status_code::invalid_argument ? 2 : 1;
    }
  } else if (job.solve.person >= 0) {
    std::fprintf(stderr, "avatarmap convert: --person applies to a landmark input only\n");
    return 2;
  }
  if (runs.size() > 1) {
    for (std::size_t i = 0; i < runs.size(); ++i) {
      convert_file_job one = job;
      one.solve.person = runs[i].person;
      one.output = runs[i].output;
      if (!avatars.empty()) one.avatar = avatars[i % avatars.size()];
      if (!quiet) std::fprintf(stderr, "person %d -> %s\n", runs[i].person, one.output.c_str());
      if (const int rc = convert_one(one, fps_given, fps, quiet, dump_path); rc != 0) return rc;
    }
    return 0;
  }
  if (runs.size() == 1) job.solve.person = runs[0].person;
  return convert_one(job, fps_given, fps, quiet, dump_path);
}

}  // namespace avatarmap::cli
