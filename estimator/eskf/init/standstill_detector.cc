#include "estimator/eskf/init/standstill_detector.h"

#include <algorithm>
#include <cmath>

namespace rover::estimator {
namespace {

double MaxStd(const Eigen::Vector3d& sum, const Eigen::Vector3d& sq, double n) {
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Vector3d var = (sq / n - mean.cwiseProduct(mean)).cwiseMax(0.0);
  return std::sqrt(var.maxCoeff() * n / std::max(n - 1.0, 1.0));
}

}  // namespace

StandstillDetector::StandstillDetector(int window_samples)
    : window_(std::clamp(window_samples, 2, kCapacity)) {
  Clear();
}

void StandstillDetector::Clear() {
  count_ = 0;
  head_ = 0;
  since_recompute_ = 0;
  sum_gyro_.setZero();
  sum_accel_.setZero();
  sq_gyro_.setZero();
  sq_accel_.setZero();
}

void StandstillDetector::Add(const ImuMeasurement& m) {
  const size_t slot = static_cast<size_t>(head_);
  if (count_ == window_) {
    sum_gyro_ -= gyro_[slot];
    sum_accel_ -= accel_[slot];
    sq_gyro_ -= gyro_[slot].cwiseProduct(gyro_[slot]);
    sq_accel_ -= accel_[slot].cwiseProduct(accel_[slot]);
  } else {
    ++count_;
  }
  gyro_[slot] = m.angular_velocity_rad_s;
  accel_[slot] = m.linear_acceleration_m_s2;
  sum_gyro_ += gyro_[slot];
  sum_accel_ += accel_[slot];
  sq_gyro_ += gyro_[slot].cwiseProduct(gyro_[slot]);
  sq_accel_ += accel_[slot].cwiseProduct(accel_[slot]);
  head_ = (head_ + 1) % window_;
  if (++since_recompute_ >= window_) Recompute();
}

void StandstillDetector::Recompute() {
  since_recompute_ = 0;
  sum_gyro_.setZero();
  sum_accel_.setZero();
  sq_gyro_.setZero();
  sq_accel_.setZero();
  for (int k = 0; k < count_; ++k) {
    const size_t s = static_cast<size_t>(k);
    sum_gyro_ += gyro_[s];
    sum_accel_ += accel_[s];
    sq_gyro_ += gyro_[s].cwiseProduct(gyro_[s]);
    sq_accel_ += accel_[s].cwiseProduct(accel_[s]);
  }
}

double StandstillDetector::MaxGyroStd() const { return MaxStd(sum_gyro_, sq_gyro_, count_d()); }
double StandstillDetector::MaxAccelStd() const { return MaxStd(sum_accel_, sq_accel_, count_d()); }

}  // namespace rover::estimator
