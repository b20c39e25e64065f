// Push+pop cost of SpscRing.
//
// * SingleThread: one thread pushes and pops alternately; the item stays in
//   the L1 cache, so this is the bookkeeping cost of the ring itself.
// * CrossThread: a producer thread pushes (spinning while full) and a consumer
//   thread pops; ns per item is wall time / items and includes the cache-line
//   transfers between the two cores. Only meaningful on an otherwise idle
//   machine with at least two cores; pin with taskset for stable figures.

#include <benchmark/benchmark.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "core/ring/spsc_ring.h"

namespace rover {
namespace {

template <std::size_t kBytes>
struct Item {
  std::array<uint64_t, kBytes / sizeof(uint64_t)> words{};
};
static_assert(sizeof(Item<16>) == 16 && sizeof(Item<256>) == 256);

constexpr std::size_t kCapacity = 1024;

// Waiting side of the cross-thread benchmark: spin with a CPU hint first (so
// the other core's cache line is not hammered), then yield the CPU in case
// both threads share one core (a loaded machine), which would otherwise make
// every wait last a whole scheduler time slice.
inline void Backoff(int spins) {
  if (spins < 64) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
  } else {
    std::this_thread::yield();
  }
}

template <std::size_t kBytes, OverflowPolicy kPolicy>
void BM_SingleThread(benchmark::State& state) {
  auto ring = std::make_unique<SpscRing<Item<kBytes>, kCapacity, kPolicy>>();
  Item<kBytes> in;
  Item<kBytes> out;
  for (auto _ : state) {
    ring->TryPush(in);
    ring->TryPop(&out);
    benchmark::DoNotOptimize(out);
    ++in.words[0];
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(kBytes));
}

template <std::size_t kBytes, OverflowPolicy kPolicy>
void BM_CrossThread(benchmark::State& state) {
  auto ring = std::make_unique<SpscRing<Item<kBytes>, kCapacity, kPolicy>>();
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> consumed{0};
  std::thread consumer([&] {
    Item<kBytes> out;
    uint64_t count = 0;
    int idle_spins = 0;
    while (!stop.load(std::memory_order_relaxed)) {
      if (ring->TryPop(&out)) {
        benchmark::DoNotOptimize(out);
        ++count;
        idle_spins = 0;
      } else {
        Backoff(idle_spins++);
      }
    }
    while (ring->TryPop(&out)) {
      ++count;
    }
    consumed.store(count, std::memory_order_relaxed);
  });
  Item<kBytes> in;
  for (auto _ : state) {
    // kReject: wait for room so every item crosses; kOverwriteOldest never
    // waits, so its figure is the producer's rate (the consumer drops some).
    for (int spins = 0; !ring->TryPush(in); ++spins) {
      Backoff(spins);
    }
    ++in.words[0];
  }
  stop.store(true, std::memory_order_relaxed);
  consumer.join();
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(kBytes));
  state.counters["delivered_%"] =
      100.0 * static_cast<double>(consumed.load()) / static_cast<double>(state.iterations());
  state.counters["high_water"] = static_cast<double>(ring->high_water_mark());
}

constexpr OverflowPolicy kReject = OverflowPolicy::kReject;
constexpr OverflowPolicy kOverwrite = OverflowPolicy::kOverwriteOldest;

BENCHMARK(BM_SingleThread<16, kReject>)->Name("SingleThread/16B/Reject");
BENCHMARK(BM_SingleThread<256, kReject>)->Name("SingleThread/256B/Reject");
BENCHMARK(BM_SingleThread<16, kOverwrite>)->Name("SingleThread/16B/OverwriteOldest");
BENCHMARK(BM_SingleThread<256, kOverwrite>)->Name("SingleThread/256B/OverwriteOldest");
BENCHMARK(BM_CrossThread<16, kReject>)->Name("CrossThread/16B/Reject")->UseRealTime();
BENCHMARK(BM_CrossThread<256, kReject>)->Name("CrossThread/256B/Reject")->UseRealTime();
BENCHMARK(BM_CrossThread<16, kOverwrite>)->Name("CrossThread/16B/OverwriteOldest")->UseRealTime();
BENCHMARK(BM_CrossThread<256, kOverwrite>)->Name("CrossThread/256B/OverwriteOldest")->UseRealTime();

}  // namespace
}  // namespace rover

BENCHMARK_MAIN();
