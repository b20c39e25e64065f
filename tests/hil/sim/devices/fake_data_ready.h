#ifndef ROVER_TESTS_HIL_SIM_DEVICES_FAKE_DATA_READY_H_
#define ROVER_TESTS_HIL_SIM_DEVICES_FAKE_DATA_READY_H_

// A data-ready line for the simulated ADIS16448: each Wait() plays the next
// sample instant, latches that sample into the device and reports the edge,
// stamped start + k * period. Scripted gaps (edges that never come) and an
// end after which it times out; optionally the falling edge of each pulse
// too.

#include <cstdint>
#include <set>

#include "drivers/gpio/gpio_edge_source.h"
#include "hil/sim/devices/simulated_adis16448.h"

namespace rover::testing {

class FakeDataReady final : public drivers::GpioEdgeSource {
 public:
  FakeDataReady(sim::SimulatedAdis16448* device, Duration period)
      : device_(device), period_(period) {}

  drivers::ReadStatus Wait(drivers::GpioEdge* edge, Duration /*timeout*/) override {
    if (emit_falling_ && pending_falling_) {
      pending_falling_ = false;
      edge->stamp = last_rising_ + Duration::Microseconds(50);
      edge->line = 27;
      edge->rising = false;
      return drivers::ReadStatus::kOk;
    }
    while (missing_.count(next_) != 0) ++next_;
    if (next_ >= end_) return drivers::ReadStatus::kTimeout;
    const uint64_t k = next_++;
    device_->LatchSample(k);
    last_rising_ = start_ + period_ * static_cast<int64_t>(k);
    edge->stamp = last_rising_;
    edge->line = 27;
    edge->rising = true;
    pending_falling_ = true;
    return drivers::ReadStatus::kOk;
  }
  uint64_t lost_edges() const override { return 0; }

  /// Sample instants with no edge.
  void Skip(uint64_t k) { missing_.insert(k); }
  /// Edges stop (Wait times out) from sample k on; a later EndAt() lets
  /// them come again.
  void EndAt(uint64_t k) { end_ = k; }
  void EmitFallingEdges(bool on) { emit_falling_ = on; }
  Time start() const { return start_; }

 private:
  sim::SimulatedAdis16448* device_;
  Duration period_;
  Time start_ = Time::FromSeconds(100.0);
  uint64_t next_ = 0;
  uint64_t end_ = UINT64_MAX;
  std::set<uint64_t> missing_;
  bool emit_falling_ = false;
  bool pending_falling_ = false;
  Time last_rising_;
};

}  // namespace rover::testing

#endif  // ROVER_TESTS_HIL_SIM_DEVICES_FAKE_DATA_READY_H_
