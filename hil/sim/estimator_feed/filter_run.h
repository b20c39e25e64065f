#ifndef ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_RUN_H_
#define ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_RUN_H_

// Runs the local reference filter over a FilterFeed and scores it against
// the ground truth in the filter's own local frames.
//
// Frames. The filter's frame 0 is defined at initialisation (time t_0 of its
// first output) by the TRUE body position and TRUE yaw at t_0: the true local
// frame is T_world_L0 = (p_true(t_0), Rz(yaw_true(t_0))). Each frame switch
// (FrameSwitchRecord at t_k) starts frame k defined the same way at t_k. For
// every output in frame k:
//   dp = p_true_Lk - p,  dv = v_true_Lk - v,  dtheta = Log(R^T R_true_Lk)
// (the output covariance's conventions), with the NEES of dp (3 dof, position
// block) and of dtheta (3 dof, attitude block). The global error chains the
// filter's own switch records, T_L0_Lk = T_L0_L1 ... T_Lk-1_Lk, and compares
// T_L0_Lk * (p, R) with the true pose in the true frame 0, so it does not
// reset at switches.
//
// NEES averages skip the first nees_skip_s after initialisation and after
// every switch: the position covariance (and the yaw direction of the
// attitude covariance) is exactly zero there, so the NEES is undefined, and it
// stays numerically ill-conditioned for a short while.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "estimator/eskf/eskf_health.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/eskf_output.h"
#include "hil/sim/estimator_feed/filter_feed.h"

namespace rover::sim {

/// Filter options matching the feed's simulated sensors: the scenario IMU's
/// noise densities, rate and ranges, standard gravity; the rover's wheel
/// radius, track, the wheel model's yaw scrub factor and the wheel-axle
/// centre relative to the IMU as lever arm; wheels enabled as in the feed.
/// Everything else keeps the EskfOptions defaults.
estimator::EskfOptions EskfOptionsForFeed(const FilterFeed& feed);
/// The same for a scenario's rover without a feed (roverd on the simulator).
estimator::EskfOptions EskfOptionsForScenario(const Scenario& scenario,
                                              const RoverTrajectory& trajectory,
                                              const WheelOdometryModelOptions& wheel_options,
                                              bool wheels_enabled);

struct FilterRunOptions {
  /// Excluded from the NEES averages after initialisation and each switch.
  double nees_skip_s = 1.0;
  /// Keep every per-output error sample in the result (for plots and tests).
  bool keep_samples = true;
};

/// Errors of one filter output against the truth.
struct FilterErrorSample {
  Time stamp;
  uint32_t frame_id = 0;
  Eigen::Vector3d dp_local_m = Eigen::Vector3d::Zero();       ///< p_true - p, frame k
  Eigen::Vector3d dv_local_m_s = Eigen::Vector3d::Zero();     ///< v_true - v, frame k
  Eigen::Vector3d dtheta_rad = Eigen::Vector3d::Zero();       ///< Log(R^T R_true)
  Eigen::Vector3d dp_global_m = Eigen::Vector3d::Zero();      ///< p_true - p, frame 0 chain
  Eigen::Vector3d sigma_p_m = Eigen::Vector3d::Zero();        ///< sqrt of the diagonal
  Eigen::Vector3d sigma_theta_rad = Eigen::Vector3d::Zero();  ///< sqrt of the diagonal
  double nees_position = 0.0;
  double nees_attitude = 0.0;
  bool nees_valid = false;  ///< outside the skip windows and with an invertible covariance
};

struct FilterRunResult {
  uint64_t outputs = 0;
  uint64_t frame_switches = 0;
  bool all_finite = true;  ///< every output value and covariance finite
  /// Output frame ids and switch records agree (frame k after the k-th switch).
  bool frame_ids_consistent = true;
  Time init_stamp;  ///< first output (zero if the filter never initialised)
  Time last_stamp;
  double distance_m = 0.0;  ///< horizontal distance driven between init and the last output

  // Position error, per frame (resets at switches) and global (frame-0 chain).
  double final_position_error_m = 0.0;
  double mean_position_error_m = 0.0;
  double max_position_error_m = 0.0;
  double final_global_position_error_m = 0.0;
  double mean_global_position_error_m = 0.0;
  double max_global_position_error_m = 0.0;
  double final_attitude_error_rad = 0.0;
  double max_attitude_error_rad = 0.0;
  double max_velocity_error_m_s = 0.0;

  double mean_nees_position = 0.0;  ///< 3 for a consistent filter
  double mean_nees_attitude = 0.0;  ///< 3 for a consistent filter
  uint64_t nees_samples = 0;

  estimator::EskfHealth health;  ///< the filter's counters at the end
  std::vector<estimator::RejectRecord> rejects;
  std::vector<estimator::FrameSwitchRecord> switches;
  std::vector<FilterErrorSample> samples;  ///< if FilterRunOptions::keep_samples

  double run_wall_time_s = 0.0;  ///< time spent in the filter and the scoring

  /// Rejections of `kind` other than kNotInitialised (inputs before the
  /// filter started are expected to be refused).
  uint64_t RejectedAfterInit(estimator::InputKind kind) const;
};

/// Runs a LocalReferenceFilter with `options` over every input of `feed`.
FilterRunResult RunFilter(const FilterFeed& feed, const estimator::EskfOptions& options,
                          const FilterRunOptions& run_options = {});

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_ESTIMATOR_FEED_FILTER_RUN_H_
