// A UDP socket of the tests bound to an ephemeral port of a loopback address (IPv4 or IPv6),
// for reading back what a sender under test sends; receive() waits up to 2 s.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace avatarmap::test {

class udp_receiver {
 public:
  /// `receive_buffer` > 0 asks the kernel for that many bytes of queue (SO_RCVBUF), so that a
  /// test's burst of datagrams is kept until read.
  explicit udp_receiver(int family = AF_INET, int receive_buffer = 0) {
    fd_ = ::socket(family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) return;
    if (receive_buffer > 0)
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    if (family == AF_INET6) {
      sockaddr_in6 a{};
      a.sin6_family = AF_INET6;
      a.sin6_addr = in6addr_loopback;
      if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        close_fd();
        return;
      }
      socklen_t n = sizeof a;
      ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
      port_ = ntohs(a.sin6_port);
    } else {
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        close_fd();
        return;
      }
      socklen_t n = sizeof a;
      ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
      port_ = ntohs(a.sin_port);
    }
    timeval tv{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  udp_receiver(const udp_receiver&) = delete;
  udp_receiver& operator=(const udp_receiver&) = delete;
  ~udp_receiver() { close_fd(); }
  bool ok() const { return fd_ >= 0; }
  int port() const { return port_; }
  void close_fd() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  /// One datagram, or empty after the 2 s timeout.
  std::vector<std::uint8_t> receive() {
    std::vector<std::uint8_t> buf(65536);
    const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
    buf.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return buf;
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

}  // namespace avatarmap::test
