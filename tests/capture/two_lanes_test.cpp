// two_lanes (src/capture/two_lanes.hpp): every task of every batch runs exactly once and has
// finished when run_batch returns; both threads take tasks; batches of one task and empty
// batches work; destroying the lanes with the worker asleep returns.
#include "capture/two_lanes.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <thread>

namespace avatarmap::capture_detail {
namespace {

TEST(two_lanes, every_task_once_and_done_when_the_batch_returns) {
  two_lanes lanes;
  constexpr int k_batches = 2000;
  std::atomic<int> runs[two_lanes::k_max_tasks];
  for (int b = 0; b < k_batches; ++b) {
    const int count = b % (two_lanes::k_max_tasks + 1);  // 0..4 tasks
    for (auto& r : runs) r.store(0);
    auto task = [&](int i) {
      if (b % 50 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
      runs[i].fetch_add(1);
    };
    lanes.run_batch(count, task);
    for (int i = 0; i < two_lanes::k_max_tasks; ++i) {
      ASSERT_EQ(runs[i].load(), i < count ? 1 : 0) << "batch " << b << " task " << i;
    }
  }
  // Both lanes work: in a batch of two, each task waits (up to 10 s, however loaded the
  // machine) for the other to have started, which only a second thread can do.
  std::atomic<int> started{0};
  std::set<std::thread::id> pair;
  std::mutex pair_mutex;
  auto side_by_side = [&](int) {
    started.fetch_add(1);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started.load() < 2 && std::chrono::steady_clock::now() < give_up)
      std::this_thread::yield();
    std::lock_guard<std::mutex> lock(pair_mutex);
    pair.insert(std::this_thread::get_id());
  };
  lanes.run_batch(2, side_by_side);
  EXPECT_EQ(started.load(), 2);
  EXPECT_EQ(pair.size(), 2u) << "the two tasks of a batch did not run side by side";
}

TEST(two_lanes, two_long_tasks_overlap) {
  two_lanes lanes;
  std::atomic<int> running{0}, most{0};
  auto task = [&](int) {
    const int now = running.fetch_add(1) + 1;
    int m = most.load();
    while (now > m && !most.compare_exchange_weak(m, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    running.fetch_sub(1);
  };
  for (int i = 0; i < 5 && most.load() < 2; ++i) lanes.run_batch(2, task);
  EXPECT_EQ(most.load(), 2) << "the two tasks of a batch never ran at the same time";
}

}  // namespace
}  // namespace avatarmap::capture_detail
