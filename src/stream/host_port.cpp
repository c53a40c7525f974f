#include "avatarmap/stream/host_port.hpp"

#include <arpa/inet.h>

namespace avatarmap {

namespace {

bool parse_port(std::string_view s, int& out) {
  if (s.empty() || s.size() > 5) return false;
  int v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  if (v < 1 || v > 65535) return false;
  out = v;
  return true;
}

bool is_ipv6(const std::string& s) {
  unsigned char buf[16];
  return inet_pton(AF_INET6, s.c_str(), buf) == 1;
}

}  // namespace

status parse_host_port(std::string_view text, int default_port, host_port& out) {
  out = host_port{};
  const std::string quoted = "'" + std::string(text) + "'";
  auto fail = [&](const char* why) {
    return status::error(quoted + " is not a destination (" + why +
                         "): give HOST, HOST:PORT, [IPV6]:PORT or an IPv6 address, e.g. "
                         "127.0.0.1:39539");
  };
  if (!(default_port >= 1 && default_port <= 65535)) return fail("the default port is invalid");
  for (char c : text)
    if (static_cast<unsigned char>(c) <= ' ' || c == 0x7f)
      return fail("it contains a space or a control character");
  std::string host;
  int port = default_port;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos) return fail("'[' without ']'");
    host = std::string(text.substr(1, close - 1));
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return fail("something other than :PORT after ']'");
      if (!parse_port(rest.substr(1), port)) return fail("the port is not a number in 1..65535");
    }
    if (host.empty()) return fail("the host is empty");
    if (!is_ipv6(host)) return fail("brackets hold an IPv6 address");
  } else {
    const std::size_t first = text.find(':');
    const std::size_t last = text.rfind(':');
    if (text.find_first_of("[]") != std::string_view::npos) return fail("a misplaced bracket");
    if (first != std::string_view::npos && first != last) {
      host = std::string(text);  // several colons: a bare IPv6 address, no port
      if (!is_ipv6(host)) return fail("an IPv6 address with a port needs brackets: [ADDR]:PORT");
    } else if (first != std::string_view::npos) {
      host = std::string(text.substr(0, first));
      if (!parse_port(text.substr(first + 1), port))
        return fail("the port is not a number in 1..65535");
    } else {
      host = std::string(text);
    }
    if (host.empty()) return fail("the host is empty");
  }
  out.host = std::move(host);
  out.port = port;
  return {};
}

}  // namespace avatarmap
