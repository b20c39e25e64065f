// Checks that need the uninstrumented allocator or real mlockall, so they
// only run in the dev build (see CMakeLists.txt).

#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <memory>

#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/loop_probe.h"
#include "firmware/runtime/rt/periodic_timer.h"
#include "firmware/runtime/rt/rt_setup.h"
#include "firmware/runtime/rt/rt_thread.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"

namespace rover::runtime {
namespace {

TEST(RtNoSanitizerTest, LoopIterationNeverAllocatesOnTheRealTimeThread) {
  // The IMU loop's per-tick path on a real RtThread with the real clock:
  // neither operator new nor any malloc-family call.
  auto probe = std::make_unique<LoopProbe>(Duration::Microseconds(200));
  uint64_t news = 1;
  uint64_t mallocs = 1;
  uint64_t ticks = 0;
  RtThreadOptions options;
  options.name = "rt_alloc";
  {
    RtThread thread(options, [&](std::stop_token) {
      PeriodicTimer timer(Duration::Microseconds(200));
      testing::ScopedAllocationCheck new_check;
      testing::ScopedMallocCheck malloc_check;
      for (int i = 0; i < 200; ++i) {
        const PeriodicTimer::Tick tick = timer.WaitNext();
        probe->OnWake(tick);
        probe->OnEstimatePublished(tick.deadline, Time::Now());
      }
      const LoopProbeSnapshot snapshot = probe->Snapshot();
      news = new_check.allocations();
      mallocs = malloc_check.mallocs();
      ticks = snapshot.ticks;
    });
  }
  EXPECT_EQ(news, 0u);
  EXPECT_EQ(mallocs, 0u);
  EXPECT_EQ(ticks, 200u);
}

TEST(RtNoSanitizerTest, HistogramRecordMergeAndSummarizeMakeNoMallocCalls) {
  auto a = std::make_unique<LatencyHistogram>();
  auto b = std::make_unique<LatencyHistogram>();
  b->Record(42'000);
  testing::ScopedMallocCheck check;
  for (int64_t v = 0; v < 5'000'000; v += 1'234) a->Record(v);
  a->Merge(*b);
  const LatencySummary s = a->Summarize();
  EXPECT_EQ(check.mallocs(), 0u);
  EXPECT_GT(s.count, 0u);
}

TEST(RtNoSanitizerTest, MlockallEitherSucceedsOrIsReportedInTheWarning) {
  RtSetupOptions options;
  options.lock_memory = true;
  const RtSetupReport r = RtSetup::Apply(options);
  munlockall();  // leave the test process as it was
  EXPECT_TRUE(r.lock_requested);
  if (r.memory_locked) {
    EXPECT_EQ(r.lock_errno, 0);
  } else {
    EXPECT_NE(r.lock_errno, 0);
    EXPECT_NE(r.warning.find("mlockall refused: "), std::string::npos) << r.warning;
    EXPECT_NE(r.warning.find("pageable memory"), std::string::npos) << r.warning;
  }
  EXPECT_EQ(r.warning.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace rover::runtime
