// Result of loading and configuration calls: ok, or an error with a message that names the
// file, line, key or field and what to do. Per-frame calls use plain bool instead.
#pragma once

#include <string>
#include <utility>

namespace avatarmap {

class status {
 public:
  status() = default;  // ok
  static status error(std::string message) { return status(std::move(message)); }
  /// An error caused by memory running out (an input too large for the process), so that
  /// callers can tell it from a malformed input: the C API reports AVM_ERROR_OUT_OF_MEMORY.
  static status out_of_memory(std::string message) {
    status s(std::move(message));
    s.out_of_memory_ = true;
    return s;
  }

  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  /// Empty when ok.
  const std::string& message() const { return message_; }
  bool is_out_of_memory() const { return out_of_memory_; }

 private:
  explicit status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  bool out_of_memory_ = false;
  std::string message_;
};

}  // namespace avatarmap
