#include "avatarmap/stream/udp_sender.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace avatarmap {

namespace {

std::string numeric_address(const sockaddr* sa) {
  char text[INET6_ADDRSTRLEN] = {};
  if (sa->sa_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(sa);
    inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
    return "[" + std::string(text) + "]:" + std::to_string(ntohs(a->sin6_port));
  }
  const auto* a = reinterpret_cast<const sockaddr_in*>(sa);
  inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(a->sin_port));
}

}  // namespace

status udp_sender::open(const host_port& to) {
  close();
  stats_ = {};
  warning_.clear();
  address_.clear();
  if (to.host.empty() || to.port < 1 || to.port > 65535)
    return status::error("udp: no host, or a port outside 1..65535");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(to.port);
  const int rc = getaddrinfo(to.host.c_str(), port.c_str(), &hints, &found);
  if (rc != 0 || found == nullptr)
    return status::error(
        "cannot resolve host '" + to.host + "': " +
        (rc == EAI_SYSTEM ? std::string(std::strerror(errno)) : std::string(gai_strerror(rc))) +
        " (give a name this machine resolves, or a numeric address)");
  const addrinfo* pick = nullptr;
  for (const addrinfo* a = found; a != nullptr && pick == nullptr; a = a->ai_next)
    if (a->ai_family == AF_INET) pick = a;
  for (const addrinfo* a = found; a != nullptr && pick == nullptr; a = a->ai_next)
    if (a->ai_family == AF_INET6) pick = a;
  if (pick == nullptr || pick->ai_addrlen > sizeof addr_) {
    freeaddrinfo(found);
    return status::error("host '" + to.host + "' has no IPv4 or IPv6 address");
  }
  std::memcpy(addr_, pick->ai_addr, pick->ai_addrlen);
  addr_len_ = static_cast<unsigned>(pick->ai_addrlen);
  const int family = pick->ai_family;
  freeaddrinfo(found);
  const auto* sa = reinterpret_cast<const sockaddr*>(addr_);
  address_ = numeric_address(sa);

  fd_ = ::socket(family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    return status::error("cannot open a UDP socket for " + address_ + ": " + std::strerror(errno));
  // Connected, the socket hears of refusals (no receiver) on a later send.
  connected_ = ::connect(fd_, sa, addr_len_) == 0;
  if (!connected_)
    warning_ = address_ + " cannot be reached now (" + std::strerror(errno) +
               "): sends are counted as errors until it can";
  return {};
}

void udp_sender::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  connected_ = false;
}

bool udp_sender::send(const void* data, std::size_t size) {
  if (fd_ < 0) {
    ++stats_.errors;
    return false;
  }
  for (;;) {
    const ssize_t n = connected_ ? ::send(fd_, data, size, MSG_DONTWAIT | MSG_NOSIGNAL)
                                 : ::sendto(fd_, data, size, MSG_DONTWAIT | MSG_NOSIGNAL,
                                            reinterpret_cast<const sockaddr*>(addr_),
                                            static_cast<socklen_t>(addr_len_));
    if (n >= 0) {
      ++stats_.sent;
      return true;
    }
    const int e = errno;
    if (e == EINTR) continue;
    if (e == EAGAIN || e == EWOULDBLOCK || e == ENOBUFS)
      ++stats_.dropped;
    else if (e == ECONNREFUSED)
      ++stats_.refused;
    else
      ++stats_.errors;
    return false;
  }
}

}  // namespace avatarmap
