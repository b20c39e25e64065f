#ifndef ROVER_HIL_SIM_ESTIMATOR_FEED_SYNTHETIC_VO_H_
#define ROVER_HIL_SIM_ESTIMATOR_FEED_SYNTHETIC_VO_H_

// A synthetic keyframe stereo VO for testing the local reference filter: it
// turns the true body poses at the camera capture times into the delayed
// relative-pose measurements a keyframe VO would deliver (thesis 4.1.1: delta
// poses from the latest keyframe to the current image, a history of 5
// keyframes, ~250 ms delay).
//
// Noise. For each measurement the stated covariance is diagonal with
//   sigma_trans = trans_base_m + trans_per_m * |dp|                 (each axis)
//   sigma_rot   = rot_base_rad + rot_per_rad * |dtheta| + rot_per_m * |dp|
// evaluated at the TRUE delta (dp, dtheta = Log(dR)), and the noise is drawn
// exactly from it, with the filter's convention p_meas = p_true + n_p,
// R_meas = R_true Exp(n_theta). A consistent filter therefore sees
// Mahalanobis distances that are chi-square with 6 dof.
//
// Keyframes. The first processed frame at or after `start_delay_s` (after the
// first capture time given) is the first keyframe; it yields no measurement.
// Every later processed frame yields one measurement from the current
// keyframe; the frame becomes the new keyframe (to_is_keyframe) when its
// distance from the keyframe exceeds keyframe_distance_m, its rotation
// exceeds keyframe_angle_rad, or it is the keyframe_max_frames-th processed
// frame since the keyframe. The VO holds max_keyframes keyframes;
// oldest_keyframe_stamp is the oldest one held after this frame. Frames are
// dropped (never processed, no measurement) with drop_probability.
//
// Delivery. stamp = max(to_stamp + latency, previous delivery), latency =
// clamp(latency_base_s + N(0, latency_jitter_sigma_s), latency_min_s,
// latency_max_s): the VO is sequential, so deliveries stay in capture order
// and are at most latency_max_s late.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/time/time.h"
#include "estimator/eskf/eskf_input.h"

namespace rover::sim {

/// The VO's stated (and true) noise model; see the file comment.
struct VoNoiseModel {
  double trans_base_m = 0.002;
  double trans_per_m = 0.005;  ///< fraction of the travelled distance
  double rot_base_rad = 0.05 * std::numbers::pi / 180.0;
  double rot_per_rad = 0.0;  ///< fraction of the rotation angle
  double rot_per_m = 0.0;    ///< rad per metre travelled

  /// Small noise (2 mm + 0.5 %, 0.05 deg): for consistency tests.
  static VoNoiseModel IdealConsistent();
  /// A stereo VO on rough terrain (5 mm + 1 %, 0.1 deg + 1 % + 0.2 deg/m).
  static VoNoiseModel Realistic();
  /// "ideal-consistent" or "realistic"; throws std::invalid_argument otherwise.
  static VoNoiseModel Preset(const std::string& name);

  /// The diagonal covariance of [n_p; n_theta] for a true delta.
  estimator::Matrix6d Covariance(const Eigen::Vector3d& dp_m,
                                 const Eigen::Vector3d& dtheta_rad) const;
};

struct SyntheticVoOptions {
  bool enabled = true;
  VoNoiseModel noise = VoNoiseModel::Realistic();
  double keyframe_distance_m = 0.5;
  double keyframe_angle_rad = 10.0 * std::numbers::pi / 180.0;
  int keyframe_max_frames = 10;
  int max_keyframes = 5;
  double drop_probability = 0.0;
  /// The first keyframe is taken this long after the first capture time, so
  /// the filter (which initialises after init.window_s of standstill) has
  /// cloned its trigger.
  double start_delay_s = 1.5;
  double latency_base_s = 0.15;
  double latency_jitter_sigma_s = 0.03;
  double latency_min_s = 0.05;
  double latency_max_s = 0.45;

  /// Keys (all optional): enabled, preset ("ideal-consistent" | "realistic",
  /// sets the noise model), then the noise keys trans_base_m, trans_per_m,
  /// rot_base_rad, rot_per_rad, rot_per_m (override the preset), and
  /// keyframe_distance_m, keyframe_angle_rad, keyframe_max_frames,
  /// max_keyframes, drop_probability, start_delay_s, latency_base_s,
  /// latency_jitter_sigma_s, latency_min_s, latency_max_s. Ranges checked;
  /// latency_min_s <= latency_base_s <= latency_max_s <= 0.5 s.
  static SyntheticVoOptions Load(const ConfigNode& node);
  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
};

/// One camera frame: capture time and the true body pose T_world_body.
struct VoFrame {
  Time capture;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
};

/// Counters of one VO run.
struct SyntheticVoStats {
  uint64_t frames = 0;
  uint64_t dropped = 0;
  uint64_t measurements = 0;
  uint64_t keyframes = 0;  ///< including the first one
};

/// Runs the synthetic VO over `frames` (strictly increasing capture times)
/// with noise, drops and latency drawn from independent streams derived from
/// `seed`. Returns the measurements in delivery order (= capture order).
std::vector<estimator::RelativePoseMeasurement> RunSyntheticVo(const SyntheticVoOptions& options,
                                                               const std::vector<VoFrame>& frames,
                                                               uint64_t seed,
                                                               SyntheticVoStats* stats = nullptr);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_ESTIMATOR_FEED_SYNTHETIC_VO_H_
