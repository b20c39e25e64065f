#include "estimator/eskf/local_reference_filter.h"

#include <cmath>

#include "core/geometry/yaw.h"
#include "estimator/eskf/frame_switcher.h"

namespace rover::estimator {
namespace {

Duration SecondsToDuration(double s) {
  return Duration::Nanoseconds(static_cast<int64_t>(std::llround(s * 1e9)));
}

int WindowSamples(double window_s, double rate_hz) {
  return static_cast<int>(std::lround(window_s * rate_hz));
}

// Linear interpolation of two IMU readings at `stamp` (m0.stamp <= stamp <= m1.stamp).
ImuMeasurement Interpolate(const ImuMeasurement& m0, const ImuMeasurement& m1, Time stamp) {
  const double span = (m1.stamp - m0.stamp).ToSeconds();
  const double a = span > 0.0 ? (stamp - m0.stamp).ToSeconds() / span : 1.0;
  ImuMeasurement m;
  m.stamp = stamp;
  m.angular_velocity_rad_s = (1.0 - a) * m0.angular_velocity_rad_s + a * m1.angular_velocity_rad_s;
  m.linear_acceleration_m_s2 =
      (1.0 - a) * m0.linear_acceleration_m_s2 + a * m1.linear_acceleration_m_s2;
  return m;
}

bool IsFinite(const ImuMeasurement& m) {
  return m.angular_velocity_rad_s.allFinite() && m.linear_acceleration_m_s2.allFinite();
}

}  // namespace

LocalReferenceFilter::LocalReferenceFilter(const EskfOptions& options, EskfOutputSink* sink)
    : options_(options),
      sink_(sink),
      propagator_(options.imu),
      relative_pose_updater_(options.relative_pose),
      wheel_updater_(options.wheels),
      zupt_updater_(options.zupt, options.imu),
      init_detector_(WindowSamples(options.init.window_s, options.imu.rate_hz)),
      zupt_detector_(WindowSamples(options.zupt.window_s, options.imu.rate_hz)),
      state_(std::make_unique<FilterState>()),
      recovery_(SecondsToDuration(options.health.recovery_s)),
      max_gap_(SecondsToDuration(options.health.max_imu_gap_s)) {
  output_.status = kStatusNotInitialised;
  health_.status = kStatusNotInitialised;
}

void LocalReferenceFilter::Process(const EskfInput& input) {
  struct Visitor {
    LocalReferenceFilter* f;
    void operator()(const ImuMeasurement& m) const { f->AddImu(m); }
    void operator()(const CloneTrigger& m) const { f->AddCloneTrigger(m); }
    void operator()(const RelativePoseMeasurement& m) const { f->AddRelativePose(m); }
    void operator()(const WheelSpeedMeasurement& m) const { f->AddWheelSpeeds(m); }
    void operator()(const FrameSwitchRequest& m) const { f->RequestFrameSwitch(m); }
    void operator()(const PoseReportRequest& m) const { f->RequestPoseReport(m); }
  };
  std::visit(Visitor{this}, input);
}

// ---------------------------------------------------------------- IMU

void LocalReferenceFilter::AddImu(const ImuMeasurement& m) {
  if (!IsFinite(m)) {
    last_invalid_imu_ = have_last_imu_ ? last_imu_.stamp : m.stamp;
    return Reject(m.stamp, InputKind::kImu, RejectReason::kNonFinite);
  }
  if (have_last_imu_ && m.stamp <= last_imu_.stamp) {
    last_invalid_imu_ = last_imu_.stamp;
    return Reject(m.stamp, InputKind::kImu, RejectReason::kOutOfOrder);
  }
  if (m.angular_velocity_rad_s.cwiseAbs().maxCoeff() >= options_.imu.gyro_range_rad_s ||
      m.linear_acceleration_m_s2.cwiseAbs().maxCoeff() >= options_.imu.accel_range_m_s2) {
    // A clipped reading is wrong by an unknown amount: skip it and integrate
    // across it from the neighbours, like a dropped sample.
    last_invalid_imu_ = m.stamp;
    return Reject(m.stamp, InputKind::kImu, RejectReason::kSaturated);
  }
  Accept(InputKind::kImu);
  if (!initialised_) {
    // A gap breaks the standstill window.
    if (have_last_imu_ && m.stamp - last_imu_.stamp > max_gap_) init_detector_.Clear();
    init_detector_.Add(m);
    last_imu_ = m;
    have_last_imu_ = true;
    if (init_detector_.Full() &&
        init_detector_.MaxAccelStd() < options_.init.accel_std_threshold_m_s2 &&
        init_detector_.MaxGyroStd() < options_.init.gyro_std_threshold_rad_s) {
      Initialise(m);
      EmitState();
    }
    return;
  }
  const Duration dt = m.stamp - last_imu_.stamp;
  if (dt > max_gap_) {
    ++health_.imu_gaps;
    last_gap_ = m.stamp;
    zupt_detector_.Clear();
  }
  if (dt.ToSeconds() > health_.longest_imu_gap_s) health_.longest_imu_gap_s = dt.ToSeconds();
  PropagateTo(m);
  zupt_detector_.Add(m);
  MaybeZeroVelocityUpdate();
  EmitState();
}

void LocalReferenceFilter::PropagateTo(const ImuMeasurement& m) {
  FilterState& s = *state_;
  // Clone at each pending trigger inside (last, m], in order.
  int consumed = 0;
  while (consumed < pending_trigger_count_ &&
         pending_triggers_[static_cast<size_t>(consumed)] <= m.stamp) {
    const Time t = pending_triggers_[static_cast<size_t>(consumed)];
    const ImuMeasurement mid = Interpolate(last_imu_, m, t);
    if (t > s.core.stamp) {
      propagator_.Propagate(s, last_imu_, mid);
      last_imu_ = mid;
    }
    CloneNow();
    ++consumed;
  }
  for (int k = consumed; k < pending_trigger_count_; ++k) {
    pending_triggers_[static_cast<size_t>(k - consumed)] =
        pending_triggers_[static_cast<size_t>(k)];
  }
  pending_trigger_count_ -= consumed;
  if (m.stamp > s.core.stamp) propagator_.Propagate(s, last_imu_, m);
  last_imu_ = m;
}

void LocalReferenceFilter::Initialise(const ImuMeasurement& m) {
  FilterState& s = *state_;
  const Eigen::Vector3d f = init_detector_.MeanAccel();
  // At rest the accelerometer measures R^T (0, 0, g): roll and pitch follow;
  // yaw is unobservable and defines the first local frame (yaw = 0).
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  const Eigen::Quaterniond q = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  s.core = NominalState{};
  s.core.stamp = m.stamp;
  s.core.SetAttitude(q);
  s.core.gyro_bias_rad_s = init_detector_.MeanGyro();

  const InitOptions& io = options_.init;
  const double g = options_.imu.gravity_m_s2;
  const double n = static_cast<double>(init_detector_.window_samples());
  const double gyro_sample_sigma =
      options_.imu.gyro_noise_density_rad_s_sqrt_hz * std::sqrt(options_.imu.rate_hz);
  const double sigma_bg = gyro_sample_sigma / std::sqrt(n) + io.gyro_bias_sigma_floor_rad_s;
  // The accelerometer bias is indistinguishable from a tilt at rest: a tilt
  // error of b_a / g is what an unknown bias of that size leaves behind.
  const double sigma_tilt = io.accel_bias_sigma_m_s2 / g;
  s.P.setZero();
  s.P.block<3, 3>(kDv, kDv).diagonal().setConstant(io.velocity_sigma_m_s * io.velocity_sigma_m_s);
  s.P.block<3, 3>(kDtheta, kDtheta).diagonal().setConstant(sigma_tilt * sigma_tilt);
  s.P.block<3, 3>(kDba, kDba)
      .diagonal()
      .setConstant(io.accel_bias_sigma_m_s2 * io.accel_bias_sigma_m_s2);
  s.P.block<3, 3>(kDbg, kDbg).diagonal().setConstant(sigma_bg * sigma_bg);
  s.pending_transition.setIdentity();
  s.clone_count = 0;
  s.frame_id = 0;
  // Position and yaw define the frame: make their uncertainty exactly zero.
  FrameSwitcher::ResetPositionAndYaw(s);
  initialised_ = true;
  last_aiding_ = m.stamp;
}

// ---------------------------------------------------------------- clones

void LocalReferenceFilter::AddCloneTrigger(const CloneTrigger& m) {
  if (!initialised_)
    return Reject(m.stamp, InputKind::kCloneTrigger, RejectReason::kNotInitialised);
  if (m.stamp <= last_trigger_stamp_) {
    return Reject(m.stamp, InputKind::kCloneTrigger, RejectReason::kOutOfOrder);
  }
  const FilterState& s = *state_;
  if (m.stamp > s.core.stamp) {
    if (pending_trigger_count_ == kMaxPendingTriggers) {
      return Reject(m.stamp, InputKind::kCloneTrigger, RejectReason::kCloneLimit);
    }
    pending_triggers_[static_cast<size_t>(pending_trigger_count_++)] = m.stamp;
  } else if (s.core.stamp - m.stamp <= SecondsToDuration(options_.clones.max_trigger_lateness_s)) {
    if (m.stamp == s.core.stamp) {
      CloneNow();
    } else {
      CloneLate(m.stamp);
    }
  } else {
    return Reject(m.stamp, InputKind::kCloneTrigger, RejectReason::kTooOld);
  }
  last_trigger_stamp_ = m.stamp;
  Accept(InputKind::kCloneTrigger);
}

void LocalReferenceFilter::CloneNow() {
  FilterState& s = *state_;
  s.SyncCrossCovariance();
  if (!MakeRoomForClone()) return;
  s.AppendCloneOfCore();
  ++health_.clones_created;
}

void LocalReferenceFilter::CloneLate(Time stamp) {
  // Integrate back from the current state with the latest reading held
  // constant; the clone's error is the back-step Jacobian times the core error.
  FilterState& s = *state_;
  ImuMeasurement back = last_imu_;
  back.stamp = stamp;
  ImuMeasurement now = last_imu_;
  now.stamp = s.core.stamp;
  const PropagationStep step = propagator_.Integrate(s.core, now, back);
  Matrix15d phi = Matrix15d::Identity();
  step.phi.ApplyLeft(phi);
  Eigen::Matrix<double, 6, 15> J;
  J.topRows<3>() = phi.middleRows<3>(kDp);
  J.bottomRows<3>() = phi.middleRows<3>(kDtheta);
  PoseClone pose;
  pose.stamp = stamp;
  pose.p_local_body = step.next.p_local_body;
  pose.SetAttitude(step.next.q_local_body);
  s.SyncCrossCovariance();
  if (!MakeRoomForClone()) return;
  // Keep clones in capture order: a late clone is older than any pending
  // one but newer than every existing clone (triggers are monotonic).
  s.AppendCloneFromCore(J, pose);
  ++health_.clones_created;
}

bool LocalReferenceFilter::MakeRoomForClone() {
  FilterState& s = *state_;
  if (s.clone_count < options_.clones.max_clones) return true;
  // Victim, in order of preference:
  //  1. the oldest measured non-keyframe clone (normally already gone);
  //  2. the oldest keyframe other than the newest one: the VO measures from
  //     its newest keyframe most of the time, and older keyframes only
  //     matter for revisits;
  //  3. the oldest clone still waiting for its measurement: with 0.1 s
  //     frames and up to 0.5 s latency, the oldest pending one is the most
  //     likely to be a frame the VO dropped;
  //  4. the oldest clone.
  int newest_keyframe = -1;
  for (int i = 0; i < s.clone_count; ++i) {
    if (s.clones[static_cast<size_t>(i)].keyframe) newest_keyframe = i;
  }
  int victim = -1;
  for (int i = 0; i < s.clone_count && victim < 0; ++i) {
    const PoseClone& c = s.clones[static_cast<size_t>(i)];
    if (c.measured && !c.keyframe) victim = i;
  }
  for (int i = 0; i < s.clone_count && victim < 0; ++i) {
    if (s.clones[static_cast<size_t>(i)].keyframe && i != newest_keyframe) victim = i;
  }
  for (int i = 0; i < s.clone_count && victim < 0; ++i) {
    if (!s.clones[static_cast<size_t>(i)].keyframe) victim = i;
  }
  if (victim < 0) victim = 0;
  s.RemoveClone(victim);
  ++health_.clones_evicted;
  return true;
}

// ---------------------------------------------------------------- relative pose

void LocalReferenceFilter::AddRelativePose(const RelativePoseMeasurement& m) {
  const InputKind kind = InputKind::kRelativePose;
  if (!initialised_) return Reject(m.to_stamp, kind, RejectReason::kNotInitialised);
  if (!m.p_from_to.allFinite() || !m.q_from_to.coeffs().allFinite() || !m.covariance.allFinite() ||
      m.q_from_to.norm() < 0.5) {
    return Reject(m.to_stamp, kind, RejectReason::kNonFinite);
  }
  const Eigen::LLT<Matrix6d> llt(0.5 * (m.covariance + m.covariance.transpose()));
  if (llt.info() != Eigen::Success ||
      (m.covariance - m.covariance.transpose()).cwiseAbs().maxCoeff() >
          1e-9 * m.covariance.cwiseAbs().maxCoeff()) {
    return Reject(m.to_stamp, kind, RejectReason::kBadCovariance);
  }
  if (m.from_stamp >= m.to_stamp || m.stamp < m.to_stamp) {
    return Reject(m.to_stamp, kind, RejectReason::kOutOfOrder);
  }
  if (m.stamp - m.to_stamp > SecondsToDuration(options_.relative_pose.max_delay_s)) {
    return Reject(m.to_stamp, kind, RejectReason::kTooOld);
  }
  FilterState& s = *state_;
  const Duration tol = SecondsToDuration(options_.clones.stamp_tolerance_s);
  const int ia = s.FindClone(m.from_stamp, tol);
  const int ib = s.FindClone(m.to_stamp, tol);
  if (ia < 0 || ib < 0) {
    const bool too_old = s.clone_count == 0 || m.from_stamp < s.clones[0].stamp - tol;
    return Reject(m.to_stamp, kind, too_old ? RejectReason::kTooOld : RejectReason::kUnknownClone);
  }
  const UpdateOutcome out = relative_pose_updater_.Update(s, m, ia, ib);
  if (out.numerical) {
    last_numerical_ = s.core.stamp;
    return Reject(m.to_stamp, kind, RejectReason::kNumerical);
  }
  if (out.gated) {
    // The clone stays: the next measurement may still use it as a keyframe.
    AfterRelativePose(ib, m);
    return Reject(m.to_stamp, kind, RejectReason::kGated, out.mahalanobis_sq,
                  relative_pose_updater_.gate());
  }
  Accept(kind);
  last_aiding_ = s.core.stamp;
  AfterRelativePose(ib, m);
}

void LocalReferenceFilter::AfterRelativePose(int ib, const RelativePoseMeasurement& m) {
  FilterState& s = *state_;
  PoseClone& b = s.clones[static_cast<size_t>(ib)];
  b.measured = true;
  if (m.to_is_keyframe) b.keyframe = true;
  // A clone used as the start of a measurement is a keyframe of the VO (its
  // first keyframe is never the end of a measurement).
  const int ia = s.FindClone(m.from_stamp, SecondsToDuration(options_.clones.stamp_tolerance_s));
  if (ia >= 0) s.clones[static_cast<size_t>(ia)].keyframe = true;
  // Keyframes the VO has dropped will never be referenced again.
  if (m.oldest_keyframe_stamp > Time::Zero()) {
    for (int i = ib - 1; i >= 0; --i) {
      PoseClone& c = s.clones[static_cast<size_t>(i)];
      if (c.keyframe && c.stamp < m.oldest_keyframe_stamp) c.keyframe = false;
    }
  }
  // Marginalise, newest first so indices stay valid: the current frame if it
  // is not a keyframe, and every older non-keyframe clone the VO skipped (it
  // processes frames in capture order, so none of them will be measured).
  for (int i = ib; i >= 0; --i) {
    const PoseClone& c = s.clones[static_cast<size_t>(i)];
    if (!c.keyframe) {
      s.RemoveClone(i);
      ++health_.clones_marginalised;
    }
  }
}

// ---------------------------------------------------------------- wheels

void LocalReferenceFilter::AddWheelSpeeds(const WheelSpeedMeasurement& m) {
  const InputKind kind = InputKind::kWheelSpeeds;
  for (double w : m.wheel_rate_rad_s) {
    if (!std::isfinite(w)) return Reject(m.stamp, kind, RejectReason::kNonFinite);
  }
  if (m.stamp <= last_wheel_stamp_) return Reject(m.stamp, kind, RejectReason::kOutOfOrder);
  last_wheel_stamp_ = m.stamp;
  for (double w : m.wheel_rate_rad_s) {
    if (std::abs(w) >= options_.zupt.wheel_rate_threshold_rad_s) last_wheel_motion_ = m.stamp;
  }
  if (!initialised_) return Reject(m.stamp, kind, RejectReason::kNotInitialised);
  if (state_->core.stamp - m.stamp > SecondsToDuration(options_.wheels.max_delay_s)) {
    return Reject(m.stamp, kind, RejectReason::kTooOld);
  }
  Accept(kind);
  if (!options_.wheels.enabled) return;
  if (wheel_count_ == 0) wheel_window_start_ = m.stamp;
  for (size_t k = 0; k < 4; ++k) wheel_sum_[k] += m.wheel_rate_rad_s[k];
  ++wheel_count_;
  if (m.stamp - wheel_window_start_ >= SecondsToDuration(options_.wheels.update_period_s)) {
    ApplyWheelAverage();
  }
}

void LocalReferenceFilter::ApplyWheelAverage() {
  std::array<double, 4> mean{};
  for (size_t k = 0; k < 4; ++k) mean[k] = wheel_sum_[k] / static_cast<double>(wheel_count_);
  wheel_sum_ = {};
  wheel_count_ = 0;
  FilterState& s = *state_;
  const UpdateOutcome out = wheel_updater_.Update(s, wheel_updater_.FromWheelRates(mean),
                                                  last_imu_.angular_velocity_rad_s);
  if (out.numerical) {
    last_numerical_ = s.core.stamp;
    Reject(s.core.stamp, InputKind::kWheelSpeeds, RejectReason::kNumerical);
  } else if (out.gated) {
    Reject(s.core.stamp, InputKind::kWheelSpeeds, RejectReason::kGated, out.mahalanobis_sq,
           wheel_updater_.gate());
  } else {
    last_aiding_ = s.core.stamp;
  }
}

// ---------------------------------------------------------------- standstill

void LocalReferenceFilter::MaybeZeroVelocityUpdate() {
  standing_ = false;
  const ZuptOptions& z = options_.zupt;
  if (!z.enabled || !zupt_detector_.Full()) return;
  FilterState& s = *state_;
  const bool wheels_recent = s.core.stamp - last_wheel_stamp_ <=
                             SecondsToDuration(4.0 * options_.wheels.update_period_s + 0.05);
  // The wheels must have been still for the whole IMU window: at the end of
  // a turn the wheels stop while the window still holds the slowing
  // rotation, which would otherwise leak into the gyro bias.
  const bool wheels_still = s.core.stamp - last_wheel_motion_ > SecondsToDuration(z.window_s);
  if (!wheels_recent && !z.allow_imu_only) return;
  if (wheels_recent && !wheels_still) return;
  const Eigen::Vector3d rate = zupt_detector_.MeanGyro() - s.core.gyro_bias_rad_s;
  if (rate.norm() > z.gyro_threshold_rad_s ||
      zupt_detector_.MaxAccelStd() > z.accel_std_threshold_m_s2) {
    return;
  }
  standing_ = true;
  if (s.core.stamp - last_zupt_ < SecondsToDuration(z.period_s)) return;
  last_zupt_ = s.core.stamp;
  const UpdateOutcome out =
      zupt_updater_.Update(s, zupt_detector_.MeanGyro(), zupt_detector_.window_samples());
  if (out.applied) {
    ++health_.zero_velocity_updates;
    last_aiding_ = s.core.stamp;
  } else if (out.numerical) {
    last_numerical_ = s.core.stamp;
  }
}

// ---------------------------------------------------------------- requests

void LocalReferenceFilter::RequestFrameSwitch(const FrameSwitchRequest& m) {
  if (!initialised_) return Reject(m.stamp, InputKind::kFrameSwitch, RejectReason::kNotInitialised);
  const FrameSwitchRecord record = FrameSwitcher::Switch(*state_);
  ++health_.frame_switches;
  Accept(InputKind::kFrameSwitch);
  if (sink_ != nullptr) sink_->OnFrameSwitch(record);
}

void LocalReferenceFilter::RequestPoseReport(const PoseReportRequest& m) {
  if (!initialised_) return Reject(m.stamp, InputKind::kPoseReport, RejectReason::kNotInitialised);
  const FilterState& s = *state_;
  PoseReport r;
  r.stamp = s.core.stamp;
  r.request_id = m.id;
  r.frame_id = s.frame_id;
  r.p_local_body = s.core.p_local_body;
  r.q_local_body = s.core.q_local_body;
  r.covariance.topLeftCorner<3, 3>() = s.P.block<3, 3>(kDp, kDp);
  r.covariance.topRightCorner<3, 3>() = s.P.block<3, 3>(kDp, kDtheta);
  r.covariance.bottomLeftCorner<3, 3>() = s.P.block<3, 3>(kDtheta, kDp);
  r.covariance.bottomRightCorner<3, 3>() = s.P.block<3, 3>(kDtheta, kDtheta);
  Accept(InputKind::kPoseReport);
  if (sink_ != nullptr) sink_->OnPoseReport(r);
}

// ---------------------------------------------------------------- outputs

bool LocalReferenceFilter::Recent(Time event) const {
  return state_->core.stamp - event <= recovery_;
}

uint32_t LocalReferenceFilter::StatusFlags() const {
  uint32_t flags = 0;
  if (!initialised_) return kStatusNotInitialised;
  if (Recent(last_gap_)) flags |= kStatusImuGap;
  if (Recent(last_invalid_imu_)) flags |= kStatusImuInvalid;
  if (Recent(last_numerical_)) flags |= kStatusNumerical;
  if (state_->core.stamp - last_aiding_ > SecondsToDuration(options_.health.aiding_timeout_s)) {
    flags |= kStatusNoAiding;
  }
  if (standing_) flags |= kStatusStandstill;
  return flags;
}

void LocalReferenceFilter::EmitState() {
  const FilterState& s = *state_;
  if (!s.IsFinite()) {
    // Never emit NaN: keep the previous output and flag it. Inputs are
    // validated and updates refuse non-finite corrections, so this is a
    // last line of defence.
    last_numerical_ = s.core.stamp;
    output_.status |= kStatusNumerical;
    health_.status = output_.status;
    return;
  }
  output_.stamp = s.core.stamp;
  output_.frame_id = s.frame_id;
  output_.p_local_body = s.core.p_local_body;
  output_.v_local_m_s = s.core.v_local_m_s;
  output_.q_local_body = s.core.q_local_body;
  output_.accel_bias_m_s2 = s.core.accel_bias_m_s2;
  output_.gyro_bias_rad_s = s.core.gyro_bias_rad_s;
  output_.angular_velocity_body_rad_s = last_imu_.angular_velocity_rad_s - s.core.gyro_bias_rad_s;
  output_.covariance = s.P.topLeftCorner<15, 15>();
  output_.status = StatusFlags();
  health_.status = output_.status;
  if (sink_ != nullptr) sink_->OnState(output_);
}

void LocalReferenceFilter::Reject(Time stamp, InputKind kind, RejectReason reason, double d2,
                                  double gate) {
  ++health_.rejected[static_cast<size_t>(kind)][static_cast<size_t>(reason)];
  if (sink_ != nullptr) {
    RejectRecord r;
    r.stamp = stamp;
    r.kind = kind;
    r.reason = reason;
    r.mahalanobis_sq = d2;
    r.gate = gate;
    sink_->OnReject(r);
  }
}

const char* ToString(RejectReason reason) {
  switch (reason) {
    case RejectReason::kNonFinite:
      return "non-finite value";
    case RejectReason::kOutOfOrder:
      return "time stamp out of order";
    case RejectReason::kSaturated:
      return "saturated reading";
    case RejectReason::kNotInitialised:
      return "filter not initialised";
    case RejectReason::kTooOld:
      return "too old";
    case RejectReason::kUnknownClone:
      return "no clone at the capture time";
    case RejectReason::kGated:
      return "failed the chi-square gate";
    case RejectReason::kBadCovariance:
      return "covariance not symmetric positive definite";
    case RejectReason::kCloneLimit:
      return "no room for another clone";
    case RejectReason::kNumerical:
      return "numerical failure";
  }
  return "unknown";
}

const char* ToString(InputKind kind) {
  switch (kind) {
    case InputKind::kImu:
      return "imu";
    case InputKind::kCloneTrigger:
      return "clone trigger";
    case InputKind::kRelativePose:
      return "relative pose";
    case InputKind::kWheelSpeeds:
      return "wheel speeds";
    case InputKind::kFrameSwitch:
      return "frame switch";
    case InputKind::kPoseReport:
      return "pose report";
  }
  return "unknown";
}

}  // namespace rover::estimator
