#include "hil/sim/estimator_feed/filter_run.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "estimator/eskf/local_reference_filter.h"
#include "estimator/feed/filter_options.h"

namespace rover::sim {
namespace {

using estimator::EskfOutput;
using estimator::FrameSwitchRecord;

// A gravity-aligned frame seen from the world: origin and yaw.
struct Frame4 {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // Rz(yaw)
};

Frame4 TrueFrameAt(const FilterFeed& feed, Time t) {
  const TruthSample truth = feed.TruthAt(t);
  Frame4 f;
  f.origin = truth.p_world_body;
  f.R = Rz(YawOf(truth.q_world_body.toRotationMatrix()));
  return f;
}

double Nees(const Eigen::Matrix3d& P, const Eigen::Vector3d& e, bool* ok) {
  const Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (P + P.transpose()));
  if (llt.info() != Eigen::Success || !(P.diagonal().minCoeff() > 0.0)) {
    *ok = false;
    return 0.0;
  }
  return e.dot(llt.solve(e));
}

// Scores every output as it is emitted (outputs are not stored: long runs
// would need gigabytes).
class Scorer : public estimator::EskfOutputSink {
 public:
  Scorer(const FilterFeed& feed, const FilterRunOptions& options, FilterRunResult* result)
      : feed_(feed), options_(options), r_(*result) {}

  void OnState(const EskfOutput& o) override {
    const bool finite = o.p_local_body.allFinite() && o.v_local_m_s.allFinite() &&
                        o.q_local_body.coeffs().allFinite() && o.covariance.allFinite();
    r_.all_finite = r_.all_finite && finite;
    const TruthSample truth = feed_.TruthAt(o.stamp);
    if (r_.outputs == 0) {
      r_.init_stamp = o.stamp;
      true_frames_.assign(1, TrueFrameAt(feed_, o.stamp));
      frame_start_ = o.stamp;
      last_xy_ = truth.p_world_body.head<2>();
    }
    ++r_.outputs;
    r_.last_stamp = o.stamp;
    r_.distance_m += (truth.p_world_body.head<2>() - last_xy_).norm();
    last_xy_ = truth.p_world_body.head<2>();
    if (!finite) return;

    const auto k = static_cast<std::size_t>(o.frame_id);
    if (k >= true_frames_.size()) {
      // An output in a frame no switch record announced: score it in the
      // latest known frame (and let the error show it).
      frame_mismatch_ = true;
    }
    const Frame4& f = true_frames_[std::min(k, true_frames_.size() - 1)];
    const Eigen::Matrix3d R_w = truth.q_world_body.toRotationMatrix();
    const Eigen::Vector3d p_true = f.R.transpose() * (truth.p_world_body - f.origin);
    const Eigen::Vector3d v_true = f.R.transpose() * truth.v_world_m_s;
    const Eigen::Matrix3d R_true = f.R.transpose() * R_w;
    const Eigen::Matrix3d R = o.q_local_body.normalized().toRotationMatrix();

    FilterErrorSample s;
    s.stamp = o.stamp;
    s.frame_id = o.frame_id;
    s.dp_local_m = p_true - o.p_local_body;
    s.dv_local_m_s = v_true - o.v_local_m_s;
    s.dtheta_rad = LogSO3(R.transpose() * R_true);
    const Frame4& f0 = true_frames_.front();
    const Eigen::Vector3d p_true_0 = f0.R.transpose() * (truth.p_world_body - f0.origin);
    s.dp_global_m = p_true_0 - (chain_.origin + chain_.R * o.p_local_body);

    s.sigma_p_m = o.covariance.diagonal().segment<3>(0).cwiseMax(0.0).cwiseSqrt();
    s.sigma_theta_rad = o.covariance.diagonal().segment<3>(6).cwiseMax(0.0).cwiseSqrt();
    if (o.stamp - frame_start_ >= Duration::FromSeconds(options_.nees_skip_s)) {
      bool ok = true;
      s.nees_position = Nees(o.covariance.block<3, 3>(0, 0), s.dp_local_m, &ok);
      s.nees_attitude = Nees(o.covariance.block<3, 3>(6, 6), s.dtheta_rad, &ok);
      s.nees_valid = ok;
    }
    if (s.nees_valid) {
      sum_nees_p_ += s.nees_position;
      sum_nees_a_ += s.nees_attitude;
      ++r_.nees_samples;
    }
    const double e = s.dp_local_m.norm();
    const double eg = s.dp_global_m.norm();
    sum_e_ += e;
    sum_eg_ += eg;
    ++scored_;
    r_.final_position_error_m = e;
    r_.final_global_position_error_m = eg;
    r_.max_position_error_m = std::max(r_.max_position_error_m, e);
    r_.max_global_position_error_m = std::max(r_.max_global_position_error_m, eg);
    r_.final_attitude_error_rad = s.dtheta_rad.norm();
    r_.max_attitude_error_rad = std::max(r_.max_attitude_error_rad, s.dtheta_rad.norm());
    r_.max_velocity_error_m_s = std::max(r_.max_velocity_error_m_s, s.dv_local_m_s.norm());
    if (options_.keep_samples) r_.samples.push_back(s);
  }

  void OnFrameSwitch(const FrameSwitchRecord& record) override {
    r_.switches.push_back(record);
    ++r_.frame_switches;
    if (record.new_frame_id != true_frames_.size()) frame_mismatch_ = true;
    true_frames_.push_back(TrueFrameAt(feed_, record.stamp));
    // T_L0_Lnew = T_L0_Lold * (p_old_new, Rz(yaw_old_new)).
    chain_.origin += chain_.R * record.p_old_new;
    chain_.R = chain_.R * Rz(record.yaw_old_new_rad);
    frame_start_ = record.stamp;
  }

  void OnPoseReport(const estimator::PoseReport&) override {}

  void OnReject(const estimator::RejectRecord& record) override { r_.rejects.push_back(record); }

  void Finish() {
    if (scored_ > 0) {
      r_.mean_position_error_m = sum_e_ / static_cast<double>(scored_);
      r_.mean_global_position_error_m = sum_eg_ / static_cast<double>(scored_);
    }
    if (r_.nees_samples > 0) {
      r_.mean_nees_position = sum_nees_p_ / static_cast<double>(r_.nees_samples);
      r_.mean_nees_attitude = sum_nees_a_ / static_cast<double>(r_.nees_samples);
    }
    r_.frame_ids_consistent = !frame_mismatch_;
  }

 private:
  const FilterFeed& feed_;
  const FilterRunOptions& options_;
  FilterRunResult& r_;
  std::vector<Frame4> true_frames_;
  Frame4 chain_;  // the filter's current frame in its frame 0
  Time frame_start_;
  Eigen::Vector2d last_xy_ = Eigen::Vector2d::Zero();
  double sum_e_ = 0.0, sum_eg_ = 0.0, sum_nees_p_ = 0.0, sum_nees_a_ = 0.0;
  uint64_t scored_ = 0;
  bool frame_mismatch_ = false;
};

}  // namespace

estimator::EskfOptions EskfOptionsForFeed(const FilterFeed& feed) {
  return EskfOptionsForScenario(feed.scenario(), feed.trajectory(), feed.wheel_options(),
                                feed.options().wheels_enabled);
}

estimator::EskfOptions EskfOptionsForScenario(const Scenario& scenario,
                                              const RoverTrajectory& trajectory,
                                              const WheelOdometryModelOptions& wheel_options,
                                              bool wheels_enabled) {
  // The simulated rover's calibration, through the rule every board uses.
  calib::BoardCalibration calibration;
  calibration.imu = ImuCalibrationOf(scenario.imu);
  if (wheels_enabled) calibration.wheels = WheelCalibrationOf(trajectory, wheel_options);
  estimator::EskfOptions o = estimator::FilterOptionsFromCalibration(calibration);
  // What no calibration file states. An ideal (unbounded) sensor never
  // saturates: keep the filter's limit high.
  constexpr double kUnbounded = 1e4;
  const ImuModelOptions& imu = scenario.imu;
  o.imu.gyro_range_rad_s = std::isfinite(imu.gyro.range) ? imu.gyro.range : kUnbounded;
  o.imu.accel_range_m_s2 = std::isfinite(imu.accel.range) ? imu.accel.range : kUnbounded;
  o.imu.gravity_m_s2 = kStandardGravity_m_s2;
  return o;
}

uint64_t FilterRunResult::RejectedAfterInit(estimator::InputKind kind) const {
  return health.Rejected(kind) - health.Rejected(kind, estimator::RejectReason::kNotInitialised);
}

FilterRunResult RunFilter(const FilterFeed& feed, const estimator::EskfOptions& options,
                          const FilterRunOptions& run_options) {
  const Time wall_start = Time::Now();
  FilterRunResult result;
  Scorer scorer(feed, run_options, &result);
  estimator::LocalReferenceFilter filter(options, &scorer);
  for (const estimator::EskfInput& input : feed.inputs()) filter.Process(input);
  scorer.Finish();
  result.health = filter.health();
  result.run_wall_time_s = (Time::Now() - wall_start).ToSeconds();
  return result;
}

}  // namespace rover::sim
