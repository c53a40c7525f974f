#include "avatarmap/stream/osc_writer.hpp"

#include <cstring>

namespace avatarmap {

namespace {

// Bytes an OSC string of `n` characters takes: the characters, a NUL, padding to 4.
constexpr std::size_t padded_size(std::size_t n) { return (n + 4) & ~std::size_t{3}; }

bool valid_types(std::string_view types) {
  for (char c : types)
    if (c != 'i' && c != 'f' && c != 's') return false;
  return true;
}

}  // namespace

void osc_writer::clear() {
  size_ = 0;
  element_start_ = 0;
  type_cursor_ = 0;
  ok_ = true;
  in_bundle_ = false;
  in_message_ = false;
}

bool osc_writer::reserve(std::size_t n) {
  if (!ok_) return false;
  if (n > capacity_ - size_) {
    ok_ = false;
    return false;
  }
  return true;
}

void osc_writer::put_u32(std::uint32_t v) {
  buffer_[size_++] = static_cast<std::uint8_t>(v >> 24);
  buffer_[size_++] = static_cast<std::uint8_t>(v >> 16);
  buffer_[size_++] = static_cast<std::uint8_t>(v >> 8);
  buffer_[size_++] = static_cast<std::uint8_t>(v);
}

void osc_writer::put_padded(std::string_view s) {
  const std::size_t total = padded_size(s.size());
  if (!s.empty()) std::memcpy(buffer_ + size_, s.data(), s.size());
  std::memset(buffer_ + size_ + s.size(), 0, total - s.size());
  size_ += total;
}

void osc_writer::begin_bundle(std::uint64_t time_tag) {
  if (!ok_) return;
  if (size_ != 0 || in_bundle_) {  // bundles are written only as whole packets, not nested
    ok_ = false;
    return;
  }
  if (!reserve(16)) return;
  put_padded("#bundle");
  put_u32(static_cast<std::uint32_t>(time_tag >> 32));
  put_u32(static_cast<std::uint32_t>(time_tag));
  in_bundle_ = true;
}

void osc_writer::end_bundle() {
  if (!ok_) return;
  if (!in_bundle_ || in_message_) {
    ok_ = false;
    return;
  }
  in_bundle_ = false;
}

void osc_writer::begin_message(std::string_view address, std::string_view types) {
  if (!ok_) return;
  // Outside a bundle a packet is exactly one message.
  if (in_message_ || (!in_bundle_ && size_ != 0) || address.empty() || address[0] != '/' ||
      address.find('\0') != std::string_view::npos || !valid_types(types)) {
    ok_ = false;
    return;
  }
  const std::size_t need =
      (in_bundle_ ? 4 : 0) + padded_size(address.size()) + padded_size(types.size() + 1);
  if (!reserve(need)) return;
  if (in_bundle_) {
    element_start_ = size_;
    put_u32(0);  // the element's size, filled in by end_message
  }
  put_padded(address);
  type_cursor_ = size_ + 1;  // after the ','
  buffer_[size_] = ',';
  if (!types.empty()) std::memcpy(buffer_ + size_ + 1, types.data(), types.size());
  std::memset(buffer_ + size_ + 1 + types.size(), 0,
              padded_size(types.size() + 1) - types.size() - 1);
  size_ += padded_size(types.size() + 1);
  in_message_ = true;
}

// Consumes the next type letter of the open message; fails on a mismatch or when none is left
// (the type string ends with a NUL, which no argument matches).
bool osc_writer::next_type(char want) {
  if (!ok_) return false;
  if (!in_message_ || buffer_[type_cursor_] != static_cast<std::uint8_t>(want)) {
    ok_ = false;
    return false;
  }
  ++type_cursor_;
  return true;
}

void osc_writer::add_int32(std::int32_t value) {
  if (!next_type('i') || !reserve(4)) return;
  put_u32(static_cast<std::uint32_t>(value));
}

void osc_writer::add_float32(float value) {
  if (!next_type('f') || !reserve(4)) return;
  std::uint32_t bits;
  static_assert(sizeof bits == sizeof value, "float must be 32-bit IEEE 754");
  std::memcpy(&bits, &value, sizeof bits);
  put_u32(bits);
}

void osc_writer::add_string(std::string_view value) {
  if (!ok_) return;
  if (value.find('\0') != std::string_view::npos) {
    ok_ = false;
    return;
  }
  if (!next_type('s') || !reserve(padded_size(value.size()))) return;
  put_padded(value);
}

void osc_writer::end_message() {
  if (!ok_) return;
  if (!in_message_ || buffer_[type_cursor_] != 0) {  // not open, or arguments missing
    ok_ = false;
    return;
  }
  in_message_ = false;
  if (in_bundle_) {
    const std::size_t end = size_;
    const std::size_t element = end - element_start_ - 4;
    size_ = element_start_;
    put_u32(static_cast<std::uint32_t>(element));
    size_ = end;
  }
}

}  // namespace avatarmap
