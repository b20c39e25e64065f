#include "hil/sim/motion/rover_trajectory.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "hil/sim/motion/euler_rates.h"

namespace rover::sim {
namespace {

constexpr double kTiny = 1e-9;

double WrapPi(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

double Heading(const Eigen::Vector2d& d) { return std::atan2(d.y(), d.x()); }

// Gauss-Legendre nodes and weights on [-1, 1]. The rounded corners integrate
// cos/sin of a degree-7 polynomial heading; 16 nodes are exact to rounding.
struct GaussLegendre {
  static constexpr int kN = 16;
  std::array<double, kN> node{};
  std::array<double, kN> weight{};

  GaussLegendre() {
    for (int i = 0; i < kN; ++i) {
      // Newton on the Legendre polynomial P_n from the classic initial guess.
      double z = std::cos(M_PI * (i + 0.75) / (kN + 0.5));
      double dp = 1.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p = 1.0, p_prev = 0.0;
        for (int j = 1; j <= kN; ++j) {
          const double p_prev2 = p_prev;
          p_prev = p;
          p = ((2.0 * j - 1.0) * z * p_prev - (j - 1.0) * p_prev2) / j;
        }
        dp = kN * (z * p - p_prev) / (z * z - 1.0);
        const double step = p / dp;
        z -= step;
        if (std::abs(step) < 1e-16) break;
      }
      node[static_cast<std::size_t>(i)] = z;
      weight[static_cast<std::size_t>(i)] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

const GaussLegendre& Quadrature() {
  static const GaussLegendre quadrature;
  return quadrature;
}

// Displacement along a rounded corner of length `length` whose heading is
// yaw0 + delta * S(x), from x = 0 to x = x_end (fractions of the length).
Eigen::Vector2d BlendOffset(double yaw0, double delta, double length, double x_end) {
  const GaussLegendre& q = Quadrature();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < GaussLegendre::kN; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double x = 0.5 * x_end * (q.node[k] + 1.0);
    const double yaw = yaw0 + delta * SepticStep::Value(x);
    sum += q.weight[k] * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
  }
  return 0.5 * x_end * length * sum;
}

// A rounded corner of heading change delta and arc length L cuts d = L * k
// off each adjacent leg; by the symmetry of S about x = 1/2 the chord is
// along the bisector, so k = (integral of cos(delta (S - 1/2))) / (2 cos(delta / 2)).
double BlendCutPerLength(double delta) {
  const GaussLegendre& q = Quadrature();
  double sum = 0.0;
  for (int i = 0; i < GaussLegendre::kN; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double x = 0.5 * (q.node[k] + 1.0);
    sum += q.weight[k] * std::cos(delta * (SepticStep::Value(x) - 0.5));
  }
  return 0.5 * sum / (2.0 * std::cos(0.5 * delta));
}

// Value, first and second time derivative of f(u(t)).
struct TimeJet {
  double value, rate, accel;
};
TimeJet Chain(const Jet2& f, double u_rate, double u_accel) {
  return {f.value, f.d1 * u_rate, f.d2 * u_rate * u_rate + f.d1 * u_accel};
}

}  // namespace

RoverTrajectoryOptions RoverTrajectoryOptions::Load(const ConfigNode& node) {
  RoverTrajectoryOptions o;
  o.wheelbase_m = node.GetInRange<double>("wheelbase_m", 0.1, 5.0);
  o.track_m = node.GetInRange<double>("track_m", 0.1, 5.0);
  o.wheel_radius_m = node.GetInRange<double>("wheel_radius_m", 0.02, 1.0);
  o.wheel_width_m = node.GetInRange<double>("wheel_width_m", 0.01, 1.0);
  o.body_height_m = node.GetInRange<double>("body_height_m", 0.0, 3.0);
  o.max_accel_m_s2 = node.GetInRange<double>("max_accel_m_s2", 0.01, 5.0);
  o.max_jerk_m_s3 = node.GetInRange<double>("max_jerk_m_s3", 0.01, 50.0);
  o.max_yaw_rate_rad_s = node.GetInRange<double>("max_yaw_rate_rad_s", 0.01, 3.0);
  o.max_yaw_accel_rad_s2 = node.GetInRange<double>("max_yaw_accel_rad_s2", 0.01, 10.0);
  o.turn_in_place_threshold_rad = node.GetInRange<double>("turn_in_place_threshold_rad", 0.0, 1.5);
  o.corner_blend_length_m = node.GetInRange<double>("corner_blend_length_m", 0.05, 10.0);
  o.terrain_sample_spacing_m = node.GetInRange<double>("terrain_sample_spacing_m", 0.005, 1.0);
  return o;
}

RoverTrajectory::RoverTrajectory(const Route& route, const Heightfield& terrain,
                                 const RoverTrajectoryOptions& options)
    : options_(options), turn_radius_m_(0.5 * std::hypot(options.wheelbase_m, options.track_m)) {
  Plan(route);
  SampleTerrain(terrain);
}

double RoverTrajectory::TurnDuration(double delta_yaw) const {
  const double a = std::abs(delta_yaw);
  return std::max(SepticStep::kMaxFirstDerivative * a / options_.max_yaw_rate_rad_s,
                  std::sqrt(SepticStep::kMaxSecondDerivative * a / options_.max_yaw_accel_rad_s2));
}

double RoverTrajectory::RampDuration(double delta_v) const {
  const double a = std::abs(delta_v);
  return std::max(SepticStep::kMaxFirstDerivative * a / options_.max_accel_m_s2,
                  std::sqrt(SepticStep::kMaxSecondDerivative * a / options_.max_jerk_m_s3));
}

void RoverTrajectory::AddSegment(Segment segment) {
  segment.t_begin = duration_s_;
  segment.u_begin = u_total_;
  duration_s_ += segment.duration;
  u_total_ += segment.u_length;
  if (segment.kind != SegmentKind::kDrive) {
    phases_.push_back(
        {segment.kind == SegmentKind::kHold ? MotionPhase::kHold : MotionPhase::kTurnInPlace,
         segment.t_begin, duration_s_, 0.0});
  }
  if (segment.u_length > 0.0) u_segments_.push_back(static_cast<int>(segments_.size()));
  segments_.push_back(segment);
}

void RoverTrajectory::Plan(const Route& route) {
  route.Validate();
  const std::vector<Waypoint>& wps = route.waypoints;
  Eigen::Vector2d xy = route.start_xy_m;
  double yaw = route.start_yaw_rad;
  const auto hold = [&](double duration_s) {
    if (duration_s <= 0.0) return;
    Segment s;
    s.kind = SegmentKind::kHold;
    s.duration = duration_s;
    s.xy = xy;
    s.yaw_begin = yaw;
    AddSegment(s);
  };
  hold(route.start_hold_s);
  std::size_t i = 0;
  while (i < wps.size()) {
    // The rover stands at xy: face the first leg by turning on the spot.
    const double delta = WrapPi(Heading(wps[i].xy_m - xy) - yaw);
    if (std::abs(delta) > kTiny) {
      Segment s;
      s.kind = SegmentKind::kTurn;
      s.duration = TurnDuration(delta);
      s.u_length = turn_radius_m_ * std::abs(delta);
      s.xy = xy;
      s.yaw_begin = yaw;
      s.delta_yaw = delta;
      AddSegment(s);
      yaw += delta;
    }
    // Drive on through every waypoint without a stop whose corner is gentle.
    std::vector<Eigen::Vector2d> points{xy, wps[i].xy_m};
    std::vector<double> speeds{wps[i].speed_m_s};
    std::size_t j = i;
    while (j + 1 < wps.size() && wps[j].stop_s <= 0.0) {
      const double corner = WrapPi(Heading(wps[j + 1].xy_m - wps[j].xy_m) -
                                   Heading(wps[j].xy_m - points[points.size() - 2]));
      if (std::abs(corner) > options_.turn_in_place_threshold_rad) break;
      points.push_back(wps[j + 1].xy_m);
      speeds.push_back(wps[j + 1].speed_m_s);
      ++j;
    }
    yaw = AddDrive(points, speeds, yaw, static_cast<int>(i));
    xy = wps[j].xy_m;
    hold(wps[j].stop_s);
    i = j + 1;
  }
  hold(route.end_hold_s);
}

double RoverTrajectory::AddDrive(const std::vector<Eigen::Vector2d>& points,
                                 const std::vector<double>& speeds, double yaw,
                                 int first_waypoint) {
  const std::size_t n = speeds.size();  // legs; leg k runs points[k] -> points[k + 1]
  std::vector<double> length(n), heading(n);
  std::vector<Eigen::Vector2d> dir(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d d = points[k + 1] - points[k];
    length[k] = d.norm();
    dir[k] = d / length[k];
    heading[k] = k == 0 ? yaw : heading[k - 1] + WrapPi(Heading(d) - heading[k - 1]);
  }
  // Corner k sits at points[k + 1], between leg k and leg k + 1.
  std::vector<double> blend_length(n, 0.0), cut(n, 0.0), delta(n, 0.0);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    delta[k] = heading[k + 1] - heading[k];
    if (std::abs(delta[k]) <= kTiny) continue;
    blend_length[k] = options_.corner_blend_length_m;
    cut[k] = blend_length[k] * BlendCutPerLength(delta[k]);
    // Short legs get a tighter corner, so that some straight part remains.
    const double limit = 0.45 * std::min(length[k], length[k + 1]);
    if (cut[k] > limit) {
      blend_length[k] *= limit / cut[k];
      cut[k] = limit;
    }
  }

  Drive drive;
  std::vector<double> leg_end_s(n);  // arc length where leg k hands over to leg k + 1
  double s = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double cut_in = k == 0 ? 0.0 : cut[k - 1];
    PathElement straight;
    straight.s_begin = s;
    straight.length = std::max(0.0, length[k] - cut_in - cut[k]);
    straight.start_xy = points[k] + cut_in * dir[k];
    straight.start_yaw = heading[k];
    drive.path.push_back(straight);
    s += straight.length;
    if (blend_length[k] > 0.0) {
      PathElement blend;
      blend.s_begin = s;
      blend.length = blend_length[k];
      blend.start_xy = points[k + 1] - cut[k] * dir[k];
      blend.start_yaw = heading[k];
      blend.delta_yaw = delta[k];
      drive.path.push_back(blend);
      s += blend.length;
    }
    // By symmetry the waypoint's "moment" is the middle of its corner.
    leg_end_s[k] = s - 0.5 * blend_length[k];
  }
  drive.length = s;
  leg_end_s[n - 1] = s;

  // Speed: a slower leg's limit holds over all of it, so a slow-down ends at
  // the leg's start and a speed-up begins there; from and to rest likewise.
  const double t0 = duration_s_;
  double t = 0.0, s_piece = 0.0;
  const auto add_piece = [&](double v0, double v1, double duration_s) {
    SpeedPiece p;
    p.t_begin = t;
    p.duration = duration_s;
    p.s_begin = s_piece;
    p.v0 = v0;
    p.v1 = v1;
    drive.speed.push_back(p);
    const MotionPhase phase = v1 > v0   ? MotionPhase::kAccelerate
                              : v1 < v0 ? MotionPhase::kDecelerate
                                        : MotionPhase::kCruise;
    phases_.push_back({phase, t0 + t, t0 + t + duration_s, v0 == v1 ? v0 : 0.0});
    t += duration_s;
    s_piece += 0.5 * (v0 + v1) * duration_s;
  };
  for (std::size_t k = 0; k < n; ++k) {
    const double v = speeds[k];
    const double v_before = k == 0 ? 0.0 : speeds[k - 1];
    const double v_after = k + 1 == n ? 0.0 : speeds[k + 1];
    const double ramp_in_s = v_before < v ? RampDuration(v - v_before) : 0.0;
    const double ramp_out_s = v_after < v ? RampDuration(v - v_after) : 0.0;
    const double ramp_in_m = 0.5 * (v_before + v) * ramp_in_s;
    const double ramp_out_m = 0.5 * (v + v_after) * ramp_out_s;
    const double leg_m = leg_end_s[k] - (k == 0 ? 0.0 : leg_end_s[k - 1]);
    const double cruise_m = leg_m - ramp_in_m - ramp_out_m;
    if (cruise_m < -1e-9) {
      throw std::invalid_argument("route: the leg to waypoint " +
                                  std::to_string(first_waypoint + static_cast<int>(k)) + " is " +
                                  std::to_string(leg_m) +
                                  " m long (after corner rounding) but its speed changes need " +
                                  std::to_string(ramp_in_m + ramp_out_m) +
                                  " m; lengthen the leg, lower its speed or raise max_accel_m_s2");
    }
    if (ramp_in_s > 0.0) add_piece(v_before, v, ramp_in_s);
    if (cruise_m > 0.0) add_piece(v, v, cruise_m / v);
    if (ramp_out_s > 0.0) add_piece(v, v_after, ramp_out_s);
  }
  drive.duration = t;
  distance_m_ += drive.length;

  Segment seg;
  seg.kind = SegmentKind::kDrive;
  seg.duration = drive.duration;
  seg.u_length = drive.length;
  seg.drive = static_cast<int>(drives_.size());
  drives_.push_back(std::move(drive));
  AddSegment(seg);
  return heading[n - 1];
}

RoverTrajectory::PathPoint RoverTrajectory::PathAt(const Drive& drive, double s) const {
  s = std::clamp(s, 0.0, drive.length);
  const auto it =
      std::upper_bound(drive.path.begin(), drive.path.end(), s,
                       [](double value, const PathElement& e) { return value < e.s_begin; });
  const PathElement& e = it == drive.path.begin() ? *it : *(it - 1);
  const double sigma = std::clamp(s - e.s_begin, 0.0, e.length);
  PathPoint out;
  if (e.delta_yaw == 0.0) {
    out.xy = e.start_xy + sigma * Eigen::Vector2d(std::cos(e.start_yaw), std::sin(e.start_yaw));
    out.yaw = e.start_yaw;
    out.yaw_d1 = 0.0;
    out.yaw_d2 = 0.0;
    return out;
  }
  const double x = sigma / e.length;
  out.xy = e.start_xy + BlendOffset(e.start_yaw, e.delta_yaw, e.length, x);
  out.yaw = e.start_yaw + e.delta_yaw * SepticStep::Value(x);
  out.yaw_d1 = e.delta_yaw * SepticStep::D1(x) / e.length;
  out.yaw_d2 = e.delta_yaw * SepticStep::D2(x) / (e.length * e.length);
  return out;
}

RoverTrajectory::PlanarState RoverTrajectory::EvaluatePlanar(double t_s) const {
  const double t = std::clamp(t_s, 0.0, duration_s_);
  const auto it =
      std::upper_bound(segments_.begin(), segments_.end(), t,
                       [](double value, const Segment& seg) { return value < seg.t_begin; });
  const Segment& seg = it == segments_.begin() ? *it : *(it - 1);
  const double tau = t - seg.t_begin;
  PlanarState out;
  out.u = seg.u_begin;
  switch (seg.kind) {
    case SegmentKind::kHold:
      out.xy = seg.xy;
      out.yaw = seg.yaw_begin;
      return out;
    case SegmentKind::kTurn: {
      const double x = tau / seg.duration;
      const double inv_t = 1.0 / seg.duration;
      out.xy = seg.xy;
      out.yaw = seg.yaw_begin + seg.delta_yaw * SepticStep::Value(x);
      out.yaw_rate = seg.delta_yaw * SepticStep::D1(x) * inv_t;
      out.yaw_accel = seg.delta_yaw * SepticStep::D2(x) * inv_t * inv_t;
      const double travel = turn_radius_m_ * std::abs(seg.delta_yaw);
      out.u += travel * SepticStep::Value(x);
      out.u_rate = travel * SepticStep::D1(x) * inv_t;
      out.u_accel = travel * SepticStep::D2(x) * inv_t * inv_t;
      return out;
    }
    case SegmentKind::kDrive:
      break;
  }
  const Drive& drive = drives_[static_cast<std::size_t>(seg.drive)];
  const auto pit =
      std::upper_bound(drive.speed.begin(), drive.speed.end(), tau,
                       [](double value, const SpeedPiece& p) { return value < p.t_begin; });
  const SpeedPiece& p = pit == drive.speed.begin() ? *pit : *(pit - 1);
  const double x = std::clamp((tau - p.t_begin) / p.duration, 0.0, 1.0);
  const double dv = p.v1 - p.v0;
  const double s = p.s_begin + p.duration * (p.v0 * x + dv * SepticStep::Integral(x));
  const double s_rate = p.v0 + dv * SepticStep::Value(x);
  const double s_accel = dv * SepticStep::D1(x) / p.duration;
  const PathPoint pp = PathAt(drive, s);
  const Eigen::Vector2d tangent(std::cos(pp.yaw), std::sin(pp.yaw));
  const Eigen::Vector2d normal(-tangent.y(), tangent.x());
  out.xy = pp.xy;
  out.v_xy = s_rate * tangent;
  out.a_xy = s_accel * tangent + s_rate * s_rate * pp.yaw_d1 * normal;
  out.yaw = pp.yaw;
  out.yaw_rate = pp.yaw_d1 * s_rate;
  out.yaw_accel = pp.yaw_d2 * s_rate * s_rate + pp.yaw_d1 * s_accel;
  out.u += std::clamp(s, 0.0, drive.length);
  out.u_rate = s_rate;
  out.u_accel = s_accel;
  return out;
}

Eigen::Vector3d RoverTrajectory::PoseAtU(double u) const {
  u = std::clamp(u, 0.0, u_total_);
  const auto it =
      std::upper_bound(u_segments_.begin(), u_segments_.end(), u, [this](double value, int index) {
        return value < segments_[static_cast<std::size_t>(index)].u_begin;
      });
  const Segment& seg =
      segments_[static_cast<std::size_t>(it == u_segments_.begin() ? *it : *(it - 1))];
  const double local = std::clamp(u - seg.u_begin, 0.0, seg.u_length);
  if (seg.kind == SegmentKind::kTurn) {
    // u and yaw both follow S on a turn, so yaw is linear in u.
    return {seg.xy.x(), seg.xy.y(), seg.yaw_begin + seg.delta_yaw * local / seg.u_length};
  }
  const PathPoint pp = PathAt(drives_[static_cast<std::size_t>(seg.drive)], local);
  return {pp.xy.x(), pp.xy.y(), pp.yaw};
}

RoverTrajectory::Contact RoverTrajectory::ContactAt(const Heightfield& terrain,
                                                    const Eigen::Vector3d& pose) const {
  const Eigen::Vector2d xy = pose.head<2>();
  const Eigen::Vector2d forward(std::cos(pose.z()), std::sin(pose.z()));
  const Eigen::Vector2d left(-forward.y(), forward.x());
  const double r = options_.wheel_radius_m;
  std::array<double, kWheelCount> h{};
  for (int w = 0; w < kWheelCount; ++w) {
    const Eigen::Vector3d c = WheelCenterBody(w);
    const Eigen::Vector2d center = xy + c.x() * forward + c.y() * left;
    // The wheel rests on the highest terrain point under its footprint, seen
    // through its rim: a point at distance xi ahead of the axle lifts the
    // wheel by h(xi) + sqrt(r^2 - xi^2) - r.
    double best = -std::numeric_limits<double>::infinity();
    constexpr int kAlong = 9;
    for (int a = 0; a < kAlong; ++a) {
      const double xi = 0.8 * r * (2.0 * a / (kAlong - 1) - 1.0);
      const double rim = std::sqrt(r * r - xi * xi) - r;
      for (int b = -1; b <= 1; ++b) {
        const Eigen::Vector2d p = center + xi * forward + 0.5 * b * options_.wheel_width_m * left;
        best = std::max(best, terrain.HeightAt(p.x(), p.y()) + rim);
      }
    }
    h[static_cast<std::size_t>(w)] = best;
  }
  const double slope_forward = (h[kFrontLeft] + h[kFrontRight] - h[kRearLeft] - h[kRearRight]) /
                               (2.0 * options_.wheelbase_m);
  const double slope_left =
      (h[kFrontLeft] + h[kRearLeft] - h[kFrontRight] - h[kRearRight]) / (2.0 * options_.track_m);
  Contact out;
  out.z_m = 0.25 * (h[0] + h[1] + h[2] + h[3]) + options_.body_height_m;
  out.pitch_rad = -std::atan(slope_forward);
  out.roll_rad = std::atan(slope_left / std::sqrt(1.0 + slope_forward * slope_forward));
  return out;
}

void RoverTrajectory::SampleTerrain(const Heightfield& terrain) {
  const double du = options_.terrain_sample_spacing_m;
  const auto count = static_cast<std::size_t>(std::ceil(u_total_ / du)) + 1;
  std::vector<double> z(count), roll(count), pitch(count);
  for (std::size_t j = 0; j < count; ++j) {
    const Contact c = ContactAt(terrain, PoseAtU(static_cast<double>(j) * du));
    z[j] = c.z_m;
    roll[j] = c.roll_rad;
    pitch[j] = c.pitch_rad;
  }
  z_m_ = QuinticBSpline(std::move(z), du);
  roll_rad_ = QuinticBSpline(std::move(roll), du);
  pitch_rad_ = QuinticBSpline(std::move(pitch), du);
}

TrajectorySample RoverTrajectory::Evaluate(double t_s) const {
  const PlanarState ps = EvaluatePlanar(t_s);
  const TimeJet z = Chain(z_m_.Evaluate(ps.u), ps.u_rate, ps.u_accel);
  const TimeJet roll = Chain(roll_rad_.Evaluate(ps.u), ps.u_rate, ps.u_accel);
  const TimeJet pitch = Chain(pitch_rad_.Evaluate(ps.u), ps.u_rate, ps.u_accel);

  TrajectorySample out;
  out.t_s = std::clamp(t_s, 0.0, duration_s_);
  out.p_world_body = {ps.xy.x(), ps.xy.y(), z.value};
  out.v_world_m_s = {ps.v_xy.x(), ps.v_xy.y(), z.rate};
  out.a_world_m_s2 = {ps.a_xy.x(), ps.a_xy.y(), z.accel};
  // Built from half-angle quaternions so the sign is continuous in time.
  out.q_world_body = Eigen::AngleAxisd(ps.yaw, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(pitch.value, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(roll.value, Eigen::Vector3d::UnitX());

  EulerZyxJet euler;
  euler.roll = roll.value;
  euler.pitch = pitch.value;
  euler.yaw = ps.yaw;
  euler.roll_rate = roll.rate;
  euler.pitch_rate = pitch.rate;
  euler.yaw_rate = ps.yaw_rate;
  euler.roll_accel = roll.accel;
  euler.pitch_accel = pitch.accel;
  euler.yaw_accel = ps.yaw_accel;
  out.omega_body_rad_s = BodyRates_rad_s(euler);
  out.alpha_body_rad_s2 = BodyAngularAcceleration_rad_s2(euler);
  out.specific_force_body_m_s2 =
      out.q_world_body.conjugate() * (out.a_world_m_s2 - GravityWorld_m_s2());
  return out;
}

MotionPhase RoverTrajectory::PhaseAt(double t_s) const {
  const double t = std::clamp(t_s, 0.0, duration_s_);
  const auto it =
      std::upper_bound(phases_.begin(), phases_.end(), t,
                       [](double value, const PhaseInterval& p) { return value < p.begin_s; });
  return (it == phases_.begin() ? *it : *(it - 1)).phase;
}

std::vector<double> RoverTrajectory::KnotTimes_s() const {
  std::vector<double> knots;
  for (const Segment& seg : segments_) {
    knots.push_back(seg.t_begin);
    if (seg.kind != SegmentKind::kDrive) continue;
    const Drive& drive = drives_[static_cast<std::size_t>(seg.drive)];
    for (const SpeedPiece& p : drive.speed) knots.push_back(seg.t_begin + p.t_begin);
    // Path-element joints: invert the monotonic s(t) by bisection.
    for (const PathElement& e : drive.path) {
      if (e.s_begin <= 0.0) continue;
      double lo = seg.t_begin, hi = seg.t_begin + seg.duration;
      for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        (EvaluatePlanar(mid).u - seg.u_begin < e.s_begin ? lo : hi) = mid;
      }
      knots.push_back(0.5 * (lo + hi));
    }
  }
  knots.push_back(duration_s_);
  std::sort(knots.begin(), knots.end());
  return knots;
}

Eigen::Vector3d RoverTrajectory::WheelCenterBody(int wheel) const {
  const bool front = wheel == kFrontLeft || wheel == kFrontRight;
  const bool left = wheel == kFrontLeft || wheel == kRearLeft;
  return {(front ? 0.5 : -0.5) * options_.wheelbase_m, (left ? 0.5 : -0.5) * options_.track_m,
          options_.wheel_radius_m - options_.body_height_m};
}

std::array<double, kWheelCount> RoverTrajectory::WheelRollingSpeeds_m_s(
    const TrajectorySample& sample, double yaw_scrub_factor) const {
  const Eigen::Vector3d v_body = sample.q_world_body.conjugate() * sample.v_world_m_s;
  const Eigen::Vector3d& w = sample.omega_body_rad_s;
  std::array<double, kWheelCount> out{};
  for (int i = 0; i < kWheelCount; ++i) {
    const Eigen::Vector3d r = WheelCenterBody(i);
    out[static_cast<std::size_t>(i)] =
        v_body.x() + w.y() * r.z() - yaw_scrub_factor * w.z() * r.y();
  }
  return out;
}

void MovingCarrierPoses(const std::vector<const RoverTrajectory*>& trajectories, std::size_t hidden,
                        double t_s, std::vector<Eigen::Isometry3d>* T_world_carriers) {
  T_world_carriers->resize(trajectories.size());
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    const RoverTrajectory& t = *trajectories[i];
    (*T_world_carriers)[i] =
        PoseOf(t.Evaluate(t_s)) * Eigen::Translation3d(0, 0, -t.options().body_height_m);
    if (i == hidden) (*T_world_carriers)[i].translation().z() -= 1.0e4;
  }
}

}  // namespace rover::sim
