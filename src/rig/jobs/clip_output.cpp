#include "avatarmap/jobs/clip_output.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "avatarmap/export/animated_glb.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/retarget_clip.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "common/file_extension.hpp"

namespace avatarmap {

namespace {

using jobs_detail::ends_with_nocase;

// "PATH: message" unless the message already names PATH.
std::string naming(const std::string& path, const std::string& msg) {
  return msg.find(path) != std::string::npos ? msg : path + ": " + msg;
}

bool writes_on_avatar(const clip_format_info& f, const std::string& avatar_path) {
  return f.uses_avatar && !avatar_path.empty();
}

}  // namespace

const clip_format_info* find_clip_format(std::string_view path) {
  // Longest extension first would matter if one ended another; none does today
  // (".pose.jsonl" is the only two-part one), so table order is fine.
  for (const clip_format_info& f : k_clip_formats)
    if (ends_with_nocase(path, f.extension)) return &f;
  return nullptr;
}

std::string clip_format_list() {
  std::string s;
  for (std::size_t i = 0; i < k_clip_formats.size(); ++i) {
    if (i > 0) s += i + 1 == k_clip_formats.size() ? " or " : ", ";
    s += k_clip_formats[i].extension;
  }
  return s;
}

status clip_format_for(const std::string& path, const clip_format_info*& out) {
  out = find_clip_format(path);
  if (out == nullptr)
    return status::error(path + ": unknown output format; the name must end in " +
                         clip_format_list() + " (any case)");
  return {};
}

status clip_output_job::validate() const {
  const clip_format_info* format = nullptr;
  if (status st = clip_format_for(path, format); !st.ok()) return st;
  if (!(std::isfinite(fps) && fps >= 0.0 && fps <= k_max_output_fps))
    return status::error(path + ": fps must be 0 (the frames' own times) or in (0, " +
                         limit_text(k_max_fps) + "], got " + seconds_text(fps, 6));
  if (frames == nullptr) return status::error(path + ": clip_output_job.frames is not set");
  if (frames->empty())
    return status::error(path + ": the clip has no frames; add frames before writing it");
  if (format->needs_avatar && avatar_path.empty())
    return status::error(path + ": " + std::string(format->extension) +
                         " output needs an avatar (the model to animate)");
  const std::string& name = what.empty() ? path : what;
  double t_min = frames->front().t, t_max = t_min;
  for (std::size_t i = 0; i < frames->size(); ++i) {
    const double t = (*frames)[i].t;
    if (!std::isfinite(t))
      return status::error(name + ": frame " + std::to_string(i) + " has no finite time (t = " +
                           seconds_text(t) + "); every frame needs a time in seconds");
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  // The span and the output size before any work, for every format: an avatar output at fps 0
  // is written at k_default_rig_fps, the others keep one frame per frame (1 fps stands in for
  // the span check alone). min/max rather than first/last: a .pose.jsonl at fps 0 passes the
  // frames through in their own order.
  const double checked_fps = fps > 0.0                                ? fps
                             : writes_on_avatar(*format, avatar_path) ? k_default_rig_fps
                                                                      : 1.0;
  std::size_t count = 0;
  return resampled_frame_count(t_min, t_max, checked_fps, name, count);
}

status clip_output_job::run(clip_output_summary& s) const {
  s = clip_output_summary{};
  if (status st = validate(); !st.ok()) return st;
  const clip_format_info& format = *find_clip_format(path);
  s.format = &format;
  const std::string& name = what.empty() ? path : what;
  const bool on_avatar = writes_on_avatar(format, avatar_path);
  if (on_avatar && avatar_rig == nullptr)
    return status::invalid_argument(path +
                                    ": clip_output_job.avatar_rig is not set (build the rig of " +
                                    avatar_path + " first)");

  // One resampling for every format (resample_clip: in-order times, equal times allowed, the
  // later frame winning); the writers then get frames at fixed steps from t = 0.
  const double rate = fps > 0.0 ? fps : on_avatar ? k_default_rig_fps : 0.0;
  std::vector<proxy_pose> resampled;
  if (rate > 0.0) {
    if (status st = resample_clip(*frames, rate, true, resampled, name); !st.ok()) return st;
  }
  const std::vector<proxy_pose>& written = rate > 0.0 ? resampled : *frames;
  s.fps = rate;
  s.frames_written = written.size();

  std::vector<rig_pose> rig_poses;
  if (on_avatar) {
    retarget_clip_job rj;
    rj.frames = &written;
    rj.target = avatar_rig;
    rj.binding = avatar_binding;
    rj.table = avatar_table;
    rj.keep_feet_on_ground = keep_feet_on_ground;
    rj.root_motion = root_motion;
    rj.foot_lock = foot_lock;
    rj.what = name;
    if (status st = rj.run(rig_poses, &s.standing_hips_height, &s.foot_lock_warning); !st.ok())
      return st.code() == status_code::parse ? st.with_message(naming(avatar_path, st.message()))
                                             : st;
  }

  // Proxy outputs: the feet locked on the proxy skeleton the writers use, when the clip has
  // contacts at all (a clip without any is written exactly as given).
  std::vector<proxy_pose> locked;
  const bool proxy_output =
      format.format == clip_format::vrma || (format.format == clip_format::bvh && !on_avatar);
  if (proxy_output && foot_lock.enabled &&
      std::any_of(written.begin(), written.end(), [](const proxy_pose& p) {
        return p.foot_contact[0] > 0.f || p.foot_contact[1] > 0.f;
      })) {
    locked = written;
    if (status st = lock_feet(locked, foot_lock); !st.ok()) return st;
  }
  const std::vector<proxy_pose>& proxy_frames = locked.empty() ? written : locked;

  status st;
  switch (format.format) {
    case clip_format::vrma: {
      st = write_vrma(path, proxy_frames);  // at the written frames' own (resampled) times
      break;
    }
    case clip_format::bvh: {
      if (on_avatar) {
        rig_bvh_options o;
        o.fps = rate;
        st = write_rig_bvh(path, *avatar_rig, rig_poses, o);
      } else {
        bvh_write_options o;
        o.fps = rate;  // Frame Time 1 / fps (0: the frames' mean spacing)
        st = write_bvh(path, proxy_frames, o);
      }
      break;
    }
    case clip_format::pose_jsonl: {
      pose_writer w;
      pose_file_header h;
      h.present = true;
      h.fps = rate > 0.0 ? rate : source_fps;
      st = w.open(path, h);
      for (std::size_t i = 0; st.ok() && i < written.size(); ++i) st = w.write(written[i]);
      if (st.ok()) st = w.commit();
      break;
    }
    case clip_format::glb: {
      animated_glb_options o;
      o.fps = rate;
      o.expressions = &written;  // the face: one proxy pose per rig pose (retarget_clip_job)
      st = write_animated_glb(avatar_path, *avatar_rig, rig_poses, o, path);
      break;
    }
  }
  if (!st.ok()) return st.is_out_of_memory() ? st : st.with_message(naming(path, st.message()));
  if (out_frames != nullptr) *out_frames = proxy_frames;
  if (out_rig_poses != nullptr) *out_rig_poses = std::move(rig_poses);
  return {};
}

}  // namespace avatarmap
