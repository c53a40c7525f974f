// A small OSC 1.0 decoder for the tests, written from the specification independently of the
// encoder under test: a packet (one message or a bundle of messages) -> a list of messages with
// their arguments. Returns false on anything malformed (sizes, padding, type tags).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace avatarmap::test {

struct osc_arg {
  char type = 0;
  std::int32_t i = 0;
  float f = 0.f;
  std::string s;
};

struct osc_message {
  std::string address;
  std::string types;  // without the ','
  std::vector<osc_arg> args;
};

struct osc_packet {
  bool is_bundle = false;
  std::uint64_t time_tag = 0;
  std::vector<osc_message> messages;
};

namespace detail {
inline std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}
// Reads an OSC string at p[pos, end): NUL-terminated, padded with NULs to a multiple of 4.
inline bool read_string(const std::uint8_t* p, std::size_t end, std::size_t& pos,
                        std::string& out) {
  std::size_t n = pos;
  while (n < end && p[n] != 0) ++n;
  if (n >= end) return false;
  out.assign(reinterpret_cast<const char*>(p + pos), n - pos);
  std::size_t next = pos + ((n - pos) / 4 + 1) * 4;
  if (next > end) return false;
  for (std::size_t k = n; k < next; ++k)
    if (p[k] != 0) return false;
  pos = next;
  return true;
}
inline bool read_message(const std::uint8_t* p, std::size_t begin, std::size_t end,
                         osc_message& m) {
  std::size_t pos = begin;
  std::string tags;
  if (!read_string(p, end, pos, m.address) || m.address.empty() || m.address[0] != '/')
    return false;
  if (!read_string(p, end, pos, tags) || tags.empty() || tags[0] != ',') return false;
  m.types = tags.substr(1);
  for (char t : m.types) {
    osc_arg a;
    a.type = t;
    if (t == 'i' || t == 'f') {
      if (pos + 4 > end) return false;
      const std::uint32_t v = be32(p + pos);
      pos += 4;
      if (t == 'i')
        a.i = static_cast<std::int32_t>(v);
      else
        std::memcpy(&a.f, &v, 4);
    } else if (t == 's') {
      if (!read_string(p, end, pos, a.s)) return false;
    } else {
      return false;
    }
    m.args.push_back(a);
  }
  return pos == end;
}
}  // namespace detail

inline bool read_osc_packet(const std::uint8_t* p, std::size_t size, osc_packet& out) {
  out = osc_packet{};
  if (size % 4 != 0) return false;
  if (size >= 16 && std::memcmp(p, "#bundle\0", 8) == 0) {
    out.is_bundle = true;
    out.time_tag = (std::uint64_t{detail::be32(p + 8)} << 32) | detail::be32(p + 12);
    std::size_t pos = 16;
    while (pos < size) {
      if (pos + 4 > size) return false;
      const std::uint32_t n = detail::be32(p + pos);
      pos += 4;
      if (n % 4 != 0 || n > size - pos) return false;
      osc_message m;
      if (!detail::read_message(p, pos, pos + n, m)) return false;
      out.messages.push_back(std::move(m));
      pos += n;
    }
    return true;
  }
  osc_message m;
  if (!detail::read_message(p, 0, size, m)) return false;
  out.messages.push_back(std::move(m));
  return true;
}

}  // namespace avatarmap::test
