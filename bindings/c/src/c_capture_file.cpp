// avm_capture_file: `avatarmap capture INPUT -o OUT` as a library call.
#include "avatarmap/avatarmap.h"
#include "c_guard.hpp"

using namespace avatarmap::c_api;

extern "C" {

AVATARMAP_C_API avm_status avm_capture_file(const char* input, const char* out_landmarks,
                                            const avm_estimator_options* options,
                                            avm_capture_summary* out_summary,
                                            avm_progress_fn progress, void* user, char* err,
                                            size_t err_size) {
  (void)input, (void)out_landmarks, (void)options, (void)out_summary, (void)progress, (void)user;
  copy_message(err, err_size, "avm_capture_file: not implemented yet in this build");
  return AVM_ERROR_UNSUPPORTED;
}

}  // extern "C"
