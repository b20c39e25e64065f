#include <gtest/gtest.h>

#include "drivers/can/canopen_wheel_protocol.h"
#include "hil/sim/live/sim_can_bus.h"
#include "hil/sim/live/sim_imu_driver.h"
#include "hil/sim/live/sim_stereo_camera_driver.h"

namespace rover::sim {
namespace {

constexpr Time kStart = Time::FromNanoseconds(5'000'000'000);

Heightfield Flat() {
  return Heightfield(201, 201, 0.25, Eigen::Vector2d(-25, -25), std::vector<float>(201 * 201));
}

Route ShortRoute() {
  Route route;
  route.start_hold_s = 0.5;
  route.DriveTo({3, 0}, 0.3);
  return route;
}

ImuModelOptions Imu() {
  ImuModelOptions o;
  o.rate_hz = 400;
  o.gyro.noise_density = 1e-4;
  o.accel.noise_density = 1e-3;
  o.seed = 5;
  return o;
}

TEST(SimImuDriverTest, LockstepDeliversTheModelsSamplesThenEnds) {
  const Heightfield terrain = Flat();
  const RoverTrajectory trajectory(ShortRoute(), terrain);
  const drivers::ReplayClock lockstep(false, kStart);
  const Time end = kStart + Duration::Seconds(2);
  SimImuDriver driver(Imu(), trajectory, lockstep, kStart, end);
  ImuModel reference(Imu(), kStart);
  drivers::ImuSample sample;
  int n = 0;
  while (driver.Read(&sample, Duration::Zero()) == drivers::ReadStatus::kOk) {
    const drivers::ImuSample expected = reference.Next(trajectory);
    ASSERT_EQ(sample.stamp, expected.stamp);
    ASSERT_EQ(sample.angular_velocity_rad_s, expected.angular_velocity_rad_s);
    ASSERT_EQ(sample.linear_acceleration_m_s2, expected.linear_acceleration_m_s2);
    ++n;
  }
  EXPECT_EQ(n, 800);
  EXPECT_EQ(driver.Read(&sample, Duration::Zero()), drivers::ReadStatus::kEndOfStream);
}

TEST(SimImuDriverTest, RealTimeHoldsSamplesBackUntilDue) {
  const Heightfield terrain = Flat();
  const RoverTrajectory trajectory(ShortRoute(), terrain);
  const drivers::ReplayClock realtime(true, kStart);
  SimImuDriver driver(Imu(), trajectory, realtime, kStart, kStart + Duration::Seconds(10));
  drivers::ImuSample sample;
  const Time wall_start = Time::Now();
  for (int i = 0; i < 40; ++i) {
    ASSERT_EQ(driver.Read(&sample, Duration::Seconds(1)), drivers::ReadStatus::kOk);
  }
  // 40 samples at 400 Hz cannot arrive in less than 39 periods.
  EXPECT_GE((Time::Now() - wall_start).ToSeconds(), 39 * 0.0025 - 0.002);
  // The next sample is 2.5 ms away: a zero timeout reports it is not there yet.
  EXPECT_EQ(driver.Read(&sample, Duration::Zero()), drivers::ReadStatus::kTimeout);
}

TEST(SimWheelCanBusTest, DeliversSyncAndFourTpdosEveryTenMilliseconds) {
  const Heightfield terrain = Flat();
  const RoverTrajectory trajectory(ShortRoute(), terrain);
  const drivers::ReplayClock lockstep(false, kStart);
  SimWheelCanBus bus(WheelOdometryModelOptions{}, trajectory, terrain, lockstep, kStart,
                     kStart + Duration::Seconds(1));
  drivers::CanFrame frame;
  int syncs = 0, tpdos = 0, heartbeats = 0;
  Time last;
  while (bus.Receive(&frame, Duration::Zero()) == drivers::ReadStatus::kOk) {
    ASSERT_GE(frame.stamp, last);
    last = frame.stamp;
    if (drivers::IsSync(frame)) ++syncs;
    if (const auto tpdo = drivers::DecodeWheelTpdo1(frame)) {
      EXPECT_GE(tpdo->node_id, 1);
      EXPECT_LE(tpdo->node_id, 4);
      ++tpdos;
    }
    if (drivers::DecodeHeartbeat(frame).has_value()) ++heartbeats;
  }
  EXPECT_EQ(syncs, 100);
  EXPECT_NEAR(tpdos, 400, 4);  // the last SYNC's TPDOs may fall past the end
  EXPECT_EQ(heartbeats, 4);
  EXPECT_TRUE(bus.Send(frame));
}

TEST(SimStereoCameraDriverTest, RendersAtTriggerTimes) {
  WorldOptions options;
  options.size_m = 24;
  options.rock_count = 20;
  options.crater_count = 0;
  options.landmark_post_count = 1;
  const World world = World::Generate(options, 3);
  const RoverTrajectory trajectory(ShortRoute(), world.terrain);
  const std::vector<const RoverTrajectory*> carriers;
  StereoCameraOptions camera;
  StereoRenderer renderer(world, camera);
  const GpioEdgeModel triggers(GpioEdgeOptions{}, kStart);
  const drivers::ReplayClock lockstep(false, kStart);
  SimStereoCameraDriver driver(renderer, trajectory, carriers, kNoHiddenCarrier, triggers, lockstep,
                               kStart, kStart + Duration::Milliseconds(250));
  drivers::StereoFrame frame;
  for (uint64_t k = 0; k < 3; ++k) {
    ASSERT_EQ(driver.Next(&frame, Duration::Zero()), drivers::ReadStatus::kOk);
    EXPECT_EQ(frame.stamp, triggers.CameraTriggerTime(k));
    EXPECT_EQ(frame.sequence, k);
    EXPECT_EQ(frame.cam0.width_px, camera.width_px);
    EXPECT_EQ(frame.cam1.height_px, camera.height_px);
    ASSERT_NE(frame.cam1.data, nullptr);
    driver.Release(frame);
  }
  EXPECT_EQ(driver.Next(&frame, Duration::Zero()), drivers::ReadStatus::kEndOfStream);
}

}  // namespace
}  // namespace rover::sim
