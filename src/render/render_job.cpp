// include/avatarmap/render/render_job.hpp: the animation read (or, for a .glb, left to the
// page), the browser and the viewer's server started, the camera framed on the motion, then
// frame by frame: pose (or time) -> the page draws -> screenshot -> PNG decoded -> composed
// (beside the source video) -> video_writer. Everything the loop needs is allocated before it.
#include "avatarmap/render/render_job.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/capture/overlay.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/resources.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "avatarmap/jobs/retarget_clip.hpp"
#include "avatarmap/media/video_source.hpp"
#include "avatarmap/media/video_writer.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/stream/pose_server.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "common/file_extension.hpp"
#include "common/pose_text.hpp"
#include "render/devtools_pipe.hpp"
#include "render/png_decode.hpp"

namespace avatarmap {
namespace {

using clock_type = std::chrono::steady_clock;

bool is_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

enum class animation_kind { poses, vrma, bvh, glb, unknown };

animation_kind kind_of(const std::string& path) {
  using jobs_detail::ends_with_nocase;
  if (ends_with_nocase(path, ".pose.jsonl")) return animation_kind::poses;
  if (ends_with_nocase(path, ".vrma")) return animation_kind::vrma;
  if (ends_with_nocase(path, ".bvh")) return animation_kind::bvh;
  if (ends_with_nocase(path, ".glb")) return animation_kind::glb;
  return animation_kind::unknown;
}

std::string number_text(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string folder_or_first_tried(resource kind, const std::string& given) {
  if (!given.empty()) return given;
  resource_lookup r = find_resource(kind);
  if (!r.folder.empty() || r.tried.empty()) return r.folder;
  const std::string& last = r.tried.back();
  return last.substr(0, last.rfind(" ("));
}

// Base64 (the screenshot's "data") into `out` (reused), with `padding` zero bytes after it.
bool decode_base64(std::string_view text, std::vector<std::uint8_t>& out, std::size_t padding) {
  static const auto table = [] {
    std::array<std::int8_t, 256> t{};
    t.fill(-1);
    const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int i = 0; i < 64; ++i)
      t[static_cast<unsigned char>(digits[i])] = static_cast<std::int8_t>(i);
    return t;
  }();
  out.resize(text.size() / 4 * 3 + padding + 3);
  std::size_t n = 0;
  std::uint32_t acc = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    const int v = table[static_cast<unsigned char>(c)];
    if (v < 0) {
      if (c == '\\' || c == '\n' || c == '\r') continue;  // JSON may escape '/' as "\/"
      return false;
    }
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out[n++] = static_cast<std::uint8_t>((acc >> bits) & 0xFF);
    }
  }
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(n), out.end(), std::uint8_t{0});
  out.resize(n + padding);
  return true;
}

// The camera that keeps the motion's hips (avatar world, metres) and the body around them in
// view: looking along -Z from the front (the avatar faces +Z), horizontal field of view 50°.
struct framing {
  double cam[3];
  double look[3];
  double hfov = 50;
};

// The box the hips move in (finite values only); with none, the rest hips at X = Z = 0.
void hips_range(const std::vector<std::array<double, 3>>& hips, double rest_hips_y, double lo[3],
                double hi[3]) {
  for (int i = 0; i < 3; ++i) lo[i] = 1e30, hi[i] = -1e30;
  for (const auto& p : hips)
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(p[i])) continue;
      lo[i] = std::min(lo[i], p[i]);
      hi[i] = std::max(hi[i], p[i]);
    }
  for (int i = 0; i < 3; ++i)
    if (lo[i] > hi[i]) lo[i] = hi[i] = (i == 1 ? rest_hips_y : 0.0);
}

framing frame_motion(const std::vector<std::array<double, 3>>& hips, double rest_hips_y, int width,
                     int height) {
  double lo[3], hi[3];
  hips_range(hips, rest_hips_y, lo, hi);
  const double r = std::max(0.2, rest_hips_y);
  const double y_low = std::min(0.0, lo[1] - r);
  const double y_high = hi[1] + 1.0 * r;  // the head (and hands raised) above the hips
  const double half_w = (hi[0] - lo[0]) / 2 + 0.65 * r;
  const double aspect = static_cast<double>(width) / height;
  framing f;
  const double hfov = f.hfov * M_PI / 180;
  const double tan_h = std::tan(hfov / 2), tan_v = tan_h / aspect;
  const double d = std::max((y_high - y_low) / 2 * 1.12 / tan_v, half_w * 1.1 / tan_h) +
                   (hi[2] - lo[2]) / 2 + 0.25 * r;
  f.look[0] = (lo[0] + hi[0]) / 2;
  f.look[1] = (y_low + y_high) / 2;
  f.look[2] = (lo[2] + hi[2]) / 2;
  f.cam[0] = f.look[0];
  f.cam[1] = f.look[1] + 0.08 * d;
  f.cam[2] = f.look[2] + d;
  return f;
}

// The head in close-up: the head's rest height above the hips (0.83 of the hips' rest height:
// the built-in avatar's eyes, 0.79 m above 0.95 m hips) over the middle of the hips' range,
// k_face_view_height metres of height in view plus the range the hips move up and down, the
// camera level with the face.
constexpr double k_face_view_height = 0.5;
constexpr double k_head_over_hips = 0.83;

framing frame_face(const std::vector<std::array<double, 3>>& hips, double rest_hips_y, int width,
                   int height) {
  double lo[3], hi[3];
  hips_range(hips, rest_hips_y, lo, hi);
  framing f;
  const double aspect = static_cast<double>(width) / height;
  const double tan_v = std::tan(f.hfov * M_PI / 180 / 2) / aspect;
  const double d = (k_face_view_height + (hi[1] - lo[1])) / 2 / tan_v + (hi[2] - lo[2]) / 2;
  f.look[0] = f.cam[0] = (lo[0] + hi[0]) / 2;
  f.look[1] = f.cam[1] = (lo[1] + hi[1]) / 2 + k_head_over_hips * std::max(0.2, rest_hips_y);
  f.look[2] = (lo[2] + hi[2]) / 2;
  f.cam[2] = f.look[2] + d;
  return f;
}

// Nearest-neighbour scale of `src` (RGB8) to fit inside the w x h panel at `dst`, centred.
struct panel_scaler {
  std::vector<int> xs, ys;
  int ox = 0, oy = 0;
  void plan(int sw, int sh, int w, int h) {
    const double s = std::min(static_cast<double>(w) / sw, static_cast<double>(h) / sh);
    const int dw = std::max(1, std::min(w, static_cast<int>(std::lround(sw * s))));
    const int dh = std::max(1, std::min(h, static_cast<int>(std::lround(sh * s))));
    ox = (w - dw) / 2;
    oy = (h - dh) / 2;
    xs.resize(static_cast<std::size_t>(dw));
    ys.resize(static_cast<std::size_t>(dh));
    for (int x = 0; x < dw; ++x) xs[x] = std::min(sw - 1, static_cast<int>((x + 0.5) / s));
    for (int y = 0; y < dh; ++y) ys[y] = std::min(sh - 1, static_cast<int>((y + 0.5) / s));
  }
  void run(const std::uint8_t* src, int src_stride, std::uint8_t* dst, int dst_stride) const {
    for (std::size_t y = 0; y < ys.size(); ++y) {
      const std::uint8_t* row = src + static_cast<std::ptrdiff_t>(ys[y]) * src_stride;
      std::uint8_t* out = dst + static_cast<std::ptrdiff_t>(oy + static_cast<int>(y)) * dst_stride +
                          static_cast<std::ptrdiff_t>(ox) * 3;
      for (std::size_t x = 0; x < xs.size(); ++x) std::memcpy(out + 3 * x, row + 3 * xs[x], 3);
    }
  }
};

status check_finite(const std::vector<proxy_pose>& frames, const std::string& what) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const proxy_pose& p = frames[i];
    bool ok = std::isfinite(p.t) && std::isfinite(p.hips_position.x) &&
              std::isfinite(p.hips_position.y) && std::isfinite(p.hips_position.z);
    for (const glm::quat& q : p.rotations)
      ok = ok && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
           std::isfinite(q.w);
    for (const float e : p.expressions) ok = ok && std::isfinite(e);
    if (!ok)
      return status::parse_error(what + ": frame " + std::to_string(i + 1) +
                                 " has a value that is not a finite number; fix or drop it");
  }
  return {};
}

// The value of a Runtime.evaluate reply ("result":{"result":{"type":..,"value":V}}).
status reply_value(const std::string& reply, nlohmann::json& out) {
  try {
    out = nlohmann::json::parse(reply).at("result").at("result").value("value", nlohmann::json());
  } catch (const std::exception& e) {
    return status::internal(std::string("render: an unexpected reply from the page: ") + e.what());
  }
  return {};
}

}  // namespace

status render_options::validate() const {
  if (animation.empty()) return status::error("render: no animation given");
  if (output.empty()) return status::error("render: no output given (-o OUT.mp4)");
  using jobs_detail::ends_with_nocase;
  if (!ends_with_nocase(output, ".mp4") && !ends_with_nocase(output, ".mov") &&
      !ends_with_nocase(output, ".mkv"))
    return status::error("render: " + output + ": the output must be a .mp4, .mov or .mkv video");
  if (width < 16 || width > 4096 || height < 16 || height > 4096)
    return status::error("render: the size must be 16..4096 pixels a side, got " +
                         std::to_string(width) + "x" + std::to_string(height));
  if (!video.empty() && width < 32)
    return status::error("render: beside a video the width must be at least 32");
  if (!(fps == 0 || (std::isfinite(fps) && fps >= 1 && fps <= 240)))
    return status::error(
        "render: the frame rate must be 1..240 frames per second (or 0: the "
        "animation's own), got " +
        number_text(fps));
  for (const double t : stills)
    if (!std::isfinite(t) || t < 0)
      return status::error("render: a still's time must be a number of seconds >= 0, got " +
                           number_text(t));
  if (!landmarks.empty() && video.empty())
    return status::error(
        "render: landmarks are drawn on the source video: give it too "
        "(--video SOURCE.mp4)");
  if (kind_of(animation) == animation_kind::glb && !avatar.empty())
    return status::error("render: " + animation +
                         " is an avatar with its animation: it needs "
                         "no --avatar");
  if (!(step_timeout_s > 0)) return status::error("render: step_timeout_s must be > 0");
  return {};
}

std::string render_still_path(const std::string& output, double t) {
  const std::size_t slash = output.rfind('/');
  const std::size_t dot = output.rfind('.');
  const std::string stem =
      dot != std::string::npos && (slash == std::string::npos || dot > slash + 1)
          ? output.substr(0, dot)
          : output;
  return stem + "_t" + number_text(t) + ".png";
}

std::string find_render_browser(const std::string& chromium) {
  if (!chromium.empty()) {
    if (chromium.find('/') != std::string::npos)
      return ::access(chromium.c_str(), X_OK) == 0 ? chromium : "";
  }
  const char* path = std::getenv("PATH");
  const std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
  const std::vector<std::string> names =
      chromium.empty() ? std::vector<std::string>{"chromium", "chromium-browser", "google-chrome"}
                       : std::vector<std::string>{chromium};
  for (const std::string& name : names) {
    for (std::size_t start = 0; start <= dirs.size();) {
      std::size_t end = dirs.find(':', start);
      if (end == std::string::npos) end = dirs.size();
      const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
      const std::string candidate = dir + "/" + name;
      if (is_file(candidate) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
      start = end + 1;
    }
  }
  return {};
}

status render_job(const render_options& o,
                  const std::function<void(const render_progress&)>& progress,
                  render_summary* summary) {
  const auto started = clock_type::now();
  if (status st = o.validate(); !st) return st;
  const animation_kind kind = kind_of(o.animation);
  if (!is_file(o.animation)) return status::io_error("render: " + o.animation + ": no such file");
  if (kind == animation_kind::unknown)
    return status::error("render: " + o.animation +
                         ": not an animation render knows by its extension: give a .vrma, a "
                         ".pose.jsonl, a .bvh or an avatar .glb with its animation");
  const std::string browser_path = find_render_browser(o.chromium);
  if (browser_path.empty())
    return status::unsupported(
        o.chromium.empty()
            ? "render: no chromium found on the PATH: install Debian's chromium: sudo apt-get "
              "install chromium"
            : "render: the browser " + o.chromium +
                  " is not an executable; install Debian's "
                  "chromium: sudo apt-get install chromium");
  if (!video_writer_available())
    return status::unsupported("render: this build has no FFmpeg: it cannot write videos");

  // ---- the animation, the avatar -------------------------------------------------------
  std::vector<proxy_pose> poses;  // resampled at fps, times from 0
  double fps = o.fps;
  float performer_hips = 0;
  if (kind != animation_kind::glb) {
    motion_clip clip;
    if (status st = read_motion(o.animation, nullptr, clip); !st) return st;
    if (clip.frames.empty())
      return status::parse_error("render: " + o.animation + " has no frames");
    if (status st = check_finite(clip.frames, o.animation); !st) return st;
    if (fps <= 0) {
      fps = 30;
      if (kind == animation_kind::poses) {
        if (clip.source_fps > 0) {
          fps = clip.source_fps;
        } else if (clip.frames.size() > 1) {
          std::vector<double> dt;
          for (std::size_t i = 1; i < clip.frames.size(); ++i)
            if (clip.frames[i].t > clip.frames[i - 1].t)
              dt.push_back(clip.frames[i].t - clip.frames[i - 1].t);
          if (!dt.empty()) {
            std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
            fps = std::round(1000 / dt[dt.size() / 2]) / 1000;
          }
        }
        fps = std::clamp(fps, 1.0, 240.0);
      }
    }
    if (status st = resample_clip(clip.frames, fps, true, poses, o.animation); !st) return st;
    if (!standing_hips_height(clip.frames, o.animation, performer_hips).ok()) performer_hips = 0;
  } else if (fps <= 0) {
    fps = 30;
  }

  pose_server_options server_options;
  server_options.host = "127.0.0.1";
  server_options.port = 0;
  server_options.port_option.clear();
  server_options.page_dir = folder_or_first_tried(resource::viewer_page, o.page_dir);
  server_options.modules_dir = folder_or_first_tried(resource::viewer_modules, o.modules_dir);
  const std::string avatar_file = kind == animation_kind::glb ? o.animation : o.avatar;
  if (avatar_file.empty()) {
    if (status st = builtin_avatar_glb(builtin_avatar_options{}, server_options.avatar_data); !st)
      return st;
    server_options.avatar_name = "builtin.vrm";
  } else {
    raw_rig rig;
    if (status st = load_avatar(avatar_file, rig); !st) return st;
    if (rig.source != rig_source::vrm0 && rig.source != rig_source::vrm1)
      return status::error("render: " + avatar_file +
                           " is not a VRM avatar (no VRM humanoid): the viewer shows VRM 0.x and "
                           "1.0 models");
    server_options.avatar_path = avatar_file;
  }

  // ---- the source video and its landmarks ------------------------------------------------
  const bool beside = !o.video.empty();
  const int panel_w = beside ? o.width / 2 : o.width;
  const int panel_h = o.height;
  const int panel_x = beside ? o.width - panel_w : 0;
  video_source source;
  std::vector<landmark_frame> marks;
  if (beside) {
    if (status st = source.open(o.video); !st) return st;
    if (!o.landmarks.empty()) {
      landmark_reader reader;
      if (status st = reader.open(o.landmarks); !st) return st;
      landmark_frame f;
      for (;;) {
        const read_result r = reader.next(f);
        if (r == read_result::end) break;
        if (r == read_result::error)
          return status::failure(reader.error_code(), "render: " + reader.error());
        marks.push_back(f);
      }
      std::stable_sort(marks.begin(), marks.end(),
                       [](const landmark_frame& a, const landmark_frame& b) { return a.t < b.t; });
    }
  }

  // ---- the browser and the page --------------------------------------------------------------
  render_detail::devtools_browser browser;
  if (status st = browser.start(browser_path, panel_w, panel_h, o.cancel, o.step_timeout_s); !st)
    return st;
  pose_server server;
  if (status st = server.start(server_options); !st) return st;
  std::string reply;
  reply.reserve(1 << 20);
  {
    const std::string metrics = "{\"width\":" + std::to_string(panel_w) +
                                ",\"height\":" + std::to_string(panel_h) +
                                ",\"deviceScaleFactor\":1,\"mobile\":false}";
    if (status st = browser.call("Emulation.setDeviceMetricsOverride", metrics, reply); !st)
      return st;
  }
  std::string query = "render=1&w=" + std::to_string(panel_w) + "&h=" + std::to_string(panel_h);
  if (kind != animation_kind::glb && performer_hips > 0)
    query += "&performerHips=" + number_text(performer_hips);
  {
    const std::string url = server.url() + "?" + query;
    if (status st = browser.call("Page.navigate", "{\"url\":\"" + url + "\"}", reply); !st)
      return st;
    const auto deadline = clock_type::now() + std::chrono::duration<double>(o.step_timeout_s);
    for (;;) {
      if (status st =
              browser.evaluate("!!(window.avatarmapViewer && window.avatarmapViewer.ready && "
                               "window.avatarmapViewer.avatarInfo)",
                               reply);
          !st)
        return st;
      nlohmann::json v;
      if (status st = reply_value(reply, v); !st) return st;
      if (v.is_boolean() && v.get<bool>()) break;
      if (clock_type::now() > deadline)
        return status::io_error(
            "render: the viewer page did not start within " + number_text(o.step_timeout_s) +
            " s: are the viewer's modules in " + server_options.modules_dir + "? (" +
            script_command("scripts/fetch_viewer_modules.sh") + " fetches them)");
      if (o.cancel && o.cancel->load()) return status::error("render: interrupted");
      ::usleep(50000);
    }
  }
  nlohmann::json info;
  if (status st = browser.evaluate(
          "window.avatarmapViewer.ready().then(() => window.avatarmapViewer.avatarInfo())", reply);
      !st)
    return st;
  if (status st = reply_value(reply, info); !st) return st;
  const double rest_hips_y = info.value("restHipsY", 1.0);
  const double flip = info.value("flip", 1.0);

  // ---- frames and camera -------------------------------------------------------------------
  std::size_t total = poses.size();
  std::vector<std::array<double, 3>> hips;
  if (kind == animation_kind::glb) {
    nlohmann::json glb;
    if (status st = browser.evaluate("window.avatarmapViewer.loadGlbAnimation()", reply); !st)
      return st;
    if (status st = reply_value(reply, glb); !st) return st;
    const double duration = glb.value("duration", 0.0);
    if (status st = resampled_frame_count(0, duration, fps, o.animation, total); !st) return st;
    for (const auto& p : glb.value("hips", nlohmann::json::array()))
      if (p.is_array() && p.size() == 3)
        hips.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
  } else {
    const double s = performer_hips > 0 ? rest_hips_y / performer_hips : 1.0;
    for (const proxy_pose& p : poses)
      hips.push_back(
          {flip * p.hips_position.x * s, p.hips_position.y * s, flip * p.hips_position.z * s});
  }
  const framing f = o.framing == render_options::framing_kind::face
                        ? frame_face(hips, rest_hips_y, panel_w, panel_h)
                        : frame_motion(hips, rest_hips_y, panel_w, panel_h);
  auto triple = [](const double* v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.4f,%.4f,%.4f", v[0], v[1], v[2]);
    return std::string(buf);
  };
  const std::string camera_query =
      "&cam=" + triple(f.cam) + "&look=" + triple(f.look) + "&hfov=" + number_text(f.hfov);
  {
    const std::string set = "window.avatarmapViewer.setCamera({cam: [" + triple(f.cam) +
                            "], look: [" + triple(f.look) + "], hfov: " + number_text(f.hfov) +
                            ", vfov: null}) && 0";
    if (status st = browser.evaluate(set, reply); !st) return st;
  }

  // Stills: the frame nearest each time.
  std::vector<std::pair<std::size_t, double>> still_frames;  // frame, time asked
  for (const double t : o.stills) {
    const double k = std::round(t * fps);
    if (!(k < static_cast<double>(total)))
      return status::error("render: a still at " + number_text(t) +
                           " s is past the animation's "
                           "end (" +
                           number_text(static_cast<double>(total - 1) / fps) + " s)");
    still_frames.emplace_back(static_cast<std::size_t>(k), t);
  }
  std::vector<std::vector<std::uint8_t>> still_pixels(still_frames.size());

  // ---- the loop ---------------------------------------------------------------------------------
  video_writer writer;
  video_writer_options writer_options;
  writer_options.crf = 18;
  writer_options.max_threads = 0;
  if (status st = writer.open(o.output, o.width, o.height, fps, writer_options); !st) return st;

  const int stride = o.width * 3;
  std::vector<std::uint8_t> frame(static_cast<std::size_t>(stride) * o.height, 0);
  std::vector<std::uint8_t> png;
  png.reserve(static_cast<std::size_t>(panel_w) * panel_h * 4);
  std::string expression;
  expression.reserve(io_detail::k_pose_line_max + 256);
  std::vector<char> line(io_detail::k_pose_line_max + io_detail::k_shortest_float_room);
  for (std::vector<std::uint8_t>& still : still_pixels) still.resize(frame.size());
  const std::string screenshot =
      "{\"format\":\"png\",\"clip\":{\"x\":0,\"y\":0,\"width\":" + std::to_string(panel_w) +
      ",\"height\":" + std::to_string(panel_h) +
      ",\"scale\":1},\"optimizeForSpeed\":true,\"captureBeyondViewport\":false}";
  render_detail::png_decoder decoder;

  // The source: its newest frame at or before each frame's time, copied (and drawn on).
  std::vector<std::uint8_t> source_frame, source_drawn;
  int source_w = 0, source_h = 0;
  image_view pending{};
  double pending_t = 0;
  bool have_pending = false;
  bool have_source = false;
  double source_t = 0;
  std::size_t mark = 0;
  panel_scaler scaler;
  if (beside) {
    const read_result r = source.next(pending, pending_t);
    have_pending = r == read_result::frame;
    if (!have_pending) return status::io_error("render: " + o.video + ": no frame could be read");
    source_w = pending.width;
    source_h = pending.height;
    source_frame.assign(static_cast<std::size_t>(source_w) * source_h * 3, 0);
    source_drawn = source_frame;
    scaler.plan(source_w, source_h, panel_w, panel_h);
  }

  const auto loop_start = clock_type::now();
  for (std::size_t i = 0; i < total; ++i) {
    if (o.cancel && o.cancel->load()) return status::error("render: interrupted");
    const double t = static_cast<double>(i) / fps;
    expression.clear();
    if (kind == animation_kind::glb) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "window.avatarmapViewer.renderGlbAt(%.9g).then(() => 0)", t);
      expression += buf;
    } else {
      io_detail::memory_text text(line.data(), io_detail::k_pose_line_max);
      if (!io_detail::put_pose_line(text, poses[i], pose_write_options{}, false))
        return status::internal("render: a pose line does not fit its buffer");
      expression += "window.avatarmapViewer.renderPose(";
      expression.append(text.data(), text.size());
      expression += ").then(() => 0)";
    }
    if (status st = browser.evaluate(expression, reply); !st) return st;
    if (status st = browser.call("Page.captureScreenshot", screenshot, reply); !st) return st;
    const std::size_t at = reply.find("\"data\":\"");
    const std::size_t end = at == std::string::npos ? at : reply.find('"', at + 8);
    if (end == std::string::npos)
      return status::internal("render: the browser's screenshot reply has no data");
    if (!decode_base64(std::string_view(reply).substr(at + 8, end - at - 8), png,
                       render_detail::png_decoder::k_png_padding))
      return status::internal("render: the browser's screenshot is not base64");
    if (status st =
            decoder.decode(png.data(), png.size() - render_detail::png_decoder::k_png_padding,
                           panel_w, panel_h, frame.data() + panel_x * 3, stride);
        !st)
      return st;

    if (beside) {
      bool changed = false;
      while (have_pending && pending_t <= t + 1e-6) {
        if (pending.width != source_w || pending.height != source_h)
          return status::error("render: " + o.video + ": its frames change size");
        for (int y = 0; y < source_h; ++y)
          std::memcpy(source_frame.data() + static_cast<std::size_t>(y) * source_w * 3,
                      pending.data + static_cast<std::ptrdiff_t>(y) * pending.stride_bytes,
                      static_cast<std::size_t>(source_w) * 3);
        source_t = pending_t;
        have_source = changed = true;
        read_result r = source.next(pending, pending_t);
        while (r == read_result::error) r = source.next(pending, pending_t);  // skip bad frames
        have_pending = r == read_result::frame;
      }
      if (changed) {
        std::memcpy(source_drawn.data(), source_frame.data(), source_frame.size());
        while (mark + 1 < marks.size() && marks[mark + 1].t <= source_t + 1e-3) ++mark;
        if (!marks.empty() && marks[mark].t <= source_t + 1e-3) {
          overlay_job job;
          job.image = {source_drawn.data(), source_w, source_h, source_w * 3};
          job.frame = &marks[mark];
          job.run();
        }
        if (have_source) scaler.run(source_drawn.data(), source_w * 3, frame.data(), stride);
      }
    }
    for (std::size_t s = 0; s < still_frames.size(); ++s)
      if (still_frames[s].first == i)
        std::copy(frame.begin(), frame.end(), still_pixels[s].begin());
    image_view view{frame.data(), o.width, o.height, stride, pixel_format::rgb8};
    if (status st = writer.write(view, t); !st) return st;
    if (progress) {
      const double elapsed = std::chrono::duration<double>(clock_type::now() - loop_start).count();
      progress({static_cast<std::int64_t>(i + 1), static_cast<std::int64_t>(total),
                elapsed > 0 ? (i + 1) / elapsed : 0});
    }
  }
  const double loop_seconds = std::chrono::duration<double>(clock_type::now() - loop_start).count();
  server.stop();
  browser.close();
  const int out_w = writer.output_width(), out_h = writer.output_height();
  const std::string encoder = writer.encoder_name();
  if (status st = writer.close(); !st) return st;

  // Stills after the video: any failure removes everything written.
  std::vector<std::string> written;
  for (std::size_t s = 0; s < still_frames.size(); ++s) {
    const std::string path = render_still_path(o.output, still_frames[s].second);
    video_writer still;
    image_view view{still_pixels[s].data(), o.width, o.height, stride, pixel_format::rgb8};
    status st = still.open(path, o.width, o.height, fps);
    if (st) st = still.write(view, 0);
    if (st) st = still.close();
    if (!st) {
      for (const std::string& w : written) ::unlink(w.c_str());
      ::unlink(o.output.c_str());
      return st;
    }
    written.push_back(path);
  }
  if (summary) {
    summary->frames = static_cast<std::int64_t>(total);
    summary->width = out_w;
    summary->height = out_h;
    summary->fps = fps;
    summary->seconds = std::chrono::duration<double>(clock_type::now() - started).count();
    summary->render_seconds = loop_seconds;
    summary->encoder = encoder;
    summary->stills = written;
    summary->viewer_query = query + camera_query;
  }
  return {};
}

}  // namespace avatarmap
