// Behaviour of the local reference filter as a whole: initialisation,
// cloning, delayed updates, standstill, frame switches, bad input, and the
// real-time and determinism contracts.

#include "estimator/eskf/local_reference_filter.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "tests/estimator/eskf/eskf_test_util.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"

namespace rover::estimator {
namespace {

using test::RecordingSink;

constexpr double kRateHz = 400.0;
constexpr int64_t kPeriodNs = 2'500'000;

Time At(int64_t ns) { return Time::FromNanoseconds(ns); }
Time AtSeconds(double s) { return At(static_cast<int64_t>(std::llround(s * 1e9))); }

// A rover standing still with the given attitude, gyro bias and white noise.
class StaticImu {
 public:
  StaticImu(const Eigen::Matrix3d& R, const Eigen::Vector3d& gyro_bias, double noise_scale,
            uint64_t seed)
      : R_(R), gyro_bias_(gyro_bias), noise_scale_(noise_scale), rng_(seed) {}

  ImuMeasurement At(Time t) {
    std::normal_distribution<double> n(0.0, 1.0);
    ImuMeasurement m;
    m.stamp = t;
    const double sg = 1.745e-4 * std::sqrt(kRateHz) * noise_scale_;
    const double sa = 5.88e-4 * std::sqrt(kRateHz) * noise_scale_;
    m.angular_velocity_rad_s = gyro_bias_ + sg * Eigen::Vector3d(n(rng_), n(rng_), n(rng_));
    m.linear_acceleration_m_s2 = R_.transpose() * Eigen::Vector3d(0, 0, 9.80665) + accel_bias +
                                 sa * Eigen::Vector3d(n(rng_), n(rng_), n(rng_));
    return m;
  }

  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();

 private:
  Eigen::Matrix3d R_;
  Eigen::Vector3d gyro_bias_;
  double noise_scale_;
  std::mt19937_64 rng_;
};

Eigen::Matrix3d Tilt(double roll, double pitch) {
  return (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Feeds static samples k0 .. k1-1 (sample k at k * 2.5 ms).
void FeedStatic(LocalReferenceFilter& f, StaticImu& imu, int k0, int k1) {
  for (int k = k0; k < k1; ++k) f.AddImu(imu.At(At(k * kPeriodNs)));
}

EskfOptions DefaultOptions() {
  EskfOptions o;
  o.imu.rate_hz = kRateHz;
  return o;
}

TEST(LocalReferenceFilterTest, InitialisesRollPitchAndGyroBiasFromStandstill) {
  const Eigen::Vector3d bias(0.01, -0.02, 0.005);
  StaticImu imu(Tilt(0.08, -0.05), bias, 1.0, 1);
  RecordingSink sink;
  LocalReferenceFilter f(DefaultOptions(), &sink);
  f.AddCloneTrigger({At(kPeriodNs)});
  EXPECT_EQ(f.health().Rejected(InputKind::kCloneTrigger, RejectReason::kNotInitialised), 1u);
  FeedStatic(f, imu, 0, 399);
  EXPECT_FALSE(f.initialised());
  EXPECT_TRUE(sink.states.empty());
  FeedStatic(f, imu, 399, 400);
  ASSERT_TRUE(f.initialised());
  ASSERT_EQ(sink.states.size(), 1u);
  const EskfOutput& o = sink.states.back();
  const Eigen::Matrix3d R = o.q_local_body.toRotationMatrix();
  const YawRollPitchSplit split = SplitYawRollPitch(R);
  EXPECT_NEAR(split.yaw_rad, 0.0, 1e-12);
  EXPECT_LT(LogSO3(split.R_rollpitch.transpose() * Tilt(0.08, -0.05)).norm(), 1e-3);
  EXPECT_LT((o.gyro_bias_rad_s - bias).norm(), 1e-3);
  EXPECT_EQ(o.p_local_body, Eigen::Vector3d::Zero());
  EXPECT_EQ((o.covariance.block<3, 3>(kDp, kDp).norm()), 0.0);
  const Eigen::RowVector3d j = YawJacobianRight(R);
  const double yaw_var = j * o.covariance.block<3, 3>(kDtheta, kDtheta) * j.transpose();
  EXPECT_LT(yaw_var, 1e-16);
  EXPECT_GT(o.covariance(kDtheta, kDtheta), 0.0);  // tilt is uncertain
  EXPECT_EQ(o.status & kStatusNotInitialised, 0u);
}

TEST(LocalReferenceFilterTest, DoesNotInitialiseWhileMoving) {
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 100.0, 2);
  LocalReferenceFilter f(DefaultOptions(), nullptr);
  FeedStatic(f, imu, 0, 2000);
  EXPECT_FALSE(f.initialised());
}

// Standing still until t0, then turning about z at a constant rate.
class TurnOnSpot {
 public:
  TurnOnSpot(double t0_s, double rate_rad_s) : t0_(t0_s), rate_(rate_rad_s) {}
  Eigen::Matrix3d Attitude(double t) const {
    return Rz(t > t0_ ? rate_ * (t - t0_) : 0.0) * Tilt(0.03, 0.02);
  }
  ImuMeasurement At(Time stamp) const {
    const double t = stamp.ToSeconds();
    ImuMeasurement m;
    m.stamp = stamp;
    const Eigen::Matrix3d R = Attitude(t);
    m.angular_velocity_rad_s = R.transpose() * Eigen::Vector3d(0, 0, t > t0_ ? rate_ : 0.0);
    m.linear_acceleration_m_s2 = R.transpose() * Eigen::Vector3d(0, 0, 9.80665);
    return m;
  }

 private:
  double t0_, rate_;
};

TEST(LocalReferenceFilterTest, ClonesAtTheExactTriggerTime) {
  const TurnOnSpot motion(1.5, 0.5);
  LocalReferenceFilter f(DefaultOptions(), nullptr);
  int k = 0;
  for (; k < 800; ++k) f.AddImu(motion.At(At(k * kPeriodNs)));  // to 2.0 s
  ASSERT_TRUE(f.initialised());
  // A trigger between samples (in the future) and one slightly in the past.
  const Time future = At(k * kPeriodNs + 1'234'567);
  const Time past = At((k - 1) * kPeriodNs - 700'000);
  f.AddCloneTrigger({past});
  f.AddCloneTrigger({future});
  for (int n = 0; n < 4; ++n, ++k) f.AddImu(motion.At(At(k * kPeriodNs)));
  const FilterState& s = f.state();
  ASSERT_EQ(s.clone_count, 2);
  EXPECT_EQ(s.clones[0].stamp, past);
  EXPECT_EQ(s.clones[1].stamp, future);
  // The local frame is the initial pose with yaw removed: compare relative
  // rotations since initialisation (the turn started after it).
  const Eigen::Matrix3d R_init = motion.Attitude(1.0);
  const Eigen::Matrix3d yaw0 = Rz(YawOf(R_init));
  for (int i = 0; i < 2; ++i) {
    const PoseClone& c = s.clones[static_cast<size_t>(i)];
    const Eigen::Matrix3d truth = yaw0.transpose() * motion.Attitude(c.stamp.ToSeconds());
    // The trapezoid rule smooths the rate step at the start of the turn
    // (0.5 rad/s * 1.25 ms); after that, integration is exact.
    EXPECT_LT(LogSO3(c.R_local_body.transpose() * truth).norm(), 1e-3) << "clone " << i;
    EXPECT_LT(c.p_local_body.norm(), 1e-6);
  }
  const Eigen::Matrix3d relative = s.clones[0].R_local_body.transpose() * s.clones[1].R_local_body;
  const Eigen::Matrix3d relative_truth =
      motion.Attitude(past.ToSeconds()).transpose() * motion.Attitude(future.ToSeconds());
  EXPECT_LT(LogSO3(relative.transpose() * relative_truth).norm(), 1e-9);
  EXPECT_EQ(f.health().clones_created, 2u);
}

// A static rover whose accelerometer has a bias the filter does not know yet:
// the filter's position drifts; a relative pose of "no motion" between two
// clones must pull the current velocity back.
struct DriftSetup {
  RecordingSink sink;
  LocalReferenceFilter filter{DefaultOptions(), &sink};
  StaticImu imu{Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 0.0, 3};
  int k = 0;

  DriftSetup() {
    for (; k < 400; ++k) filter.AddImu(imu.At(At(k * kPeriodNs)));
    imu.accel_bias = Eigen::Vector3d(0.05, -0.04, 0.0);
  }
  void RunTo(double t_s) {
    for (; k * kPeriodNs <= AtSeconds(t_s).nanoseconds(); ++k) {
      filter.AddImu(imu.At(At(k * kPeriodNs)));
    }
  }
  RelativePoseMeasurement NoMotion(Time from, Time to, Time delivered) const {
    RelativePoseMeasurement z;
    z.stamp = delivered;
    z.from_stamp = from;
    z.to_stamp = to;
    z.covariance = Matrix6d::Identity() * 1e-6;
    return z;
  }
};

TEST(LocalReferenceFilterTest, DelayedRelativePoseCorrectsTheCurrentState) {
  DriftSetup d;
  const Time t1 = AtSeconds(1.5), t2 = AtSeconds(2.5);
  d.filter.AddCloneTrigger({t1});
  d.RunTo(2.0);
  d.filter.AddCloneTrigger({t2});
  d.RunTo(2.9);  // the measurement arrives 0.4 s after t2
  const double speed_before = d.filter.output().v_local_m_s.norm();
  EXPECT_GT(speed_before, 0.02);
  d.filter.AddRelativePose(d.NoMotion(t1, t2, AtSeconds(2.9)));
  EXPECT_EQ(d.filter.health().Accepted(InputKind::kRelativePose), 1u);
  d.RunTo(2.91);
  EXPECT_LT(d.filter.output().v_local_m_s.norm(), 0.2 * speed_before);
  // The clone of t2 was not a keyframe: marginalised; t1 was the start:
  // kept as a keyframe.
  ASSERT_EQ(d.filter.state().clone_count, 1);
  EXPECT_EQ(d.filter.state().clones[0].stamp, t1);
  EXPECT_TRUE(d.filter.state().clones[0].keyframe);
}

TEST(LocalReferenceFilterTest, RejectsLateUnknownAndTooOldRelativePoses) {
  DriftSetup d;
  const Time t1 = AtSeconds(1.5), t2 = AtSeconds(1.6);
  d.filter.AddCloneTrigger({t1});
  d.filter.AddCloneTrigger({t2});
  d.RunTo(2.2);
  const auto& h = d.filter.health();
  d.filter.AddRelativePose(d.NoMotion(t1, t2, AtSeconds(2.2)));  // 0.6 s late
  EXPECT_EQ(h.Rejected(InputKind::kRelativePose, RejectReason::kTooOld), 1u);
  d.filter.AddRelativePose(d.NoMotion(AtSeconds(1.2), t2, AtSeconds(2.0)));  // before every clone
  EXPECT_EQ(h.Rejected(InputKind::kRelativePose, RejectReason::kTooOld), 2u);
  d.filter.AddRelativePose(d.NoMotion(t1, AtSeconds(1.55), AtSeconds(2.0)));  // no clone there
  EXPECT_EQ(h.Rejected(InputKind::kRelativePose, RejectReason::kUnknownClone), 1u);
  RelativePoseMeasurement bad = d.NoMotion(t1, t2, AtSeconds(2.0));
  bad.covariance(0, 0) = -1.0;
  d.filter.AddRelativePose(bad);
  EXPECT_EQ(h.Rejected(InputKind::kRelativePose, RejectReason::kBadCovariance), 1u);
  bad = d.NoMotion(t1, t2, AtSeconds(2.0));
  bad.p_from_to.x() = std::numeric_limits<double>::quiet_NaN();
  d.filter.AddRelativePose(bad);
  EXPECT_EQ(h.Rejected(InputKind::kRelativePose, RejectReason::kNonFinite), 1u);
  EXPECT_EQ(h.Accepted(InputKind::kRelativePose), 0u);
  EXPECT_EQ(d.sink.rejects.size(), 5u);
}

TEST(LocalReferenceFilterTest, GatesOutliersAndLogsThem) {
  DriftSetup d;
  const Time t1 = AtSeconds(1.5), t2 = AtSeconds(1.6);
  d.filter.AddCloneTrigger({t1});
  d.filter.AddCloneTrigger({t2});
  d.RunTo(1.8);
  const Eigen::Vector3d p_before = d.filter.output().p_local_body;
  RelativePoseMeasurement z = d.NoMotion(t1, t2, AtSeconds(1.8));
  z.p_from_to = Eigen::Vector3d(1.0, 0.0, 0.0);  // 1 m jump, stated 1 mm
  d.filter.AddRelativePose(z);
  EXPECT_EQ(d.filter.health().Rejected(InputKind::kRelativePose, RejectReason::kGated), 1u);
  ASSERT_FALSE(d.sink.rejects.empty());
  const RejectRecord& r = d.sink.rejects.back();
  EXPECT_EQ(r.reason, RejectReason::kGated);
  EXPECT_GT(r.mahalanobis_sq, r.gate);
  EXPECT_NEAR(r.gate, 22.46, 0.01);  // chi-square 6 dof at 0.999
  EXPECT_EQ(d.filter.state().core.p_local_body, p_before);
}

TEST(LocalReferenceFilterTest, BadImuSamplesAreRejectedAndFlagged) {
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1.0, 4);
  RecordingSink sink;
  LocalReferenceFilter f(DefaultOptions(), &sink);
  FeedStatic(f, imu, 0, 400);
  ASSERT_TRUE(f.initialised());
  ImuMeasurement nan = imu.At(At(400 * kPeriodNs));
  nan.angular_velocity_rad_s.y() = std::numeric_limits<double>::quiet_NaN();
  f.AddImu(nan);
  ImuMeasurement inf = imu.At(At(400 * kPeriodNs));
  inf.linear_acceleration_m_s2.z() = std::numeric_limits<double>::infinity();
  f.AddImu(inf);
  FeedStatic(f, imu, 400, 401);
  f.AddImu(imu.At(At(400 * kPeriodNs)));  // duplicate
  f.AddImu(imu.At(At(300 * kPeriodNs)));  // older
  ImuMeasurement saturated = imu.At(At(401 * kPeriodNs));
  saturated.linear_acceleration_m_s2.x() = 200.0;
  f.AddImu(saturated);
  const EskfHealth& h = f.health();
  EXPECT_EQ(h.Rejected(InputKind::kImu, RejectReason::kNonFinite), 2u);
  EXPECT_EQ(h.Rejected(InputKind::kImu, RejectReason::kOutOfOrder), 2u);
  EXPECT_EQ(h.Rejected(InputKind::kImu, RejectReason::kSaturated), 1u);
  FeedStatic(f, imu, 402, 410);
  EXPECT_NE(f.output().status & kStatusImuInvalid, 0u);
  // Recovery: the flag clears recovery_s after the last bad sample.
  FeedStatic(f, imu, 410, 410 + 400);
  EXPECT_EQ(f.output().status & kStatusImuInvalid, 0u);
  for (const EskfOutput& o : sink.states) {
    ASSERT_TRUE(o.p_local_body.allFinite() && o.covariance.allFinite());
  }
}

TEST(LocalReferenceFilterTest, ImuGapSetsDegradedFlagAndRecovers) {
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1.0, 5);
  LocalReferenceFilter f(DefaultOptions(), nullptr);
  FeedStatic(f, imu, 0, 400);
  FeedStatic(f, imu, 480, 481);  // 0.2 s gap
  EXPECT_NE(f.output().status & kStatusImuGap, 0u);
  EXPECT_EQ(f.health().imu_gaps, 1u);
  EXPECT_NEAR(f.health().longest_imu_gap_s, 0.2025, 1e-9);  // samples 399 -> 480
  const double var_after_gap = f.output().covariance(kDv, kDv);
  FeedStatic(f, imu, 481, 481 + 400);
  EXPECT_EQ(f.output().status & kStatusImuGap, 0u);
  EXPECT_TRUE(f.output().p_local_body.allFinite());
  EXPECT_GT(var_after_gap, 0.0);
}

TEST(LocalReferenceFilterTest, ZeroVelocityUpdatesOnlyWhenWheelsStandStill) {
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.002, 0.0, -0.001), 1.0, 6);
  LocalReferenceFilter f(DefaultOptions(), nullptr);
  int k = 0;
  const auto run = [&](int samples, double wheel_rate) {
    for (int n = 0; n < samples; ++n, ++k) {
      f.AddImu(imu.At(At(k * kPeriodNs)));
      if (k % 4 == 0)
        f.AddWheelSpeeds({At(k * kPeriodNs), {wheel_rate, wheel_rate, wheel_rate, wheel_rate}});
    }
  };
  run(400, 0.0);
  ASSERT_TRUE(f.initialised());
  run(800, 0.0);
  const uint64_t zupts = f.health().zero_velocity_updates;
  EXPECT_GE(zupts, 6u);
  EXPECT_NE(f.output().status & kStatusStandstill, 0u);
  EXPECT_LT(std::sqrt(f.output().covariance(kDv, kDv)), 0.01);
  // Wheels turning (a wheel-speed / IMU disagreement, but the point is that
  // the standstill test must fail): no more zero-velocity updates.
  run(400, 0.5);
  EXPECT_EQ(f.health().zero_velocity_updates, zupts);
  EXPECT_EQ(f.output().status & kStatusStandstill, 0u);
}

TEST(LocalReferenceFilterTest, ZeroVelocityWaitsUntilTheWheelsStoodStillForAWholeWindow) {
  // The IMU is still but the wheels only stop at 2.0 s (as at the end of a
  // turn, when the IMU window still holds the slowing rotation).
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1.0, 9);
  LocalReferenceFilter f(DefaultOptions(), nullptr);
  const double window_s = f.options().zupt.window_s;
  uint64_t zupts_at_stop = 0;
  Time first_zupt = Time::Max();
  for (int k = 0; k < 1400; ++k) {
    const Time t = At(k * kPeriodNs);
    const double rate = t < AtSeconds(2.0) ? 0.3 : 0.0;
    if (k % 4 == 0) f.AddWheelSpeeds({t, {rate, rate, rate, rate}});
    f.AddImu(imu.At(t));
    if (t == AtSeconds(2.0)) zupts_at_stop = f.health().zero_velocity_updates;
    if (first_zupt == Time::Max() && f.health().zero_velocity_updates > zupts_at_stop &&
        t > AtSeconds(2.0)) {
      first_zupt = t;
    }
  }
  EXPECT_EQ(zupts_at_stop, 0u);
  ASSERT_NE(first_zupt, Time::Max());
  EXPECT_GT((first_zupt - AtSeconds(2.0)).ToSeconds(), window_s - 0.011);
  EXPECT_LT((first_zupt - AtSeconds(2.0)).ToSeconds(), window_s + 0.02);
}

TEST(LocalReferenceFilterTest, EvictionKeepsTheNewestKeyframe) {
  DriftSetup d;
  EskfOptions o = DefaultOptions();
  // Triggers every 0.1 s from 1.5 s; measurements every frame, keyframes at
  // 1.5 s and 1.8 s; then five frames whose measurements never come (VO
  // stalled): they and the old keyframe compete for six slots.
  for (int i = 0; i < 4; ++i) d.filter.AddCloneTrigger({AtSeconds(1.5 + 0.1 * i)});
  d.RunTo(1.95);
  const auto kf = [&](double from, double to, bool keyframe) {
    RelativePoseMeasurement z = d.NoMotion(AtSeconds(from), AtSeconds(to), AtSeconds(1.95));
    z.to_is_keyframe = keyframe;
    d.filter.AddRelativePose(z);
  };
  kf(1.5, 1.6, false);
  kf(1.5, 1.7, false);
  kf(1.5, 1.8, true);
  ASSERT_EQ(d.filter.state().clone_count, 2);  // keyframes 1.5 and 1.8
  for (int i = 0; i < 6; ++i) d.filter.AddCloneTrigger({AtSeconds(2.0 + 0.1 * i)});
  d.RunTo(2.6);
  const FilterState& s = d.filter.state();
  ASSERT_EQ(s.clone_count, o.clones.max_clones);
  bool newest_keyframe_kept = false;
  for (int i = 0; i < s.clone_count; ++i) {
    newest_keyframe_kept |= s.clones[static_cast<size_t>(i)].stamp == AtSeconds(1.8);
    EXPECT_NE(s.clones[static_cast<size_t>(i)].stamp, AtSeconds(1.5));  // the old keyframe went
  }
  EXPECT_TRUE(newest_keyframe_kept);
  EXPECT_EQ(d.filter.health().clones_evicted, 2u);
  // The VO catches up from its newest keyframe: accepted.
  RelativePoseMeasurement z = d.NoMotion(AtSeconds(1.8), AtSeconds(2.5), AtSeconds(2.6));
  d.filter.AddRelativePose(z);
  EXPECT_EQ(d.filter.health().Accepted(InputKind::kRelativePose), 4u);
}

TEST(LocalReferenceFilterTest, FrameSwitchAndPoseReportThroughTheFilter) {
  DriftSetup d;
  d.RunTo(2.0);
  const Eigen::Vector3d p = d.filter.output().p_local_body;
  ASSERT_GT(p.norm(), 1e-3);
  d.filter.RequestPoseReport({AtSeconds(2.0), 7});
  d.filter.RequestFrameSwitch({AtSeconds(2.0)});
  d.RunTo(2.01);
  ASSERT_EQ(d.sink.reports.size(), 1u);
  EXPECT_EQ(d.sink.reports[0].request_id, 7u);
  EXPECT_EQ(d.sink.reports[0].p_local_body, p);
  EXPECT_GT(d.sink.reports[0].covariance(0, 0), 0.0);
  ASSERT_EQ(d.sink.switches.size(), 1u);
  EXPECT_EQ(d.sink.switches[0].p_old_new, p);
  EXPECT_NEAR(d.sink.switches[0].covariance(0, 0), d.sink.reports[0].covariance(0, 0), 1e-15);
  EXPECT_EQ(d.filter.output().frame_id, 1u);
  EXPECT_LT(d.filter.output().p_local_body.norm(), 1e-3);  // restarted at the origin
}

TEST(LocalReferenceFilterTest, NeverEmitsNonFiniteValuesOnGarbage) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> pick(0, 9);
  std::normal_distribution<double> n(0.0, 1.0);
  StaticImu imu(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1.0, 8);
  RecordingSink sink;
  LocalReferenceFilter f(DefaultOptions(), &sink);
  FeedStatic(f, imu, 0, 400);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 400; k < 4000; ++k) {
    ImuMeasurement m = imu.At(At(k * kPeriodNs + static_cast<int64_t>(n(rng) * 1e6)));
    switch (pick(rng)) {
      case 0:
        m.angular_velocity_rad_s.x() = nan;
        break;
      case 1:
        m.linear_acceleration_m_s2 *= 1e3;
        break;
      case 2:
        m.stamp = At(k * kPeriodNs - 50'000'000);
        break;
      case 3:
        m.linear_acceleration_m_s2 += Eigen::Vector3d(n(rng), n(rng), n(rng)) * 30.0;
        break;
      default:
        break;
    }
    f.AddImu(m);
    if (k % 40 == 0) f.AddCloneTrigger({At(k * kPeriodNs + 1000)});
    if (k % 40 == 20) {
      RelativePoseMeasurement z;
      z.stamp = At(k * kPeriodNs);
      z.from_stamp = At((k - 60) * kPeriodNs + 1000);
      z.to_stamp = At((k - 20) * kPeriodNs + 1000);
      z.p_from_to = Eigen::Vector3d(n(rng), n(rng), n(rng)) * (pick(rng) == 0 ? 1e6 : 0.1);
      z.q_from_to = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng));
      z.covariance = Matrix6d::Identity() * std::pow(10.0, n(rng) * 3.0);
      f.AddRelativePose(z);
    }
    if (k % 4 == 0) {
      f.AddWheelSpeeds(
          {At(k * kPeriodNs), {n(rng) * 5, n(rng) * 5, pick(rng) == 0 ? nan : 0.0, 1.0}});
    }
    if (k % 500 == 0) f.RequestFrameSwitch({At(k * kPeriodNs)});
  }
  ASSERT_FALSE(sink.states.empty());
  for (const EskfOutput& o : sink.states) {
    ASSERT_TRUE(o.p_local_body.allFinite() && o.v_local_m_s.allFinite() &&
                o.q_local_body.coeffs().allFinite() && o.covariance.allFinite());
  }
}

// A sink that only counts, like roverd's ring pushes: no allocation.
class CountingSink : public EskfOutputSink {
 public:
  void OnState(const EskfOutput& o) override {
    last_x += o.p_local_body.x();
    ++states;
  }
  void OnFrameSwitch(const FrameSwitchRecord&) override { ++switches; }
  void OnPoseReport(const PoseReport&) override { ++reports; }
  void OnReject(const RejectRecord&) override { ++rejects; }
  double last_x = 0.0;
  int states = 0, switches = 0, reports = 0, rejects = 0;
};

// One second of everything the filter does: IMU steps at 400 Hz, clones at
// 10 Hz, delayed relative poses, wheel speeds at 100 Hz, a frame switch and a
// pose report.
void RunBusySecond(LocalReferenceFilter& f, const TurnOnSpot& motion, int& k) {
  const int k_end = k + 400;
  for (; k < k_end; ++k) {
    const Time t = At(k * kPeriodNs);
    f.AddImu(motion.At(t));
    if (k % 40 == 0) f.AddCloneTrigger({t + Duration::Nanoseconds(1000)});
    if (k % 40 == 10 && k >= 1200) {
      RelativePoseMeasurement z;
      z.stamp = t;
      z.from_stamp = At((k - 90) * kPeriodNs + 1000);
      z.to_stamp = At((k - 50) * kPeriodNs + 1000);
      z.q_from_to = Eigen::Quaterniond(motion.Attitude(z.from_stamp.ToSeconds()).transpose() *
                                       motion.Attitude(z.to_stamp.ToSeconds()));
      z.covariance = Matrix6d::Identity() * 1e-4;
      z.to_is_keyframe = (k % 120 == 10);
      f.AddRelativePose(z);
    }
    if (k % 4 == 0) f.AddWheelSpeeds({t, {-0.5, 0.5, -0.5, 0.5}});
    if (k % 200 == 100) f.RequestPoseReport({t, static_cast<uint64_t>(k)});
    if (k % 400 == 300) f.RequestFrameSwitch({t});
  }
}

TEST(LocalReferenceFilterTest, NoHeapAllocationAfterInitialisation) {
  const TurnOnSpot motion(1.5, 0.3);
  CountingSink sink;
  LocalReferenceFilter f(DefaultOptions(), &sink);
  int k = 0;
  RunBusySecond(f, motion, k);  // initialises
  RunBusySecond(f, motion, k);  // fills the clone window
  ASSERT_TRUE(f.initialised());
  testing::ScopedAllocationCheck news;
  testing::ScopedMallocCheck mallocs;
  for (int s = 0; s < 5; ++s) RunBusySecond(f, motion, k);
  EXPECT_EQ(news.allocations(), 0u);
  EXPECT_EQ(mallocs.mallocs(), 0u);
  // It really did the work.
  EXPECT_GT(f.health().Accepted(InputKind::kRelativePose), 20u);
  EXPECT_GT(f.health().frame_switches, 4u);
  EXPECT_GT(sink.reports, 8);
  EXPECT_GE(f.state().clone_count, 1);
}

uint64_t Fnv1a(uint64_t h, const void* data, size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

class HashingSink : public EskfOutputSink {
 public:
  void OnState(const EskfOutput& o) override {
    hash = Fnv1a(hash, o.p_local_body.data(), sizeof(double) * 3);
    hash = Fnv1a(hash, o.v_local_m_s.data(), sizeof(double) * 3);
    hash = Fnv1a(hash, o.q_local_body.coeffs().data(), sizeof(double) * 4);
    hash = Fnv1a(hash, o.covariance.data(), sizeof(double) * 225);
  }
  void OnFrameSwitch(const FrameSwitchRecord& r) override {
    hash = Fnv1a(hash, r.covariance.data(), sizeof(double) * 16);
  }
  void OnPoseReport(const PoseReport& r) override {
    hash = Fnv1a(hash, r.covariance.data(), sizeof(double) * 36);
  }
  void OnReject(const RejectRecord& r) override { hash = Fnv1a(hash, &r.reason, 1); }
  uint64_t hash = 1469598103934665603ull;
};

uint64_t RunAndHash() {
  const TurnOnSpot motion(1.5, 0.3);
  HashingSink sink;
  LocalReferenceFilter f(DefaultOptions(), &sink);
  int k = 0;
  for (int s = 0; s < 6; ++s) RunBusySecond(f, motion, k);
  return sink.hash;
}

uint64_t HashInChildProcess() {
  int fds[2];
  if (pipe(fds) != 0) return 0;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const uint64_t h = RunAndHash();
    const ssize_t written = write(fds[1], &h, sizeof h);
    _exit(written == sizeof h ? 0 : 1);
  }
  close(fds[1]);
  uint64_t h = 0;
  const ssize_t got = read(fds[0], &h, sizeof h);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  return got == sizeof h && WIFEXITED(status) && WEXITSTATUS(status) == 0 ? h : 0;
}

TEST(LocalReferenceFilterTest, OutputsAreBitIdenticalAcrossProcesses) {
  const uint64_t a = HashInChildProcess();
  const uint64_t b = HashInChildProcess();
  ASSERT_NE(a, 0u);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, RunAndHash());
}

}  // namespace
}  // namespace rover::estimator
