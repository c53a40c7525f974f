// A UDP sender that never blocks the caller (POSIX sockets): the destination is resolved once,
// when opened; each send() hands one datagram to the kernel without waiting. A send that would
// block (the socket's buffer is full) is dropped and counted; a "connection refused" reported
// back by the destination's host (ICMP port unreachable: no receiver is listening there) is
// counted and ignored, as is any other error, so a live loop keeps its pace whatever the network
// does. send() allocates nothing.
// Thread-safety: one thread sends; stats() is read by it or after it stopped.
#pragma once

#include <cstddef>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/stream/host_port.hpp"

namespace avatarmap {

struct udp_send_stats {
  long sent = 0;     // datagrams the kernel accepted
  long dropped = 0;  // would have blocked (socket buffer full): not sent
  long refused = 0;  // a previous datagram was refused (no receiver at the port): this one not sent
  long errors = 0;   // any other failure (unreachable network, datagram too large, ...)
};

class udp_sender {
 public:
  udp_sender() = default;
  ~udp_sender() { close(); }
  udp_sender(const udp_sender&) = delete;
  udp_sender& operator=(const udp_sender&) = delete;

  /// Resolves `to` (a name's IPv4 address when it has one, else its IPv6 one: most receivers
  /// listen on IPv4 only; give an IPv6 address to use IPv6) and opens a non-blocking socket
  /// toward it. Fails, with a message naming the host, when the name does not resolve or no
  /// socket can be opened. When the destination cannot be reached yet (no route), open()
  /// succeeds with warning() saying so, and sends count as errors until it can be reached.
  status open(const host_port& to);
  void close();
  bool is_open() const { return fd_ >= 0; }

  /// Sends one datagram; never blocks. True when the kernel took it; otherwise counted in
  /// stats() (dropped, refused or errors).
  bool send(const void* data, std::size_t size);

  const udp_send_stats& stats() const { return stats_; }
  /// The resolved destination, numeric: "127.0.0.1:39539", "[::1]:39539".
  const std::string& address() const { return address_; }
  /// Empty, or why the destination was not reachable when opened.
  const std::string& warning() const { return warning_; }

 private:
  int fd_ = -1;
  bool connected_ = false;                   // connect() worked: send() then learns of refusals
  alignas(8) unsigned char addr_[128] = {};  // the resolved sockaddr (sockaddr_storage's size)
  unsigned addr_len_ = 0;
  udp_send_stats stats_{};
  std::string address_;
  std::string warning_;
};

}  // namespace avatarmap
