// A raw-socket HTTP and WebSocket client for the pose server's tests (pose_server_test.cpp,
// pose_server_load_test.cpp): requests with any Host or Origin header, partial requests, and
// whole WebSocket text messages (RFC 6455, unmasked server frames). Loopback (127.0.0.1) only.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <string>

#include "avatarmap/stream/pose_server.hpp"

namespace avatarmap::test {

/// A TCP connection to 127.0.0.1:port (receive time-out 10 s), or -1.
inline int connect_to(int port, int rcvbuf = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

inline void send_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
    if (n <= 0) return;
    off += static_cast<std::size_t>(n);
  }
}

struct http_answer {
  int status = 0;  // 0: no answer (refused, closed or timed out)
  std::string head, body;
  std::string header(const std::string& name) const {
    std::string lower = head;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto p = lower.find("\r\n" + name + ":");
    if (p == std::string::npos) return {};
    const auto start = head.find_first_not_of(' ', p + name.size() + 3);
    return head.substr(start, head.find("\r\n", start) - start);
  }
};

/// Reads an answer from `fd` (head + Content-Length bytes, or until closed) and closes it.
inline http_answer read_answer(int fd) {
  http_answer r;
  std::string data;
  char buf[65536];
  for (;;) {
    const auto end = data.find("\r\n\r\n");
    if (end != std::string::npos) {
      r.head = data.substr(0, end + 2);
      const std::string len = r.header("content-length");
      if (!len.empty() && data.size() - end - 4 >= std::stoul(len)) break;
    }
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    data.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const auto end = data.find("\r\n\r\n");
  if (end == std::string::npos) return http_answer{};
  r.head = data.substr(0, end + 2);
  r.body = data.substr(end + 4);
  if (r.head.size() > 12) r.status = std::atoi(r.head.c_str() + 9);
  return r;
}

/// Sends a raw request, reads the answer.
inline http_answer request(int port, const std::string& raw) {
  const int fd = connect_to(port);
  if (fd < 0) return http_answer{};
  send_all(fd, raw);
  return read_answer(fd);
}

/// A GET request whose Host header is exactly `host_header`.
inline std::string get_request(const std::string& path, const std::string& host_header) {
  return "GET " + path + " HTTP/1.1\r\nHost: " + host_header + "\r\nConnection: close\r\n\r\n";
}

/// GET of `path` with "Host: HOST:PORT".
inline http_answer get(int port, const std::string& path, const std::string& host = "127.0.0.1") {
  return request(port, get_request(path, host + ":" + std::to_string(port)));
}

/// A WebSocket client on a raw socket (RFC 6455): the handshake, then whole text messages.
struct ws_client {
  int fd = -1;
  std::string pending;   // bytes read past the last message
  std::string response;  // the handshake's answer

  bool open(int port, const std::string& extra_headers, int rcvbuf = 0,
            const std::string& key = "dGhlIHNhbXBsZSBub25jZQ==",
            const std::string& host = "127.0.0.1") {
    fd = connect_to(port, rcvbuf);
    if (fd < 0) return false;
    send_all(fd, "GET /pose HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
                     "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: " + key +
                     "\r\nSec-WebSocket-Version: 13\r\n" + extra_headers + "\r\n");
    char buf[4096];
    while (pending.find("\r\n\r\n") == std::string::npos) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) return false;
      pending.append(buf, static_cast<std::size_t>(n));
    }
    const auto end = pending.find("\r\n\r\n");
    response = pending.substr(0, end + 2);
    pending.erase(0, end + 4);
    return response.rfind("HTTP/1.1 101", 0) == 0;
  }
  bool read_bytes(std::size_t n) {
    char buf[65536];
    while (pending.size() < n) {
      const ssize_t got = ::recv(fd, buf, sizeof buf, 0);
      if (got <= 0) return false;
      pending.append(buf, static_cast<std::size_t>(got));
    }
    return true;
  }
  /// The next text message (server frames are unmasked); false on close or time-out.
  bool read(std::string& out) {
    out.clear();
    for (;;) {
      if (!read_bytes(2)) return false;
      const auto b0 = static_cast<unsigned char>(pending[0]);
      const auto b1 = static_cast<unsigned char>(pending[1]);
      std::size_t header = 2, len = b1 & 0x7f;
      if (len == 126) {
        if (!read_bytes(4)) return false;
        len =
            (static_cast<unsigned char>(pending[2]) << 8) | static_cast<unsigned char>(pending[3]);
        header = 4;
      } else if (len == 127) {
        if (!read_bytes(10)) return false;
        len = 0;
        for (int i = 2; i < 10; ++i) len = (len << 8) | static_cast<unsigned char>(pending[i]);
        header = 10;
      }
      if (b1 & 0x80) return false;  // a server never masks
      if (!read_bytes(header + len)) return false;
      const int opcode = b0 & 0x0f;
      out += pending.substr(header, len);
      pending.erase(0, header + len);
      if (opcode == 8) return false;
      if (b0 & 0x80) return true;
    }
  }
  void close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  ~ws_client() { close(); }
};

inline const std::string k_protocol_header =
    std::string("Sec-WebSocket-Protocol: ") + k_pose_socket_protocol + "\r\n";

}  // namespace avatarmap::test
