// Renders an animation to a video file with the project's browser viewer (docs/render.md):
// the viewer's render mode (viewer/viewer.js `?render=1`) in Debian's headless Chromium,
// driven over the DevTools protocol on a pipe, served by the viewer's own server on
// 127.0.0.1; each frame is drawn at a fixed time (frame i at i / fps, not the wall clock),
// screenshotted, decoded and encoded by video_writer. Optionally side by side with the source
// video (and its landmark overlay), and still PNGs at given times.
//
// The browser runs with a private temporary profile in a process group of its own; whatever
// happens (an error, a cancel) it is stopped and its profile removed before render_job
// returns. The video and the stills appear only once all of them are written (atomically).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// Options of render_job; a struct so that fields can be added compatibly.
struct render_options {
  /// The animation: a .vrma, a *.pose.jsonl (proxy poses), a .bvh (read as `convert` reads
  /// it), or a .glb avatar with its own glTF animation (`convert -o x.glb`; then `avatar`
  /// must be empty: the .glb is the avatar). Any case.
  std::string animation;
  /// The video to write: .mp4, .mov or .mkv (H.264 through video_writer).
  std::string output;
  /// The VRM 0.x / 1.0 avatar that plays a .vrma or pose file; empty = the built-in avatar.
  std::string avatar;
  /// Size of the video in pixels (each 16..4096). With `video`, each half is width / 2.
  int width = 1280;
  int height = 720;
  /// Frames per second; 0 = the animation's own (a pose file's from its time stamps, rounded
  /// to 1/1000; 30 for .vrma, .bvh and .glb).
  double fps = 0;
  /// Times in seconds (from the animation's start) of still PNGs, written beside the output
  /// as render_still_path(output, t): the frame nearest each time, exactly as in the video
  /// before encoding.
  std::vector<double> stills;
  /// A source video shown on the left, matched by time (its frame at or before each frame's
  /// time); empty = the avatar alone.
  std::string video;
  /// Its landmarks (*.landmarks.jsonl), drawn on it with overlay_job; needs `video`.
  std::string landmarks;
  /// What the camera frames: the whole motion (body), or the head in close-up (face: the
  /// head's rest height over the motion's mean hips, about 0.5 m of height in view), as a
  /// webcam sees a face; for checking the face end to end (docs/render.md).
  enum class framing_kind { body, face };
  framing_kind framing = framing_kind::body;
  /// The browser; empty = `chromium` (else `chromium-browser`, `google-chrome`) on the PATH.
  std::string chromium;
  /// The viewer's page and modules folders; empty = find_resource's (as `avatarmap view`).
  std::string page_dir;
  std::string modules_dir;
  /// Longest wait for one browser step (start, page load, one frame), seconds.
  double step_timeout_s = 60;
  /// Set (from any thread, a signal handler included) to stop: render_job then cleans up
  /// and fails with "interrupted". May be null.
  const std::atomic<bool>* cancel = nullptr;

  /// ok, or a message naming the option: sizes, fps, extensions, landmarks without video, a
  /// .glb with an avatar, still times not finite or negative.
  status validate() const;
};

/// Where the job is, for a progress line.
struct render_progress {
  std::int64_t done = 0;         // frames encoded
  std::int64_t total = 0;        // frames to encode
  double frames_per_second = 0;  // encoded so far per wall-clock second
};

/// What the job did.
struct render_summary {
  std::int64_t frames = 0;
  int width = 0, height = 0;  // of the video
  double fps = 0;
  double seconds = 0;               // wall clock, browser start included
  double render_seconds = 0;        // the frame loop alone
  std::string encoder;              // video_writer's encoder ("libx264", "mpeg4")
  std::vector<std::string> stills;  // the PNGs written
  /// The viewer page's query that shows the same camera (for `avatarmap view`'s page in render
  /// mode, docs/world-benchmark-rendered.md): "render=1&w=..&h=..&cam=..&look=..&hfov=..",
  /// with "&performerHips=.." for poses.
  std::string viewer_query;
};

/// The file name of the still at time `t` for `output`: OUT's folder and stem (the name
/// without its last extension) + "_t" + t in seconds (shortest text, "1.5", "2") + ".png".
std::string render_still_path(const std::string& output, double t);

/// The browser render_job would run (options.chromium, else the first of chromium,
/// chromium-browser, google-chrome on the PATH); empty when none is found.
std::string find_render_browser(const std::string& chromium = {});

/// Renders. Progress is called after each frame (may be empty). Fails, with a message that
/// says what to do, on: bad options; no browser ("install Debian's chromium: sudo apt-get
/// install chromium"); an animation that cannot be read, has no frames or a value that is not
/// finite; an avatar that is not VRM; a page that does not load (the viewer's modules
/// missing: scripts/fetch_viewer_modules.sh); the browser dying; a video that cannot be
/// written; a cancel. No output is left on failure.
status render_job(const render_options& options,
                  const std::function<void(const render_progress&)>& progress,
                  render_summary* summary = nullptr);

}  // namespace avatarmap
