// Plays a *.pose.jsonl file (docs/file-formats.md) in a loop at the pace of its time stamps, on
// a thread of its own, handing each pose to a sink: what `avatarmap view FILE.pose.jsonl` feeds
// the pose server with (docs/viewer.md).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

class pose_file_player {
 public:
  pose_file_player();
  ~pose_file_player();  // stop()s
  pose_file_player(const pose_file_player&) = delete;
  pose_file_player& operator=(const pose_file_player&) = delete;

  /// Reads the whole file once to check it: fails with the reader's message (file, line, what
  /// is wrong) or when it holds no pose. Then frames() and duration() are known.
  status open(const std::string& path);
  long frames() const;
  /// Seconds from the first pose's t to the last's.
  double duration() const;

  /// Starts the thread: pose i is handed to `sink` at (t_i - t_0) seconds after each loop's
  /// start (on that thread; the pose's t is the file's); after the last pose, one frame
  /// interval later, the file plays again from its start. Poses whose t does not increase are
  /// spaced by the header's fps (30 without one). Call after a successful open(), once.
  void start(std::function<void(const proxy_pose&)> sink);
  /// Stops the thread (within one frame interval); idempotent.
  void stop();
  /// ok, or why playback stopped (the file changed and no longer reads); any thread.
  status error() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
