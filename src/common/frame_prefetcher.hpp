// Reads and parses a landmark file on a second thread while the caller solves and writes:
// the two halves of solve_file_job (parse | solve and write) then use both cores
// (prefetch_ring.hpp).
#pragma once

#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "common/prefetch_ring.hpp"

namespace avatarmap::jobs_detail {

class frame_prefetcher {
 public:
  /// Takes over an opened reader. When stop_at_error, reading stops after the first
  /// malformed line (it is still delivered, as an error). Frames are handed over `batch` at a
  /// time (prefetch_ring.hpp): one wake-up of the caller per batch, not per frame.
  frame_prefetcher(landmark_reader& reader, bool stop_at_error, int capacity = 64, int batch = 16)
      : ring_(
            capacity,
            [&reader, stop_at_error](slot& s) {
              s.kind = reader.next(s.frame);
              if (s.kind == read_result::error) {
                s.error = reader.error();
                s.code = reader.error_code();
              }
              return !(s.kind == read_result::end ||
                       (s.kind == read_result::error && stop_at_error));
            },
            batch) {}

  /// Waits for the next item. For read_result::frame, `frame()` is valid until release();
  /// for read_result::error, `error()` says what and where. read_result::end ends the stream.
  read_result next() {
    current_ = &ring_.next();
    return current_->kind;
  }
  const landmark_frame& frame() const { return current_->frame; }
  const std::string& error() const { return current_->error; }
  status_code error_code() const { return current_->code; }
  /// Hands the current item's slot back to the reader.
  void release() { ring_.release(); }

 private:
  struct slot {
    landmark_frame frame;
    read_result kind = read_result::end;
    std::string error;
    status_code code = status_code::parse;
  };
  prefetch_ring<slot> ring_;
  slot* current_ = nullptr;
};

}  // namespace avatarmap::jobs_detail
