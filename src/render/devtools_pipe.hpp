// Internal: headless Chromium driven over the DevTools protocol on a pipe
// (--remote-debugging-pipe: messages are JSON texts each ended by a NUL byte, written to the
// child's fd 3 and read from its fd 4). One page, attached in flat mode; calls wait for their
// own reply (events in between are skipped). The browser runs in a process group of its own
// with a private temporary profile; close() (and the destructor) stops the whole group and
// removes the profile.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap::render_detail {

class devtools_browser {
 public:
  devtools_browser() = default;
  ~devtools_browser();
  devtools_browser(const devtools_browser&) = delete;
  devtools_browser& operator=(const devtools_browser&) = delete;

  /// Starts `chromium` headless (a window of width x height) and attaches to a new page.
  /// `cancel` (may be null) is checked while waiting; `timeout_s` bounds each wait.
  status start(const std::string& chromium, int width, int height, const std::atomic<bool>* cancel,
               double timeout_s);

  /// Calls `method` with `params` (a JSON object's text) on the page; `reply` (reused: its
  /// capacity is kept) receives the reply's whole text. Fails on a protocol error (its
  /// message), a JavaScript exception of Runtime.evaluate (its text), the browser's death, a
  /// timeout or a cancel.
  status call(std::string_view method, std::string_view params, std::string& reply);

  /// Evaluates `expression` (a promise is awaited; its value returned by value) into `reply`.
  status evaluate(std::string_view expression, std::string& reply);

  /// Stops the browser (its process group) and removes the profile. Idempotent.
  void close();

 private:
  status send(std::string_view method, std::string_view params, bool on_page, long& out_id);
  status wait_reply(long id, std::string& reply);
  status browser_gone(const char* doing);

  pid_t pid_ = -1;
  int to_browser_ = -1;
  int from_browser_ = -1;
  std::string profile_;
  std::string session_;
  std::string out_;     // the message being sent (reused)
  std::string in_;      // bytes read and not yet taken (reused)
  std::string params_;  // evaluate()'s parameters (reused)
  long next_id_ = 0;
  double timeout_s_ = 60;
  const std::atomic<bool>* cancel_ = nullptr;
};

}  // namespace avatarmap::render_detail
