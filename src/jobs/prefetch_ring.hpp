// Produces items on a second thread while the caller consumes them: a bounded ring of slots
// (allocated once) between a producer and the caller. The producer blocks when the ring is
// full, the caller when it is empty. Used to parse landmark files and to decode video ahead
// of the work on each item, so that the two halves of a command use both cores.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace avatarmap::jobs_detail {

template <class Slot>
class prefetch_ring {
 public:
  /// `fill` writes the next item into a slot (on the producer thread) and returns false when
  /// that item is the last one (the end marker or a fatal error, which the slot then says).
  prefetch_ring(int capacity, std::function<bool(Slot&)> fill)
      : fill_(std::move(fill)), slots_(static_cast<size_t>(capacity < 1 ? 1 : capacity)) {
    thread_ = std::thread([this] { run(); });
  }
  ~prefetch_ring() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cancelled_ = true;
    }
    not_full_.notify_all();
    thread_.join();
  }
  prefetch_ring(const prefetch_ring&) = delete;
  prefetch_ring& operator=(const prefetch_ring&) = delete;

  /// Waits for the next item; valid until release(). Not to be called after the last item.
  Slot& next() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [this] { return tail_ != head_; });
    return slots_[tail_ % slots_.size()];
  }
  /// Hands the current item's slot back to the producer.
  void release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++tail_;
    }
    not_full_.notify_one();
  }

 private:
  void run() {
    for (;;) {
      size_t index;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        not_full_.wait(lock, [this] { return cancelled_ || head_ - tail_ < slots_.size(); });
        if (cancelled_) return;
        index = head_ % slots_.size();
      }
      // Fill outside the lock: the caller only touches slots behind head_.
      const bool more = fill_(slots_[index]);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++head_;
      }
      not_empty_.notify_one();
      if (!more) return;
    }
  }

  std::function<bool(Slot&)> fill_;
  std::vector<Slot> slots_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  size_t head_ = 0;  // items produced
  size_t tail_ = 0;  // items consumed
  bool cancelled_ = false;
  std::thread thread_;
};

}  // namespace avatarmap::jobs_detail
