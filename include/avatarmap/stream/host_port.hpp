// A network destination as a user writes it: HOST, HOST:PORT, [IPV6] or [IPV6]:PORT, or a bare
// IPv6 address (no port). HOST is a name or an IPv4 address; nothing is resolved here.
#pragma once

#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

struct host_port {
  std::string host;  // without brackets
  int port = 0;      // 1 .. 65535
};

/// Parses `text` into `out`; the port is `default_port` (1 .. 65535) when the text gives none.
/// Fails, with a message that quotes `text` and shows the accepted forms, on an empty host, a
/// port that is not a number in 1 .. 65535, an unclosed or misplaced bracket, a space or
/// control character, or several colons outside brackets that do not form an IPv6 address (an
/// IPv6 address with a port needs brackets: [::1]:39539).
status parse_host_port(std::string_view text, int default_port, host_port& out);

}  // namespace avatarmap
