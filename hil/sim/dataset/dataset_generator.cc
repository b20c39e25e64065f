#include "hil/sim/dataset/dataset_generator.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "hil/sim/dataset/euroc_writer.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/scenario/team_rovers.h"
#include "hil/sim/seed.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/sensors/imu_model.h"
#include "hil/sim/sensors/wheel_odometry_model.h"

namespace rover::sim {
namespace {

double SecondsSince(Time start) { return (Time::Now() - start).ToSeconds(); }

// Everything one rover records, into its own EuRoC-layout folder.
// `team.trajectories[self]` is the recording rover; its own tag carrier is
// hidden from its view.
struct RoverContext {
  const Scenario& scenario;
  const World& world;
  const TeamRovers& team;
  std::size_t self;
};

void GenerateRoverData(const RoverContext& c, const GenerateOptions& options,
                       const std::string& out_dir, double duration_s, GenerateResult* result) {
  EurocWriter writer(out_dir);
  const RoverTrajectory& trajectory = c.team.trajectories[c.self];
  const Time t0 = kDatasetStartTime;
  const Time end = t0 + Duration::FromSeconds(duration_s);

  ImuModelOptions imu_options = c.scenario.imu;
  imu_options.seed = RoverImuSeed(c.scenario, options.seed, c.self);
  writer.WriteImuCalibration(ImuCalibrationOf(imu_options));
  const StereoCameraOptions& camera = c.scenario.camera;
  writer.WriteCameraCalibration(0, CameraModelOf(camera, camera.T_body_cam0));
  writer.WriteCameraCalibration(1, CameraModelOf(camera, camera.T_body_cam1()));

  // IMU, its data-ready edges and the ground truth (with the IMU's true
  // biases) come from one pass over the IMU samples.
  const GpioEdgeModel gpio(c.scenario.gpio, t0);
  ImuModel imu(imu_options, t0);
  const Duration gt_period = Duration::FromSeconds(1.0 / c.scenario.ground_truth_rate_hz);
  Time next_gt = t0;
  double driven_m = 0;
  Eigen::Vector2d last_xy = trajectory.Evaluate(0).p_world_body.head<2>();
  for (;;) {
    const drivers::ImuSample sample = imu.Next(trajectory);
    if (sample.stamp >= end) break;
    writer.AddImu(sample);
    ++result->imu_samples;
    for (const drivers::GpioEdge& edge : gpio.ImuDataReadyEdges(sample.stamp)) {
      writer.AddGpioEdge(edge, "imu_data_ready");
      ++result->gpio_edges;
    }
    while (next_gt <= sample.stamp) {
      const TrajectorySample gt = trajectory.Evaluate((next_gt - t0).ToSeconds());
      writer.AddGroundTruth({next_gt, gt.p_world_body, gt.q_world_body, gt.v_world_m_s,
                             imu.gyro_bias_rad_s(), imu.accel_bias_m_s2()});
      driven_m += (gt.p_world_body.head<2>() - last_xy).norm();
      last_xy = gt.p_world_body.head<2>();
      next_gt += gt_period;
    }
  }
  if (c.self == 0) result->distance_m = driven_m;

  // Wheel drives on the CAN bus.
  WheelOdometryModelOptions wheel_options;
  if (!c.scenario.wheels_config.empty()) {
    wheel_options = WheelOdometryModelOptions::LoadFile(c.scenario.wheels_config);
  }
  writer.WriteWheelCalibration(WheelCalibrationOf(trajectory, wheel_options));
  WheelOdometryModel wheels(wheel_options, trajectory, c.world.terrain, t0);
  std::vector<drivers::CanFrame> frames;
  std::vector<WheelSyncState> states;
  wheels.Advance(end, &frames, &states);
  for (const drivers::CanFrame& f : frames) writer.AddCanFrame(f);
  for (const WheelSyncState& s : states) {
    writer.AddWheel({s.stamp, s.angular_velocity_rad_s, s.encoder_ticks});
  }
  result->can_frames += frames.size();

  // Stereo pairs at the trigger edges.
  for (const drivers::GpioEdge& edge : gpio.CameraTriggerEdges(t0, end)) {
    writer.AddGpioEdge(edge, "camera_trigger");
    ++result->gpio_edges;
  }
  const std::vector<Time> triggers = gpio.CameraTriggerTimes(t0, end);
  StereoRenderer renderer(c.world, camera);
  result->gl_renderer = renderer.gl_renderer();
  RenderedStereoFrame frame;
  const std::vector<const RoverTrajectory*> carriers = c.team.CarrierTrajectories();
  const std::size_t hidden = c.team.HiddenCarrier(c.self);
  std::vector<Eigen::Isometry3d> T_world_carriers;
  for (std::size_t k = 0; k < triggers.size(); ++k) {
    const double t_s = (triggers[k] - t0).ToSeconds();
    MovingCarrierPoses(carriers, hidden, t_s, &T_world_carriers);
    const Time render_start = Time::Now();
    renderer.Render(PoseOf(trajectory.Evaluate(t_s)), T_world_carriers, k, &frame);
    const Time write_start = Time::Now();
    result->render_time_s += (write_start - render_start).ToSeconds();
    writer.AddStereo(triggers[k], frame.cam0, frame.cam1);
    writer.AddDepth(triggers[k], frame.depth0_m);
    std::size_t moving = 0;
    for (const TagCarrier& carrier : c.world.carriers) {
      if (carrier.is_static) continue;
      if (moving != hidden) {
        for (const TagMarker& tag : carrier.tags) {
          writer.AddTagPose(triggers[k], carrier.name, tag.id,
                            T_world_carriers[moving] * tag.T_carrier_tag);
        }
      }
      ++moving;
    }
    result->write_time_s += SecondsSince(write_start);
    ++result->stereo_frames;
    if (options.progress) {
      const double done = static_cast<double>(c.self) +
                          static_cast<double>(k + 1) / static_cast<double>(triggers.size());
      options.progress(done / static_cast<double>(c.team.size()), t_s);
    }
  }
  writer.Close();
}

}  // namespace

GenerateResult GenerateDataset(const Scenario& scenario, const GenerateOptions& options) {
  const Time wall_start = Time::Now();
  GenerateResult result;
  const std::filesystem::path out(options.out_dir);
  if (std::filesystem::exists(out / "mav0")) {
    throw drivers::DatasetError((out / "mav0").string() +
                                ": already exists; choose an empty output folder");
  }
  const World world = World::Generate(scenario.world, options.seed);
  ExportWorldGroundTruth(world, (out / "world").string());
  result.world_time_s = SecondsSince(wall_start);

  // Rover 0 records the main dataset; other rovers drive their own routes and
  // record theirs into <out>/<carrier name>/.
  const TeamRovers team = MakeTeamRovers(scenario, world);
  const double main_duration_s = team.trajectories[0].duration_s();
  const double duration_s = options.max_duration_s > 0
                                ? std::min(options.max_duration_s, main_duration_s)
                                : main_duration_s;
  result.sim_duration_s = duration_s;
  for (std::size_t self = 0; self < team.size(); ++self) {
    const RoverContext context{scenario, world, team, self};
    const std::string dir = self == 0 ? out.string() : (out / team.names[self]).string();
    GenerateRoverData(context, options, dir, duration_s, &result);
  }
  result.rover_datasets = team.size();
  result.wall_time_s = SecondsSince(wall_start);
  return result;
}

}  // namespace rover::sim
