#ifndef ROVER_HIL_SIM_SENSORS_WHEEL_ODOMETRY_MODEL_H_
#define ROVER_HIL_SIM_SENSORS_WHEEL_ODOMETRY_MODEL_H_

// Wheel encoders of the four drives, emitted as the CANopen frames of
// canopen_wheel_protocol.h.
//
// Kinematics: each wheel's ideal rolling speed is the velocity of its centre
// along the body x axis (RoverTrajectory::WheelRollingSpeeds_m_s), with the
// yaw-rate part scaled by yaw_scrub_factor (skid-steered wheels spin faster
// than the geometric ideal to yaw the rover). Slip: the drive turns faster
// than it rolls,
//   omega = v_roll / (r (1 - s)),
//   s = clamp(slip_base_ratio + slip_slope_gain_per_rad * tilt
//             + slip_roughness_gain_per_m * roughness + n(t), 0, slip_max_ratio),
// with tilt the rover's angle from level (rad), roughness the RMS deviation
// of the terrain around the wheel from its best-fit plane (m) and n(t) a
// seeded Ornstein-Uhlenbeck process per wheel. The wheel angle integrates
// omega (trapezoid rule at integration_rate_hz); the encoder counts
// floor(angle / 2 pi * ticks_per_wheel_rev).
//
// Bus timing: SYNC at start + sync_phase_s + k * 10 ms; the four TPDO1s follow
// it tpdo_first_delay_s + (node - 1) * tpdo_stagger_s (+ jitter) later, with
// the wheel state latched at the SYNC, as synchronous PDOs do; each node's
// heartbeat at start + heartbeat_phase_s[node - 1] + n seconds.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "core/calib/wheel_calibration.h"
#include "core/config/config.h"
#include "core/time/time.h"
#include "drivers/can/can_frame.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/world/world.h"

namespace rover::sim {

struct WheelOdometryModelOptions {
  uint32_t encoder_counts_per_motor_rev = 4096;
  double gear_ratio = 100.0;  ///< motor revolutions per wheel revolution
  double yaw_scrub_factor = 1.0;
  double slip_base_ratio = 0.0;
  double slip_slope_gain_per_rad = 0.0;
  double slip_roughness_gain_per_m = 0.0;
  double slip_noise_sigma = 0.0;          ///< stationary std of n(t)
  double slip_noise_correlation_s = 0.5;  ///< time constant of n(t)
  double slip_max_ratio = 0.6;
  double roughness_patch_m = 0.3;           ///< side of the terrain patch around a wheel
  double velocity_noise_sigma_rad_s = 0.0;  ///< on the reported velocity only
  double integration_rate_hz = 1000.0;
  double sync_phase_s = 0.0;
  double tpdo_first_delay_s = 200e-6;
  double tpdo_stagger_s = 130e-6;
  double tpdo_jitter_sigma_s = 0.0;
  Eigen::Vector4d heartbeat_phase_s{0.11, 0.37, 0.62, 0.88};  ///< per node, in [0, 1)
  uint64_t seed = 1;

  double ticks_per_wheel_rev() const { return encoder_counts_per_motor_rev * gear_ratio; }

  /// Loads every key above (all required, same names) with range checks.
  static WheelOdometryModelOptions Load(const ConfigNode& node);
  /// Loads a whole file, rejecting unknown keys.
  static WheelOdometryModelOptions LoadFile(const std::string& path);
};

/// Ground truth of the drives at one SYNC (arrays in WheelIndex order).
struct WheelSyncState {
  Time stamp;
  std::array<double, kWheelCount> rolling_speed_m_s{};  ///< ideal, without slip
  std::array<double, kWheelCount> slip_ratio{};
  std::array<double, kWheelCount> angular_velocity_rad_s{};  ///< true wheel rate
  std::array<double, kWheelCount> angle_rad{};               ///< since start
  std::array<int64_t, kWheelCount> encoder_ticks{};          ///< unwrapped
  std::array<double, kWheelCount> roughness_m{};
  double tilt_rad = 0.0;
};

/// What a wheel calibration of the simulated rover would find: its wheel
/// radius and track, the mean of its wheel centres as the lever arm, the body
/// origin as the point without sideways velocity (the simulated planar path
/// is the body origin's; a real rover's is its wheel-contact centre), its yaw
/// scrub, and its mean slip against tilt (the roughness term and the slip
/// noise stay uncalibrated, as a field calibration would leave them).
calib::WheelCalibration WheelCalibrationOf(const RoverTrajectory& trajectory,
                                           const WheelOdometryModelOptions& options);

class WheelOdometryModel {
 public:
  /// `trajectory` and `terrain` must outlive the model; trajectory time 0 is
  /// `start`, where every encoder reads 0.
  WheelOdometryModel(const WheelOdometryModelOptions& options, const RoverTrajectory& trajectory,
                     const Heightfield& terrain, Time start);

  /// Appends to `frames` every frame stamped before `until`, in time order,
  /// and (if not null) to `states` the truth at each SYNC emitted.
  void Advance(Time until, std::vector<drivers::CanFrame>* frames,
               std::vector<WheelSyncState>* states = nullptr);

  Time SyncTime(uint64_t k) const;
  const WheelOdometryModelOptions& options() const { return options_; }

 private:
  struct WheelRates {
    std::array<double, kWheelCount> rolling_m_s{}, slip{}, omega_rad_s{}, roughness_m{};
    double tilt_rad = 0.0;
  };
  WheelRates RatesAt(double t_s) const;
  double RoughnessAt(const Eigen::Vector2d& xy) const;
  void IntegrateTo(double t_s);
  void GenerateSync(uint64_t k, std::vector<WheelSyncState>* states);

  WheelOdometryModelOptions options_;
  const RoverTrajectory& trajectory_;
  const Heightfield& terrain_;
  Time start_;
  uint64_t next_sync_ = 0;
  std::array<uint64_t, kWheelCount> next_heartbeat_{};
  std::deque<drivers::CanFrame> pending_;

  // Integration state.
  double t_s_ = 0.0;
  WheelRates rates_;
  std::array<double, kWheelCount> angle_rad_{};
  std::array<double, kWheelCount> slip_noise_{};

  std::mt19937_64 slip_rng_, velocity_rng_, timing_rng_;
  std::normal_distribution<double> slip_normal_, velocity_normal_, timing_normal_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SENSORS_WHEEL_ODOMETRY_MODEL_H_
