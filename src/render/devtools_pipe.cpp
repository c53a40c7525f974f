// src/render/devtools_pipe.hpp.
#include "render/devtools_pipe.hpp"

#include <fcntl.h>
#include <ftw.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <vector>

extern char** environ;

namespace avatarmap::render_detail {
namespace {

using clock_type = std::chrono::steady_clock;

int remove_entry(const char* path, const struct stat*, int, struct FTW*) {
  ::remove(path);
  return 0;
}

// The last lines of the browser's log (its stderr), for a message.
std::string log_tail(const std::string& profile) {
  std::string text;
  if (FILE* f = std::fopen((profile + "/chromium.log").c_str(), "rb")) {
    char buf[4096];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
      text.append(buf, n);
      if (text.size() > 16384) text.erase(0, text.size() - 1024);
    }
    std::fclose(f);
  }
  if (text.size() > 600) text.erase(0, text.size() - 600);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

// The reply's id when `message` starts with {"id":N (Chrome writes the id first); -1 otherwise.
long reply_id(std::string_view message) {
  constexpr std::string_view head = "{\"id\":";
  if (message.substr(0, head.size()) != head) return -1;
  long id = 0;
  std::size_t i = head.size();
  if (i >= message.size() || message[i] < '0' || message[i] > '9') return -1;
  for (; i < message.size() && message[i] >= '0' && message[i] <= '9'; ++i)
    id = id * 10 + (message[i] - '0');
  return id;
}

}  // namespace

devtools_browser::~devtools_browser() { close(); }

status devtools_browser::start(const std::string& chromium, int width, int height,
                               const std::atomic<bool>* cancel, double timeout_s) {
  close();
  cancel_ = cancel;
  timeout_s_ = timeout_s;
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/avatarmap-render-XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  if (!::mkdtemp(name.data()))
    return status::io_error("render: cannot create a temporary browser profile under " +
                            pattern.substr(0, pattern.rfind('/')) + ": " + std::strerror(errno));
  profile_ = name.data();

  int ours_in[2] = {-1, -1}, ours_out[2] = {-1, -1};  // [0] ours, [1] the browser's
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ours_in) != 0 ||
      ::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ours_out) != 0) {
    const int err = errno;
    for (int fd : {ours_in[0], ours_in[1], ours_out[0], ours_out[1]})
      if (fd >= 0) ::close(fd);
    close();
    return status::io_error(std::string("render: socketpair: ") + std::strerror(err));
  }
  // ours_in: the browser reads commands on its fd 3; ours_out: it writes replies on its fd 4.
  const int log_fd =
      ::open((profile_ + "/chromium.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);

  std::vector<std::string> args = {
      chromium,
      "--headless",
      "--use-angle=swiftshader",
      "--enable-unsafe-swiftshader",
      "--ignore-gpu-blocklist",
      "--no-first-run",
      "--no-default-browser-check",
      "--disable-background-timer-throttling",
      "--disable-renderer-backgrounding",
      "--disable-backgrounding-occluded-windows",
      "--disable-extensions",
      "--mute-audio",
      "--hide-scrollbars",
      "--window-size=" + std::to_string(width) + "," + std::to_string(height),
      "--remote-debugging-pipe",
      "--user-data-dir=" + profile_};
  if (::geteuid() == 0) args.push_back("--no-sandbox");  // Chromium refuses root otherwise
  args.push_back("about:blank");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // The child: async-signal-safe calls only until exec.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    const int in_fd = ::fcntl(ours_in[1], F_DUPFD, 10);
    const int out_fd = ::fcntl(ours_out[1], F_DUPFD, 10);
    if (in_fd < 0 || out_fd < 0 || ::dup2(in_fd, 3) < 0 || ::dup2(out_fd, 4) < 0) ::_exit(127);
    if (null_fd >= 0) ::dup2(null_fd, 0);
    if (log_fd >= 0) {
      ::dup2(log_fd, 1);
      ::dup2(log_fd, 2);
    }
    ::execve(argv[0], argv.data(), environ);
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::close(ours_in[1]);
  ::close(ours_out[1]);
  if (log_fd >= 0) ::close(log_fd);
  if (null_fd >= 0) ::close(null_fd);
  to_browser_ = ours_in[0];
  from_browser_ = ours_out[0];
  if (pid < 0) {
    close();
    return status::io_error(std::string("render: cannot start ") + chromium + ": " +
                            std::strerror(fork_errno));
  }
  pid_ = pid;
  ::setpgid(pid_, pid_);  // also here, so that it holds before the child runs

  // One page, attached in flat mode: its calls carry the session id.
  std::string reply;
  long id = 0;
  if (status st = send("Target.createTarget", R"({"url":"about:blank"})", false, id); !st)
    return st;
  if (status st = wait_reply(id, reply); !st) return st;
  std::string target;
  try {
    target = nlohmann::json::parse(reply).at("result").at("targetId").get<std::string>();
  } catch (const std::exception&) {
    return status::internal("render: the browser's Target.createTarget reply has no targetId");
  }
  if (status st = send("Target.attachToTarget",
                       R"({"targetId":")" + target + R"(","flatten":true})", false, id);
      !st)
    return st;
  if (status st = wait_reply(id, reply); !st) return st;
  try {
    session_ = nlohmann::json::parse(reply).at("result").at("sessionId").get<std::string>();
  } catch (const std::exception&) {
    return status::internal("render: the browser's Target.attachToTarget reply has no sessionId");
  }
  return {};
}

status devtools_browser::send(std::string_view method, std::string_view params, bool on_page,
                              long& out_id) {
  if (to_browser_ < 0) return status::internal("render: the browser is not running");
  out_id = ++next_id_;
  out_.clear();
  out_ += "{\"id\":";
  out_ += std::to_string(out_id);  // short: within the small-string buffer
  if (on_page) {
    out_ += ",\"sessionId\":\"";
    out_ += session_;
    out_ += '"';
  }
  out_ += ",\"method\":\"";
  out_ += method;
  out_ += "\",\"params\":";
  out_ += params.empty() ? std::string_view("{}") : params;
  out_ += '}';
  out_ += '\0';
  std::size_t done = 0;
  while (done < out_.size()) {
    const ssize_t n = ::send(to_browser_, out_.data() + done, out_.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return browser_gone("sending a command");
    done += static_cast<std::size_t>(n);
  }
  return {};
}

status devtools_browser::wait_reply(long id, std::string& reply) {
  const auto deadline = clock_type::now() + std::chrono::duration<double>(timeout_s_);
  char chunk[65536];
  std::size_t scanned = 0;
  for (;;) {
    // Whole messages first.
    for (;;) {
      const std::size_t end = in_.find('\0', scanned);
      if (end == std::string::npos) {
        scanned = in_.size();
        break;
      }
      const std::string_view message(in_.data(), end);
      if (reply_id(message) == id) {
        reply.assign(message);
        in_.erase(0, end + 1);
        // A protocol error: {"id":N,"error":{"code":..,"message":".."}} (small).
        if (reply.size() < 65536 && reply.find("\"error\":{") != std::string::npos &&
            reply.find("\"result\":") == std::string::npos) {
          std::string text = reply;
          try {
            text = nlohmann::json::parse(reply).at("error").at("message").get<std::string>();
          } catch (const std::exception&) {
          }
          return status::internal("render: the browser refused a command: " + text);
        }
        return {};
      }
      in_.erase(0, end + 1);  // an event or another reply
      scanned = 0;
    }
    if (cancel_ && cancel_->load()) return status::error("render: interrupted");
    if (clock_type::now() > deadline)
      return status::io_error("render: the browser did not answer within " +
                              std::to_string(static_cast<int>(timeout_s_)) + " s");
    pollfd p{from_browser_, POLLIN, 0};
    const int r = ::poll(&p, 1, 100);
    if (r < 0 && errno != EINTR) return browser_gone("waiting for a reply");
    if (r <= 0) continue;
    const ssize_t n = ::read(from_browser_, chunk, sizeof chunk);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) return browser_gone("waiting for a reply");
    in_.append(chunk, static_cast<std::size_t>(n));
  }
}

status devtools_browser::call(std::string_view method, std::string_view params,
                              std::string& reply) {
  long id = 0;
  if (status st = send(method, params, true, id); !st) return st;
  return wait_reply(id, reply);
}

status devtools_browser::evaluate(std::string_view expression, std::string& reply) {
  // The expression as a JSON string, into a reused buffer (no allocation per frame).
  params_.clear();
  params_ += "{\"expression\":\"";
  for (const char c : expression) {
    if (c == '"' || c == '\\') {
      params_ += '\\';
      params_ += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      params_ += ' ';
    } else {
      params_ += c;
    }
  }
  params_ += "\",\"awaitPromise\":true,\"returnByValue\":true}";
  const std::string& params = params_;
  if (status st = call("Runtime.evaluate", params, reply); !st) return st;
  if (reply.find("\"exceptionDetails\":") == std::string::npos) return {};
  std::string text;
  try {
    const nlohmann::json j = nlohmann::json::parse(reply).at("result").at("exceptionDetails");
    if (j.contains("exception") && j["exception"].contains("description"))
      text = j["exception"]["description"].get<std::string>();
    else
      text = j.value("text", std::string("an exception"));
  } catch (const std::exception&) {
    text = reply.substr(0, 300);
  }
  if (const auto nl = text.find('\n'); nl != std::string::npos) text.resize(nl);
  return status::error("render: the viewer page: " + text);
}

status devtools_browser::browser_gone(const char* doing) {
  if (cancel_ && cancel_->load()) return status::error("render: interrupted");
  std::string why;
  if (pid_ > 0) {
    int st = 0;
    if (::waitpid(pid_, &st, WNOHANG) == pid_) {
      pid_ = -pid_;  // reaped; the group is still killed by close()
      if (WIFEXITED(st) && WEXITSTATUS(st) == 127)
        why = " (it could not be run)";
      else if (WIFEXITED(st))
        why = " (it exited with status " + std::to_string(WEXITSTATUS(st)) + ")";
      else if (WIFSIGNALED(st))
        why = " (killed by signal " + std::to_string(WTERMSIG(st)) + ")";
    }
  }
  const std::string tail = profile_.empty() ? std::string() : log_tail(profile_);
  return status::io_error(std::string("render: the browser stopped while ") + doing + why +
                          (tail.empty() ? std::string() : "; its last words: " + tail));
}

void devtools_browser::close() {
  if (pid_ != -1) {
    const pid_t group = pid_ > 0 ? pid_ : -pid_;
    if (pid_ > 0 && to_browser_ >= 0) {
      // Politely first: Browser.close, a few seconds to go.
      long id = 0;
      (void)send("Browser.close", "", false, id);
    }
    if (to_browser_ >= 0) ::close(to_browser_);
    to_browser_ = -1;
    if (pid_ > 0) {
      const auto deadline = clock_type::now() + std::chrono::seconds(3);
      int st = 0;
      while (::waitpid(pid_, &st, WNOHANG) == 0) {
        if (clock_type::now() > deadline) {
          ::kill(-group, SIGKILL);
          ::waitpid(pid_, &st, 0);
          break;
        }
        ::usleep(20000);
      }
    }
    // Helpers of the browser (GPU, renderer, zygote) still in its group.
    ::kill(-group, SIGKILL);
    pid_ = -1;
  }
  if (to_browser_ >= 0) ::close(to_browser_);
  if (from_browser_ >= 0) ::close(from_browser_);
  to_browser_ = from_browser_ = -1;
  if (!profile_.empty()) {
    // Chromium's helpers may still write for a moment after the kill: a second pass.
    for (int pass = 0; pass < 3; ++pass) {
      ::nftw(profile_.c_str(), remove_entry, 16, FTW_DEPTH | FTW_PHYS);
      if (::access(profile_.c_str(), F_OK) != 0) break;
      ::usleep(50000);
    }
    profile_.clear();
  }
  session_.clear();
  in_.clear();
}

}  // namespace avatarmap::render_detail
