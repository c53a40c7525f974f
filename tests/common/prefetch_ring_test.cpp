// prefetch_ring (src/common/prefetch_ring.hpp): every item once and in order whatever the
// capacity, batch and which side is slower; the last item reaches the caller even when it
// does not fill a batch; a producer that waits on its caller still makes progress; destroying
// the ring with the producer blocked on a full ring returns; past the last item a default slot.
#include "common/prefetch_ring.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace avatarmap::jobs_detail {
namespace {

struct item {
  long value = -1;
  bool last = false;
};

// Spends a little time on one side so that the other is sometimes ahead, sometimes behind.
void dawdle(long i, long every) {
  if (every > 0 && i % every == 0)
    for (int k = 0; k < 50; ++k) std::this_thread::yield();
}

TEST(prefetch_ring, delivers_every_item_once_in_order) {
  constexpr long k_items = 1000;
  for (int capacity : {1, 3, 64}) {
    for (int batch : {1, 4, 16, 1000}) {  // 1000: clamped to the capacity
      for (long slow_producer : {0L, 7L}) {
        long produced = 0;
        prefetch_ring<item> ring(
            capacity,
            [&](item& it) {
              dawdle(produced, slow_producer);
              it.value = produced++;
              it.last = produced == k_items;
              return !it.last;
            },
            batch);
        for (long i = 0;; ++i) {
          item& it = ring.next();
          ASSERT_EQ(it.value, i) << "capacity " << capacity << " batch " << batch;
          const bool last = it.last;
          ring.release();
          dawdle(i, slow_producer ? 0 : 5);
          if (last) {
            EXPECT_EQ(i, k_items - 1);
            break;
          }
        }
      }
    }
  }
}

TEST(prefetch_ring, past_the_last_item_next_gives_a_default_slot_not_an_old_one) {
  // The producer's last item is an error the caller cannot tell from any other (capture: the
  // input could not be reopened for the next loop); the caller warns and asks again. It must get
  // a default slot (the users' "end"), not the slots it consumed before (which replayed old
  // frames forever).
  for (int capacity : {1, 4}) {
    long produced = 0;
    prefetch_ring<item> ring(capacity, [&](item& it) {
      it.value = produced++;
      return produced < 3;  // three items, the third the last
    });
    for (long i = 0; i < 3; ++i) {
      EXPECT_EQ(ring.next().value, i);
      ring.release();
    }
    for (int again = 0; again < 5; ++again) {
      const item& it = ring.next();
      EXPECT_EQ(it.value, -1) << "capacity " << capacity;
      EXPECT_FALSE(it.last);
    }
  }
}

TEST(prefetch_ring, the_last_item_reaches_the_caller_before_a_batch_is_full) {
  long produced = 0;
  prefetch_ring<item> ring(
      64,
      [&](item& it) {
        it.value = produced++;
        it.last = produced == 5;
        return !it.last;
      },
      16);
  for (long i = 0; i < 5; ++i) {
    item& it = ring.next();
    EXPECT_EQ(it.value, i);
    EXPECT_EQ(it.last, i == 4);
    ring.release();
  }
}

TEST(prefetch_ring, a_producer_that_waits_for_its_caller_still_makes_progress) {
  // Each item is produced only once the caller has taken the one before (a live source that
  // answers requests): never 16 ready at once, so the caller must take what there is.
  std::atomic<long> taken{0};
  long produced = 0;
  prefetch_ring<item> ring(
      64,
      [&](item& it) {
        while (taken.load() < produced) std::this_thread::yield();
        it.value = produced++;
        it.last = produced == 20;
        return !it.last;
      },
      16);
  for (long i = 0; i < 20; ++i) {
    item& it = ring.next();
    EXPECT_EQ(it.value, i);
    ring.release();
    taken.store(i + 1);
  }
}

TEST(prefetch_ring, destroying_it_with_the_producer_blocked_on_a_full_ring_returns) {
  for (int batch : {1, 3}) {
    long produced = 0;
    {
      prefetch_ring<item> ring(
          4,
          [&](item& it) {
            it.value = produced++;
            return true;  // endless
          },
          batch);
      for (long i = 0; i < 2; ++i) {
        EXPECT_EQ(ring.next().value, i);
        ring.release();
      }
    }  // the caller stops early: the destructor cancels the producer
    EXPECT_GE(produced, 2);
  }
}

// The caller may hold two items (a frame in flight in a pipelined estimator and the next):
// each next() takes a new one, release() gives back the oldest, and the contents of a held
// item stay what they were while the producer refills the other slots.
TEST(prefetch_ring, caller_holds_two_items) {
  constexpr long k_items = 500;
  for (int capacity : {2, 3, 8}) {
    long produced = 0;
    prefetch_ring<item> ring(capacity, [&](item& it) {
      dawdle(produced, 5);
      it.value = produced++;
      it.last = produced == k_items;
      return !it.last;
    });
    const item* held = &ring.next();
    ASSERT_EQ(held->value, 0);
    long seen = 1;
    for (;;) {
      const item& it = ring.next();
      EXPECT_EQ(it.value, seen) << "capacity " << capacity;
      EXPECT_EQ(held->value, seen - 1) << "a held item changed";
      ++seen;
      ring.release();  // the older one
      held = &it;
      if (it.last) break;
    }
    EXPECT_EQ(seen, k_items);
  }
}

}  // namespace
}  // namespace avatarmap::jobs_detail
