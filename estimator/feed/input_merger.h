#ifndef ROVER_ESTIMATOR_FEED_INPUT_MERGER_H_
#define ROVER_ESTIMATOR_FEED_INPUT_MERGER_H_

// Merges the aiding inputs (wheel speeds, clone triggers, relative poses,
// requests) into the IMU stream in the filter's input order (input_order.h).
// The IMU sample drives the merge: Step(sample) feeds every held input that
// goes before the sample, then the sample, then every held input stamped at
// the sample's time (they come after it at equal stamps). Inputs stamped
// later wait for a later sample, so an input handed over by the time its
// stamp's IMU sample is stepped lands exactly where a global sort would put
// it.
//
// Real-time: a fixed array, insertion sort, no allocation, no locks; Push()
// refuses an input when full. One thread (the IMU thread) owns it.
//
// An input that arrives after its IMU sample has been stepped is late: it is
// still fed (before the next sample, so nothing is lost) and counted, and the
// filter decides whether it can use it.

#include <array>
#include <cstddef>
#include <cstdint>

#include "estimator/eskf/eskf_input.h"
#include "estimator/feed/input_order.h"

namespace rover::estimator {

template <std::size_t kCapacity>
class InputMerger {
 public:
  /// Holds `input` (any kind but an IMU sample) in order. False when the
  /// merger already holds kCapacity inputs: the caller keeps the input and
  /// retries after the next Step().
  bool Push(const EskfInput& input) {
    if (count_ == kCapacity) return false;
    std::size_t i = count_;
    while (i > 0 && InputBefore(input, held_[i - 1])) {
      held_[i] = held_[i - 1];
      --i;
    }
    held_[i] = input;
    ++count_;
    return true;
  }

  /// Feeds `feed(input)` every held input that goes before `imu`, then the
  /// sample itself, then every held input stamped at `imu.stamp`.
  template <typename Feed>
  void Step(const ImuMeasurement& imu, Feed&& feed) {
    const EskfInput sample(imu);
    std::size_t fed = FeedWhile([&](const EskfInput& in) { return InputBefore(in, sample); }, feed);
    feed(sample);
    have_stepped_ = true;
    last_imu_stamp_ = imu.stamp;
    fed += FeedWhile([&](const EskfInput& in) { return !(imu.stamp < StampOf(in)); }, feed, fed);
    Compact(fed);
  }

  /// Feeds every held input, whatever its stamp (end of a run).
  template <typename Feed>
  void Drain(Feed&& feed) {
    Compact(FeedWhile([](const EskfInput&) { return true; }, feed));
  }

  /// How many inputs are held.
  std::size_t size() const { return count_; }
  /// Inputs fed after an IMU sample later than their stamp had been stepped.
  uint64_t late_inputs() const { return late_inputs_; }

 private:
  // Feeds held inputs from `from` on while `due` holds; returns how many.
  template <typename Due, typename Feed>
  std::size_t FeedWhile(Due&& due, Feed& feed, std::size_t from = 0) {
    std::size_t i = from;
    for (; i < count_ && due(held_[i]); ++i) {
      if (have_stepped_ && StampOf(held_[i]) < last_imu_stamp_) ++late_inputs_;
      feed(held_[i]);
    }
    return i - from;
  }

  // Drops the first `fed` inputs.
  void Compact(std::size_t fed) {
    for (std::size_t i = fed; i < count_; ++i) held_[i - fed] = held_[i];
    count_ -= fed;
  }

  std::array<EskfInput, kCapacity> held_{};
  std::size_t count_ = 0;
  bool have_stepped_ = false;
  Time last_imu_stamp_;
  uint64_t late_inputs_ = 0;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_FEED_INPUT_MERGER_H_
