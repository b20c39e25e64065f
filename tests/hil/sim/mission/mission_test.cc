// The main job end to end: roverd's threads on the simulator's drivers in
// lockstep (rendered stereo pair, VO, CAN wheel drives) record a flight log,
// and the log replays bit-exactly through the estimator.

#include "hil/sim/mission/sim_mission.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/log/mcap/mcap_reader.h"
#include "estimator/io/log_replay.h"
#include "hil/sim/experiments/map_command.h"
#include "tests/support/temp_dir.h"

namespace rover::sim {
namespace {

TEST(MissionTest, ShortMissionRecordsAndReplaysBitExactly) {
  const rover::testing::TempDir dir;
  MissionOptions options;
  options.scenario = "short";
  options.seed = 2;
  options.lockstep = true;
  options.out_dir = dir.path().string();
  options.max_duration_s = 12.0;
  const MissionResult r = RunMission(options);
  // A single rover keeps the single-rover log name.
  EXPECT_EQ(std::filesystem::path(r.log_path).filename(), "mission-short.mcap");
  EXPECT_EQ(r.rover_name, "rover_a");

  const roverd::RoverdStats& s = r.stats;
  EXPECT_TRUE(r.filter_initialised);
  EXPECT_NEAR(static_cast<double>(s.imu_samples), 4800.0, 1.0);  // 12 s at 400 Hz
  EXPECT_EQ(s.imu_drops, 0u);
  EXPECT_EQ(s.frames, 120u);
  EXPECT_EQ(s.frame_drops, 0u);  // lockstep never drops
  EXPECT_GT(s.vo_measurements, 100u);
  EXPECT_GT(s.filter.Accepted(estimator::InputKind::kRelativePose), 80u);
  EXPECT_GT(s.wheel_readings, 1100u);
  EXPECT_EQ(s.loop.ring_drops, 0u);
  EXPECT_EQ(r.log_drops, 0u);
  EXPECT_GT(r.distance_m, 2.0);
  EXPECT_LT(r.filter_final_error_pct, 1.0);

  std::ostringstream summary;
  PrintMissionSummary(r, summary);
  const std::string text = summary.str();
  const std::string last = text.substr(text.rfind("RESULT"));
  for (const char* key :
       {"scenario=short", "distance_m=", "filter_final_err_pct=", "slam_final_err_pct=nan",
        "imu_drops=0", "frame_drops=0", "loop_latency_us_p999=", "rover=0", "log="}) {
    EXPECT_NE(last.find(key), std::string::npos) << key << " missing from " << last;
  }

  const estimator::io::ReplayResult replay = estimator::io::ReplayLog(r.log_path);
  EXPECT_TRUE(replay.bit_exact) << replay.first_difference;
  EXPECT_EQ(replay.inputs, s.loop.inputs);
  EXPECT_EQ(replay.states_compared, s.loop.states);
}

}  // namespace
}  // namespace rover::sim

namespace rover::sim {
namespace {

// Sensor loss degrades gracefully and visibly (DESIGN.md): the filter keeps
// running on what is left, and the health report names the lost sensor.
MissionResult RunWithLoss(double camera_loss_at_s, double can_loss_at_s,
                          const std::filesystem::path& dir) {
  MissionOptions options;
  options.scenario = "short";
  options.seed = 1;
  options.lockstep = true;
  options.out_dir = dir.string();
  options.max_duration_s = 16.0;
  options.camera_loss_at_s = camera_loss_at_s;
  options.can_loss_at_s = can_loss_at_s;
  options.images.mode = roverd::ImageLogMode::kNone;
  return RunMission(options);
}

TEST(MissionTest, LosingTheCamerasLeavesImuAndWheels) {
  const rover::testing::TempDir dir;
  const MissionResult r = RunWithLoss(8.0, 0.0, dir.path());
  const roverd::RoverdStats& s = r.stats;
  EXPECT_EQ(s.frames, 80u);  // 8 s at 10 Hz, then nothing
  EXPECT_NEAR(static_cast<double>(s.imu_samples), 6400.0, 1.0);
  EXPECT_GT(s.wheel_readings, 1500u);  // wheels to the end
  EXPECT_TRUE(r.filter_initialised);
  EXPECT_LT(r.filter_final_error_pct, 2.0) << "IMU + wheels alone for 8 s";
  EXPECT_NE(s.health.find("camera STALE"), std::string::npos) << s.health;
  EXPECT_NE(s.health.find("wheels ok"), std::string::npos) << s.health;
}

TEST(MissionTest, LosingTheCanBusLeavesImuAndVo) {
  const rover::testing::TempDir dir;
  const MissionResult r = RunWithLoss(0.0, 8.0, dir.path());
  const roverd::RoverdStats& s = r.stats;
  EXPECT_EQ(s.frames, 160u);
  EXPECT_LT(s.wheel_readings, 820u);
  EXPECT_GT(s.filter.Accepted(estimator::InputKind::kRelativePose), 120u) << "VO to the end";
  EXPECT_TRUE(r.filter_initialised);
  EXPECT_LT(r.filter_final_error_pct, 1.0);
  EXPECT_NE(s.health.find("wheels STALE"), std::string::npos) << s.health;
  EXPECT_NE(s.health.find("camera ok"), std::string::npos) << s.health;
}

// Six seconds of two-rovers as its second rover, rover_b, which waits at
// (14, 0) facing west for 45 s while rover_a drives off after 2 s.
MissionResult RunRoverB(const std::filesystem::path& dir) {
  MissionOptions options;
  options.scenario = "two-rovers";
  options.rover = 1;
  options.seed = 1;
  options.lockstep = true;
  options.out_dir = dir.string();
  options.max_duration_s = 6.0;
  options.images.mode = roverd::ImageLogMode::kNone;
  return RunMission(options);
}

// A team scenario run as its second rover: rover_b's own route, its own log
// and metadata, and sensors that agree with that truth.
TEST(MissionTest, RoverOneOfATeamDrivesItsOwnRoute) {
  const rover::testing::TempDir dir;
  const MissionResult r = RunRoverB(dir.path());

  EXPECT_EQ(r.rover, 1u);
  EXPECT_EQ(r.rover_name, "rover_b");
  EXPECT_NEAR(r.p_world_body_start_m.x(), 14.0, 1e-6);
  EXPECT_NEAR(r.p_world_body_start_m.y(), 0.0, 1e-6);
  EXPECT_NEAR(r.sim_duration_s, 6.0, 1e-9);
  EXPECT_EQ(std::filesystem::path(r.log_path).filename(), "mission-two-rovers-rover_b.mcap");
  EXPECT_NEAR(static_cast<double>(r.stats.imu_samples), 2400.0, 1.0);  // 6 s at 400 Hz
  // rover_b holds still at its start (rover_a drives off after 2 s): the
  // truth drives nowhere, and the sensors agree with it. (With rover_a's IMU
  // the final error was 0.38 m; with rover_b's it is below a millimetre.)
  ASSERT_TRUE(r.filter_initialised);
  EXPECT_LT(r.distance_m, 1e-6);
  EXPECT_LT(r.filter_final_error_m, 0.05);

  std::map<std::string, std::string> mission;
  const log::McapReader reader = log::McapReader::Open(r.log_path);
  for (const log::Metadata& m : reader.metadata()) {
    if (m.name == "mission") mission = m.metadata;
  }
  EXPECT_EQ(mission["scenario"], "two-rovers");
  EXPECT_EQ(mission["rover"], "1");
  EXPECT_EQ(mission["rover_name"], "rover_b");

  std::ostringstream summary;
  PrintMissionSummary(r, summary);
  const std::string text = summary.str();
  const std::string last = text.substr(text.rfind("RESULT"));
  EXPECT_NE(last.find(" rover=1 log=" + r.log_path), std::string::npos) << last;
}

// `rover-sim map` scores a mission against the trajectory of the rover its
// log names, not always the scenario's route.
TEST(MissionTest, MapEvaluationTakesTheLoggedRoversTruth) {
  const rover::testing::TempDir dir;
  const MissionResult r = RunRoverB(dir.path());
  experiments::MapCommandOptions o;
  o.mission_log = r.log_path;  // no mapd logs: an empty map, but the truth is chosen
  std::ostringstream as_logged;
  experiments::EvaluateMission(o, as_logged);
  EXPECT_NE(as_logged.str().find("ground truth: rover 1 (rover_b) of two-rovers"),
            std::string::npos)
      << as_logged.str();

  o.rover = 0;  // --rover overrides the log
  std::ostringstream overridden;
  experiments::EvaluateMission(o, overridden);
  EXPECT_NE(overridden.str().find("ground truth: rover 0 (rover_a) of two-rovers"),
            std::string::npos)
      << overridden.str();

  // A scenario without that rover is refused, naming the log.
  o.rover = -1;
  o.scenario = "short";
  try {
    std::ostringstream report;
    experiments::EvaluateMission(o, report);
    FAIL() << "rover 1 of short was scored";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(r.log_path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("has 1 rover"), std::string::npos) << e.what();
  }
}

TEST(MissionTest, ARoverOutsideTheTeamIsRefusedNamingTheCount) {
  MissionOptions options;
  options.scenario = "two-rovers";
  options.rover = 2;
  try {
    RunMission(options);
    FAIL() << "rover 2 of two-rovers ran";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("two-rovers"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("has 2 rovers"), std::string::npos) << e.what();
  }
}

TEST(MissionTest, OnlyOtherRoversLogUnderTheirName) {
  EXPECT_EQ(MissionLogName("short", 0, "rover_a"), "mission-short.mcap");
  EXPECT_EQ(MissionLogName("two-rovers", 0, "rover_a"), "mission-two-rovers.mcap");
  EXPECT_EQ(MissionLogName("two-rovers", 1, "rover_b"), "mission-two-rovers-rover_b.mcap");
}

}  // namespace
}  // namespace rover::sim
