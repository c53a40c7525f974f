#include "avatarmap/jobs/convert_file.hpp"

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/rig/bvh_rig.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "common/file_extension.hpp"

namespace avatarmap {

namespace {

using jobs_detail::ends_with_nocase;

const motion_input_info& info_of(motion_input kind) {
  for (const motion_input_info& i : k_motion_inputs)
    if (i.kind == kind) return i;
  return k_motion_inputs[0];
}

// Rule 3 of find_motion_input: the kind the first bytes of a regular file name, or null. Reads
// at most one short line; a file that cannot be opened is left to the reader to report.
const motion_input_info* sniff(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return nullptr;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return nullptr;
  char buf[256];
  const std::size_t n = std::fread(buf, 1, sizeof buf, f);
  std::fclose(f);
  const std::string_view head(buf, n);
  if (head.substr(0, 4) == "glTF") return &info_of(motion_input::vrma);
  const std::string_view line = head.substr(0, head.find('\n'));
  if (line.empty() || line.front() != '{') return nullptr;
  // The header the writers put first: {"format":"avatarmap.pose",...} (spaces allowed).
  const std::size_t key = line.find("\"format\"");
  if (key == std::string_view::npos) return nullptr;
  std::string_view rest = line.substr(key + 8);
  while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t' || rest.front() == ':'))
    rest.remove_prefix(1);
  if (rest.substr(0, 16) == "\"avatarmap.pose\"") return &info_of(motion_input::poses);
  if (rest.substr(0, 21) == "\"avatarmap.landmarks\"") return &info_of(motion_input::landmarks);
  return nullptr;
}

std::string without_suffix(const std::string& path, std::size_t n) {
  return path.substr(0, path.size() - n);
}

status read_pose_file(const std::string& path, motion_clip& out) {
  pose_reader reader;
  if (status st = reader.open(path); !st.ok()) return st;
  out.source_fps = reader.header().fps;
  proxy_pose p;
  for (;;) {
    const read_result r = reader.next(p);
    if (r == read_result::end) return {};
    if (r == read_result::error) return status::failure(reader.error_code(), reader.error());
    out.frames.push_back(p);
  }
}

}  // namespace

std::string motion_input_list() {
  std::string s;
  for (std::size_t i = 0; i < k_motion_inputs.size(); ++i) {
    if (i > 0) s += i + 1 == k_motion_inputs.size() ? " or " : ", ";
    s += "*";
    s += k_motion_inputs[i].extension;
  }
  return s;
}

status find_motion_input(const std::string& path, const motion_input_info*& out,
                         std::string* out_stem) {
  out = nullptr;
  for (const motion_input_info& i : k_motion_inputs) {
    if (ends_with_nocase(path, i.extension)) {
      out = &i;
      if (out_stem != nullptr) *out_stem = without_suffix(path, i.extension.size());
      return {};
    }
  }
  if (path == "-") {
    out = &info_of(motion_input::landmarks);
    if (out_stem != nullptr) *out_stem = path;
    return {};
  }
  const std::size_t slash = path.rfind('/');
  const std::size_t dot = path.rfind('.');
  const std::size_t ext = dot != std::string::npos && (slash == std::string::npos || dot > slash)
                              ? path.size() - dot
                              : 0;
  out = sniff(path);
  if (out == nullptr && ends_with_nocase(path, ".jsonl")) out = &info_of(motion_input::landmarks);
  if (out != nullptr) {
    if (out_stem != nullptr) *out_stem = without_suffix(path, ext);
    return {};
  }
  return status::invalid_argument(path + ": unknown input type (give " + motion_input_list() + ")");
}

status read_motion(const std::string& path, const solve_file_job* solve, motion_clip& out) {
  out = motion_clip{};
  if (status st = find_motion_input(path, out.input); !st.ok()) return st;
  status st;
  switch (out.input->kind) {
    case motion_input::vrma: {
      vrma_clip clip;
      st = read_vrma(path, clip);
      out.frames = std::move(clip.frames);
      break;
    }
    case motion_input::poses:
      st = read_pose_file(path, out);
      break;
    case motion_input::bvh: {
      bvh_motion_summary bvh;
      st = read_bvh_motion(path, bvh_motion_options{}, out.frames, &bvh);
      if (st.ok() && bvh.frame_time > 0.0) out.source_fps = 1.0 / bvh.frame_time;
      break;
    }
    case motion_input::landmarks: {
      if (solve == nullptr)
        return status::invalid_argument(
            path + ": a landmark file, not poses: solve it first (as `avatarmap solve` does)");
      solve_file_job job = *solve;
      job.input = path;
      job.output.clear();
      job.source = nullptr;
      std::vector<proxy_pose>& frames = out.frames;
      job.sink = [&frames](const proxy_pose& p) {
        frames.push_back(p);
        return status{};
      };
      st = job.run(out.solve);
      out.source_fps = out.solve.fps;  // the landmarks' nominal rate, as `avatarmap solve` writes
      break;
    }
  }
  if (!st.ok()) {
    out.frames.clear();
    return st;
  }
  out.out_of_order = sort_clip_by_time(out.frames);
  return {};
}

status convert_file_job::validate() const {
  if (input.empty()) return status::invalid_argument("convert_file_job.input is not set");
  if (output.empty()) return status::invalid_argument("convert_file_job.output is not set");
  const clip_format_info* format = nullptr;
  if (status st = clip_format_for(output, format); !st.ok()) return st;
  if (!(std::isfinite(fps) && fps >= 0.0 && fps <= k_max_output_fps))
    return status::invalid_argument(output + ": fps must be 0 (the frames' own times) or in (0, " +
                                    seconds_text(k_max_output_fps, 0) + "], got " +
                                    seconds_text(fps, 6));
  if (format->needs_avatar && avatar.empty())
    return status::invalid_argument(std::string(format->extension) + " output needs " +
                                    avatar_name + " (the model to animate)");
  if (format->needs_avatar && ends_with_nocase(avatar, ".bvh"))
    return status::invalid_argument(
        std::string(format->extension) + " output needs a glTF or VRM avatar (a mesh to " +
        "animate); " + avatar + " is a BVH skeleton: write .bvh with it instead");
  // The solve's own fields (a landmark input is known only once the file is looked at).
  solve_file_job s = solve;
  s.input = input;
  s.sink = [](const proxy_pose&) { return status{}; };
  return s.validate();
}

status convert_file_job::run(convert_file_summary& out) const {
  out = convert_file_summary{};
  const auto t_start = std::chrono::steady_clock::now();
  if (status st = validate(); !st.ok()) return st;
  const clip_format_info& format = *find_clip_format(output);
  if (status st = find_motion_input(input, out.input); !st.ok()) return st;

  // The avatar first, so that a bad avatar fails before any long work.
  std::shared_ptr<const bound_avatar> bound;
  if (format.uses_avatar && !avatar.empty()) {
    auto b = std::make_shared<bound_avatar>();
    const status st = bind_avatar(avatar, binding, *b);
    bound = out.avatar = std::move(b);  // kept on failure too: failed_step says where
    if (!st.ok()) return st;
  }

  motion_clip clip;
  solve_file_job s = solve;
  if (!s.warning && warning) s.warning = warning;
  if (status st = read_motion(input, &s, clip); !st.ok()) {
    out.solve = clip.solve;
    return st;
  }
  out.solve = clip.solve;
  out.source_fps = clip.source_fps;
  out.frames_read = clip.frames.size();
  out.out_of_order = clip.out_of_order;
  if (clip.frames.empty()) return status::invalid_argument(input + " has no frames");
  out.t_first = clip.frames.front().t;
  out.t_last = clip.frames.back().t;
  // Outputs at the frames' own times keep them; the others are resampled (avatar outputs at
  // fps 0 too: k_default_rig_fps).
  const bool resampled = fps > 0.0 || (format.uses_avatar && bound != nullptr);
  if (clip.out_of_order > 0 && warning)
    warning(std::to_string(clip.out_of_order) + " frame(s) of " + input +
            " were out of time order; sorted by time before " +
            (resampled ? "resampling" : "writing"));

  clip_output_job job;
  job.path = output;
  job.frames = &clip.frames;
  job.fps = fps;
  job.source_fps = clip.source_fps;
  job.what = input;
  if (bound != nullptr) {
    job.avatar_path = avatar;
    job.avatar_rig = &bound->rig;
    job.avatar_binding = bound->binding;
    job.avatar_table = bound->table();
  }
  job.keep_feet_on_ground = keep_feet_on_ground;
  job.root_motion = root_motion;
  job.foot_lock = foot_lock;
  job.out_frames = out_frames;
  job.out_rig_poses = out_rig_poses;
  if (status st = job.run(out.output); !st.ok()) return st;
  if (!out.output.foot_lock_warning.empty() && warning)
    warning(avatar + ": " + out.output.foot_lock_warning);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return {};
}

}  // namespace avatarmap
