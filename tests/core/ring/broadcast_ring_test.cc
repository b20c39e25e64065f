#include "core/ring/broadcast_ring.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "tests/support/allocation_counter.h"

namespace rover {
namespace {

uint64_t Read(const BroadcastRing& ring, BroadcastRing::Cursor* cursor, uint64_t window,
              uint64_t* skipped, bool* ok) {
  uint64_t value = 0;
  *ok = ring.ReadNext(cursor, window, &value, skipped);
  return value;
}

TEST(BroadcastRingTest, EveryReaderSeesEveryRecord) {
  BroadcastRing ring(sizeof(uint64_t), 8);
  BroadcastRing::Cursor a = ring.MakeCursor(0);
  BroadcastRing::Cursor b = ring.MakeCursor(0);
  for (uint64_t i = 0; i < 5; ++i) {
    ring.Write(&i);
  }
  EXPECT_EQ(ring.write_count(), 5u);
  uint64_t skipped = 0;
  bool ok = false;
  for (uint64_t i = 0; i < 5; ++i) {
    EXPECT_EQ(Read(ring, &a, 7, &skipped, &ok), i);
    EXPECT_TRUE(ok);
  }
  Read(ring, &a, 7, &skipped, &ok);
  EXPECT_FALSE(ok);
  for (uint64_t i = 0; i < 5; ++i) {
    EXPECT_EQ(Read(ring, &b, 7, &skipped, &ok), i);
    EXPECT_TRUE(ok);
  }
  EXPECT_EQ(skipped, 0u);
}

TEST(BroadcastRingTest, WindowDropsOldestAndCountsThem) {
  BroadcastRing ring(sizeof(uint64_t), 16);
  BroadcastRing::Cursor cursor = ring.MakeCursor(0);
  for (uint64_t i = 0; i < 10; ++i) {
    ring.Write(&i);
  }
  uint64_t skipped = 0;
  bool ok = false;
  EXPECT_EQ(Read(ring, &cursor, 3, &skipped, &ok), 7u);  // Newest 3: 7, 8, 9.
  EXPECT_TRUE(ok);
  EXPECT_EQ(skipped, 7u);
  EXPECT_EQ(Read(ring, &cursor, 3, &skipped, &ok), 8u);
  EXPECT_EQ(Read(ring, &cursor, 3, &skipped, &ok), 9u);
  Read(ring, &cursor, 3, &skipped, &ok);
  EXPECT_FALSE(ok);
  EXPECT_EQ(skipped, 7u);
}

TEST(BroadcastRingTest, WindowIsClampedBelowCapacity) {
  BroadcastRing ring(sizeof(uint64_t), 4);
  BroadcastRing::Cursor cursor = ring.MakeCursor(0);
  for (uint64_t i = 0; i < 100; ++i) {
    ring.Write(&i);
  }
  uint64_t skipped = 0;
  bool ok = false;
  // At most capacity - 1 = 3 records are retained for a reader.
  EXPECT_EQ(Read(ring, &cursor, 1000, &skipped, &ok), 97u);
  EXPECT_EQ(skipped, 97u);
}

TEST(BroadcastRingTest, CursorBacklogReplaysNewestRecords) {
  BroadcastRing ring(sizeof(uint64_t), 8);
  EXPECT_EQ(ring.MakeCursor(5).next_index, 0u) << "cannot replay more than was written";
  for (uint64_t i = 0; i < 20; ++i) {
    ring.Write(&i);
  }
  BroadcastRing::Cursor cursor = ring.MakeCursor(2);
  uint64_t skipped = 0;
  bool ok = false;
  EXPECT_EQ(Read(ring, &cursor, 7, &skipped, &ok), 18u);
  EXPECT_EQ(Read(ring, &cursor, 7, &skipped, &ok), 19u);
  EXPECT_EQ(ring.MakeCursor(100).next_index, 20u - 7u);
}

TEST(BroadcastRingTest, OddRecordSizes) {
  struct Odd {
    std::array<char, 13> text;
  };
  BroadcastRing ring(sizeof(Odd), 2);
  BroadcastRing::Cursor cursor = ring.MakeCursor(0);
  Odd in{};
  std::memcpy(in.text.data(), "thirteen byte", 13);
  ring.Write(&in);
  Odd out{};
  uint64_t skipped = 0;
  ASSERT_TRUE(ring.ReadNext(&cursor, 1, &out, &skipped));
  EXPECT_EQ(std::memcmp(out.text.data(), "thirteen byte", 13), 0);
}

TEST(BroadcastRingTest, NoAllocationInWriteOrRead) {
  BroadcastRing ring(64, 32);
  BroadcastRing::Cursor cursor = ring.MakeCursor(0);
  std::array<uint64_t, 8> record{};
  uint64_t skipped = 0;
  testing::ScopedAllocationCheck check;
  for (uint64_t i = 0; i < 1000; ++i) {
    record.fill(i);
    ring.Write(record.data());
    ring.ReadNext(&cursor, 8, record.data(), &skipped);
  }
  EXPECT_EQ(check.allocations(), 0u);
}

TEST(BroadcastRingStressTest, ConcurrentReadersSeeIncreasingUntornRecords) {
  constexpr uint64_t kRecords = 200'000;
  constexpr std::size_t kWords = 16;  // 128-byte records, torn copies detectable.
  BroadcastRing ring(kWords * sizeof(uint64_t), 64);
  std::atomic<bool> writer_done{false};

  struct ReaderResult {
    uint64_t received = 0;
    uint64_t skipped = 0;
    uint64_t bad = 0;  // Torn or out of order.
    uint64_t last = 0;
  };
  std::array<ReaderResult, 2> results;
  // Cursors are made before the writer starts, so readers own every record.
  auto reader = [&](ReaderResult* result, BroadcastRing::Cursor cursor, uint64_t window) {
    std::array<uint64_t, kWords> record{};
    int64_t last = -1;
    auto take_all = [&] {
      while (ring.ReadNext(&cursor, window, record.data(), &result->skipped)) {
        ++result->received;
        for (const uint64_t w : record) {
          if (w != record[0]) {
            ++result->bad;
            break;
          }
        }
        if (static_cast<int64_t>(record[0]) <= last) {
          ++result->bad;
        }
        last = static_cast<int64_t>(record[0]);
      }
    };
    while (!writer_done.load(std::memory_order_acquire)) {
      take_all();
      std::this_thread::yield();
    }
    take_all();
    result->last = static_cast<uint64_t>(last);
  };
  std::thread r0(reader, &results[0], ring.MakeCursor(0), 63);
  std::thread r1(reader, &results[1], ring.MakeCursor(0), 4);
  std::thread writer([&] {
    std::array<uint64_t, kWords> record{};
    for (uint64_t i = 0; i < kRecords; ++i) {
      record.fill(i);
      ring.Write(record.data());
    }
    writer_done.store(true, std::memory_order_release);
  });
  writer.join();
  r0.join();
  r1.join();
  for (const ReaderResult& r : results) {
    EXPECT_EQ(r.bad, 0u);
    EXPECT_EQ(r.last, kRecords - 1) << "the newest record always survives";
    EXPECT_EQ(r.received + r.skipped, kRecords) << "every record is read or counted as skipped";
  }
}

}  // namespace
}  // namespace rover
