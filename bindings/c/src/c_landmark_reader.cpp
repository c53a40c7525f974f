// The C API's landmark-file reader (avm_landmark_reader_*): the library's landmark_reader,
// parsing ahead on a second thread (the frame_prefetcher of `avatarmap solve`) while the caller
// copies frames into its frame blocks.
#include <cstdint>
#include <memory>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "c_frame_block.hpp"
#include "c_guard.hpp"
#include "common/frame_prefetcher.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

struct avm_landmark_reader : avatarmap::c_api::error_slot {
  am::landmark_reader reader;
  // Parses `reader` ahead on its own thread, from the first read on (a malformed line is
  // handed over as an error and reading goes on); stopped and joined by the destructor.
  std::unique_ptr<am::jobs_detail::frame_prefetcher> ahead;
  bool ended = false;  // the prefetcher gave the end: it must not be asked again
};

extern "C" {

AVATARMAP_C_API avm_status avm_landmark_reader_open(const char* path, avm_landmark_reader** out) {
  set_create_error("");
  if (out != nullptr) *out = nullptr;
  if (path == nullptr || out == nullptr)
    return to_create_error(AVM_ERROR_INVALID_ARGUMENT,
                           "avm_landmark_reader_open: path and out must not be NULL");
  return guard("avm_landmark_reader_open", to_create_error, [&]() -> avm_status {
    std::unique_ptr<avm_landmark_reader> r(new avm_landmark_reader());
    const am::status st = r->reader.open(path);
    // io: the file cannot be opened; parse: the header line is bad.
    if (!st.ok()) return to_create_error(avm_code(st), st.message().c_str());
    r->last_error.reserve(256);
    *out = r.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_landmark_reader_header(const avm_landmark_reader* r,
                                                      int32_t* image_width, int32_t* image_height,
                                                      double* fps) {
  if (r == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_landmark_reader_header", to_handle(r), [&]() -> avm_status {
    const am::landmark_file_header& h = r->reader.header();
    if (image_width != nullptr) *image_width = h.image_width;
    if (image_height != nullptr) *image_height = h.image_height;
    if (fps != nullptr) *fps = h.fps;
    r->last_error.clear();
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_landmark_reader_read(avm_landmark_reader* r,
                                                    const avm_frame_block* block,
                                                    int64_t* out_read) {
  if (r == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  r->last_error.clear();
  if (out_read != nullptr) *out_read = 0;
  if (block == nullptr || out_read == nullptr)
    return fail(r, AVM_ERROR_INVALID_ARGUMENT,
                "avm_landmark_reader_read: block and out_read must not be NULL");
  if (const char* bad = check_block_to_fill(*block))
    return fail(r, AVM_ERROR_INVALID_ARGUMENT, bad);
  if (block->t == nullptr)
    return fail(r, AVM_ERROR_INVALID_ARGUMENT, "avm_landmark_reader_read: block->t is NULL");
  return guard("avm_landmark_reader_read", to_handle(r), [&]() -> avm_status {
    if (!r->ahead) r->ahead = std::make_unique<am::jobs_detail::frame_prefetcher>(r->reader, false);
    int64_t n = 0;
    for (; n < block->count && !r->ended; ++n) {
      const am::read_result res = r->ahead->next();
      if (res == am::read_result::end) {
        r->ended = true;
        break;
      }
      if (res == am::read_result::error) {
        *out_read = n;
        const avm_status code = avm_code(r->ahead->error_code());  // parse, or io
        fail(r, code, r->ahead->error().c_str());
        r->ahead->release();
        return code;
      }
      frame_to_block_row(r->ahead->frame(), *block, n);
      r->ahead->release();
    }
    *out_read = n;
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_landmark_reader_last_error(const avm_landmark_reader* r) {
  return guard_value<const char*>("", [&] { return r == nullptr ? "" : r->last_error.c_str(); });
}

AVATARMAP_C_API void avm_landmark_reader_destroy(avm_landmark_reader* r) {
  guard_value(0, [&] {
    delete r;
    return 0;
  });
}

}  // extern "C"
