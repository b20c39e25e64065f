#include "hil/sim/mission/sim_mission.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <ostream>
#include <thread>

#include "drivers/replay/euroc_replay.h"
#include "estimator/feed/filter_options.h"
#include "firmware/roverd/roverd_process.h"
#include "firmware/roverd/roverd_summary.h"
#include "hil/sim/dataset/dataset_generator.h"
#include "hil/sim/estimator_feed/filter_run.h"
#include "hil/sim/live/sim_camera_trigger.h"
#include "hil/sim/live/sim_can_bus.h"
#include "hil/sim/live/sim_imu_driver.h"
#include "hil/sim/live/sim_stereo_camera_driver.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/scenario/team_rovers.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;

// Latest filter output for the status line and the summary. Written on the
// IMU thread (wait-free: a sequence counter around relaxed atomic fields),
// read by the status thread.
class LatestState final : public roverd::EstimatorListener {
 public:
  void OnState(const estimator::EskfOutput& o) override {
    // Frame switches (requested by mapd) move the local frame; the error
    // against ground truth is scored in frame 0, so chain them back.
    const Eigen::Vector3d p0 = p_0_frame_ + R_0_frame_ * o.p_local_body;
    const uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    stamp_ns_.store(o.stamp.nanoseconds(), std::memory_order_relaxed);
    for (std::size_t i = 0; i < 3; ++i) {
      p_[i].store(p0[static_cast<int>(i)], std::memory_order_relaxed);
    }
    initialised_.store((o.status & estimator::kStatusNotInitialised) == 0,
                       std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);
    if ((o.status & estimator::kStatusNotInitialised) == 0 && !init_stamp_ns_) {
      init_stamp_ns_ = o.stamp.nanoseconds();  // IMU thread only until the run ends
    }
  }
  void OnFrameSwitch(const estimator::FrameSwitchRecord& r) override {
    p_0_frame_ += R_0_frame_ * r.p_old_new;
    R_0_frame_ = R_0_frame_ * Eigen::AngleAxisd(r.yaw_old_new_rad, Eigen::Vector3d::UnitZ());
    frame_switches_.fetch_add(1, std::memory_order_relaxed);
  }
  uint64_t frame_switches() const { return frame_switches_.load(std::memory_order_relaxed); }

  struct Snapshot {
    Time stamp;
    Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< in frame 0
    bool initialised = false;
  };
  Snapshot Read() const {
    Snapshot out;
    for (;;) {
      const uint64_t s0 = seq_.load(std::memory_order_acquire);
      if (s0 % 2 == 1) continue;
      out.stamp = Time::FromNanoseconds(stamp_ns_.load(std::memory_order_relaxed));
      for (std::size_t i = 0; i < 3; ++i) {
        out.p[static_cast<int>(i)] = p_[i].load(std::memory_order_relaxed);
      }
      out.initialised = initialised_.load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s0) return out;
    }
  }
  std::optional<int64_t> init_stamp_ns() const { return init_stamp_ns_; }

 private:
  std::atomic<uint64_t> seq_{0};
  std::atomic<int64_t> stamp_ns_{0};
  std::array<std::atomic<double>, 3> p_{};
  std::atomic<bool> initialised_{false};
  std::optional<int64_t> init_stamp_ns_;
  // Frame 0 <- current local frame; IMU thread only.
  Eigen::Vector3d p_0_frame_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_0_frame_ = Eigen::Matrix3d::Identity();
  std::atomic<uint64_t> frame_switches_{0};
};

// The true pose in the filter's frame 0: defined by the true position and
// yaw at the filter's initialisation (as FilterRun scores it).
Eigen::Vector3d TrueInFrame0(const RoverTrajectory& trajectory, Time start, Time init, Time t) {
  const TrajectorySample s0 = trajectory.Evaluate((init - start).ToSeconds());
  const TrajectorySample s = trajectory.Evaluate((t - start).ToSeconds());
  const Eigen::Matrix3d R0 = s0.q_world_body.toRotationMatrix();
  const double yaw0 = std::atan2(R0(1, 0), R0(0, 0));
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return Rz.transpose() * (s.p_world_body - s0.p_world_body);
}

double DistanceDriven(const RoverTrajectory& trajectory, double from_s, double to_s) {
  double d = 0.0;
  Eigen::Vector2d last = trajectory.Evaluate(from_s).p_world_body.head<2>();
  for (double t = from_s + 0.05; t <= to_s; t += 0.05) {
    const Eigen::Vector2d p = trajectory.Evaluate(t).p_world_body.head<2>();
    d += (p - last).norm();
    last = p;
  }
  return d;
}

std::string Fixed(double v, int digits) {
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

}  // namespace

MissionResult RunMission(const MissionOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  MissionResult result;
  result.scenario = options.scenario;
  result.rover = options.rover;
  const Scenario scenario =
      LoadScenario(FindScenario(DefaultScenarioDir(), options.scenario), DefaultSimConfigDir());
  CheckRoverIndex(scenario, options.rover);
  const World world = World::Generate(scenario.world, options.seed);
  // The simulated rover drives its own route; the other rovers of a team
  // scenario drive theirs in its camera's view, as in `rover-sim generate`.
  const TeamRovers team = MakeTeamRovers(scenario, world);
  const RoverTrajectory& trajectory = team.trajectories[options.rover];
  result.rover_name = team.names[options.rover];
  result.p_world_body_start_m = trajectory.Evaluate(0.0).p_world_body;
  double duration_s = trajectory.duration_s();
  if (options.max_duration_s > 0.0) duration_s = std::min(duration_s, options.max_duration_s);
  result.sim_duration_s = duration_s;
  StereoRenderer renderer(world, scenario.camera);  // slow: before the clock starts
  renderer.ReleaseThread();                         // it renders on roverd's camera thread
  // Lockstep uses the datasets' fixed time origin; in real time the sensors
  // stamp on CLOCK_MONOTONIC, as real ones do, from now on.
  const Time start = options.lockstep ? kDatasetStartTime : Time::Now();
  const Time end = start + Duration::FromSeconds(duration_s);
  // The simulated rover's sensors, seeded as `rover-sim generate` seeds them.
  ImuModelOptions imu_options = scenario.imu;
  imu_options.seed = RoverImuSeed(scenario, options.seed, options.rover);
  WheelOdometryModelOptions wheel_options;
  if (!scenario.wheels_config.empty()) {
    wheel_options = WheelOdometryModelOptions::LoadFile(scenario.wheels_config);
  }
  const drivers::ReplayClock clock(!options.lockstep, start);
  SimImuDriver imu(imu_options, trajectory, clock, start, end);
  const auto lost_at = [&](double loss_s) {
    return loss_s > 0.0 ? std::min(end, start + Duration::FromSeconds(loss_s)) : end;
  };
  SimWheelCanBus can(wheel_options, trajectory, world.terrain, clock, start,
                     lost_at(options.can_loss_at_s));
  const GpioEdgeModel triggers(scenario.gpio, start);
  const std::vector<const RoverTrajectory*> carriers = team.CarrierTrajectories();
  SimStereoCameraDriver camera(renderer, trajectory, carriers, team.HiddenCarrier(options.rover),
                               triggers, clock, start, lost_at(options.camera_loss_at_s));

  roverd::RoverdOptions rover;
  rover.estimator = EskfOptionsForScenario(scenario, trajectory, wheel_options, true);
  roverd::CameraSetup head;
  head.cam0 = CameraModelOf(scenario.camera, scenario.camera.T_body_cam0);
  head.cam1 = CameraModelOf(scenario.camera, scenario.camera.T_body_cam1());
  head.vo = estimator::VoOptionsFromCalibration(scenario.camera.rate_hz);
  rover.camera = head;
  rover.lockstep = options.lockstep;
  if (options.board) roverd::ApplyBoard(*options.board, &rover);

  result.log_path = (fs::path(options.out_dir) /
                     MissionLogName(options.scenario, options.rover, result.rover_name))
                        .string();
  roverd::RoverdProcessOptions process_options;
  process_options.log_path = result.log_path;
  process_options.metadata["mission"] = {{"scenario", options.scenario},
                                         // which rover of the scenario: its ground truth is
                                         // that rover's trajectory (team_rovers.h)
                                         {"rover", std::to_string(options.rover)},
                                         {"rover_name", result.rover_name},
                                         {"seed", std::to_string(options.seed)},
                                         {"lockstep", options.lockstep ? "true" : "false"},
                                         // the simulator's time origin: ground truth is
                                         // trajectory(t - start)
                                         {"start_ns", std::to_string(start.nanoseconds())}};
  process_options.ipc_runtime_name = options.ipc_runtime_name;
  process_options.images = options.images;
  process_options.program_name = "roverd-sim";
  if (options.board) {
    process_options.lock_memory = options.board->realtime.lock_memory;
    process_options.imu_thread = options.board->threads.imu;
    process_options.roudi_wait = Duration::FromSeconds(options.board->ipc.roudi_wait_s);
    if (options.board->log_service) {
      // The board's HTTP log service serves this mission's log folder.
      process_options.log_service = *options.board->log_service;
      process_options.log_service->log_folder = options.out_dir;
    }
  }
  LatestState latest;
  SimCameraTrigger trigger(triggers, clock, start, lost_at(options.camera_loss_at_s));
  roverd::RoverdProcess process(rover, {&imu, &camera, &trigger, &can}, process_options, &latest);
  const roverd::MapdLink* mapd_link = process.mapd_link();
  result.ipc = mapd_link != nullptr;
  std::atomic<bool> done{false};
  std::thread status([&] {
    // Rates over the last status period, in simulated time.
    roverd::Roverd::LiveCounters last_counts;
    Time last_stamp = start;
    while (!done.load()) {
      for (int i = 0; i < 10 && !done.load(); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      if (done.load() || !options.status) continue;
      const LatestState::Snapshot s = latest.Read();
      const roverd::Roverd::LiveCounters counts = process.roverd().live();
      const double dt_s = (s.stamp - last_stamp).ToSeconds();
      const auto rate = [dt_s](uint64_t now_count, uint64_t then_count) {
        return dt_s > 0.0 ? Fixed(static_cast<double>(now_count - then_count) / dt_s, 0) : "-";
      };
      std::string line = "t " + Fixed((s.stamp - start).ToSeconds(), 1) + "/" +
                         Fixed(duration_s, 0) + " s  imu " +
                         rate(counts.imu_samples, last_counts.imu_samples) + " Hz  cam " +
                         rate(counts.frames, last_counts.frames) + " Hz  wheels " +
                         rate(counts.wheel_readings, last_counts.wheel_readings) + " Hz  drops " +
                         std::to_string(counts.frame_drops);
      last_counts = counts;
      last_stamp = s.stamp;
      if (s.initialised && latest.init_stamp_ns()) {
        const Eigen::Vector3d truth = TrueInFrame0(
            trajectory, start, Time::FromNanoseconds(*latest.init_stamp_ns()), s.stamp);
        line += "  p " + Fixed(s.p.x(), 2) + " " + Fixed(s.p.y(), 2) + " " + Fixed(s.p.z(), 2) +
                " m  err " + Fixed((truth - s.p).norm(), 3) + " m";
      } else {
        line += "  (filter initialising)";
      }
      if (mapd_link) {
        line += "  mapd " + std::string(mapd_link->MapdConnected() ? "up" : "DOWN") + ", frame " +
                std::to_string(latest.frame_switches());
      }
      options.status(line);
    }
  });
  roverd::RoverdProcessResult run;
  try {
    run = process.Run();
  } catch (...) {
    done.store(true);
    status.join();
    throw;
  }
  done.store(true);
  status.join();
  result.stats = run.stats;
  if (run.mapd_link) result.mapd_link = *run.mapd_link;
  result.log_service_port = run.log_service_port;
  result.frame_switches = latest.frame_switches();
  result.log_records = run.log.written;
  result.log_drops = run.log.dropped;

  const LatestState::Snapshot last = latest.Read();
  if (last.initialised && latest.init_stamp_ns()) {
    const Time init = Time::FromNanoseconds(*latest.init_stamp_ns());
    result.filter_initialised = true;
    result.filter_final_error_m =
        (TrueInFrame0(trajectory, start, init, last.stamp) - last.p).norm();
    result.distance_m =
        DistanceDriven(trajectory, (init - start).ToSeconds(), (last.stamp - start).ToSeconds());
    result.filter_final_error_pct = result.distance_m > 0.0
                                        ? 100.0 * result.filter_final_error_m / result.distance_m
                                        : std::numeric_limits<double>::quiet_NaN();
  }
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

std::string MissionLogName(const std::string& scenario, std::size_t rover,
                           const std::string& rover_name) {
  // Rover 0 keeps the single-rover name, so existing paths stay valid.
  return rover == 0 ? "mission-" + scenario + ".mcap"
                    : "mission-" + scenario + "-" + rover_name + ".mcap";
}

void PrintMissionSummary(const MissionResult& r, std::ostream& out) {
  const roverd::RoverdStats& s = r.stats;
  out << "mission " << r.scenario << ", rover " << r.rover << " (" << r.rover_name << ", from x "
      << Fixed(r.p_world_body_start_m.x(), 2) << " y " << Fixed(r.p_world_body_start_m.y(), 2)
      << " m): " << Fixed(r.sim_duration_s, 1) << " s simulated in " << Fixed(r.wall_time_s, 1)
      << " s wall time\n";
  roverd::PrintRoverdStats(
      s, r.ipc ? std::optional<roverd::MapdLinkStats>(r.mapd_link) : std::nullopt, out);
  if (r.ipc) out << "          " << r.frame_switches << " frame switches\n";
  if (r.filter_initialised) {
    out << "  error   " << Fixed(r.filter_final_error_m, 3) << " m after " << Fixed(r.distance_m, 1)
        << " m (" << Fixed(r.filter_final_error_pct, 3)
        << " % of distance), against the simulator's ground truth\n";
  } else {
    out << "  error   the filter never initialised\n";
  }
  if (r.log_service_port != 0) {
    out << "  service the board's log service listens on port " << r.log_service_port << "\n";
  }
  out << "  log     " << r.log_path << " (" << r.log_records << " records, " << r.log_drops
      << " dropped); replay it with `rover replay " << r.log_path << "`\n";
  const auto num = [](double v, int digits) { return std::isfinite(v) ? Fixed(v, digits) : "nan"; };
  out << "RESULT scenario=" << r.scenario << " distance_m=" << num(r.distance_m, 3)
      << " filter_final_err_pct="
      << (r.filter_initialised ? num(r.filter_final_error_pct, 4) : std::string("nan"))
      << " slam_final_err_pct=nan imu_drops=" << s.imu_drops << " frame_drops=" << s.frame_drops
      << " loop_latency_us_p999="
      << num(static_cast<double>(s.sample_to_estimate.count > 0 ? s.sample_to_estimate.p999_ns
                                                                : s.step_latency.p999_ns) /
                 1000.0,
             1)
      << " rover=" << r.rover << " log=" << r.log_path << "\n";
}

}  // namespace rover::sim
