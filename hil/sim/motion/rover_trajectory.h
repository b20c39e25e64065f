#ifndef ROVER_HIL_SIM_MOTION_ROVER_TRAJECTORY_H_
#define ROVER_HIL_SIM_MOTION_ROVER_TRAJECTORY_H_

// The simulated rover's motion over the terrain, with analytic derivatives.
//
// Plan in the plane. A Route becomes a sequence of pieces in time:
//  * holds (standing still);
//  * turns on the spot: x, y fixed, yaw = yaw0 + dyaw * S(t / T), with S the
//    septic smoothstep (zero rate, acceleration and jerk at both ends);
//  * drives: a path of straight lines and rounded corners (heading follows
//    S over a blend length, so curvature is continuous and zero at both ends),
//    traversed with a speed profile of cruise pieces joined by S-shaped
//    ramps (continuous acceleration and jerk; ramps limited in acceleration
//    and jerk). Drives start and end at rest.
// Position, velocity, acceleration, yaw rate and yaw acceleration are closed
// forms (a rounded corner's position is a 16-point Gauss-Legendre quadrature
// of its heading, exact to rounding) and C^2 across every junction, because
// each piece starts and ends with matching values, first and second
// derivatives (zero at rest, constant speed and zero curvature otherwise).
//
// Terrain contact. The raw bilinear heightfield is only C^0, so heights,
// roll and pitch are not taken from it at the evaluation time. Instead a
// motion parameter u (metres) advances with the wheels' travel: it grows by
// the arc length on drives and by r_c * |dyaw| on turns (r_c = half the
// wheel-base diagonal, the wheels' travel when turning on the spot), and it
// stands still during holds. The planar pose is a pure function of u. At
// u = 0, du, 2 du, ... (du = terrain_sample_spacing_m) the four wheel
// contacts are found (each wheel rests on the highest point of the terrain
// under its footprint, through its circular rim profile), and
//   z     = mean contact height + body_height_m,
//   pitch = -atan(s_f),  roll = atan(s_l / sqrt(1 + s_f^2)),
// with s_f, s_l the forward and leftward slopes of the least-squares plane
// through the contacts (roll and pitch are the Z-Y-X Euler angles of the
// body whose x and y axes lie in that plane). Each of z, roll, pitch is a
// uniform quintic B-spline in u with the samples as control points: C^4 in
// u, and a mild low-pass like a suspension's. Since u(t) is C^2 (C^4 on
// drives) and constant during holds, z(u(t)), roll(u(t)), pitch(u(t)) are C^2
// in time and exactly still while the rover stands. Attitude is
// R = Rz(yaw) Ry(pitch) Rx(roll); body rates and their derivatives follow
// from the Euler-angle rates exactly.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/config/config.h"
#include "hil/sim/motion/route.h"
#include "hil/sim/motion/smooth_profiles.h"
#include "hil/sim/motion/trajectory_sample.h"
#include "hil/sim/world/world.h"

namespace rover::sim {

/// Wheel order used everywhere in the simulator; it is also the CANopen node
/// id minus one (node 1 front-left, 2 front-right, 3 rear-left, 4 rear-right).
enum WheelIndex : int { kFrontLeft = 0, kFrontRight = 1, kRearLeft = 2, kRearRight = 3 };
inline constexpr int kWheelCount = 4;

/// Rover geometry and motion limits.
struct RoverTrajectoryOptions {
  double wheelbase_m = 0.6;  ///< front to rear axle
  double track_m = 0.5;      ///< left to right wheel centre
  double wheel_radius_m = 0.1;
  double wheel_width_m = 0.1;
  double body_height_m = 0.35;  ///< IMU (body origin) above the mean wheel contact
  double max_accel_m_s2 = 0.25;
  double max_jerk_m_s3 = 0.5;
  double max_yaw_rate_rad_s = 0.4;
  double max_yaw_accel_rad_s2 = 0.4;
  /// Heading changes above this (or any at a stop) are turns on the spot;
  /// smaller ones are rounded off while driving.
  double turn_in_place_threshold_rad = 0.35;
  double corner_blend_length_m = 1.0;  ///< arc length of a rounded corner (shortened on short legs)
  double terrain_sample_spacing_m = 0.05;

  /// Reads every key (all required) with range checks.
  static RoverTrajectoryOptions Load(const ConfigNode& node);
};

/// What the rover is doing at a given time.
enum class MotionPhase { kHold, kTurnInPlace, kAccelerate, kCruise, kDecelerate };

/// A time interval of one phase. For kCruise, speed_m_s is the ground-track
/// (horizontal) cruise speed; otherwise 0.
struct PhaseInterval {
  MotionPhase phase = MotionPhase::kHold;
  double begin_s = 0.0;
  double end_s = 0.0;
  double speed_m_s = 0.0;
};

class RoverTrajectory : public MotionSource {
 public:
  /// Plans `route` (validated; throws std::invalid_argument if it cannot be
  /// driven within the limits, e.g. a leg too short for its speed changes)
  /// and samples `terrain` along it. The terrain is only read here.
  RoverTrajectory(const Route& route, const Heightfield& terrain,
                  const RoverTrajectoryOptions& options = {});

  /// Exact state at t_s; clamped to [0, duration_s()].
  TrajectorySample Evaluate(double t_s) const override;

  double duration_s() const { return duration_s_; }
  /// Ground-track (horizontal) length of the drives.
  double distance_m() const { return distance_m_; }
  const RoverTrajectoryOptions& options() const { return options_; }

  /// Phase intervals covering [0, duration_s()] in order.
  const std::vector<PhaseInterval>& phases() const { return phases_; }
  MotionPhase PhaseAt(double t_s) const;
  /// Times where one analytic piece meets the next (for continuity checks).
  std::vector<double> KnotTimes_s() const;

  /// Centre of a wheel in the body frame.
  Eigen::Vector3d WheelCenterBody(int wheel) const;
  /// Ideal rolling speed of each wheel (order of WheelIndex): the velocity of
  /// the wheel centre along the body x axis, v_x + (omega x r_wheel)_x. On a
  /// skid-steered rover the sideways part is scrubbed, not rolled.
  /// `yaw_scrub_factor` (>= 1) scales the yaw-rate part: skid-steered wheels
  /// must turn faster than the geometric ideal to yaw the rover.
  std::array<double, kWheelCount> WheelRollingSpeeds_m_s(const TrajectorySample& sample,
                                                         double yaw_scrub_factor = 1.0) const;

  /// Terrain-derived height, roll and pitch as functions of the motion
  /// parameter (exposed for tests and plots).
  const QuinticBSpline& z_profile() const { return z_m_; }
  const QuinticBSpline& roll_profile() const { return roll_rad_; }
  const QuinticBSpline& pitch_profile() const { return pitch_rad_; }

  /// Planar state with the motion parameter u and its derivatives.
  struct PlanarState {
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();
    Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
    Eigen::Vector2d a_xy = Eigen::Vector2d::Zero();
    double yaw = 0.0, yaw_rate = 0.0, yaw_accel = 0.0;
    double u = 0.0, u_rate = 0.0, u_accel = 0.0;
  };
  PlanarState EvaluatePlanar(double t_s) const;

 private:
  // A geometric piece of a drive, parametrised by arc length s.
  struct PathElement {
    double s_begin = 0.0;
    double length = 0.0;
    Eigen::Vector2d start_xy = Eigen::Vector2d::Zero();
    double start_yaw = 0.0;
    double delta_yaw = 0.0;  // 0: straight
  };
  // A piece of a drive's speed profile (a ramp if v0 != v1).
  struct SpeedPiece {
    double t_begin = 0.0;
    double duration = 0.0;
    double s_begin = 0.0;
    double v0 = 0.0, v1 = 0.0;
  };
  struct Drive {
    std::vector<PathElement> path;
    std::vector<SpeedPiece> speed;
    double length = 0.0;
    double duration = 0.0;
  };
  enum class SegmentKind { kHold, kTurn, kDrive };
  struct Segment {
    SegmentKind kind = SegmentKind::kHold;
    double t_begin = 0.0;
    double duration = 0.0;
    double u_begin = 0.0;
    double u_length = 0.0;
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // hold, turn
    double yaw_begin = 0.0;                        // hold, turn
    double delta_yaw = 0.0;                        // turn
    int drive = -1;                                // drive
  };
  struct PathPoint {
    Eigen::Vector2d xy;
    double yaw, yaw_d1, yaw_d2;  // derivatives with respect to s
  };
  struct Contact {
    double z_m, roll_rad, pitch_rad;
  };

  void Plan(const Route& route);
  double AddDrive(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& speeds,
                  double yaw, int first_waypoint);
  void AddSegment(Segment segment);
  void SampleTerrain(const Heightfield& terrain);
  PathPoint PathAt(const Drive& drive, double s) const;
  Eigen::Vector3d PoseAtU(double u) const;  // x, y, yaw
  Contact ContactAt(const Heightfield& terrain, const Eigen::Vector3d& pose) const;
  double TurnDuration(double delta_yaw) const;
  double RampDuration(double delta_v) const;

  RoverTrajectoryOptions options_;
  std::vector<Segment> segments_;
  std::vector<int> u_segments_;  // segments that advance u (turns, drives)
  std::vector<Drive> drives_;
  std::vector<PhaseInterval> phases_;
  double duration_s_ = 0.0;
  double distance_m_ = 0.0;
  double u_total_ = 0.0;
  double turn_radius_m_ = 0.0;  // wheel travel per radian of turning on the spot
  QuinticBSpline z_m_, roll_rad_, pitch_rad_;
};

/// No carrier is hidden (see MovingCarrierPoses).
inline constexpr std::size_t kNoHiddenCarrier = static_cast<std::size_t>(-1);

/// World poses T_world_carrier of moving tag carriers at `t_s`, one per
/// trajectory: a carrier's origin sits on its wheels' ground plane,
/// body_height_m below its body (IMU) frame. Carrier `hidden` is the viewing
/// rover itself: it is put far below the terrain so its camera never sees
/// its own body from inside.
void MovingCarrierPoses(const std::vector<const RoverTrajectory*>& trajectories, std::size_t hidden,
                        double t_s, std::vector<Eigen::Isometry3d>* T_world_carriers);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MOTION_ROVER_TRAJECTORY_H_
