// The C API's shared error handling (c_guard.hpp).
#include "c_guard.hpp"

#include <cstring>

namespace avatarmap::c_api {

namespace {
// avm_last_create_error(): a fixed buffer so that reporting cannot itself fail to allocate.
thread_local char t_create_error[k_error_capacity] = "";
}  // namespace

void copy_message(char* dst, std::size_t size, const char* msg) noexcept {
  if (dst == nullptr || size == 0) return;
  if (msg == nullptr) msg = "";
  std::size_t n = std::strlen(msg);
  if (n >= size) n = size - 1;
  std::memcpy(dst, msg, n);
  dst[n] = '\0';
}

void set_create_error(const char* msg) noexcept {
  copy_message(t_create_error, k_error_capacity, msg);
}

const char* create_error() noexcept { return t_create_error; }

void set_error(const error_slot* h, const char* msg) noexcept {
  if (h == nullptr) return;
  try {
    h->last_error.assign(msg != nullptr ? msg : "");
  } catch (...) {
    h->last_error.clear();
  }
}

avm_status avm_code(status_code code) noexcept {
  switch (code) {
    case status_code::ok:
      return AVM_OK;
    case status_code::invalid_argument:
      return AVM_ERROR_INVALID_ARGUMENT;
    case status_code::io:
      return AVM_ERROR_IO;
    case status_code::parse:
      return AVM_ERROR_PARSE;
    case status_code::unsupported:
      return AVM_ERROR_UNSUPPORTED;
    case status_code::out_of_memory:
      return AVM_ERROR_OUT_OF_MEMORY;
    case status_code::internal:
      break;
  }
  return AVM_ERROR_INTERNAL;
}

}  // namespace avatarmap::c_api
