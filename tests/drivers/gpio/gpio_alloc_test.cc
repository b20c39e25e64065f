// The real-time calls of the GPIO drivers never allocate: edge waits (edges,
// timeouts, errors) and trigger pulses (pulses, timeouts), checked with the
// malloc-family counter of this thread.

#include <gtest/gtest.h>

#include <cstdlib>

#include "drivers/gpio/fake_gpio_chip.h"
#include "drivers/gpio/gpio_camera_trigger.h"
#include "drivers/gpio/gpio_line_edge_source.h"
#include "tests/support/malloc_counter.h"

namespace rover::drivers {
namespace {

using rover::testing::ScopedMallocCheck;

// Guards the checks below against a counter that is not linked in.
TEST(GpioAllocationTest, TheCounterSeesAllocations) {
  void* (*volatile allocate)(std::size_t) = std::malloc;
  ScopedMallocCheck check;
  void* p = allocate(64);
  const uint64_t counted = check.mallocs();
  std::free(p);
  EXPECT_GE(counted, 1U);
}

TEST(GpioAllocationTest, EdgeWaitsDoNotAllocate) {
  FakeGpioChip chip;
  GpioLineEdgeSourceOptions o;
  o.line = 27;
  o.nominal_period = Duration::Milliseconds(10);
  GpioLineEdgeSource source(chip, o);
  const Time t0 = Time::FromNanoseconds(1'000'000'000);
  GpioEdge edge;
  uint64_t mallocs = 0;
  for (int batch = 0; batch < 10; ++batch) {
    for (int i = 0; i < 8; ++i) {
      const int k = batch * 10 + i;  // two pulses missing per batch: loss accounting runs too
      chip.InjectEdge(27, t0 + Duration::Milliseconds(10) * k, true);
      chip.InjectEdge(27, t0 + Duration::Milliseconds(10) * k + Duration::Microseconds(50), false);
    }
    chip.FailNextReads(27, batch == 3 ? 1 : 0);
    ScopedMallocCheck check;
    while (source.Wait(&edge, Duration::Zero()) != ReadStatus::kTimeout) {
    }
    source.Wait(&edge, Duration::Microseconds(200));  // a timeout that really waits
    mallocs += check.mallocs();
  }
  EXPECT_EQ(mallocs, 0U);
  EXPECT_EQ(source.stats().edges, 160U);
  EXPECT_EQ(source.lost_edges(), 36U);  // the missing pulses between batches
  EXPECT_EQ(source.stats().read_errors, 1U);
}

TEST(GpioAllocationTest, TriggerPulsesDoNotAllocate) {
  FakeGpioChip chip;
  GpioCameraTriggerOptions o;
  o.rate_hz = 100.0;
  o.line = 17;
  GpioCameraTrigger trigger(chip, o);
  Time stamp;
  uint64_t mallocs = 0;
  {
    ScopedMallocCheck check;
    for (int i = 0; i < 10; ++i) trigger.Next(&stamp, Duration::Seconds(1));
    trigger.Next(&stamp, Duration::Microseconds(100));  // timeout path
    mallocs = check.mallocs();
  }
  EXPECT_EQ(mallocs, 0U);
  EXPECT_EQ(trigger.stats().pulses, 10U);
  EXPECT_EQ(trigger.stats().timeouts, 1U);
  EXPECT_EQ(chip.transitions(17).size(), 20U);
}

}  // namespace
}  // namespace rover::drivers
