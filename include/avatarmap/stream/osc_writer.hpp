// An OSC 1.0 encoder (Open Sound Control: messages and bundles as sent over UDP, one packet per
// datagram) that writes into a buffer the caller owns: it never allocates, so a live loop can
// encode every frame without touching the heap. Encoding (docs/vmc.md, "OSC 1.0"):
//  - int32 and float32 big-endian; a float is its IEEE 754 bits;
//  - a string: its bytes, then 1 to 4 NUL bytes so that the total is a multiple of 4;
//  - a message: the address (an OSC string starting with '/'), the type tag string (',' then one
//    letter per argument: i int32, f float32, s string), then the arguments;
//  - a bundle: the string "#bundle", an 8-byte big-endian NTP time tag (1 = immediately), then
//    each element (here: messages) preceded by its size in bytes as an int32.
//
// Use: begin_bundle(), then per message begin_message(address, "sfff...") + one add_* per type
// letter + end_message(), then end_bundle(); or one message on its own. Any misuse (an address
// without '/', an unknown type letter, an argument of the wrong type or count, a NUL inside a
// string, a message left open, nesting) or running out of buffer puts the writer into a failed
// state: ok() turns false, every later call does nothing, and the bytes are not a valid packet.
// Not thread-safe; one writer per buffer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace avatarmap {

/// The OSC time tag that means "immediately" (NTP seconds 0, fraction 1).
inline constexpr std::uint64_t k_osc_immediately = 1;

class osc_writer {
 public:
  /// Writes into buffer[0, capacity) (not owned; must outlive the writer's use).
  osc_writer(std::uint8_t* buffer, std::size_t capacity) : buffer_(buffer), capacity_(capacity) {}

  /// Forgets what was written (and a failure): the next packet starts at the buffer's start.
  void clear();

  /// Starts a bundle (only at the start of a packet).
  void begin_bundle(std::uint64_t time_tag = k_osc_immediately);
  /// Ends the bundle (no message may be open).
  void end_bundle();

  /// Starts a message: `address` must start with '/'; `types` lists the arguments that follow
  /// (i, f or s each), without the leading ','; "" for none.
  void begin_message(std::string_view address, std::string_view types);
  void add_int32(std::int32_t value);
  void add_float32(float value);
  void add_string(std::string_view value);
  /// Ends the message: every argument its types named must have been added.
  void end_message();

  /// False after any misuse or overflow (see the header comment).
  bool ok() const { return ok_; }
  /// True when ok() and a whole packet is written (no bundle or message open).
  bool complete() const { return ok_ && size_ > 0 && !in_bundle_ && !in_message_; }
  const std::uint8_t* data() const { return buffer_; }
  /// Bytes written so far.
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }

 private:
  bool reserve(std::size_t n);
  void put_u32(std::uint32_t v);
  void put_padded(std::string_view s);
  bool next_type(char want);

  std::uint8_t* buffer_;
  std::size_t capacity_;
  std::size_t size_ = 0;
  std::size_t element_start_ = 0;  // where the open message's size slot is (bundles)
  std::size_t type_cursor_ = 0;    // the open message's next type letter, in the buffer
  bool ok_ = true;
  bool in_bundle_ = false;
  bool in_message_ = false;
};

}  // namespace avatarmap
