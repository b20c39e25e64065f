// Crash isolation (DESIGN.md: roverd must keep running when mapd dies):
// rover-launch runs RouDi's clients roverd-sim (real time) and mapd; the test
// kills mapd with SIGKILL mid-mission. roverd's IMU loop must show no gap in
// its log, the launcher must restart mapd, and the new mapd must resume with
// a new submap: a frame switch after the kill. The new mapd carries on with
// the pose graph the killed one logged.

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/estimator_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "estimator/io/estimator_log_records.h"
#include "estimator/io/log_replay.h"
#include "firmware/runtime/process/child_process.h"
#include "mapping/slam/graph_log.h"
#include "tests/firmware/mapd/log_topic.h"
#include "tests/support/roudi_process.h"
#include "tests/support/temp_dir.h"

namespace rover {
namespace {

namespace fs = std::filesystem;
namespace msgs = log::rover_msgs;

// The pid in `path`, once it differs from `other` (0: any).
pid_t WaitForPid(const fs::path& path, pid_t other, Duration timeout) {
  const Time deadline = Time::Now() + timeout;
  while (Time::Now() < deadline) {
    pid_t pid = 0;
    std::ifstream(path) >> pid;
    if (pid > 0 && pid != other) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

using testing::ReadTopic;

TEST(MapdCrashTest, KillingMapdLeavesNoGapInTheImuLoopAndMapdResumesWithANewSubmap) {
  std::string reason;
  auto roudi = testing::RouDiProcess::Start({.config_file = ROVER_ROUDI_CONFIG}, &reason);
  if (roudi == nullptr) {
    if (testing::OwnRouDiRequired()) FAIL() << reason;
    GTEST_SKIP() << reason;
  }
  const testing::TempDir dir;
  const fs::path run_dir = dir.path() / "run";
  const fs::path output = dir.path() / "launch.txt";
  const double duration_s = 14.0;
  runtime::ChildProcess launcher =
      runtime::ChildProcess::Spawn({.argv = {ROVER_LAUNCH,
                                             "--mapd",
                                             ROVER_MAPD,
                                             "--roverd-sim",
                                             ROVER_ROVERD_SIM,
                                             "--run-dir",
                                             run_dir.string(),
                                             "--restart-backoff-s",
                                             "0.5",
                                             "--evaluate-map",
                                             dir.path().string(),
                                             "--",
                                             "--sim",
                                             "short",
                                             "--seed",
                                             "1",
                                             "--realtime",
                                             "--max-duration-s",
                                             std::to_string(duration_s),
                                             "--out",
                                             dir.path().string()},
                                    .output_file = output.string()});
  const pid_t first = WaitForPid(run_dir / "mapd.pid", 0, Duration::Seconds(30));
  ASSERT_GT(first, 0) << testing::ReadTextFile(output);
  // Let the mission run until the first mapd has its submap (the status
  // line shows the filter in frame 1: the renderer's set-up and the
  // filter's standstill initialisation take a few seconds, more on a loaded
  // machine), then kill mapd without warning.
  const Time give_up = Time::Now() + Duration::Seconds(90);
  while (testing::ReadTextFile(output).find("mapd up, frame 1") == std::string::npos) {
    ASSERT_LT(Time::Now(), give_up) << "no frame switch yet\n" << testing::ReadTextFile(output);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const Time killed_at = Time::Now();
  ASSERT_EQ(::kill(first, SIGKILL), 0);
  const pid_t second = WaitForPid(run_dir / "mapd.pid", first, Duration::Seconds(10));
  EXPECT_GT(second, 0) << "mapd was not restarted\n" << testing::ReadTextFile(output);

  const auto status = launcher.WaitFor(Duration::Seconds(120));
  ASSERT_TRUE(status.has_value()) << testing::ReadTextFile(output);
  const std::string text = testing::ReadTextFile(output);
  ASSERT_TRUE(status->ok()) << status->Describe() << "\n" << text;
  EXPECT_NE(text.find("mapd killed by signal 9"), std::string::npos) << text;
  EXPECT_NE(text.find("restarted 1 times"), std::string::npos) << text;
  EXPECT_NE(text.find("imu_drops=0"), std::string::npos) << text;

  const std::string log_path = (dir.path() / "mission-short.mcap").string();
  // The IMU loop: every sample at 400 Hz, none missing around the kill.
  const auto imu = ReadTopic<msgs::EstimatorImu>(log_path, estimator::io::kImuInputTopic);
  ASSERT_GT(imu.size(), 300u);
  EXPECT_NEAR(static_cast<double>(imu.size()), duration_s * 400.0, 2.0);
  int64_t max_gap_ns = 0;
  for (std::size_t i = 1; i < imu.size(); ++i) {
    max_gap_ns = std::max(max_gap_ns, imu[i].stamp_ns - imu[i - 1].stamp_ns);
  }
  EXPECT_LE(max_gap_ns, 3'750'000) << "an IMU sample is missing (period 2.5 ms)";
  EXPECT_LT(imu.front().stamp_ns, killed_at.nanoseconds());
  EXPECT_GT(imu.back().stamp_ns, killed_at.nanoseconds() + 2'000'000'000);

  // One switch for the first mapd's submap, one for the restarted mapd's.
  const auto switches =
      ReadTopic<msgs::EstimatorFrameSwitch>(log_path, estimator::io::kFrameSwitchRecordTopic);
  ASSERT_GE(switches.size(), 2u) << text;
  EXPECT_LT(switches.front().stamp_ns, killed_at.nanoseconds());
  EXPECT_GT(switches.back().stamp_ns, killed_at.nanoseconds());
  EXPECT_NE(text.find("restart "), std::string::npos) << "the new mapd's submap\n" << text;

  // The pose graph survives the kill: the restarted mapd took over every
  // factor the first one had logged (same ids, same numbers), added the
  // switches it missed, and its log holds one w factor per switch roverd made.
  const auto mapd_log_of = [&](pid_t pid) {
    for (const auto& e : fs::directory_iterator(dir.path())) {
      const std::string name = e.path().filename().string();
      if (name.rfind("mapd-", 0) == 0 &&
          name.find("-" + std::to_string(pid) + ".mcap") != std::string::npos) {
        return e.path().string();
      }
    }
    return std::string();
  };
  const std::string first_log = mapd_log_of(first);
  const std::string second_log = mapd_log_of(second);
  ASSERT_FALSE(first_log.empty()) << text;
  ASSERT_FALSE(second_log.empty()) << text;
  const mapping::GraphLogContents before = mapping::ReadGraphLogs({first_log});
  const mapping::GraphLogContents after = mapping::ReadGraphLogs({second_log});
  EXPECT_TRUE(before.truncated) << "mapd was killed mid-log";
  ASSERT_GE(before.factors.size(), 2u) << "the prior and the first switch";
  ASSERT_GE(after.factors.size(), before.factors.size());
  for (std::size_t k = 0; k < before.factors.size(); ++k) {
    const mapping::GraphFactorRecord& a = before.factors[k];
    const mapping::GraphFactorRecord& b = after.factors[k];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.Describe(), b.Describe());
    EXPECT_EQ(a.T_a_b.matrix(), b.T_a_b.matrix()) << a.Describe();
    EXPECT_EQ(a.covariance, b.covariance) << a.Describe();
  }
  std::set<int64_t> switched;
  for (const mapping::GraphFactorRecord& f : after.factors) {
    if (f.kind == mapping::FactorKind::kFrameSwitch) switched.insert(f.a.index);
  }
  EXPECT_EQ(switched.size(), switches.size()) << "one w factor per switch, none lost or doubled";
  for (const auto& sw : switches) {
    EXPECT_EQ(switched.count(sw.old_frame_id), 1u) << "switch from frame " << sw.old_frame_id;
  }
  EXPECT_NE(text.find("resuming the pose graph"), std::string::npos) << text;

  const estimator::io::ReplayResult replay = estimator::io::ReplayLog(log_path);
  EXPECT_TRUE(replay.bit_exact) << replay.first_difference;
  EXPECT_EQ(replay.switches_compared, switches.size());
}

}  // namespace
}  // namespace rover
