#include "hil/sim/dataset/dataset_generator.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "hil/sim/dataset/euroc_writer.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/sensors/imu_model.h"
#include "hil/sim/sensors/wheel_odometry_model.h"

namespace rover::sim {
namespace {

drivers::ImuCalibration ImuCalibrationOf(const ImuModelOptions& imu) {
  drivers::ImuCalibration c;
  c.rate_hz = imu.rate_hz;
  c.gyroscope_noise_density_rad_s_sqrt_hz = imu.gyro.noise_density;
  c.gyroscope_random_walk_rad_s2_sqrt_hz = imu.gyro.bias_random_walk;
  c.accelerometer_noise_density_m_s2_sqrt_hz = imu.accel.noise_density;
  c.accelerometer_random_walk_m_s3_sqrt_hz = imu.accel.bias_random_walk;
  return c;  // the body frame is the IMU frame: T_BS = identity
}

drivers::CameraCalibration CameraCalibrationOf(const StereoCameraOptions& cam,
                                               const Eigen::Isometry3d& T_body_cam) {
  drivers::CameraCalibration c;
  c.width_px = cam.width_px;
  c.height_px = cam.height_px;
  c.rate_hz = cam.rate_hz;
  c.intrinsics = {cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px};
  c.distortion = cam.DistortionCoeffs();
  c.T_body_cam = T_body_cam;
  return c;
}

double SecondsSince(Time start) { return (Time::Now() - start).ToSeconds(); }

}  // namespace

GenerateResult GenerateDataset(const Scenario& scenario, const GenerateOptions& options) {
  const Time wall_start = Time::Now();
  GenerateResult result;
  EurocWriter writer(options.out_dir);

  const World world = World::Generate(scenario.world, options.seed);
  ExportWorldGroundTruth(world, (std::filesystem::path(options.out_dir) / "world").string());
  result.world_time_s = SecondsSince(wall_start);

  const RoverTrajectory trajectory(scenario.route, world.terrain);
  std::vector<RoverTrajectory> others;
  others.reserve(scenario.other_rover_routes.size());
  for (const Route& route : scenario.other_rover_routes) others.emplace_back(route, world.terrain);
  const double duration_s = options.max_duration_s > 0
                                ? std::min(options.max_duration_s, trajectory.duration_s())
                                : trajectory.duration_s();
  const Time t0 = kDatasetStartTime;
  const Time end = t0 + Duration::FromSeconds(duration_s);
  result.sim_duration_s = duration_s;

  ImuModelOptions imu_options = scenario.imu;
  imu_options.seed = scenario.imu.seed ^ (options.seed * 0x9E3779B97F4A7C15ULL);
  writer.WriteImuCalibration(ImuCalibrationOf(imu_options));
  const StereoCameraOptions& camera = scenario.camera;
  writer.WriteCameraCalibration(0, CameraCalibrationOf(camera, camera.T_body_cam0));
  writer.WriteCameraCalibration(1, CameraCalibrationOf(camera, camera.T_body_cam1()));

  // IMU, its data-ready edges and the ground truth (with the IMU's true
  // biases) come from one pass over the IMU samples.
  GpioEdgeOptions gpio_options;
  gpio_options.camera_rate_hz = camera.rate_hz;
  const GpioEdgeModel gpio(gpio_options, t0);
  ImuModel imu(imu_options, t0);
  const Duration gt_period = Duration::FromSeconds(1.0 / scenario.ground_truth_rate_hz);
  Time next_gt = t0;
  double driven_m = 0;
  Eigen::Vector2d last_xy = trajectory.Evaluate(0).p_world_body.head<2>();
  for (;;) {
    TrajectorySample truth;
    const drivers::ImuSample sample = imu.Next(trajectory, &truth);
    if (sample.stamp >= end) break;
    writer.AddImu(sample);
    ++result.imu_samples;
    for (const drivers::GpioEdge& edge : gpio.ImuDataReadyEdges(sample.stamp)) {
      writer.AddGpioEdge(edge, "imu_data_ready");
      ++result.gpio_edges;
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
  result.distance_m = driven_m;

  // Wheel drives on the CAN bus.
  WheelOdometryOptions wheel_options;
  if (!scenario.wheels_config.empty()) {
    wheel_options = WheelOdometryOptions::LoadFile(scenario.wheels_config);
  }
  WheelOdometryModel wheels(wheel_options, trajectory, world.terrain, t0);
  std::vector<drivers::CanFrame> frames;
  std::vector<WheelSyncState> states;
  wheels.Advance(end, &frames, &states);
  for (const drivers::CanFrame& f : frames) writer.AddCanFrame(f);
  for (const WheelSyncState& s : states) {
    writer.AddWheel({s.stamp, s.angular_velocity_rad_s, s.encoder_ticks});
  }
  result.can_frames = frames.size();

  // Stereo pairs at the trigger edges.
  for (const drivers::GpioEdge& edge : gpio.CameraTriggerEdges(t0, end)) {
    writer.AddGpioEdge(edge, "camera_trigger");
    ++result.gpio_edges;
  }
  const std::vector<Time> triggers = gpio.CameraTriggerTimes(t0, end);
  StereoRenderer renderer(world, camera);
  result.gl_renderer = renderer.gl_renderer();
  StereoFrame frame;
  std::vector<Eigen::Isometry3d> T_world_carriers;
  for (std::size_t k = 0; k < triggers.size(); ++k) {
    const double t_s = (triggers[k] - t0).ToSeconds();
    MovingCarrierPoses(others, t_s, &T_world_carriers);
    const Time render_start = Time::Now();
    renderer.Render(PoseOf(trajectory.Evaluate(t_s)), T_world_carriers, k, &frame);
    const Time write_start = Time::Now();
    result.render_time_s += (write_start - render_start).ToSeconds();
    writer.AddStereo(triggers[k], frame.cam0, frame.cam1);
    writer.AddDepth(triggers[k], frame.depth0_m);
    std::size_t moving = 0;
    for (const TagCarrier& carrier : world.carriers) {
      if (carrier.is_static) continue;
      for (const TagMarker& tag : carrier.tags) {
        writer.AddTagPose(triggers[k], carrier.name, tag.id,
                          T_world_carriers[moving] * tag.T_carrier_tag);
      }
      ++moving;
    }
    result.write_time_s += SecondsSince(write_start);
    ++result.stereo_frames;
    if (options.progress) {
      options.progress(static_cast<double>(k + 1) / static_cast<double>(triggers.size()), t_s);
    }
  }
  writer.Close();
  result.wall_time_s = SecondsSince(wall_start);
  return result;
}

}  // namespace rover::sim
