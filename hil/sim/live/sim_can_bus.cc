#include "hil/sim/live/sim_can_bus.h"

namespace rover::sim {
namespace {
// Frames are generated a slice at a time; one SYNC period keeps the batch
// small (5 frames) and its storage reused.
constexpr Duration kSlice = Duration::Milliseconds(10);
}  // namespace

SimWheelCanBus::SimWheelCanBus(const WheelOdometryModelOptions& options,
                               const RoverTrajectory& trajectory, const Heightfield& terrain,
                               const drivers::ReplayClock& clock, Time start, Time end)
    : model_(options, trajectory, terrain, start),
      clock_(clock),
      generated_until_(start),
      end_(end) {
  batch_.reserve(64);
}

drivers::ReadStatus SimWheelCanBus::Receive(drivers::CanFrame* frame, Duration timeout) {
  while (next_in_batch_ >= batch_.size()) {
    if (generated_until_ >= end_) return drivers::ReadStatus::kEndOfStream;
    batch_.clear();
    next_in_batch_ = 0;
    generated_until_ = std::min(generated_until_ + kSlice, end_);
    model_.Advance(generated_until_, &batch_);
  }
  const drivers::CanFrame& next = batch_[next_in_batch_];
  if (!clock_.WaitUntilDue(next.stamp, timeout)) return drivers::ReadStatus::kTimeout;
  *frame = next;
  ++next_in_batch_;
  return drivers::ReadStatus::kOk;
}

bool SimWheelCanBus::Send(const drivers::CanFrame& /*frame*/) {
  ++frames_sent_;
  return true;
}

}  // namespace rover::sim
