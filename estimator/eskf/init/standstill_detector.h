#ifndef ROVER_ESTIMATOR_ESKF_INIT_STANDSTILL_DETECTOR_H_
#define ROVER_ESTIMATOR_ESKF_INIT_STANDSTILL_DETECTOR_H_

// Sliding-window statistics of the IMU readings (mean and per-axis standard
// deviation of angular rate and specific force), used to detect standstill
// for the static initialisation and for zero-velocity updates.
//
// The window is a fixed-capacity ring. Sums are updated incrementally and
// recomputed from the ring once per window length, so rounding cannot drift
// and the cost per sample stays O(1) amortised, with no allocation.

#include <Eigen/Core>
#include <array>

#include "estimator/eskf/eskf_input.h"

namespace rover::estimator {

class StandstillDetector {
 public:
  static constexpr int kCapacity = 4096;

  /// `window_samples` is clamped to [2, kCapacity].
  explicit StandstillDetector(int window_samples);

  void Add(const ImuMeasurement& m);
  void Clear();

  /// True once the window is full.
  bool Full() const { return count_ == window_; }
  int window_samples() const { return window_; }

  Eigen::Vector3d MeanGyro() const { return sum_gyro_ / count_d(); }
  Eigen::Vector3d MeanAccel() const { return sum_accel_ / count_d(); }
  /// Largest per-axis standard deviation over the window.
  double MaxGyroStd() const;
  double MaxAccelStd() const;

 private:
  double count_d() const { return static_cast<double>(count_ > 0 ? count_ : 1); }
  void Recompute();

  int window_;
  int count_ = 0;
  int head_ = 0;  ///< next slot to write
  int since_recompute_ = 0;
  std::array<Eigen::Vector3d, kCapacity> gyro_;
  std::array<Eigen::Vector3d, kCapacity> accel_;
  Eigen::Vector3d sum_gyro_ = Eigen::Vector3d::Zero(), sum_accel_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sq_gyro_ = Eigen::Vector3d::Zero(), sq_accel_ = Eigen::Vector3d::Zero();
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_INIT_STANDSTILL_DETECTOR_H_
