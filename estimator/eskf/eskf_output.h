#ifndef ROVER_ESTIMATOR_ESKF_ESKF_OUTPUT_H_
#define ROVER_ESTIMATOR_ESKF_ESKF_OUTPUT_H_

// What the local reference filter emits: the state at IMU rate, frame-switch
// records (graph factor `w`), pose reports (graph factor `v`) and measurement
// rejections. Error-state conventions (see estimator/eskf/README.md):
//   p_true = p + dp,  v_true = v + dv,  R_true = R * Exp(dtheta),
//   b_true = b + db,  error vector [dp, dv, dtheta, dba, dbg] (15 values).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "core/time/time.h"
#include "estimator/eskf/eskf_input.h"

namespace rover::estimator {

using Matrix15d = Eigen::Matrix<double, 15, 15>;
using Matrix4d = Eigen::Matrix4d;

/// Degraded-mode flags of EskfOutput::status (a bit set).
enum EskfStatusFlag : uint32_t {
  kStatusNotInitialised = 1u << 0,  ///< still waiting for a standstill to initialise
  kStatusImuGap = 1u << 1,          ///< a recent IMU gap exceeded max_imu_gap_s
  kStatusImuInvalid = 1u << 2,      ///< recent NaN/Inf, saturated or out-of-order samples
  kStatusNoAiding = 1u << 3,        ///< no VO or wheel update accepted for aiding_timeout_s
  kStatusStandstill = 1u << 4,      ///< zero-velocity updates are being applied
  kStatusNumerical = 1u << 5,       ///< an update was refused for numerical reasons
};

/// The filter's estimate after one IMU sample.
struct EskfOutput {
  Time stamp;
  uint32_t frame_id = 0;  ///< index of the local frame; +1 per frame switch
  Eigen::Vector3d p_local_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_local_m_s = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_local_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d accel_bias_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_body_rad_s = Eigen::Vector3d::Zero();  ///< bias-corrected
  Matrix15d covariance = Matrix15d::Zero();  ///< of [dp, dv, dtheta, dba, dbg]
  uint32_t status = 0;                       ///< EskfStatusFlag bits
};

/// A frame-of-reference switch (graph factor `w`): the new local frame seen
/// from the old one. It differs from the old frame only by a translation and
/// a rotation about z, so it is given as (p, yaw) with a 4x4 covariance over
/// [dp (old frame, m); dyaw (rad)], p_true = p + dp, yaw_true = yaw + dyaw.
struct FrameSwitchRecord {
  Time stamp;
  uint32_t old_frame_id = 0;
  uint32_t new_frame_id = 0;
  Eigen::Vector3d p_old_new = Eigen::Vector3d::Zero();
  double yaw_old_new_rad = 0.0;
  Matrix4d covariance = Matrix4d::Zero();
};

/// The current pose in its local frame (graph factor `v`), with the 6x6
/// covariance over [dp; dtheta] (p_true = p + dp, R_true = R * Exp(dtheta)).
struct PoseReport {
  Time stamp;
  uint64_t request_id = 0;
  uint32_t frame_id = 0;
  Eigen::Vector3d p_local_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_local_body = Eigen::Quaterniond::Identity();
  Matrix6d covariance = Matrix6d::Zero();
};

/// Why an input was not used.
enum class RejectReason : uint8_t {
  kNonFinite,       ///< NaN or Inf in the values or covariance
  kOutOfOrder,      ///< time stamp not after the previous one of its kind
  kSaturated,       ///< IMU reading at or beyond the sensor's range
  kNotInitialised,  ///< arrived before static initialisation finished
  kTooOld,          ///< older than every clone / beyond the allowed delay
  kUnknownClone,    ///< no clone at the referenced capture time
  kGated,           ///< failed the Mahalanobis chi-square gate
  kBadCovariance,   ///< covariance not symmetric positive definite
  kCloneLimit,      ///< no clone slot could be freed
  kNumerical,       ///< the update would have produced a non-finite state
};

/// Which kind of input a RejectRecord refers to.
enum class InputKind : uint8_t {
  kImu,
  kCloneTrigger,
  kRelativePose,
  kWheelSpeeds,
  kFrameSwitch,
  kPoseReport
};

/// One rejected input, for the log (rejections are also counted in EskfHealth).
struct RejectRecord {
  Time stamp;  ///< the input's stamp
  InputKind kind = InputKind::kImu;
  RejectReason reason = RejectReason::kNonFinite;
  double mahalanobis_sq = 0.0;  ///< for kGated: the squared Mahalanobis distance
  double gate = 0.0;            ///< for kGated: the threshold it exceeded
};

const char* ToString(RejectReason reason);
const char* ToString(InputKind kind);

/// Where the filter sends what it produces. Implementations in the real-time
/// path must not allocate or block (roverd pushes into SPSC rings).
class EskfOutputSink {
 public:
  virtual ~EskfOutputSink() = default;
  virtual void OnState(const EskfOutput& output) = 0;
  virtual void OnFrameSwitch(const FrameSwitchRecord& record) = 0;
  virtual void OnPoseReport(const PoseReport& report) = 0;
  virtual void OnReject(const RejectRecord& record) = 0;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_ESKF_OUTPUT_H_
