// Two lanes of work for the capture stage: the calling thread and one worker thread take the
// tasks of a batch in order, each claiming the next unclaimed one when it is free, and the
// call returns when every task is done. The tasks of one batch must not depend on each other.
// With tasks ordered longest-expected first, the two lanes balance themselves (the lane that
// finishes first takes the next task). Used by the ONNX estimator to run the body of one
// frame beside the hands and face of the frame before (docs/capture.md, "Two lanes").
//
// The worker is started once and sleeps between batches; a batch allocates nothing.
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace avatarmap::capture_detail {

class two_lanes {
 public:
  static constexpr int k_max_tasks = 4;

  two_lanes() : worker_([this] { work(); }) {}
  ~two_lanes() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_worker_.notify_one();
    worker_.join();
  }
  two_lanes(const two_lanes&) = delete;
  two_lanes& operator=(const two_lanes&) = delete;

  /// Runs `run(i)` for i in [0, count) on the two lanes; returns when all have returned.
  /// `run` must not throw.
  template <class Fn>
  void run_batch(int count, Fn& run) {
    if (count <= 0) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      count_ = count;
      call_ = &call_task<Fn>;
      context_ = &run;
      next_.store(0);
      ++batch_;
    }
    wake_worker_.notify_one();
    claim_all();
    std::unique_lock<std::mutex> lock(mutex_);
    finished_.wait(lock, [&] { return worker_batch_ == batch_; });
  }

 private:
  template <class Fn>
  static void call_task(void* context, int i) {
    (*static_cast<Fn*>(context))(i);
  }

  // Takes tasks until none is left unclaimed.
  void claim_all() {
    for (int i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) call_(context_, i);
  }

  void work() {
    unsigned long seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_worker_.wait(lock, [&] { return stop_ || batch_ != seen; });
        if (stop_) return;
        seen = batch_;
      }
      claim_all();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        worker_batch_ = seen;  // the worker has left this batch: it claims nothing more
      }
      finished_.notify_one();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_worker_, finished_;
  unsigned long batch_ = 0, worker_batch_ = 0;  // guarded by mutex_
  bool stop_ = false;
  // Set under mutex_ before a batch starts; read by both lanes during it.
  int count_ = 0;
  void (*call_)(void*, int) = nullptr;
  void* context_ = nullptr;
  std::atomic<int> next_{0};
  std::thread worker_;  // last: starts after the members above exist
};

}  // namespace avatarmap::capture_detail
