// Produces items on a second thread while the caller consumes them: a bounded ring of slots
// (allocated once) between a producer and the caller. The producer blocks when the ring is
// full, the caller when it is empty. Used to parse landmark files and to decode video ahead
// of the work on each item, so that the two halves of a command use both cores.
//
// Items are handed over in batches: the positions of the two ends are atomics that each side
// reads without a lock, and a side that has run out (the caller of items, the producer of free
// slots) sleeps until `batch` of them are there, so that a wake-up (a system call on the other
// side) comes once per batch instead of once per item. The caller also wakes when the last item
// is ready, and after k_batch_wait with at least one item (a slow producer, e.g. a pipe, then
// adds at most that much latency). Order, contents and the last item are those of the producer.
#pragma once

#include <atomic>
#include <chrono>
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
  /// Longest wait of the caller for a whole batch while at least one item is ready.
  static constexpr std::chrono::milliseconds k_batch_wait{2};

  /// `fill` writes the next item into a slot (on the producer thread) and returns false when
  /// that item is the last one (the end marker or a fatal error, which the slot then says).
  /// `batch` (clamped to [1, capacity]): items (free slots) a waiting side waits for; 1 wakes
  /// the caller for every item.
  prefetch_ring(int capacity, std::function<bool(Slot&)> fill, int batch = 1)
      : fill_(std::move(fill)), slots_(static_cast<size_t>(capacity < 1 ? 1 : capacity)) {
    batch_ = batch < 1 ? 1 : static_cast<size_t>(batch);
    if (batch_ > slots_.size()) batch_ = slots_.size();
    thread_ = std::thread([this] { run(); });
  }
  ~prefetch_ring() {
    cancelled_.store(true);
    wake(not_full_);
    thread_.join();
  }
  prefetch_ring(const prefetch_ring&) = delete;
  prefetch_ring& operator=(const prefetch_ring&) = delete;

  /// Waits for the next item; valid until release() hands it back. The caller may hold
  /// several items (each next() takes one more, release() gives back the oldest held), at
  /// most capacity - 1 at a time. Past the producer's last item (a caller that goes on after
  /// an item that was the last without saying so, e.g. an error): a default-constructed Slot,
  /// not taken (do not release it), never a slot already consumed.
  Slot& next() {
    const size_t t = taken_;  // only this thread touches taken_
    if (head_.load() == t) {
      wait_for_items(t);
      if (head_.load() == t) {  // done, and nothing more will come
        past_end_ = Slot{};
        return past_end_;
      }
    }
    ++taken_;
    return slots_[t % slots_.size()];
  }
  /// Hands the oldest item the caller holds back to the producer.
  void release() {
    const size_t t = tail_.load(std::memory_order_relaxed) + 1;
    tail_.store(t);
    // Read after the store (both sequentially consistent): either the producer's check sees
    // the new tail or this sees that it waits (the same below for the other direction).
    const size_t wants = producer_wants_.load();
    if (wants != 0 && slots_.size() - (head_.load() - t) >= wants) wake(not_full_);
  }

 private:
  // Taking the mutex orders the notification after a waiter's check of its condition (which
  // it makes holding the mutex), so the wake-up cannot fall between check and sleep.
  void wake(std::condition_variable& cv) {
    { std::lock_guard<std::mutex> lock(mutex_); }
    cv.notify_one();
  }
  void wait_for_items(size_t t) {
    std::unique_lock<std::mutex> lock(mutex_);
    auto ready = [&](size_t n) { return head_.load() - t >= n || done_.load(); };
    consumer_wants_.store(batch_);
    if (batch_ == 1 || !not_empty_.wait_for(lock, k_batch_wait, [&] { return ready(batch_); })) {
      consumer_wants_.store(1);
      not_empty_.wait(lock, [&] { return ready(1); });
    }
    consumer_wants_.store(0);
  }
  void run() {
    for (;;) {
      const size_t h = head_.load(std::memory_order_relaxed);  // only this thread writes it
      if (h - tail_.load() == slots_.size()) {
        std::unique_lock<std::mutex> lock(mutex_);
        producer_wants_.store(batch_);
        not_full_.wait(lock, [&] {
          return cancelled_.load() || slots_.size() - (h - tail_.load()) >= batch_;
        });
        producer_wants_.store(0);
      }
      if (cancelled_.load()) return;
      // Fill outside the lock: the caller only touches slots behind head_.
      const bool more = fill_(slots_[h % slots_.size()]);
      head_.store(h + 1);
      if (!more) done_.store(true);  // after head_: a caller that sees it sees the item
      const size_t wants = consumer_wants_.load();
      if (wants != 0 && (h + 1 - tail_.load() >= wants || !more)) wake(not_empty_);
      if (!more) return;
    }
  }

  std::function<bool(Slot&)> fill_;
  std::vector<Slot> slots_;
  Slot past_end_{};  // what next() returns past the last item
  size_t batch_ = 1;
  std::mutex mutex_;  // only for sleeping and waking
  std::condition_variable not_empty_, not_full_;
  std::atomic<size_t> head_{0};  // items produced
  std::atomic<size_t> tail_{0};  // items consumed (released)
  size_t taken_ = 0;             // items the caller has taken (>= tail_)
  // What a sleeping side waits for (items, free slots); 0 when it is not sleeping.
  std::atomic<size_t> consumer_wants_{0}, producer_wants_{0};
  std::atomic<bool> done_{false};  // the last item is ready
  std::atomic<bool> cancelled_{false};
  std::thread thread_;
};

}  // namespace avatarmap::jobs_detail
