#include "hil/sim/estimator_feed/synthetic_vo.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <stdexcept>

#include "core/geometry/so3.h"
#include "hil/sim/seed.h"

namespace rover::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Independent streams of the VO (distinct from the simulator's stream ids).
constexpr uint64_t kVoNoiseStream = 0x564F'0001;
constexpr uint64_t kVoDropStream = 0x564F'0002;
constexpr uint64_t kVoLatencyStream = 0x564F'0003;

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("SyntheticVoOptions: " + what);
}

}  // namespace

VoNoiseModel VoNoiseModel::IdealConsistent() {
  VoNoiseModel m;
  m.trans_base_m = 0.002;
  m.trans_per_m = 0.005;
  m.rot_base_rad = 0.05 * kDegToRad;
  m.rot_per_rad = 0.0;
  m.rot_per_m = 0.0;
  return m;
}

VoNoiseModel VoNoiseModel::Realistic() {
  VoNoiseModel m;
  m.trans_base_m = 0.005;
  m.trans_per_m = 0.01;
  m.rot_base_rad = 0.1 * kDegToRad;
  m.rot_per_rad = 0.01;
  m.rot_per_m = 0.2 * kDegToRad;
  return m;
}

VoNoiseModel VoNoiseModel::Preset(const std::string& name) {
  if (name == "ideal-consistent") return IdealConsistent();
  if (name == "realistic") return Realistic();
  throw std::invalid_argument("unknown VO noise preset '" + name +
                              "' (known: ideal-consistent, realistic)");
}

estimator::Matrix6d VoNoiseModel::Covariance(const Eigen::Vector3d& dp_m,
                                             const Eigen::Vector3d& dtheta_rad) const {
  const double d = dp_m.norm();
  const double st = trans_base_m + trans_per_m * d;
  const double sr = rot_base_rad + rot_per_rad * dtheta_rad.norm() + rot_per_m * d;
  estimator::Matrix6d c = estimator::Matrix6d::Zero();
  c.diagonal().head<3>().setConstant(st * st);
  c.diagonal().tail<3>().setConstant(sr * sr);
  return c;
}

SyntheticVoOptions SyntheticVoOptions::Load(const ConfigNode& node) {
  SyntheticVoOptions o;
  o.enabled = node.Get<bool>("enabled", o.enabled);
  if (node.Has("preset")) {
    const std::string preset = node.Get<std::string>("preset");
    try {
      o.noise = VoNoiseModel::Preset(preset);
    } catch (const std::invalid_argument& e) {
      node.Fail("preset", e.what());
    }
  }
  VoNoiseModel& n = o.noise;
  n.trans_base_m = node.GetInRange<double>("trans_base_m", 1e-6, 1.0, n.trans_base_m);
  n.trans_per_m = node.GetInRange<double>("trans_per_m", 0.0, 1.0, n.trans_per_m);
  n.rot_base_rad = node.GetInRange<double>("rot_base_rad", 1e-7, 0.5, n.rot_base_rad);
  n.rot_per_rad = node.GetInRange<double>("rot_per_rad", 0.0, 1.0, n.rot_per_rad);
  n.rot_per_m = node.GetInRange<double>("rot_per_m", 0.0, 1.0, n.rot_per_m);
  o.keyframe_distance_m =
      node.GetInRange<double>("keyframe_distance_m", 0.01, 100.0, o.keyframe_distance_m);
  o.keyframe_angle_rad =
      node.GetInRange<double>("keyframe_angle_rad", 1e-3, std::numbers::pi, o.keyframe_angle_rad);
  o.keyframe_max_frames =
      node.GetInRange<int>("keyframe_max_frames", 1, 1000, o.keyframe_max_frames);
  o.max_keyframes = node.GetInRange<int>("max_keyframes", 1, 100, o.max_keyframes);
  o.drop_probability = node.GetInRange<double>("drop_probability", 0.0, 0.9, o.drop_probability);
  o.start_delay_s = node.GetInRange<double>("start_delay_s", 0.0, 3600.0, o.start_delay_s);
  o.latency_base_s = node.GetInRange<double>("latency_base_s", 0.0, 0.5, o.latency_base_s);
  o.latency_jitter_sigma_s =
      node.GetInRange<double>("latency_jitter_sigma_s", 0.0, 0.5, o.latency_jitter_sigma_s);
  o.latency_min_s = node.GetInRange<double>("latency_min_s", 0.0, 0.5, o.latency_min_s);
  o.latency_max_s = node.GetInRange<double>("latency_max_s", 0.0, 0.5, o.latency_max_s);
  if (!(o.latency_min_s <= o.latency_base_s && o.latency_base_s <= o.latency_max_s)) {
    node.Fail("latency_base_s", "need latency_min_s <= latency_base_s <= latency_max_s");
  }
  return o;
}

void SyntheticVoOptions::Validate() const {
  Require(noise.trans_base_m > 0.0 && noise.rot_base_rad > 0.0,
          "the base noise must be positive (the covariance must be positive definite)");
  Require(noise.trans_per_m >= 0.0 && noise.rot_per_rad >= 0.0 && noise.rot_per_m >= 0.0,
          "noise slopes must not be negative");
  Require(keyframe_distance_m > 0.0 && keyframe_angle_rad > 0.0,
          "keyframe thresholds must be positive");
  Require(keyframe_max_frames >= 1 && max_keyframes >= 1, "keyframe counts must be >= 1");
  Require(drop_probability >= 0.0 && drop_probability < 1.0, "drop_probability not in [0, 1)");
  Require(start_delay_s >= 0.0, "start_delay_s must not be negative");
  Require(latency_jitter_sigma_s >= 0.0, "latency_jitter_sigma_s must not be negative");
  Require(0.0 <= latency_min_s && latency_min_s <= latency_base_s &&
              latency_base_s <= latency_max_s && latency_max_s <= 0.5,
          "need 0 <= latency_min_s <= latency_base_s <= latency_max_s <= 0.5 s");
}

std::vector<estimator::RelativePoseMeasurement> RunSyntheticVo(const SyntheticVoOptions& options,
                                                               const std::vector<VoFrame>& frames,
                                                               uint64_t seed,
                                                               SyntheticVoStats* stats) {
  options.Validate();
  std::vector<estimator::RelativePoseMeasurement> out;
  SyntheticVoStats local;
  SyntheticVoStats& st = stats != nullptr ? *stats : local;
  st = {};
  if (!options.enabled || frames.empty()) return out;

  std::mt19937_64 noise_rng(StreamSeed(seed, kVoNoiseStream));
  std::mt19937_64 drop_rng(StreamSeed(seed, kVoDropStream));
  std::mt19937_64 latency_rng(StreamSeed(seed, kVoLatencyStream));
  std::normal_distribution<double> noise_normal(0.0, 1.0);
  std::normal_distribution<double> latency_normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  const Time begin = frames.front().capture + Duration::FromSeconds(options.start_delay_s);
  std::deque<Time> keyframes;  // capture times, oldest first
  Eigen::Isometry3d T_world_kf = Eigen::Isometry3d::Identity();
  int frames_since_keyframe = 0;
  Time last_delivery = Time::Zero();
  Time last_capture = Time::Zero();
  bool first = true;

  for (const VoFrame& frame : frames) {
    if (!first && frame.capture <= last_capture) {
      throw std::invalid_argument("RunSyntheticVo: capture times must increase strictly");
    }
    first = false;
    last_capture = frame.capture;
    if (frame.capture < begin) continue;
    ++st.frames;
    // One draw per frame, so the drop pattern does not depend on the noise.
    if (uniform(drop_rng) < options.drop_probability) {
      ++st.dropped;
      continue;
    }
    if (keyframes.empty()) {
      keyframes.push_back(frame.capture);
      T_world_kf = frame.T_world_body;
      frames_since_keyframe = 0;
      ++st.keyframes;
      continue;
    }
    ++frames_since_keyframe;
    const Eigen::Isometry3d T_kf_cur = T_world_kf.inverse() * frame.T_world_body;
    const Eigen::Vector3d dp = T_kf_cur.translation();
    const Eigen::Matrix3d dR = T_kf_cur.linear();
    const Eigen::Vector3d dtheta = LogSO3(dR);
    const bool new_keyframe = dp.norm() > options.keyframe_distance_m ||
                              dtheta.norm() > options.keyframe_angle_rad ||
                              frames_since_keyframe >= options.keyframe_max_frames;

    estimator::RelativePoseMeasurement m;
    m.from_stamp = keyframes.back();
    m.to_stamp = frame.capture;
    m.covariance = options.noise.Covariance(dp, dtheta);
    Eigen::Matrix<double, 6, 1> z;
    for (int i = 0; i < 6; ++i) z(i) = noise_normal(noise_rng);
    const Eigen::Matrix<double, 6, 1> n = m.covariance.diagonal().cwiseSqrt().cwiseProduct(z);
    m.p_from_to = dp + n.head<3>();
    m.q_from_to = Eigen::Quaterniond(dR * ExpSO3(n.tail<3>())).normalized();
    const double latency_s = std::clamp(
        options.latency_base_s + options.latency_jitter_sigma_s * latency_normal(latency_rng),
        options.latency_min_s, options.latency_max_s);
    m.stamp = std::max(frame.capture + Duration::FromSeconds(latency_s), last_delivery);
    last_delivery = m.stamp;
    m.to_is_keyframe = new_keyframe;
    if (new_keyframe) {
      keyframes.push_back(frame.capture);
      while (static_cast<int>(keyframes.size()) > options.max_keyframes) keyframes.pop_front();
      T_world_kf = frame.T_world_body;
      frames_since_keyframe = 0;
      ++st.keyframes;
    }
    m.oldest_keyframe_stamp = keyframes.front();
    out.push_back(m);
    ++st.measurements;
  }
  return out;
}

}  // namespace rover::sim
