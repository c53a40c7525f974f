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

avm_status code_for(const status& st, avm_status otherwise) noexcept {
  return st.is_out_of_memory() ? AVM_ERROR_OUT_OF_MEMORY : otherwise;
}

avm_status job_code(job_failure why) noexcept {
  switch (why) {
    case job_failure::invalid_argument:
      return AVM_ERROR_INVALID_ARGUMENT;
    case job_failure::input_io:
    case job_failure::output_io:
      return AVM_ERROR_IO;
    case job_failure::input_parse:
      return AVM_ERROR_PARSE;
    case job_failure::internal:
    case job_failure::none:
      break;
  }
  return AVM_ERROR_INTERNAL;
}

}  // namespace avatarmap::c_api
