#include "hil/sim/imu_mission.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <thread>
#include <vector>

#include "core/log/flight/flight_log.h"
#include "core/log/msgs/all_msgs.h"
#include "core/stats/percentile.h"
#include "core/time/posix_time.h"
#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

using log::geometry_msgs::Quaternion;
using log::geometry_msgs::Vector3;

Vector3 ToVector3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

bool TrySetFifoPriority(int priority) {
  if (priority <= 0) return false;
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

log::sensor_msgs::Imu MakeImuMessage(const drivers::ImuSample& m, const ImuModelOptions& imu) {
  log::sensor_msgs::Imu msg;
  msg.header.stamp = log::ToRosTime(m.stamp);
  msg.header.frame_id = "body";
  // No orientation estimate: ROS marks that with covariance[0] = -1.
  msg.orientation_covariance[0] = -1.0;
  msg.angular_velocity = ToVector3(m.angular_velocity_rad_s);
  msg.linear_acceleration = ToVector3(m.linear_acceleration_m_s2);
  // Discrete white-noise variance of the densities at the sample rate.
  const double gyro_var = std::pow(imu.gyro.noise_density, 2) * imu.rate_hz;
  const double accel_var = std::pow(imu.accel.noise_density, 2) * imu.rate_hz;
  for (int i = 0; i < 3; ++i) {
    msg.angular_velocity_covariance[static_cast<std::size_t>(4 * i)] = gyro_var;
    msg.linear_acceleration_covariance[static_cast<std::size_t>(4 * i)] = accel_var;
  }
  return msg;
}

log::nav_msgs::Odometry MakeGroundTruth(Time stamp, const TrajectorySample& s) {
  log::nav_msgs::Odometry msg;
  msg.header.stamp = log::ToRosTime(stamp);
  msg.header.frame_id = "world";
  msg.child_frame_id = "body";
  msg.pose.pose.position = {s.p_world_body.x(), s.p_world_body.y(), s.p_world_body.z()};
  msg.pose.pose.orientation =
      Quaternion{s.q_world_body.x(), s.q_world_body.y(), s.q_world_body.z(), s.q_world_body.w()};
  // Twist is expressed in the child frame (body), as nav_msgs/Odometry specifies.
  const Eigen::Vector3d v_body = s.q_world_body.conjugate() * s.v_world_m_s;
  msg.twist.twist.linear = ToVector3(v_body);
  msg.twist.twist.angular = ToVector3(s.omega_body_rad_s);
  return msg;
}

// Enough survey laps to fill the mission: one lap is planned first to learn
// its duration.
RoverTrajectory PlanMission(const ImuMissionOptions& options, const Heightfield& terrain) {
  const Eigen::Vector2d center = Eigen::Vector2d::Zero();
  const Route lap = MakeSurveyLoopRoute(center, options.loop_size_x_m, options.loop_size_y_m, 1);
  const double lap_s = RoverTrajectory(lap, terrain, options.motion).duration_s() -
                       lap.start_hold_s - lap.end_hold_s;
  const int laps = std::max(1, static_cast<int>(std::ceil(options.duration_s / lap_s)));
  return RoverTrajectory(
      MakeSurveyLoopRoute(center, options.loop_size_x_m, options.loop_size_y_m, laps), terrain,
      options.motion);
}

}  // namespace

std::string DefaultImuConfigPath() { return std::string(ROVER_HIL_CONFIG_DIR) + "/imu_mti10.yaml"; }

ImuMissionResult RunImuMission(const ImuMissionOptions& options, std::ostream& status) {
  ImuMissionResult result;
  log::FlightLogOptions log_options;
  log_options.mcap.compression = options.compression;
  log_options.mcap.zstd_level = options.zstd_level;
  log::FlightLog flight_log(log_options);
  flight_log.Open(options.output_path);
  auto* imu_channel = flight_log.AddChannel<log::sensor_msgs::Imu>("/imu");
  auto* truth_channel = flight_log.AddChannel<log::nav_msgs::Odometry>("/sim/ground_truth");
  const double rate_hz = options.imu.rate_hz;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", rate_hz);
  flight_log.WriteMetadata("mission", {{"scenario", "imu-terrain-loop"},
                                       {"imu_model", options.imu.model},
                                       {"imu_rate_hz", buf},
                                       {"seed", std::to_string(options.imu.seed)},
                                       {"terrain_seed", std::to_string(options.terrain_seed)}});

  // A gentle site without obstacles: the survey loop drives straight over it.
  WorldOptions world_options;
  world_options.size_m = options.terrain_size_m;
  world_options.max_slope_deg = 12.0;
  world_options.rock_count = 0;
  world_options.crater_count = 0;
  world_options.landmark_post_count = 0;
  const World world = World::Generate(world_options, options.terrain_seed);
  const RoverTrajectory trajectory = PlanMission(options, world.terrain);

  const auto samples = static_cast<uint64_t>(std::llround(options.duration_s * rate_hz));
  const auto truth_every = std::max<uint64_t>(
      1, static_cast<uint64_t>(std::llround(rate_hz / options.ground_truth_rate_hz)));
  // Preallocated so the loop itself never allocates.
  std::vector<double> log_cost_ns(samples), lateness_us(options.lockstep ? 0 : samples);
  std::atomic<uint64_t> done{0};
  std::atomic<bool> realtime{false};
  double distance_m = 0.0;

  flight_log.Start();
  const Time wall_start = Time::Now();
  const Time t0 = wall_start + Duration::Milliseconds(10);
  ImuModel imu(options.imu, t0);
  std::thread imu_thread([&] {
    realtime.store(TrySetFifoPriority(options.imu_thread_priority));
    Eigen::Vector2d last_xy = trajectory.Evaluate(0.0).p_world_body.head<2>();
    for (uint64_t k = 0; k < samples; ++k) {
      // The sample (and its jittered stamp) is computed ahead, then released
      // at its stamp, as a device would deliver it.
      TrajectorySample truth;
      const drivers::ImuSample m = imu.Next(trajectory, &truth);
      const Time stamp = m.stamp;
      if (!options.lockstep) {
        SleepUntil(stamp);
        lateness_us[k] = (Time::Now() - stamp).ToMicroseconds();
      }
      distance_m += (truth.p_world_body.head<2>() - last_xy).norm();
      last_xy = truth.p_world_body.head<2>();
      const auto msg = MakeImuMessage(m, options.imu);
      const Time before = Time::Now();
      imu_channel->Log(stamp, msg);
      log_cost_ns[k] = static_cast<double>((Time::Now() - before).nanoseconds());
      if (k % truth_every == 0) truth_channel->Log(stamp, MakeGroundTruth(stamp, truth));
      done.store(k + 1, std::memory_order_relaxed);
      if (options.lockstep && (k & 15) == 15) {
        // Lockstep has no clock to wait for; yield so the writer keeps up.
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    }
  });

  const bool tty = options.status_in_place;
  double next_print_s = 1.0;
  while (done.load() < samples) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const double elapsed = (Time::Now() - wall_start).ToSeconds();
    if (elapsed < next_print_s && done.load() < samples) continue;
    next_print_s = elapsed + 1.0;
    const log::FlightLogStats s = flight_log.stats();
    char line[200];
    std::snprintf(
        line, sizeof line,
        "t=%6.1f s  imu %7llu/%llu  logged %8llu  written %8llu  dropped %llu  log %s", elapsed,
        static_cast<unsigned long long>(done.load()), static_cast<unsigned long long>(samples),
        static_cast<unsigned long long>(s.logged), static_cast<unsigned long long>(s.written),
        static_cast<unsigned long long>(s.dropped),
        std::to_string(s.mcap.bytes_written / 1024).append(" KiB").c_str());
    status << (tty ? "\r" : "") << line << (tty ? "" : "\n") << std::flush;
  }
  imu_thread.join();
  if (tty) status << "\n";
  flight_log.Stop();

  const log::FlightLogStats s = flight_log.stats();
  result.imu_samples = samples;
  result.records_logged = s.logged;
  result.records_written = s.written;
  result.records_dropped = s.dropped;
  result.file_bytes = s.mcap.bytes_written;
  result.chunks = s.mcap.chunks;
  result.error = s.error;
  result.wall_time_s = (Time::Now() - wall_start).ToSeconds();
  result.distance_m = distance_m;
  result.realtime_priority = realtime.load();
  result.log_call_ns_p50 = stats::Percentile(log_cost_ns, 50.0);
  result.log_call_ns_p99 = stats::Percentile(log_cost_ns, 99.0);
  result.log_call_ns_max =
      log_cost_ns.empty() ? 0.0 : *std::max_element(log_cost_ns.begin(), log_cost_ns.end());
  result.tick_lateness_us_p99 = stats::Percentile(lateness_us, 99.0);
  return result;
}

void PrintImuMissionSummary(const ImuMissionOptions& options, const ImuMissionResult& r,
                            std::ostream& out) {
  char line[256];
  out << "mission summary (imu-terrain-loop)\n";
  std::snprintf(line, sizeof line, "  simulated:        %.1f s at %.0f Hz, %.1f m driven\n",
                options.duration_s, options.imu.rate_hz, r.distance_m);
  out << line;
  std::snprintf(line, sizeof line, "  imu model:        %s\n", options.imu.model.c_str());
  out << line;
  std::snprintf(line, sizeof line, "  imu thread:       %s\n",
                r.realtime_priority ? "SCHED_FIFO" : "normal priority (no real-time privilege)");
  out << line;
  std::snprintf(line, sizeof line, "  records:          %llu logged, %llu written, %llu dropped\n",
                static_cast<unsigned long long>(r.records_logged),
                static_cast<unsigned long long>(r.records_written),
                static_cast<unsigned long long>(r.records_dropped));
  out << line;
  std::snprintf(line, sizeof line, "  log file:         %s, %.1f KiB in %llu chunks\n",
                options.output_path.c_str(), static_cast<double>(r.file_bytes) / 1024.0,
                static_cast<unsigned long long>(r.chunks));
  out << line;
  std::snprintf(
      line, sizeof line,
      "  Log() cost:       p50 %.0f ns, p99 %.0f ns, max %.0f ns (cold cache, one call per "
      "tick; steady state: ./rover bench)\n",
      r.log_call_ns_p50, r.log_call_ns_p99, r.log_call_ns_max);
  out << line;
  if (!options.lockstep) {
    std::snprintf(line, sizeof line, "  loop lateness:    p99 %.1f us\n", r.tick_lateness_us_p99);
    out << line;
  }
  std::snprintf(line, sizeof line, "  wall time:        %.1f s\n", r.wall_time_s);
  out << line;
  out << "  result:           ";
  if (!r.error.empty()) {
    out << "FAILED: " << r.error << "\n";
  } else if (r.records_dropped > 0) {
    out << "DEGRADED: " << r.records_dropped << " records dropped (see /rover/log_health)\n";
  } else {
    out << "OK\n";
  }
}

}  // namespace rover::sim
