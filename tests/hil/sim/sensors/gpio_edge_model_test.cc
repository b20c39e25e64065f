#include "hil/sim/sensors/gpio_edge_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "hil/sim/analytic_trajectory.h"
#include "hil/sim/sensors/imu_model.h"

namespace rover::sim {
namespace {

using ::testing::HasSubstr;

std::string ConfigPath(const std::string& name) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  return std::string(source != nullptr ? source : ".") + "/hil/config/" + name;
}

TEST(GpioEdgeModelTest, CameraTriggersAtRateAndPhase) {
  GpioEdgeOptions o;
  o.camera_rate_hz = 15.0;
  o.camera_phase_s = 0.004;
  o.camera_pulse_width_s = 1e-3;
  const Time start = Time::FromNanoseconds(2'000'000'000);
  const GpioEdgeModel model(o, start);
  const std::vector<Time> rises = model.CameraTriggerTimes(start, start + Duration::Seconds(2));
  ASSERT_EQ(rises.size(), 30u);
  EXPECT_EQ(rises[0], start + Duration::Milliseconds(4));
  for (std::size_t k = 0; k < rises.size(); ++k) {
    EXPECT_EQ(rises[k], model.CameraTriggerTime(k));
    EXPECT_NEAR((rises[k] - rises[0]).ToSeconds(), static_cast<double>(k) / 15.0, 1e-9);
  }
  const std::vector<drivers::GpioEdge> edges =
      model.CameraTriggerEdges(start, start + Duration::Seconds(2));
  ASSERT_EQ(edges.size(), 60u);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    EXPECT_EQ(edges[i].line, o.camera_trigger_line);
    EXPECT_EQ(edges[i].rising, i % 2 == 0);
    if (i % 2 == 1) {
      EXPECT_EQ(edges[i].stamp - edges[i - 1].stamp, Duration::Milliseconds(1));
    }
  }
  // A window that opens inside a pulse gets its falling edge only.
  const std::vector<drivers::GpioEdge> tail =
      model.CameraTriggerEdges(rises[3] + Duration::Microseconds(500), rises[4]);
  ASSERT_EQ(tail.size(), 1u);
  EXPECT_FALSE(tail[0].rising);
}

TEST(GpioEdgeModelTest, ImuDataReadyEdgesFollowTheSampleStamps) {
  GpioEdgeOptions o;
  o.imu_data_ready_delay_s = 20e-6;
  o.imu_data_ready_pulse_width_s = 50e-6;
  const Time start = Time::FromNanoseconds(1'000'000'000);
  const GpioEdgeModel model(o, start);
  ImuModelOptions imu_options;
  imu_options.sample_time_jitter_sigma_s = 5e-6;
  ImuModel imu(imu_options, start);
  const AnalyticTrajectory motion(AnalyticTrajectoryOptions{});
  std::vector<drivers::GpioEdge> edges =
      model.CameraTriggerEdges(start, start + Duration::Seconds(1));
  std::vector<Time> stamps;
  for (int k = 0; k < 400; ++k) {
    const drivers::ImuSample s = imu.Next(motion);
    stamps.push_back(s.stamp);
    for (const drivers::GpioEdge& e : model.ImuDataReadyEdges(s.stamp)) edges.push_back(e);
  }
  GpioEdgeModel::SortByTime(&edges);
  std::size_t ready = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (i > 0) {
      EXPECT_GE(edges[i].stamp, edges[i - 1].stamp);
    }
    if (edges[i].line != o.imu_data_ready_line || !edges[i].rising) continue;
    EXPECT_EQ(edges[i].stamp, stamps[ready] + Duration::Microseconds(20));
    ++ready;
  }
  EXPECT_EQ(ready, 400u);
}

TEST(GpioEdgeModelTest, OptionsLoadAndValidate) {
  const GpioEdgeOptions o = GpioEdgeOptions::LoadFile(ConfigPath("gpio.yaml"));
  EXPECT_EQ(o.camera_rate_hz, 10.0);
  EXPECT_NE(o.camera_trigger_line, o.imu_data_ready_line);
  const ConfigNode bad = ConfigNode::LoadString(R"(camera_rate_hz: 25
camera_phase_s: 0
camera_pulse_width_s: 0.001
camera_trigger_line: 17
imu_data_ready_line: 27
imu_data_ready_delay_s: 0
imu_data_ready_pulse_width_s: 5.0e-5
)",
                                                "gpio.yaml");
  try {
    GpioEdgeOptions::Load(bad);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("gpio.yaml:1: camera_rate_hz"));
    EXPECT_THAT(e.what(), HasSubstr("[10, 20]"));
  }
}

}  // namespace
}  // namespace rover::sim
