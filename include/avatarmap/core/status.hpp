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

  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  /// Empty when ok.
  const std::string& message() const { return message_; }

 private:
  explicit status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

}  // namespace avatarmap
