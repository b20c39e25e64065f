#include "hil/sim/sensors/wheel_odometry_model.h"

#include <algorithm>
#include <cmath>

#include "drivers/can/canopen_wheel_protocol.h"
#include "hil/sim/seed.h"

namespace rover::sim {
namespace {

constexpr auto kSyncPeriod = Duration::Milliseconds(10);  // 100 Hz, DESIGN.md

}  // namespace

WheelOdometryModelOptions WheelOdometryModelOptions::Load(const ConfigNode& node) {
  WheelOdometryModelOptions o;
  o.encoder_counts_per_motor_rev =
      node.GetInRange<uint32_t>("encoder_counts_per_motor_rev", 1, 1u << 24);
  o.gear_ratio = node.GetInRange<double>("gear_ratio", 1.0, 1000.0);
  o.yaw_scrub_factor = node.GetInRange<double>("yaw_scrub_factor", 1.0, 3.0);
  o.slip_base_ratio = node.GetInRange<double>("slip_base_ratio", 0.0, 0.5);
  o.slip_slope_gain_per_rad = node.GetInRange<double>("slip_slope_gain_per_rad", 0.0, 5.0);
  o.slip_roughness_gain_per_m = node.GetInRange<double>("slip_roughness_gain_per_m", 0.0, 100.0);
  o.slip_noise_sigma = node.GetInRange<double>("slip_noise_sigma", 0.0, 0.5);
  o.slip_noise_correlation_s = node.GetInRange<double>("slip_noise_correlation_s", 0.001, 100.0);
  o.slip_max_ratio = node.GetInRange<double>("slip_max_ratio", 0.0, 0.95);
  o.roughness_patch_m = node.GetInRange<double>("roughness_patch_m", 0.01, 2.0);
  o.velocity_noise_sigma_rad_s = node.GetInRange<double>("velocity_noise_sigma_rad_s", 0.0, 1.0);
  o.integration_rate_hz = node.GetInRange<double>("integration_rate_hz", 100.0, 100000.0);
  o.sync_phase_s = node.GetInRange<double>("sync_phase_s", 0.0, 0.01);
  // The four TPDO1s must be on the bus well before the next SYNC.
  o.tpdo_first_delay_s = node.GetInRange<double>("tpdo_first_delay_s", 0.0, 0.004);
  o.tpdo_stagger_s = node.GetInRange<double>("tpdo_stagger_s", 0.0, 0.001);
  o.tpdo_jitter_sigma_s = node.GetInRange<double>("tpdo_jitter_sigma_s", 0.0, 1e-4);
  o.heartbeat_phase_s = node.Get<Eigen::Vector4d>("heartbeat_phase_s");
  if (!(o.heartbeat_phase_s.minCoeff() >= 0.0 && o.heartbeat_phase_s.maxCoeff() < 1.0)) {
    node.Fail("heartbeat_phase_s", "every phase must be in [0, 1) s");
  }
  o.seed = node.Get<uint64_t>("seed");
  return o;
}

WheelOdometryModelOptions WheelOdometryModelOptions::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  WheelOdometryModelOptions o = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return o;
}

calib::WheelCalibration WheelCalibrationOf(const RoverTrajectory& trajectory,
                                           const WheelOdometryModelOptions& options) {
  calib::WheelCalibration c;
  c.wheel_radius_m = trajectory.options().wheel_radius_m;
  c.track_m = trajectory.options().track_m;
  Eigen::Vector3d axle = Eigen::Vector3d::Zero();
  for (int w = 0; w < kWheelCount; ++w) axle += trajectory.WheelCenterBody(w);
  c.lever_arm_body_m = axle / kWheelCount;
  c.nonholonomic_point_body_m = Eigen::Vector3d::Zero();
  c.yaw_scrub_factor = options.yaw_scrub_factor;
  c.slip_ratio_base = options.slip_base_ratio;
  c.slip_ratio_per_tilt_rad = options.slip_slope_gain_per_rad;
  return c;
}

WheelOdometryModel::WheelOdometryModel(const WheelOdometryModelOptions& options,
                                       const RoverTrajectory& trajectory,
                                       const Heightfield& terrain, Time start)
    : options_(options),
      trajectory_(trajectory),
      terrain_(terrain),
      start_(start),
      slip_rng_(StreamSeed(options.seed, 1)),
      velocity_rng_(StreamSeed(options.seed, 2)),
      timing_rng_(StreamSeed(options.seed, 3)) {
  // Start the slip noise in its stationary distribution.
  for (double& n : slip_noise_) n = options_.slip_noise_sigma * slip_normal_(slip_rng_);
  rates_ = RatesAt(0.0);
}

Time WheelOdometryModel::SyncTime(uint64_t k) const {
  return start_ + Duration::FromSeconds(options_.sync_phase_s) +
         kSyncPeriod * static_cast<int64_t>(k);
}

double WheelOdometryModel::RoughnessAt(const Eigen::Vector2d& xy) const {
  // RMS residual of a 3 x 3 patch about its least-squares plane: slopes do
  // not count as roughness, bumps and steps do.
  const double a = 0.5 * options_.roughness_patch_m;
  double h[3][3];
  double mean = 0.0, gx = 0.0, gy = 0.0;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      const double v = terrain_.HeightAt(xy.x() + i * a, xy.y() + j * a);
      h[i + 1][j + 1] = v;
      mean += v / 9.0;
      gx += v * i / 6.0;  // sum(i^2) over the patch is 6
      gy += v * j / 6.0;
    }
  }
  double sum_sq = 0.0;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      const double r = h[i + 1][j + 1] - mean - gx * i - gy * j;
      sum_sq += r * r;
    }
  }
  return std::sqrt(sum_sq / 9.0);
}

WheelOdometryModel::WheelRates WheelOdometryModel::RatesAt(double t_s) const {
  const TrajectorySample s = trajectory_.Evaluate(t_s);
  WheelRates out;
  out.rolling_m_s = trajectory_.WheelRollingSpeeds_m_s(s, options_.yaw_scrub_factor);
  const Eigen::Matrix3d R = s.q_world_body.toRotationMatrix();
  out.tilt_rad = std::acos(std::clamp(R(2, 2), -1.0, 1.0));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d left(-forward.y(), forward.x());
  const double radius = trajectory_.options().wheel_radius_m;
  for (int w = 0; w < kWheelCount; ++w) {
    const auto i = static_cast<std::size_t>(w);
    const Eigen::Vector3d c = trajectory_.WheelCenterBody(w);
    out.roughness_m[i] = RoughnessAt(s.p_world_body.head<2>() + c.x() * forward + c.y() * left);
    out.slip[i] =
        std::clamp(options_.slip_base_ratio + options_.slip_slope_gain_per_rad * out.tilt_rad +
                       options_.slip_roughness_gain_per_m * out.roughness_m[i] + slip_noise_[i],
                   0.0, options_.slip_max_ratio);
    out.omega_rad_s[i] = out.rolling_m_s[i] / (radius * (1.0 - out.slip[i]));
  }
  return out;
}

void WheelOdometryModel::IntegrateTo(double t_s) {
  if (t_s <= t_s_) return;
  const double h_max = 1.0 / options_.integration_rate_hz;
  const auto steps = static_cast<int>(std::ceil((t_s - t_s_) / h_max - 1e-9));
  const double h = (t_s - t_s_) / steps;
  // Exact discretisation of the Ornstein-Uhlenbeck slip noise.
  const double decay = std::exp(-h / options_.slip_noise_correlation_s);
  const double drive = options_.slip_noise_sigma * std::sqrt(1.0 - decay * decay);
  const double t0 = t_s_;
  for (int k = 1; k <= steps; ++k) {
    for (double& n : slip_noise_) n = decay * n + drive * slip_normal_(slip_rng_);
    const WheelRates next = RatesAt(k == steps ? t_s : t0 + k * h);
    for (std::size_t i = 0; i < angle_rad_.size(); ++i) {
      angle_rad_[i] += 0.5 * h * (rates_.omega_rad_s[i] + next.omega_rad_s[i]);
    }
    rates_ = next;
  }
  t_s_ = t_s;
}

void WheelOdometryModel::GenerateSync(uint64_t k, std::vector<WheelSyncState>* states) {
  const Time sync = SyncTime(k);
  IntegrateTo((sync - start_).ToSeconds());
  std::vector<drivers::CanFrame> batch;
  batch.push_back(drivers::EncodeSync(sync));

  WheelSyncState state;
  state.stamp = sync;
  state.tilt_rad = rates_.tilt_rad;
  const double ticks_per_rad = options_.ticks_per_wheel_rev() / (2.0 * M_PI);
  for (int w = 0; w < kWheelCount; ++w) {
    const auto i = static_cast<std::size_t>(w);
    state.rolling_speed_m_s[i] = rates_.rolling_m_s[i];
    state.slip_ratio[i] = rates_.slip[i];
    state.angular_velocity_rad_s[i] = rates_.omega_rad_s[i];
    state.angle_rad[i] = angle_rad_[i];
    state.roughness_m[i] = rates_.roughness_m[i];
    state.encoder_ticks[i] = static_cast<int64_t>(std::floor(angle_rad_[i] * ticks_per_rad));

    double delay_s = options_.tpdo_first_delay_s + w * options_.tpdo_stagger_s;
    if (options_.tpdo_jitter_sigma_s > 0.0) {
      // Bounded so the nodes keep their bus order (a lower id wins arbitration).
      const double limit = 0.4 * options_.tpdo_stagger_s;
      delay_s +=
          std::clamp(options_.tpdo_jitter_sigma_s * timing_normal_(timing_rng_), -limit, limit);
    }
    drivers::WheelTpdo1 tpdo;
    tpdo.node_id = static_cast<uint8_t>(w + 1);
    double velocity = rates_.omega_rad_s[i];
    if (options_.velocity_noise_sigma_rad_s > 0.0) {
      velocity += options_.velocity_noise_sigma_rad_s * velocity_normal_(velocity_rng_);
    }
    tpdo.velocity_mrad_s = drivers::VelocityToTpdo(velocity);
    tpdo.position_ticks = drivers::WrapTicks(state.encoder_ticks[i]);
    batch.push_back(drivers::EncodeWheelTpdo1(sync + Duration::FromSeconds(delay_s), tpdo));

    // Heartbeats due in this SYNC period.
    const Time period_end = sync + kSyncPeriod;
    while (true) {
      const Time beat = start_ + Duration::FromSeconds(options_.heartbeat_phase_s[w]) +
                        Duration::Seconds(1) * static_cast<int64_t>(next_heartbeat_[i]);
      if (beat >= period_end) break;
      if (beat >= sync) {
        batch.push_back(drivers::EncodeHeartbeat(beat, {tpdo.node_id, drivers::kNmtOperational}));
      }
      ++next_heartbeat_[i];
    }
  }
  std::stable_sort(
      batch.begin(), batch.end(),
      [](const drivers::CanFrame& a, const drivers::CanFrame& b) { return a.stamp < b.stamp; });
  pending_.insert(pending_.end(), batch.begin(), batch.end());
  if (states != nullptr) states->push_back(state);
}

void WheelOdometryModel::Advance(Time until, std::vector<drivers::CanFrame>* frames,
                                 std::vector<WheelSyncState>* states) {
  while (true) {
    if (!pending_.empty()) {
      if (pending_.front().stamp >= until) return;
      frames->push_back(pending_.front());
      pending_.pop_front();
      continue;
    }
    if (SyncTime(next_sync_) >= until) return;
    GenerateSync(next_sync_++, states);
  }
}

}  // namespace rover::sim
