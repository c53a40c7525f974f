// What every C entry point shares (bindings/c/src/): the one exception boundary (guard), the
// handles' error slots, the thread-local create error, and the one mapping from a library
// status's code to avm_status. Rules kept by every avm_* function: its body runs inside guard(), so
// no exception leaves it; messages are composed in fixed buffers where memory may have run out; the
// per-frame calls allocate nothing on success.
#pragma once

#include <cstddef>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/status.hpp"

namespace avatarmap::c_api {

constexpr std::size_t k_error_capacity = 512;

/// Copies `msg` (NULL = "") into `dst` of `size` bytes, truncated and NUL-terminated; nothing
/// when `dst` is NULL or `size` is 0.
void copy_message(char* dst, std::size_t size, const char* msg) noexcept;

/// avm_last_create_error()'s thread-local buffer.
void set_create_error(const char* msg) noexcept;
const char* create_error() noexcept;

/// The last error of a handle (avm_*_last_error): every handle type derives from it.
struct error_slot {
  mutable std::string last_error;
};

/// Sets the handle's message; a failure to allocate it leaves a truncated or empty message
/// rather than turning the real error into another one.
void set_error(const error_slot* h, const char* msg) noexcept;

/// Sets the handle's message and returns `code`.
inline avm_status fail(const error_slot* h, avm_status code, const char* msg) noexcept {
  set_error(h, msg);
  return code;
}

/// The avm_status of a status_code, one to one: ok -> AVM_OK, invalid_argument ->
/// AVM_ERROR_INVALID_ARGUMENT, io -> AVM_ERROR_IO, parse -> AVM_ERROR_PARSE, unsupported ->
/// AVM_ERROR_UNSUPPORTED, out_of_memory -> AVM_ERROR_OUT_OF_MEMORY, internal ->
/// AVM_ERROR_INTERNAL (AVM_ERROR_END_OF_FILE is no failure and has no code). Every entry point
/// that reports a library status uses it (or avm_code below).
avm_status avm_code(status_code code) noexcept;
/// avm_code(st.code()): AVM_OK for an ok status.
inline avm_status avm_code(const status& st) noexcept { return avm_code(st.code()); }

// Reporters for guard(): where an entry point's error message goes.
inline avm_status to_create_error(avm_status code, const char* msg) noexcept {
  set_create_error(msg);
  return code;
}
inline avm_status silently(avm_status code, const char*) noexcept { return code; }
inline auto to_handle(const error_slot* h) noexcept {
  return [h](avm_status code, const char* msg) noexcept { return fail(h, code, msg); };
}

/// The one exception boundary of the C API: every avm_* function that can throw runs its body
/// here. Each exception becomes a status and a message in our words (composed in a fixed
/// buffer, so reporting out of memory cannot itself fail) handed to `report(code, message)`;
/// `fn` names the entry point in the message.
template <class Report, class Body>
avm_status guard(const char* fn, Report&& report, Body&& body) noexcept {
  char msg[k_error_capacity];
  try {
    return body();
  } catch (const std::bad_alloc&) {
    std::snprintf(msg, sizeof msg,
                  "%s: out of memory (the input is too large for this process; split it or "
                  "free memory)",
                  fn);
    return report(AVM_ERROR_OUT_OF_MEMORY, msg);
  } catch (const std::exception& e) {
    std::snprintf(msg, sizeof msg, "%s: internal error (%s); please report it with the input", fn,
                  e.what());
    return report(AVM_ERROR_INTERNAL, msg);
  } catch (...) {
    std::snprintf(msg, sizeof msg, "%s: unknown internal error; please report it with the input",
                  fn);
    return report(AVM_ERROR_INTERNAL, msg);
  }
}

/// guard() for entry points that return a value instead of a status (names, counts): the
/// body's value, or `fallback` when it throws (nothing to report it to).
template <class T, class Body>
T guard_value(T fallback, Body&& body) noexcept {
  try {
    return body();
  } catch (...) {
    return fallback;
  }
}

}  // namespace avatarmap::c_api
