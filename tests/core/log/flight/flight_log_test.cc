#include "core/log/flight/flight_log.h"

#include <gtest/gtest.h>

#include <map>
#include <thread>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/all_msgs.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/temp_dir.h"

namespace rover::log {
namespace {

Time StampOf(int i) { return Time::FromNanoseconds(1'000'000'000 + int64_t{i} * 2'500'000); }

sensor_msgs::Imu MakeImu(int i) {
  sensor_msgs::Imu imu;
  imu.header.stamp = ToRosTime(StampOf(i));
  imu.header.frame_id = "body";
  imu.angular_velocity.z = 0.001 * i;
  imu.linear_acceleration.z = 9.80665;
  return imu;
}

// Reads every message of `topic` back, decoded as Msg, with its sequence.
template <typename Msg>
std::vector<std::pair<uint32_t, Msg>> ReadTopic(const std::string& path, const std::string& topic) {
  McapReader reader = McapReader::Open(path);
  EXPECT_TRUE(reader.summary_ok());
  EXPECT_TRUE(reader.damage().empty());
  uint16_t id = 0;
  for (const auto& [channel_id, channel] : reader.channels()) {
    if (channel.topic == topic) id = channel_id;
  }
  EXPECT_NE(id, 0) << topic;
  std::vector<std::pair<uint32_t, Msg>> out;
  reader.ForEachMessage([&](const MessageView& m) {
    if (m.channel_id == id) {
      Msg msg;
      std::string error;
      EXPECT_TRUE(DeserializeMessage(m.data, &msg, &error)) << error;
      out.emplace_back(m.sequence, msg);
    }
    return true;
  });
  return out;
}

TEST(FlightLogTest, ProducerThreadRecordsArriveCompleteAndInOrder) {
  const testing::TempDir dir("flight_log");
  const std::string path = dir.File("a.mcap").string();
  FlightLogOptions options;
  options.drain_period = Duration::Milliseconds(1);
  options.health_period = Duration::Milliseconds(20);
  FlightLog log(options);
  log.Open(path);
  auto* imu = log.AddChannel<sensor_msgs::Imu>("/imu");
  log.Start();
  constexpr int kCount = 20000;
  std::thread producer([&] {
    for (int i = 0; i < kCount; ++i) {
      while (!imu->Log(StampOf(i), MakeImu(i))) {
        // The test wants every record; a real-time producer would not retry.
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
  });
  producer.join();
  log.Stop();
  const FlightLogStats stats = log.stats();
  EXPECT_TRUE(stats.error.empty()) << stats.error;
  EXPECT_EQ(stats.written, static_cast<uint64_t>(kCount));

  const auto records = ReadTopic<sensor_msgs::Imu>(path, "/imu");
  ASSERT_EQ(records.size(), static_cast<std::size_t>(kCount));
  // A rejected push (ring full, retried here) still consumes a sequence
  // number, so sequences increase with gaps exactly where drops happened.
  uint64_t gaps = 0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    ASSERT_EQ(records[i].second, MakeImu(static_cast<int>(i))) << i;
    if (i > 0) {
      ASSERT_GT(records[i].first, records[i - 1].first);
      gaps += records[i].first - records[i - 1].first - 1;
    }
  }
  EXPECT_EQ(gaps + records.front().first, stats.dropped);
}

TEST(FlightLogTest, DropsAreCountedAndReportedInTheLog) {
  const testing::TempDir dir("flight_log");
  const std::string path = dir.File("drops.mcap").string();
  FlightLogOptions options;
  options.drain_period = Duration::Seconds(3600);  // the writer never drains before Stop()
  options.health_period = Duration::Seconds(3600);
  FlightLog log(options);
  log.Open(path);
  auto* imu = log.AddChannel<sensor_msgs::Imu, 1024, 16>("/imu");
  log.Start();
  int accepted = 0;
  for (int i = 0; i < 100; ++i) accepted += imu->Log(StampOf(i), MakeImu(i)) ? 1 : 0;
  log.Stop();
  EXPECT_EQ(accepted, 16);
  const FlightLogStats stats = log.stats();
  EXPECT_EQ(stats.logged, 100u);
  EXPECT_EQ(stats.written, 16u);
  EXPECT_EQ(stats.dropped, 84u);

  const auto records = ReadTopic<sensor_msgs::Imu>(path, "/imu");
  ASSERT_EQ(records.size(), 16u);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(records[static_cast<std::size_t>(i)].first, static_cast<uint32_t>(i));
    EXPECT_EQ(records[static_cast<std::size_t>(i)].second, MakeImu(i));
  }
  const auto health = ReadTopic<rover_msgs::LogHealth>(path, "/rover/log_health");
  ASSERT_FALSE(health.empty());
  const rover_msgs::LogHealth& last = health.back().second;
  ASSERT_EQ(last.channels.size(), 1u);
  EXPECT_EQ(last.channels[0].topic, "/imu");
  EXPECT_EQ(last.channels[0].records_written, 16u);
  EXPECT_EQ(last.channels[0].records_dropped, 84u);
  EXPECT_EQ(last.channels[0].ring_high_water, 16u);
  EXPECT_EQ(last.records_written, 16u);
}

TEST(FlightLogTest, OversizedMessageIsACountedDrop) {
  const testing::TempDir dir("flight_log");
  FlightLog log;
  log.Open(dir.File("big.mcap").string());
  auto* diag = log.AddChannel<diagnostic_msgs::DiagnosticArray, 128, 4>("/diagnostics");
  log.Start();
  diagnostic_msgs::DiagnosticArray small, big;
  big.status.resize(1);
  big.status[0].message.assign(500, 'x');
  EXPECT_TRUE(diag->Log(Time::FromNanoseconds(1), small));
  EXPECT_FALSE(diag->Log(Time::FromNanoseconds(2), big));
  log.Stop();
  const LogChannelCounters c = diag->counters();
  EXPECT_EQ(c.dropped_oversize, 1u);
  EXPECT_EQ(c.written, 1u);
}

// The real-time contract: after Start(), Log() allocates nothing.
TEST(FlightLogTest, LogDoesNotAllocate) {
  const testing::TempDir dir("flight_log");
  FlightLog log;
  log.Open(dir.File("rt.mcap").string());
  auto* imu = log.AddChannel<sensor_msgs::Imu>("/imu");
  auto* odom = log.AddChannel<nav_msgs::Odometry>("/odom");
  log.Start();
  const sensor_msgs::Imu imu_msg = MakeImu(3);
  nav_msgs::Odometry odom_msg;
  odom_msg.header.frame_id = "local/rover1/0";
  odom_msg.child_frame_id = "body";
  uint64_t allocations = 0;
  {
    const testing::ScopedAllocationCheck check;
    for (int i = 0; i < 500; ++i) {
      imu->Log(StampOf(i), imu_msg);
      odom->Log(StampOf(i), odom_msg);
    }
    allocations = check.allocations();
  }
  log.Stop();
  EXPECT_EQ(allocations, 0u);
}

TEST(FlightLogTest, OpenFailureNamesThePath) {
  FlightLog log;
  try {
    log.Open("/nonexistent-dir/x.mcap");
    FAIL() << "expected McapError";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.mcap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::log
