// Reads and parses a landmark file on a second thread while the caller solves and writes:
// the two halves of `avatarmap solve` then use both cores. A bounded ring of frames (allocated
// once) sits between them; the reader blocks when it is full, the caller when it is empty.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap::cli {

class frame_prefetcher {
 public:
  /// Takes over an opened reader. When stop_at_error, reading stops after the first
  /// malformed line (it is still delivered, as an error).
  frame_prefetcher(landmark_reader& reader, bool stop_at_error, int capacity = 64)
      : reader_(reader), stop_at_error_(stop_at_error), slots_(static_cast<size_t>(capacity)) {
    thread_ = std::thread([this] { run(); });
  }
  ~frame_prefetcher() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cancelled_ = true;
    }
    not_full_.notify_all();
    thread_.join();
  }
  frame_prefetcher(const frame_prefetcher&) = delete;
  frame_prefetcher& operator=(const frame_prefetcher&) = delete;

  /// Waits for the next item. For read_result::frame, `frame()` is valid until release();
  /// for read_result::error, `error()` says what and where. read_result::end ends the stream.
  read_result next() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [this] { return tail_ != head_; });
    return slots_[tail_ % slots_.size()].kind;
  }
  const landmark_frame& frame() const { return slots_[tail_ % slots_.size()].frame; }
  const std::string& error() const { return slots_[tail_ % slots_.size()].error; }
  /// Hands the current item's slot back to the reader.
  void release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++tail_;
    }
    not_full_.notify_one();
  }

 private:
  struct slot {
    landmark_frame frame;
    read_result kind = read_result::end;
    std::string error;
  };

  void run() {
    for (;;) {
      size_t index;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        not_full_.wait(lock, [this] { return cancelled_ || head_ - tail_ < slots_.size(); });
        if (cancelled_) return;
        index = head_ % slots_.size();
      }
      // Parse outside the lock: the caller only touches slots behind head_.
      slot& s = slots_[index];
      s.kind = reader_.next(s.frame);
      if (s.kind == read_result::error) s.error = reader_.error();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++head_;
      }
      not_empty_.notify_one();
      if (s.kind == read_result::end || (s.kind == read_result::error && stop_at_error_)) return;
    }
  }

  landmark_reader& reader_;
  const bool stop_at_error_;
  std::vector<slot> slots_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  size_t head_ = 0;  // items produced
  size_t tail_ = 0;  // items consumed
  bool cancelled_ = false;
  std::thread thread_;
};

}  // namespace avatarmap::cli
