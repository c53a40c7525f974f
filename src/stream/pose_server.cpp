// The viewer's HTTP + WebSocket server on libwebsockets (include/avatarmap/stream/pose_server.hpp,
// docs/viewer.md). One lws context with one service thread; publish() hands poses over
// through mutex-guarded "newest pose" buffers, one per slot (person), and lws_cancel_service(),
// which wakes the service thread, which asks every WebSocket connection for a writeable
// callback; each connection then sends, one message per callback, each slot's newest pose it has
// not sent yet (the longest waiting first). lws keeps at most the unsent rest of one message per
// connection, so a slow page skips poses instead of queueing them.
#include "avatarmap/stream/pose_server.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <iterator>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "avatarmap/io/resources.hpp"
#include "common/pose_text.hpp"

#if defined(AVATARMAP_HAVE_WEBSOCKETS)
#include <libwebsockets.h>
#endif

namespace avatarmap {

namespace {

bool is_file(const std::string& p) {
  struct stat st {};
  return !p.empty() && ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// A numeric address for `host` ("localhost" = 127.0.0.1); false when it is not one.
bool parse_host(const std::string& host, sockaddr_storage& out, socklen_t& out_len) {
  std::memset(&out, 0, sizeof out);
  const std::string h = host == "localhost" ? "127.0.0.1" : host;
  auto* v4 = reinterpret_cast<sockaddr_in*>(&out);
  if (inet_pton(AF_INET, h.c_str(), &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    out_len = sizeof(sockaddr_in);
    return true;
  }
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&out);
  if (inet_pton(AF_INET6, h.c_str(), &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    out_len = sizeof(sockaddr_in6);
    return true;
  }
  return false;
}

[[maybe_unused]] bool is_loopback(const sockaddr_storage& a) {
  if (a.ss_family == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
    return (ntohl(v4->sin_addr.s_addr) >> 24) == 127;
  }
  const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
  return IN6_IS_ADDR_LOOPBACK(&v6->sin6_addr);
}

// 0.0.0.0 or ::: every address of the machine.
[[maybe_unused]] bool is_wildcard(const sockaddr_storage& a) {
  if (a.ss_family == AF_INET)
    return reinterpret_cast<const sockaddr_in*>(&a)->sin_addr.s_addr == htonl(INADDR_ANY);
  return IN6_IS_ADDR_UNSPECIFIED(&reinterpret_cast<const sockaddr_in6*>(&a)->sin6_addr);
}

// The host part of "HOST[:PORT]" or "[V6]:PORT" or a URL "scheme://HOST[:PORT]/...".
[[maybe_unused]] std::string_view host_part(std::string_view s) {
  if (auto p = s.find("://"); p != std::string_view::npos) s.remove_prefix(p + 3);
  if (!s.empty() && s[0] == '[') {
    const auto e = s.find(']');
    return e == std::string_view::npos ? std::string_view{} : s.substr(0, e + 1);
  }
  return s.substr(0, s.find_first_of(":/"));
}

// A loopback name a browser may use: 127.x.x.x, localhost, [::1].
[[maybe_unused]] bool is_loopback_name(std::string_view h) {
  if (h == "localhost" || h == "[::1]") return true;
  in_addr a{};
  return inet_pton(AF_INET, std::string(h).c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

// What binding `host`:`port` fails with, checked by binding a socket of our own (lws reports
// only that it could not); empty when it can be bound. `port_option` is the command-line option
// that sets the port (named in the advice; empty = none).
[[maybe_unused]] std::string bind_problem(const sockaddr_storage& addr, socklen_t len,
                                          const std::string& host, int port,
                                          const std::string& port_option) {
  const int fd = ::socket(addr.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return std::string("cannot create a socket: ") + std::strerror(errno);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_storage a = addr;
  if (a.ss_family == AF_INET)
    reinterpret_cast<sockaddr_in*>(&a)->sin_port = htons(static_cast<uint16_t>(port));
  else
    reinterpret_cast<sockaddr_in6*>(&a)->sin6_port = htons(static_cast<uint16_t>(port));
  std::string problem;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), len) != 0) {
    const int e = errno;
    const std::string where = host + " port " + std::to_string(port);
    if (e == EADDRINUSE)
      problem = where + " is in use by another program: choose another port (" +
                (port_option.empty() ? std::string() : port_option + "; ") +
                "port 0 picks a free one) or stop the program that holds it";
    else if (e == EADDRNOTAVAIL)
      problem = host + " is not an address of this machine: use 127.0.0.1 (the default) or one " +
                "of its own addresses";
    else if (e == EACCES)
      problem = where + ": ports below 1024 need administrator rights; choose a port from 1024";
    else
      problem = where + ": " + std::strerror(e);
  }
  ::close(fd);
  return problem;
}

}  // namespace

status pose_server_options::validate() const {
  sockaddr_storage a{};
  socklen_t len = 0;
  if (!parse_host(host, a, len))
    return status::error("pose server: host '" + host +
                         "' is not an IPv4 or IPv6 address (or localhost); e.g. 127.0.0.1");
  if (port < 0 || port > 65535)
    return status::error("pose server: port " + std::to_string(port) +
                         " is outside 0..65535 (0 picks a free port)");
  if (!is_file(page_dir + "/index.html"))
    return status::error("pose server: the viewer page is missing (" + page_dir +
                         "/index.html); point page_dir at the project's viewer/ folder");
  if (!is_file(modules_dir + "/three/build/three.module.js") ||
      !is_file(modules_dir + "/three-vrm/lib/three-vrm.module.js") ||
      !is_file(modules_dir + "/three-vrm-animation/lib/three-vrm-animation.module.js"))
    return status::error("pose server: three.js and three-vrm are missing from '" + modules_dir +
                         "': run " + script_command("scripts/fetch_viewer_modules.sh") +
                         " (or scripts/setup.sh), or set AVATARMAP_VIEWER_MODULES to the folder "
                         "it fills");
  if (!avatar_path.empty() && !is_file(avatar_path))
    return status::error("pose server: avatar '" + avatar_path + "' is not a readable file");
  if (!avatar_path.empty() && !avatar_data.empty())
    return status::error("pose server: give the avatar as avatar_path or as avatar_data, not both");
  if (!clip_path.empty() && !is_file(clip_path))
    return status::error("pose server: clip '" + clip_path + "' is not a readable file");
  if (!poses_path.empty() && !is_file(poses_path))
    return status::error("pose server: poses '" + poses_path + "' is not a readable file");
  if (!poses_path.empty() && !poses_data.empty())
    return status::error("pose server: give the poses as poses_path or as poses_data, not both");
  if (!video_path.empty() && !is_file(video_path))
    return status::error("pose server: video '" + video_path + "' is not a readable file");
  return {};
}

#if defined(AVATARMAP_HAVE_WEBSOCKETS)

namespace {

using clock_type = std::chrono::steady_clock;

// Bytes of one message: a pose line with every bone (confidence is not sent).
constexpr std::size_t k_message_capacity = io_detail::k_pose_line_max;
// Room write_shortest_float may use past the reserved bytes (pose_text.hpp).
constexpr std::size_t k_message_slack = io_detail::k_shortest_float_room + 32;
// Room for the keys publish() adds for a person: ,"person":ID,"slot":K (an int each).
constexpr std::size_t k_person_keys_room = 48;
// Bytes of a buffer that holds one message.
constexpr std::size_t k_message_buffer = k_message_capacity + k_message_slack + k_person_keys_room;
// A page's messages (its report) are small; longer ones are ignored.
constexpr std::size_t k_rx_max = 256;
// Bytes of a body served from memory (the config, the built-in avatar) written per callback.
constexpr std::size_t k_body_chunk = 16384;
// Refusals (foreign Host or Origin) logged one by one; after them, one summary line per
// k_refusal_summary_every at most, so that a page that retries in a loop cannot flood the log.
constexpr int k_refusals_logged = 5;
constexpr auto k_refusal_summary_every = std::chrono::seconds(10);
// How often the machine's addresses and name are read again when a Host matches none of them
// (a new DHCP lease, a VPN coming up).
constexpr auto k_machine_refresh_every = std::chrono::seconds(5);

// Headers every served file carries: no MIME sniffing, no framing by other sites, no referrer.
constexpr std::array<std::array<const char*, 2>, 3> k_file_headers = {{
    {"x-content-type-options:", "nosniff"},
    {"x-frame-options:", "deny"},
    {"referrer-policy:", "no-referrer"},
}};

struct http_session {
  const std::string* body;  // a body served from memory, written when writeable; or null
  std::size_t body_sent;
};

struct ws_session {
  // Per slot, the count (slot_pose::count) of the newest pose this connection has been handed
  // (0 = none).
  std::uint64_t sent_count[k_pose_server_slots];
  bool established;  // accepted (counted in open); lws zeroes the session
  std::size_t rx_len;
  bool rx_overflow;
  char rx[k_rx_max];
  char peer[64];
};

int http_callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len);
int ws_callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len);

// protocols[0] takes plain HTTP (and refuses WebSockets without our subprotocol).
const lws_protocols k_protocols[] = {
    {"http", http_callback, sizeof(http_session), 0, 0, nullptr, 0},
    {k_pose_socket_protocol, ws_callback, sizeof(ws_session), k_rx_max, 0, nullptr, 0},
    {nullptr, nullptr, 0, 0, 0, nullptr, 0}};

// lws's error log lines, kept for start()'s message; lws prints nothing itself.
std::mutex g_log_mutex;
std::string g_last_log;
void lws_log_sink(int level, const char* line) {
  if (level != LLL_ERR) return;
  std::lock_guard<std::mutex> lock(g_log_mutex);
  g_last_log = line;
  while (!g_last_log.empty() && (g_last_log.back() == '\n' || g_last_log.back() == '\r'))
    g_last_log.pop_back();
}

// A header's text for the log: printable ASCII, at most 80 characters.
std::string printable(std::string_view s) {
  std::string r;
  for (char c : s.substr(0, 80)) r += c >= 0x20 && c < 0x7f ? c : '?';
  if (s.size() > 80) r += "...";
  return r;
}

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

// An IP address as bytes: 4 (IPv4) or 16 (IPv6); an IPv4-mapped IPv6 address is its IPv4.
struct ip_address {
  int family = 0;
  std::array<unsigned char, 16> bytes{};
  bool operator==(const ip_address& o) const { return family == o.family && bytes == o.bytes; }
  bool loopback() const {
    if (family == AF_INET) return bytes[0] == 127;
    static constexpr std::array<unsigned char, 16> v6_loopback = {0, 0, 0, 0, 0, 0, 0, 0,
                                                                  0, 0, 0, 0, 0, 0, 0, 1};
    return bytes == v6_loopback;
  }
};

ip_address ip_of(const sockaddr* a) {
  ip_address r;
  if (a->sa_family == AF_INET) {
    r.family = AF_INET;
    std::memcpy(r.bytes.data(), &reinterpret_cast<const sockaddr_in*>(a)->sin_addr, 4);
  } else if (a->sa_family == AF_INET6) {
    const in6_addr& v6 = reinterpret_cast<const sockaddr_in6*>(a)->sin6_addr;
    if (IN6_IS_ADDR_V4MAPPED(&v6)) {
      r.family = AF_INET;
      std::memcpy(r.bytes.data(), v6.s6_addr + 12, 4);
    } else {
      r.family = AF_INET6;
      std::memcpy(r.bytes.data(), v6.s6_addr, 16);
    }
  }
  return r;
}

// The address a Host header's host part names ("1.2.3.4", "[v6]", "[fe80::1%25eth0]"); false
// for a name.
bool parse_ip(std::string_view host, ip_address& out) {
  std::string h(host);
  if (h.size() >= 2 && h.front() == '[' && h.back() == ']') h = h.substr(1, h.size() - 2);
  if (const auto zone = h.find('%'); zone != std::string::npos) h.resize(zone);
  sockaddr_storage a{};
  socklen_t len = 0;
  if (h == "localhost" || !parse_host(h, a, len)) return false;
  out = ip_of(reinterpret_cast<const sockaddr*>(&a));
  return true;
}

// The text of an address, IPv6 in brackets, for a URL.
std::string url_host(const ip_address& a) {
  char text[INET6_ADDRSTRLEN] = {};
  inet_ntop(a.family, a.bytes.data(), text, sizeof text);
  return a.family == AF_INET6 ? "[" + std::string(text) + "]" : std::string(text);
}

// What a Host header may name when the server listens beyond loopback: the addresses of the
// machine's interfaces, its host name (and NAME.local, its mDNS name), the names given in
// options.allowed_hosts.
struct machine_names {
  std::vector<ip_address> addresses;
  std::vector<std::string> names;  // lower case, without a trailing dot

  void read(const std::vector<std::string>& allowed) {
    addresses.clear();
    names.clear();
    ifaddrs* list = nullptr;
    if (::getifaddrs(&list) == 0) {
      for (const ifaddrs* i = list; i; i = i->ifa_next)
        if (i->ifa_addr &&
            (i->ifa_addr->sa_family == AF_INET || i->ifa_addr->sa_family == AF_INET6))
          addresses.push_back(ip_of(i->ifa_addr));
      ::freeifaddrs(list);
    }
    char name[256] = {};
    if (::gethostname(name, sizeof name - 1) == 0 && name[0]) {
      add_name(name);
      if (!std::strchr(name, '.')) add_name(std::string(name) + ".local");
    }
    for (const std::string& a : allowed) {
      ip_address ip;
      if (parse_ip(a, ip))
        addresses.push_back(ip);
      else
        add_name(a);
    }
  }
  // A name as compared: lower case, without a trailing dot ("VM." names the same as "vm").
  static std::string normalised(std::string_view n) {
    std::string l = lower(n);
    while (!l.empty() && l.back() == '.') l.pop_back();
    return l;
  }
  void add_name(std::string_view n) {
    if (std::string l = normalised(n); !l.empty()) names.push_back(std::move(l));
  }
  bool has(std::string_view host) const {
    ip_address ip;
    if (parse_ip(host, ip))
      return std::find(addresses.begin(), addresses.end(), ip) != addresses.end();
    const std::string l = normalised(host);
    return !l.empty() && std::find(names.begin(), names.end(), l) != names.end();
  }
};

// What the service thread's callbacks and publish() share (the context's user data).
struct server_state {
  pose_server_options options;
  bool loopback = true;
  int port = 0;
  std::string url, listen_address;
  std::vector<std::string> network_urls;
  std::string config_json;
  std::string file_headers;  // k_file_headers as lws_serve_http_file takes them
  std::thread thread;
  std::atomic<bool> stopping{false};
  bool started = false;

  // The newest pose of each slot, written by publish() (any thread), read by the service thread.
  struct slot_pose {
    std::vector<char> text = std::vector<char>(k_message_buffer);
    std::size_t size = 0;     // 0 = none yet
    std::uint64_t count = 0;  // poses published in this slot
    std::uint64_t stamp = 0;  // `seq` when the newest was published: the oldest unsent goes first
  };
  mutable std::mutex m;
  lws_context* context = nullptr;  // under m for publish(); set before the thread starts
  std::array<slot_pose, k_pose_server_slots> latest;
  std::uint64_t seq = 0;

  // Service thread only.
  std::vector<unsigned char> send_buffer = std::vector<unsigned char>(LWS_PRE + k_message_buffer);
  std::vector<unsigned char> http_buffer = std::vector<unsigned char>(LWS_PRE + k_body_chunk);
  machine_names machine;
  clock_type::time_point machine_read_at;
  int refusals_logged = 0;
  long refusals_unlogged = 0;
  clock_type::time_point refusals_summarised_at;

  std::atomic<int> open{0};
  std::atomic<long> connections{0}, published{0}, sent{0}, skipped{0}, refused{0};
  std::atomic<double> first_posed_ms{-1.0};

  void event(const std::string& line) const {
    if (options.on_event) options.on_event(line);
  }

  // Counts a refused request and logs it: the first k_refusals_logged one by one, the rest in
  // summaries (summarise_refusals).
  void refusal(const std::string& line) {
    ++refused;
    if (refusals_logged < k_refusals_logged) {
      ++refusals_logged;
      refusals_summarised_at = clock_type::now();
      event(line + (refusals_logged == k_refusals_logged
                        ? "; further refusals are counted in one line per 10 s"
                        : ""));
      return;
    }
    ++refusals_unlogged;
    summarise_refusals(false);
  }
  // The line about refusals not logged yet, once k_refusal_summary_every has passed since the
  // last (or now when `now_anyway`, as the server stops).
  void summarise_refusals(bool now_anyway) {
    if (refusals_unlogged == 0) return;
    const auto now = clock_type::now();
    if (!now_anyway && now - refusals_summarised_at < k_refusal_summary_every) return;
    const double seconds = std::chrono::duration<double>(now - refusals_summarised_at).count();
    char line[160];
    std::snprintf(line, sizeof line,
                  "refused %ld more requests or WebSockets for their Host or Origin over %.1f s",
                  refusals_unlogged, seconds);
    event(line);
    refusals_unlogged = 0;
    refusals_summarised_at = now;
  }

  // Whether a request's Host header names this server: a loopback name; when listening beyond
  // loopback also an address or name of this machine (machine_names). Anything else is
  // refused, so that a web page that rebinds its own domain name to this machine's address
  // cannot read the avatar or the poses (DNS rebinding). Writes the header to out_host.
  bool host_allowed(lws* wsi, std::string& out_host) {
    char host[256];
    if (lws_hdr_copy(wsi, host, sizeof host, WSI_TOKEN_HOST) <= 0) {
      out_host = lws_hdr_total_length(wsi, WSI_TOKEN_HOST) > 0 ? "(too long)" : "(none)";
      return false;
    }
    out_host = host;
    const std::string_view h = host_part(host);
    if (is_loopback_name(h)) return true;
    if (loopback) return false;
    if (machine.has(h)) return true;
    if (clock_type::now() - machine_read_at < k_machine_refresh_every) return false;
    machine.read(options.allowed_hosts);
    machine_read_at = clock_type::now();
    return machine.has(h);
  }
  // A WebSocket's Origin: absent (not a browser), or a page served from a loopback name (this
  // server's or `view --connect`'s), or with a non-loopback listener the Host itself (checked
  // by host_allowed). Writes the header to out_origin.
  bool origin_allowed(lws* wsi, std::string& out_origin) const {
    char origin[256];
    const int n = lws_hdr_copy(wsi, origin, sizeof origin, WSI_TOKEN_ORIGIN);
    if (n <= 0) {
      const bool absent = lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN) == 0;
      out_origin = absent ? "(none)" : "(too long)";
      return absent;
    }
    out_origin = origin;
    const std::string_view oh = host_part(origin);
    if (is_loopback_name(oh)) return true;
    if (loopback) return false;
    char host[256];
    return lws_hdr_copy(wsi, host, sizeof host, WSI_TOKEN_HOST) > 0 &&
           lower(host_part(host)) == lower(oh);
  }
};

server_state* server_of(lws* wsi) {
  return static_cast<server_state*>(lws_context_user(lws_get_context(wsi)));
}

std::string peer_of(lws* wsi) {
  char peer[64] = {};
  lws_get_peer_simple(wsi, peer, sizeof peer);
  return peer;
}

// A path below a served folder: segments of [A-Za-z0-9._-], none empty or starting with '.'.
bool safe_relative_path(std::string_view p) {
  if (p.empty() || p.size() > 512) return false;
  std::size_t start = 0;
  while (start <= p.size()) {
    std::size_t end = p.find('/', start);
    if (end == std::string_view::npos) end = p.size();
    const std::string_view seg = p.substr(start, end - start);
    if (seg.empty() || seg[0] == '.') return false;
    for (char c : seg)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'))
        return false;
    start = end + 1;
  }
  return true;
}

const char* mime_of(std::string_view path) {
  auto ends = [&](std::string_view e) {
    return path.size() >= e.size() && path.substr(path.size() - e.size()) == e;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".json")) return "application/json";
  if (ends(".vrm") || ends(".vrma") || ends(".glb")) return "model/gltf-binary";
  if (ends(".png")) return "image/png";
  if (ends(".jsonl")) return "application/x-ndjson";
  if (ends(".mp4") || ends(".m4v")) return "video/mp4";
  if (ends(".webm")) return "video/webm";
  if (ends(".ogv")) return "video/ogg";
  if (ends(".mov")) return "video/quicktime";
  return nullptr;  // not served
}

// The file a GET path names, or empty.
std::string route(const server_state& s, std::string_view path) {
  if (path == "/" || path == "/index.html") return s.options.page_dir + "/index.html";
  if (path == "/avatar.vrm") return s.options.avatar_path;
  if (path == "/clip.vrma") return s.options.clip_path;
  if (path == "/poses.pose.jsonl") return s.options.poses_path;
  if (path == "/video") return s.options.video_path;
  constexpr std::string_view modules = "/modules/";
  if (path.substr(0, modules.size()) == modules) {
    std::string_view rest = path.substr(modules.size());
    const std::string_view package = rest.substr(0, rest.find('/'));
    if (package != "three" && package != "three-vrm" && package != "three-vrm-animation") return {};
    if (!safe_relative_path(rest) || rest.size() < 3 || rest.substr(rest.size() - 3) != ".js")
      return {};
    return s.options.modules_dir + "/" + std::string(rest);
  }
  // The page's own files: one level, no folders.
  std::string_view name = path.substr(1);
  if (name.find('/') != std::string_view::npos || !safe_relative_path(name)) return {};
  return s.options.page_dir + "/" + std::string(name);
}

int finish(lws* wsi) { return lws_http_transaction_completed(wsi) ? -1 : 0; }

int refuse(lws* wsi, unsigned code, const char* body) {
  lws_return_http_status(wsi, code, body);
  return -1;  // close: error answers are rare and the page never makes them
}

// Answers with `body` (owned by the server, alive until it stops) from memory: the headers now,
// the body in k_body_chunk pieces as the connection takes them (LWS_CALLBACK_HTTP_WRITEABLE).
int serve_memory(lws* wsi, server_state& s, http_session* session, const std::string& body,
                 const char* mime, bool no_store) {
  unsigned char* start = s.http_buffer.data() + LWS_PRE;
  unsigned char* p = start;
  unsigned char* end = s.http_buffer.data() + s.http_buffer.size() - 1;
  if (lws_add_http_common_headers(wsi, HTTP_STATUS_OK, mime, body.size(), &p, end)) return 1;
  if (no_store &&
      lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CACHE_CONTROL,
                                   reinterpret_cast<const unsigned char*>("no-store"), 8, &p, end))
    return 1;
  for (const auto& h : k_file_headers)
    if (lws_add_http_header_by_name(wsi, reinterpret_cast<const unsigned char*>(h[0]),
                                    reinterpret_cast<const unsigned char*>(h[1]),
                                    static_cast<int>(std::strlen(h[1])), &p, end))
      return 1;
  if (lws_finalize_write_http_header(wsi, start, &p, end)) return 1;
  session->body = &body;
  session->body_sent = 0;
  lws_callback_on_writable(wsi);
  return 0;
}

int http_callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
  auto* session = static_cast<http_session*>(user);
  switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
      return 1;  // a WebSocket without our subprotocol
    case LWS_CALLBACK_HTTP: {
      server_state& s = *server_of(wsi);
      session->body = nullptr;
      std::string host;
      if (!s.host_allowed(wsi, host)) {
        s.refusal("refused a request from " + peer_of(wsi) + ": Host '" + printable(host) +
                  "' is not " +
                  (s.loopback ? "a loopback name" : "a name or address of this machine") +
                  " (a page of another site, or DNS rebinding)");
        return refuse(wsi, HTTP_STATUS_FORBIDDEN,
                      s.loopback ? "this server answers only to 127.0.0.1 and localhost"
                                 : "this server answers only to the names and addresses of its "
                                   "machine");
      }
      if (lws_hdr_total_length(wsi, WSI_TOKEN_GET_URI) <= 0)
        return refuse(wsi, HTTP_STATUS_METHOD_NOT_ALLOWED, "only GET");
      const std::string_view path(static_cast<const char*>(in),
                                  in ? std::strlen(static_cast<const char*>(in)) : 0);
      if (path == "/config.json")
        return serve_memory(wsi, s, session, s.config_json, "application/json", true);
      if (path == "/avatar.vrm" && s.options.avatar_path.empty() && !s.options.avatar_data.empty())
        return serve_memory(wsi, s, session, s.options.avatar_data, "model/gltf-binary", false);
      if (path == "/poses.pose.jsonl" && s.options.poses_path.empty() &&
          !s.options.poses_data.empty())
        return serve_memory(wsi, s, session, s.options.poses_data, "application/x-ndjson", true);
      const std::string file = route(s, path);
      // The avatar and the clip are glTF binaries whatever their names end with.
      std::string lower_file = file;
      for (char& c : lower_file) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      const char* mime = path == "/avatar.vrm" || path == "/clip.vrma" ? "model/gltf-binary"
                         : path == "/poses.pose.jsonl"                 ? "application/x-ndjson"
                         : path == "/video"                            ? mime_of(lower_file)
                                                                       : mime_of(file);
      if (file.empty() || !mime || !is_file(file))
        return refuse(wsi, HTTP_STATUS_NOT_FOUND, "not found");
      const int n = lws_serve_http_file(wsi, file.c_str(), mime, s.file_headers.c_str(),
                                        static_cast<int>(s.file_headers.size()));
      if (n < 0 || (n > 0 && lws_http_transaction_completed(wsi))) return -1;
      return 0;
    }
    case LWS_CALLBACK_HTTP_WRITEABLE: {
      if (!session || !session->body) return 0;
      server_state& s = *server_of(wsi);
      const std::string& body = *session->body;
      const std::size_t n = std::min(body.size() - session->body_sent, k_body_chunk);
      std::memcpy(s.http_buffer.data() + LWS_PRE, body.data() + session->body_sent, n);
      session->body_sent += n;
      const bool last = session->body_sent == body.size();
      if (lws_write(wsi, s.http_buffer.data() + LWS_PRE, n,
                    last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP) != static_cast<int>(n))
        return 1;
      if (!last) {
        lws_callback_on_writable(wsi);
        return 0;
      }
      session->body = nullptr;
      return finish(wsi);
    }
    case LWS_CALLBACK_HTTP_FILE_COMPLETION:
      return finish(wsi);
    default:
      return lws_callback_http_dummy(wsi, reason, user, in, len);
  }
}

int ws_callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
  auto* session = static_cast<ws_session*>(user);
  switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION: {
      server_state& s = *server_of(wsi);
      char uri[64];
      if (lws_hdr_copy(wsi, uri, sizeof uri, WSI_TOKEN_GET_URI) <= 0 ||
          std::strcmp(uri, k_pose_socket_path) != 0)
        return 1;
      std::string host, origin;
      if (!s.host_allowed(wsi, host)) {
        s.refusal("refused a WebSocket from " + peer_of(wsi) + ": Host '" + printable(host) +
                  "' is not " +
                  (s.loopback ? "a loopback name" : "a name or address of this machine"));
        return 1;
      }
      if (!s.origin_allowed(wsi, origin)) {
        s.refusal("refused a WebSocket from " + peer_of(wsi) + ": Origin '" + printable(origin) +
                  "' is a page of another site");
        return 1;
      }
      return 0;
    }
    case LWS_CALLBACK_ESTABLISHED: {
      server_state& s = *server_of(wsi);
      std::fill(std::begin(session->sent_count), std::end(session->sent_count), 0);
      session->established = true;
      session->rx_len = 0;
      session->rx_overflow = false;
      session->peer[0] = '\0';
      lws_get_peer_simple(wsi, session->peer, sizeof session->peer);
      const int open = ++s.open;
      ++s.connections;
      s.event("page connected from " + std::string(session->peer) + " (" + std::to_string(open) +
              " open)");
      lws_callback_on_writable(wsi);
      return 0;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE: {
      server_state& s = *server_of(wsi);
      std::size_t n = 0;
      std::uint64_t count = 0;
      int slot = -1;
      int unsent = 0;  // slots with a pose this connection has not been handed
      {
        std::lock_guard<std::mutex> lock(s.m);
        for (int k = 0; k < k_pose_server_slots; ++k) {
          const server_state::slot_pose& l = s.latest[static_cast<std::size_t>(k)];
          if (l.size == 0 || l.count == session->sent_count[k]) continue;
          ++unsent;
          if (slot < 0 || l.stamp < s.latest[static_cast<std::size_t>(slot)].stamp) slot = k;
        }
        if (slot < 0) return 0;
        const server_state::slot_pose& l = s.latest[static_cast<std::size_t>(slot)];
        n = l.size;
        count = l.count;
        std::memcpy(s.send_buffer.data() + LWS_PRE, l.text.data(), n);
      }
      std::uint64_t& sent_count = session->sent_count[slot];
      if (sent_count != 0 && count > sent_count + 1)
        s.skipped += static_cast<long>(count - sent_count - 1);
      sent_count = count;
      // lws sends what the socket takes and keeps the rest, then calls back only when it is
      // out: at most one message waits per connection.
      if (lws_write(wsi, s.send_buffer.data() + LWS_PRE, n, LWS_WRITE_TEXT) < static_cast<int>(n))
        return -1;
      ++s.sent;
      // Another slot's pose waits: ask again (one message per writeable callback).
      if (unsent > 1) lws_callback_on_writable(wsi);
      return 0;
    }
    case LWS_CALLBACK_RECEIVE: {
      // The page's one report: {"first_posed_ms": X}. Anything else is ignored.
      if (session->rx_len + len > k_rx_max - 1) session->rx_overflow = true;
      if (!session->rx_overflow) {
        std::memcpy(session->rx + session->rx_len, in, len);
        session->rx_len += len;
      }
      if (!lws_is_final_fragment(wsi)) return 0;
      if (!session->rx_overflow) {
        session->rx[session->rx_len] = '\0';
        constexpr const char* key = "\"first_posed_ms\":";
        if (const char* at = std::strstr(session->rx, key)) {
          char* end = nullptr;
          const double ms = std::strtod(at + std::strlen(key), &end);
          if (end != at + std::strlen(key) && ms >= 0 && ms < 1e9) {
            server_state& s = *server_of(wsi);
            s.first_posed_ms = ms;
            char line[192];
            std::snprintf(line, sizeof line,
                          "page at %s showed its first posed frame %.0f ms after it began loading",
                          session->peer, ms);
            s.event(line);
          }
        }
      }
      session->rx_len = 0;
      session->rx_overflow = false;
      return 0;
    }
    case LWS_CALLBACK_CLOSED: {
      // lws calls this for a handshake the filter refused too: only accepted ones were counted.
      if (!session || !session->established) return 0;
      session->established = false;
      server_state& s = *server_of(wsi);
      const int open = --s.open;
      s.event("page at " + std::string(session->peer) + " left (" + std::to_string(open) +
              " open)");
      return 0;
    }
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
      // publish() woke the service: every connection that has not sent the newest pose asks
      // to write (a connection still sending its last message is called when it is done).
      lws_callback_on_writable_all_protocol(lws_get_context(wsi), &k_protocols[1]);
      return 0;
    default:
      return 0;
  }
}

}  // namespace

struct pose_server::impl : server_state {};

pose_server::pose_server() : impl_(std::make_unique<impl>()) {}
pose_server::~pose_server() { stop(); }

bool pose_server::available() { return true; }

status pose_server::start(const pose_server_options& options) {
  if (impl_->started || impl_->stopping)
    return status::error("pose server: start() was already called (one start per server)");
  if (status st = options.validate(); !st) return st;
  impl& s = *impl_;
  s.options = options;
  sockaddr_storage addr{};
  socklen_t addr_len = 0;
  parse_host(options.host, addr, addr_len);
  s.loopback = is_loopback(addr);
  const std::string host = options.host == "localhost" ? "127.0.0.1" : options.host;
  if (options.port != 0) {
    if (std::string problem = bind_problem(addr, addr_len, host, options.port, options.port_option);
        !problem.empty())
      return status::error("pose server: " + problem);
  }

  nlohmann::json config;
  const bool has_avatar = !options.avatar_path.empty() || !options.avatar_data.empty();
  config["protocol"] = k_pose_socket_protocol;
  config["avatar"] = has_avatar ? nlohmann::json("/avatar.vrm") : nlohmann::json();
  config["clip"] = options.clip_path.empty() ? nlohmann::json() : nlohmann::json("/clip.vrma");
  config["pose_socket"] =
      options.pose_socket_url.empty() ? nlohmann::json() : nlohmann::json(options.pose_socket_url);
  auto base_name = [](const std::string& p) { return p.substr(p.find_last_of('/') + 1); };
  config["avatar_name"] = !options.avatar_name.empty()   ? options.avatar_name
                          : !options.avatar_path.empty() ? base_name(options.avatar_path)
                          : has_avatar                   ? std::string("avatar.vrm")
                                                         : std::string();
  config["clip_name"] = base_name(options.clip_path);
  config["avatar_animated"] = options.avatar_animated;
  const bool has_poses = !options.poses_path.empty() || !options.poses_data.empty();
  config["poses"] = has_poses ? nlohmann::json("/poses.pose.jsonl") : nlohmann::json();
  config["poses_name"] =
      !options.poses_name.empty() ? options.poses_name : base_name(options.poses_path);
  config["video"] = options.video_path.empty() ? nlohmann::json() : nlohmann::json("/video");
  config["video_name"] = base_name(options.video_path);
  s.config_json = config.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  s.file_headers.clear();
  for (const auto& h : k_file_headers) s.file_headers += std::string(h[0]) + " " + h[1] + "\r\n";
  s.machine.read(options.allowed_hosts);
  s.machine_read_at = clock_type::now();

  lws_set_log_level(LLL_ERR, lws_log_sink);
  lws_context_creation_info info;
  std::memset(&info, 0, sizeof info);
  info.port = options.port;
  info.iface = host.c_str();
  info.protocols = k_protocols;
  info.user = &s;
  // Not LWS_SERVER_OPTION_HTTP_HEADERS_SECURITY_BEST_PRACTICES_ENFORCE: its fixed
  // Content-Security-Policy forbids the page's inline import map; route()'s answers carry
  // k_file_headers instead.
  info.options = LWS_SERVER_OPTION_FAIL_UPON_UNABLE_TO_BIND;
  if (addr.ss_family == AF_INET) info.options |= LWS_SERVER_OPTION_DISABLE_IPV6;
  info.vhost_name = "avatarmap";
  info.server_string = "avatarmap";
  info.timeout_secs = 20;
  lws_context* ctx = lws_create_context(&info);
  if (!ctx) {
    std::string why;
    if (options.port != 0)
      why = bind_problem(addr, addr_len, host, options.port, options.port_option);
    if (why.empty()) {
      std::lock_guard<std::mutex> lock(g_log_mutex);
      why = "could not start on " + host + " port " + std::to_string(options.port) +
            (g_last_log.empty() ? std::string() : " (" + g_last_log + ")");
    }
    return status::error("pose server: " + why);
  }
  lws_vhost* vh = lws_get_vhost_by_name(ctx, "avatarmap");
  s.port = vh ? lws_get_vhost_listen_port(vh) : options.port;
  const std::string port_text = ":" + std::to_string(s.port);
  auto bracketed = [](const std::string& h) {
    return h.find(':') != std::string::npos ? "[" + h + "]" : h;
  };
  s.listen_address = bracketed(host) + port_text;
  const bool wildcard = is_wildcard(addr);
  const std::string shown = host == "0.0.0.0" ? "127.0.0.1" : wildcard ? "::1" : host;
  s.url = "http://" + bracketed(shown) + port_text + "/";
  s.network_urls.clear();
  if (!s.loopback && !wildcard) s.network_urls.push_back(s.url);
  if (wildcard) {
    for (const ip_address& a : s.machine.addresses) {
      // Not loopback (url() is that), not link-local IPv6 (a URL would need its zone), not IPv6
      // on an IPv4 listener.
      const bool v6 = a.family == AF_INET6;
      if (a.loopback() || (v6 && a.bytes[0] == 0xfe && (a.bytes[1] & 0xc0) == 0x80) ||
          (v6 && addr.ss_family == AF_INET))
        continue;
      const std::string u = "http://" + url_host(a) + port_text + "/";
      if (std::find(s.network_urls.begin(), s.network_urls.end(), u) == s.network_urls.end())
        s.network_urls.push_back(u);
    }
  }
  {
    std::lock_guard<std::mutex> lock(s.m);
    s.context = ctx;
  }
  s.started = true;
  s.thread = std::thread([&s, ctx] {
    while (!s.stopping.load()) {
      lws_service(ctx, 0);
      s.summarise_refusals(false);
    }
    s.summarise_refusals(true);
  });
  return {};
}

void pose_server::stop() {
  impl& s = *impl_;
  if (!s.started) return;
  s.started = false;
  lws_context* ctx = nullptr;
  {
    std::lock_guard<std::mutex> lock(s.m);
    ctx = s.context;
    s.context = nullptr;
  }
  s.stopping = true;
  lws_cancel_service(ctx);
  s.thread.join();
  lws_context_destroy(ctx);
}

int pose_server::port() const { return impl_->port; }
std::string pose_server::url() const { return impl_->url; }
std::string pose_server::listen_address() const { return impl_->listen_address; }
bool pose_server::exposed() const { return impl_->port != 0 && !impl_->loopback; }
std::vector<std::string> pose_server::network_urls() const { return impl_->network_urls; }

namespace {

// Puts ,"person":PERSON,"slot":SLOT before the closing '}' of the line text[0, size); returns
// the new size. `text` has k_person_keys_room bytes past `size`.
std::size_t add_person_keys(char* text, std::size_t size, int person, int slot) {
  char* at = text + size - 1;  // the line's closing '}'
  char* const end = text + size + k_person_keys_room;
  constexpr std::string_view person_key = ",\"person\":";
  constexpr std::string_view slot_key = ",\"slot\":";
  at = std::copy(person_key.begin(), person_key.end(), at);
  at = std::to_chars(at, end, person).ptr;
  at = std::copy(slot_key.begin(), slot_key.end(), at);
  at = std::to_chars(at, end, slot).ptr;
  *at++ = '}';
  return static_cast<std::size_t>(at - text);
}

}  // namespace

void pose_server::publish(const proxy_pose& pose, int person, int slot) {
  impl& s = *impl_;
  ++s.published;
  if (slot < 0 || slot >= k_pose_server_slots) return;
  std::lock_guard<std::mutex> lock(s.m);
  server_state::slot_pose& l = s.latest[static_cast<std::size_t>(slot)];
  io_detail::memory_text text(l.text.data(), k_message_capacity);
  if (!io_detail::put_pose_line(text, pose, pose_write_options{}, false)) {
    l.size = 0;  // the buffer holds a partial line now (never expected: it is sized for any)
    return;
  }
  l.size = person >= 0 ? add_person_keys(l.text.data(), text.size(), person, slot) : text.size();
  ++l.count;
  l.stamp = ++s.seq;
  if (s.context) lws_cancel_service(s.context);
}

void pose_server::clear(int person, int slot) {
  impl& s = *impl_;
  if (slot < 0 || slot >= k_pose_server_slots) return;
  std::lock_guard<std::mutex> lock(s.m);
  server_state::slot_pose& l = s.latest[static_cast<std::size_t>(slot)];
  constexpr std::string_view gone = "{\"gone\":true}";
  std::copy(gone.begin(), gone.end(), l.text.data());
  l.size = add_person_keys(l.text.data(), gone.size(), person, slot);
  ++l.count;
  l.stamp = ++s.seq;
  if (s.context) lws_cancel_service(s.context);
}

pose_server_stats pose_server::stats() const {
  const impl& s = *impl_;
  pose_server_stats r;
  r.pages_connected = s.open.load();
  r.connections = s.connections.load();
  r.refused = s.refused.load();
  r.published = s.published.load();
  r.sent = s.sent.load();
  r.skipped = s.skipped.load();
  r.first_posed_frame_ms = s.first_posed_ms.load();
  return r;
}

#else  // no libwebsockets: a server that says so

struct pose_server::impl {
  std::atomic<long> published{0};
};
pose_server::pose_server() : impl_(std::make_unique<impl>()) {}
pose_server::~pose_server() = default;
bool pose_server::available() { return false; }
status pose_server::start(const pose_server_options& options) {
  if (status st = options.validate(); !st) return st;
  return status::error(
      "pose server: this build has no WebSocket server (libwebsockets was not found when it was "
      "built): install libwebsockets-dev (scripts/setup.sh) and build again");
}
void pose_server::stop() {}
int pose_server::port() const { return 0; }
std::string pose_server::url() const { return {}; }
std::string pose_server::listen_address() const { return {}; }
bool pose_server::exposed() const { return false; }
std::vector<std::string> pose_server::network_urls() const { return {}; }
void pose_server::publish(const proxy_pose&, int, int) { ++impl_->published; }
void pose_server::clear(int, int) {}

pose_server_stats pose_server::stats() const {
  pose_server_stats r;
  r.published = impl_->published.load();
  return r;
}

#endif

}  // namespace avatarmap
