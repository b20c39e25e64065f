#include "core/ring/spsc_ring.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "tests/support/allocation_counter.h"

namespace rover {
namespace {

// 16 bytes, like a timestamped scalar sample.
struct Sample {
  uint64_t sequence = 0;
  uint64_t check = 0;
};

// 64 bytes of the same value: a torn copy (half old, half new) shows up as
// unequal words.
struct Record {
  std::array<uint64_t, 8> words{};

  static Record Of(uint64_t value) {
    Record r;
    r.words.fill(value);
    return r;
  }
  bool Consistent() const {
    for (const uint64_t w : words) {
      if (w != words[0]) {
        return false;
      }
    }
    return true;
  }
};

template <typename Ring>
void ExpectAccounting(const Ring& ring) {
  EXPECT_EQ(ring.pushed(), ring.popped() + ring.dropped() + ring.size());
}

static_assert(SpscRing<Sample, 8>::capacity() == 8);
static_assert(SpscRing<Sample, 8>::overflow_policy() == OverflowPolicy::kReject);
// Head, tail and slots live on separate cache lines.
static_assert(alignof(SpscRing<Sample, 8>) >= 64);

TEST(SpscRingTest, StartsEmpty) {
  SpscRing<Sample, 4> ring;
  Sample out;
  EXPECT_FALSE(ring.TryPop(&out));
  EXPECT_EQ(ring.Front(), nullptr);
  EXPECT_TRUE(ring.empty());
  EXPECT_EQ(ring.pushed(), 0u);
  EXPECT_EQ(ring.popped(), 0u);
  EXPECT_EQ(ring.dropped(), 0u);
  EXPECT_EQ(ring.high_water_mark(), 0u);
}

TEST(SpscRingTest, PopsInPushOrder) {
  SpscRing<Sample, 4> ring;
  for (uint64_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(ring.TryPush(Sample{i, ~i}));
  }
  EXPECT_EQ(ring.size(), 3u);
  for (uint64_t i = 0; i < 3; ++i) {
    Sample out;
    ASSERT_TRUE(ring.TryPop(&out));
    EXPECT_EQ(out.sequence, i);
    EXPECT_EQ(out.check, ~i);
  }
  Sample out;
  EXPECT_FALSE(ring.TryPop(&out));
  EXPECT_EQ(ring.pushed(), 3u);
  EXPECT_EQ(ring.popped(), 3u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, WrapsAroundManyTimes) {
  SpscRing<uint64_t, 4> ring;
  uint64_t next_push = 0;
  uint64_t next_pop = 0;
  // Varying fill levels cross the wrap point at every offset.
  for (int round = 0; round < 1000; ++round) {
    const int burst = 1 + round % 4;
    for (int i = 0; i < burst; ++i) {
      ASSERT_TRUE(ring.TryPush(next_push++));
    }
    for (int i = 0; i < burst; ++i) {
      uint64_t out = 0;
      ASSERT_TRUE(ring.TryPop(&out));
      ASSERT_EQ(out, next_pop++);
    }
  }
  EXPECT_EQ(ring.popped(), next_push);
  EXPECT_EQ(ring.high_water_mark(), 4u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, RejectPolicyKeepsQueuedItemsAndCountsDrops) {
  SpscRing<uint64_t, 4, OverflowPolicy::kReject> ring;
  for (uint64_t i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.TryPush(i));
  }
  EXPECT_FALSE(ring.TryPush(100));
  EXPECT_FALSE(ring.TryEmplace(uint64_t{101}));
  EXPECT_EQ(ring.dropped(), 2u);
  EXPECT_EQ(ring.pushed(), 6u);
  EXPECT_EQ(ring.size(), 4u);
  ExpectAccounting(ring);

  uint64_t out = 0;
  ASSERT_TRUE(ring.TryPop(&out));
  EXPECT_EQ(out, 0u);
  EXPECT_TRUE(ring.TryPush(4));  // Room again.
  for (uint64_t expected = 1; expected <= 4; ++expected) {
    ASSERT_TRUE(ring.TryPop(&out));
    EXPECT_EQ(out, expected);
  }
  EXPECT_EQ(ring.dropped(), 2u);
  EXPECT_EQ(ring.high_water_mark(), 4u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, OverwriteOldestKeepsNewestAndCountsLosses) {
  SpscRing<uint64_t, 4, OverflowPolicy::kOverwriteOldest> ring;
  for (uint64_t i = 0; i < 10; ++i) {
    ASSERT_TRUE(ring.TryPush(i));  // Never fails.
  }
  // The losses are visible before the consumer runs.
  EXPECT_EQ(ring.pushed(), 10u);
  EXPECT_EQ(ring.dropped(), 6u);
  EXPECT_EQ(ring.size(), 4u);
  EXPECT_EQ(ring.high_water_mark(), 4u);
  ExpectAccounting(ring);

  for (uint64_t expected = 6; expected < 10; ++expected) {
    uint64_t out = 0;
    ASSERT_TRUE(ring.TryPop(&out));
    EXPECT_EQ(out, expected);
  }
  uint64_t out = 0;
  EXPECT_FALSE(ring.TryPop(&out));
  EXPECT_EQ(ring.popped(), 4u);
  EXPECT_EQ(ring.dropped(), 6u);
  ExpectAccounting(ring);

  // Still a plain FIFO when not overflowing.
  ASSERT_TRUE(ring.TryPush(42));
  ASSERT_TRUE(ring.TryPop(&out));
  EXPECT_EQ(out, 42u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, OverwriteOldestConsumerDetectsLapWithStaleHead) {
  // The consumer caches the head; here the cache says items 1..3 are queued
  // while the producer has since overwritten them, so the first slot read
  // fails its stamp check and the consumer must resynchronise.
  SpscRing<uint64_t, 4, OverflowPolicy::kOverwriteOldest> ring;
  for (uint64_t i = 0; i < 4; ++i) {
    ring.TryPush(i);
  }
  uint64_t out = 99;
  ASSERT_TRUE(ring.TryPop(&out));
  EXPECT_EQ(out, 0u);
  for (uint64_t i = 4; i < 14; ++i) {
    ring.TryPush(i);
  }
  for (uint64_t expected = 10; expected < 14; ++expected) {
    ASSERT_TRUE(ring.TryPop(&out));
    EXPECT_EQ(out, expected);
  }
  EXPECT_FALSE(ring.TryPop(&out));
  EXPECT_EQ(ring.popped(), 5u);
  EXPECT_EQ(ring.dropped(), 9u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, OverwriteOldestWithCapacityOne) {
  SpscRing<uint64_t, 1, OverflowPolicy::kOverwriteOldest> ring;
  ring.TryPush(1);
  ring.TryPush(2);
  uint64_t out = 0;
  ASSERT_TRUE(ring.TryPop(&out));
  EXPECT_EQ(out, 2u);
  EXPECT_FALSE(ring.TryPop(&out));
  EXPECT_EQ(ring.dropped(), 1u);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, HighWaterMarkIsExactNotTheCapacity) {
  SpscRing<uint64_t, 64> ring;
  uint64_t out = 0;
  for (int round = 0; round < 100; ++round) {
    ASSERT_TRUE(ring.TryPush(1));
    ASSERT_TRUE(ring.TryPush(2));
    ASSERT_TRUE(ring.TryPop(&out));
    ASSERT_TRUE(ring.TryPop(&out));
  }
  EXPECT_EQ(ring.high_water_mark(), 2u);
  for (uint64_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(ring.TryPush(i));
  }
  EXPECT_EQ(ring.high_water_mark(), 5u);
}

TEST(SpscRingTest, InPlaceProducerAndConsumer) {
  struct Big {
    uint32_t length;
    std::array<char, 252> bytes;
  };
  SpscRing<Big, 2> ring;
  Big* slot = ring.BeginPush();
  ASSERT_NE(slot, nullptr);
  slot->length = 5;
  std::copy_n("hello", 5, slot->bytes.begin());
  EXPECT_EQ(ring.Front(), nullptr) << "uncommitted items are invisible";
  ring.CommitPush();

  EXPECT_TRUE(ring.TryPushWith([](Big& b) {
    b.length = 3;
    std::copy_n("abc", 3, b.bytes.begin());
  }));
  EXPECT_EQ(ring.BeginPush(), nullptr) << "full";
  EXPECT_FALSE(ring.TryPushWith([](Big&) { ADD_FAILURE() << "fill called on a full ring"; }));
  EXPECT_EQ(ring.dropped(), 2u);

  Big* front = ring.Front();
  ASSERT_NE(front, nullptr);
  EXPECT_EQ(std::string(front->bytes.data(), front->length), "hello");
  ring.PopFront();
  front = ring.Front();
  ASSERT_NE(front, nullptr);
  EXPECT_EQ(std::string(front->bytes.data(), front->length), "abc");
  ring.PopFront();
  EXPECT_EQ(ring.Front(), nullptr);
  ExpectAccounting(ring);
}

TEST(SpscRingTest, MoveOnlyItemsAreDestroyed) {
  // Under ASan a missing destructor call shows up as a leak.
  SpscRing<std::unique_ptr<std::string>, 4> ring;
  ASSERT_TRUE(ring.TryPush(std::make_unique<std::string>("first")));
  ASSERT_TRUE(ring.TryEmplace(std::make_unique<std::string>("second")));
  ASSERT_TRUE(ring.TryPush(std::make_unique<std::string>("left in the ring")));
  std::unique_ptr<std::string> out;
  ASSERT_TRUE(ring.TryPop(&out));
  EXPECT_EQ(*out, "first");
  std::unique_ptr<std::string>* front = ring.Front();
  ASSERT_NE(front, nullptr);
  EXPECT_EQ(**front, "second");
  ring.PopFront();
  // Rejected rvalue stays with the caller.
  SpscRing<std::unique_ptr<int>, 1> tiny;
  ASSERT_TRUE(tiny.TryPush(std::make_unique<int>(1)));
  auto keep = std::make_unique<int>(2);
  EXPECT_FALSE(tiny.TryPush(std::move(keep)));
  ASSERT_NE(keep, nullptr);
  EXPECT_EQ(*keep, 2);
}

template <typename Ring>
void ExpectNoAllocationWhilePushingAndPopping() {
  auto ring = std::make_unique<Ring>();  // Construction may allocate; the loop may not.
  Sample out;
  testing::ScopedAllocationCheck check;
  for (uint64_t i = 0; i < 10'000; ++i) {
    ring->TryPush(Sample{i, i});
    ring->TryPush(Sample{i, i});
    ring->TryPop(&out);
  }
  while (ring->TryPop(&out)) {
  }
  EXPECT_EQ(check.allocations(), 0u);
  EXPECT_EQ(check.deallocations(), 0u);
}

TEST(SpscRingTest, NoAllocationInPushOrPop) {
  ExpectNoAllocationWhilePushingAndPopping<SpscRing<Sample, 64, OverflowPolicy::kReject>>();
  ExpectNoAllocationWhilePushingAndPopping<
      SpscRing<Sample, 64, OverflowPolicy::kOverwriteOldest>>();
}

// Escapes a pointer so the new/delete pair below cannot be elided.
void* volatile g_sink = nullptr;

TEST(SpscRingTest, AllocationCounterIsLinkedIn) {
  // Guards the check above against a counter that is not linked into this
  // executable (it would then report zero for everything).
  testing::ScopedAllocationCheck check;
  int* p = new int(3);
  g_sink = p;
  delete p;
  EXPECT_EQ(check.allocations(), 1u);
  EXPECT_EQ(check.deallocations(), 1u);
}

// ------------------------------------------------------------------ stress

constexpr uint64_t kStressItems = 1'000'000;

struct StressResult {
  uint64_t received = 0;
  uint64_t out_of_order = 0;
  uint64_t torn = 0;
  uint64_t gaps = 0;  // Items skipped between consecutive receptions.
};

// Runs one producer pushing kStressItems records 0, 1, 2, ... (retrying a
// rejected push if `retry`), and one consumer popping until the producer is
// done and the ring is empty. Without retry the producer yields every 64
// items so that the consumer regularly catches up mid-lap (otherwise it can
// be starved and only ever see the last lap, which tests little).
template <typename Ring>
StressResult RunStress(Ring* ring, bool retry) {
  std::atomic<bool> producer_done{false};
  std::atomic<int> started{0};
  auto start_together = [&started] {
    started.fetch_add(1);
    while (started.load() < 2) {
      std::this_thread::yield();
    }
  };
  StressResult result;
  std::thread consumer([&] {
    start_together();
    Record r;
    int64_t last = -1;
    auto process = [&] {
      ++result.received;
      if (!r.Consistent()) {
        ++result.torn;
      }
      const auto value = static_cast<int64_t>(r.words[0]);
      if (value <= last) {
        ++result.out_of_order;
      } else {
        result.gaps += static_cast<uint64_t>(value - last - 1);
      }
      last = value;
    };
    for (;;) {
      if (ring->TryPop(&r)) {
        process();
      } else if (producer_done.load(std::memory_order_acquire)) {
        // Every push happened before the flag was set: drain and stop.
        while (ring->TryPop(&r)) {
          process();
        }
        break;
      } else {
        std::this_thread::yield();
      }
    }
  });
  std::thread producer([&] {
    start_together();
    for (uint64_t i = 0; i < kStressItems; ++i) {
      const Record r = Record::Of(i);
      if (retry) {
        while (!ring->TryPush(r)) {
          std::this_thread::yield();
        }
      } else {
        ring->TryPush(r);
        if (i % 64 == 63) {
          std::this_thread::yield();
        }
      }
    }
    producer_done.store(true, std::memory_order_release);
  });
  producer.join();
  consumer.join();
  std::printf("  received %llu of %llu, %llu dropped\n",
              static_cast<unsigned long long>(result.received),
              static_cast<unsigned long long>(kStressItems),
              static_cast<unsigned long long>(ring->dropped()));
  return result;
}

TEST(SpscRingStressTest, RejectWithRetryLosesNothing) {
  auto ring = std::make_unique<SpscRing<Record, 1024, OverflowPolicy::kReject>>();
  const StressResult result = RunStress(ring.get(), /*retry=*/true);
  EXPECT_EQ(result.received, kStressItems);
  EXPECT_EQ(result.out_of_order, 0u);
  EXPECT_EQ(result.gaps, 0u);
  EXPECT_EQ(result.torn, 0u);
  EXPECT_EQ(ring->popped(), kStressItems);
  // Every failed attempt of the retry loop counts as offered and dropped.
  EXPECT_EQ(ring->pushed(), ring->popped() + ring->dropped());
}

TEST(SpscRingStressTest, RejectAccountsForEveryDrop) {
  // Small ring: the consumer cannot keep up with a producer that never waits.
  auto ring = std::make_unique<SpscRing<Record, 16, OverflowPolicy::kReject>>();
  const StressResult result = RunStress(ring.get(), /*retry=*/false);
  EXPECT_EQ(result.out_of_order, 0u);
  EXPECT_EQ(result.torn, 0u);
  EXPECT_EQ(ring->pushed(), kStressItems);
  EXPECT_EQ(ring->popped(), result.received);
  EXPECT_EQ(ring->pushed(), ring->popped() + ring->dropped());
  // Items missing from the sequence the consumer saw are exactly the drops
  // (except trailing drops after the last received item).
  EXPECT_LE(result.gaps, ring->dropped());
  EXPECT_GT(ring->high_water_mark(), 0u);
  EXPECT_LE(ring->high_water_mark(), 16u);
}

TEST(SpscRingStressTest, OverwriteOldestAccountsForEveryLoss) {
  auto ring = std::make_unique<SpscRing<Record, 16, OverflowPolicy::kOverwriteOldest>>();
  const StressResult result = RunStress(ring.get(), /*retry=*/false);
  EXPECT_EQ(result.out_of_order, 0u);
  EXPECT_EQ(result.torn, 0u) << "a lapped slot was returned";
  EXPECT_EQ(ring->pushed(), kStressItems);
  EXPECT_EQ(ring->popped(), result.received);
  EXPECT_EQ(ring->pushed(), ring->popped() + ring->dropped());
  // In overwrite mode the newest item always survives, so every gap is an
  // overwritten item and nothing is lost after the last reception.
  EXPECT_EQ(result.gaps, ring->dropped());
}

}  // namespace
}  // namespace rover
