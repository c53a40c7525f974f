// Result of loading and configuration calls: ok, or an error with a code (what kind of failure)
// and a message that names the file, line, key or field and what to do. Per-frame calls use
// plain bool instead.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

namespace avatarmap {

/// What kind of failure a status reports, set where the failure happened so that callers (the
/// C API's avm_status, the CLI's hints, Python's exception classes) need not read the message.
/// The C API maps each code to the AVM_ERROR_* of the same name, one to one.
enum class status_code : std::uint8_t {
  ok,
  invalid_argument,  // an argument, option or field out of range; a request that cannot be met
  io,                // a file, folder or device cannot be opened, read, written or renamed
  parse,             // a file's (or a buffer's) content is malformed or does not fit its use
  unsupported,       // the feature is not built in (FFmpeg, ONNX Runtime, a backend)
  out_of_memory,     // memory ran out (an input too large for the process)
  internal,          // a stage failed on valid input (a bug, or a library beneath us)
};

/// "ok", "invalid argument", "I/O", "parse", "unsupported", "out of memory", "internal".
constexpr const char* status_code_name(status_code c) {
  switch (c) {
    case status_code::ok:
      return "ok";
    case status_code::invalid_argument:
      return "invalid argument";
    case status_code::io:
      return "I/O";
    case status_code::parse:
      return "parse";
    case status_code::unsupported:
      return "unsupported";
    case status_code::out_of_memory:
      return "out of memory";
    case status_code::internal:
      return "internal";
  }
  return "internal";
}

class status {
 public:
  status() = default;  // ok

  /// The generic error: status_code::invalid_argument (what most checks of arguments, options
  /// and fields are). A failure of another kind uses the named constructor below.
  static status error(std::string message) {
    return status(status_code::invalid_argument, std::move(message));
  }
  static status invalid_argument(std::string message) {
    return status(status_code::invalid_argument, std::move(message));
  }
  /// A file, folder or device cannot be opened, read, written or renamed.
  static status io_error(std::string message) {
    return status(status_code::io, std::move(message));
  }
  /// A file's content is malformed (a line, a key, a value) or does not fit its use.
  static status parse_error(std::string message) {
    return status(status_code::parse, std::move(message));
  }
  /// The feature is not built in this build (FFmpeg, ONNX Runtime, a capture backend).
  static status unsupported(std::string message) {
    return status(status_code::unsupported, std::move(message));
  }
  /// Memory ran out (an input too large for the process), so that callers can tell it from a
  /// malformed input: the C API reports AVM_ERROR_OUT_OF_MEMORY.
  static status out_of_memory(std::string message) {
    return status(status_code::out_of_memory, std::move(message));
  }
  /// A stage failed on valid input (an estimator's run, an encoder's internal error).
  static status internal(std::string message) {
    return status(status_code::internal, std::move(message));
  }
  /// A failure of code `code`; status_code::ok is taken as internal (a failure needs a kind).
  static status failure(status_code code, std::string message) {
    return status(code == status_code::ok ? status_code::internal : code, std::move(message));
  }

  bool ok() const { return code_ == status_code::ok; }
  explicit operator bool() const { return ok(); }
  /// status_code::ok when ok.
  status_code code() const { return code_; }
  /// Empty when ok.
  const std::string& message() const { return message_; }
  bool is_out_of_memory() const { return code_ == status_code::out_of_memory; }

  /// The same failure, its code kept, with `prefix` put before its message (say "FILE: " to
  /// name the file a step was working on). Ok stays ok.
  status prefixed(std::string_view prefix) const {
    if (ok()) return {};
    std::string m;
    m.reserve(prefix.size() + message_.size());
    m.append(prefix).append(message_);
    return status(code_, std::move(m));
  }
  /// The same failure, its code kept, with another message. Ok stays ok.
  status with_message(std::string message) const {
    if (ok()) return {};
    return status(code_, std::move(message));
  }

 private:
  status(status_code code, std::string message) : code_(code), message_(std::move(message)) {}
  status_code code_ = status_code::ok;
  std::string message_;
};

}  // namespace avatarmap
