// The roverd executable as systemd starts it: board profile `replay` on the
// EuRoC excerpt in ../shared/data, in lockstep and without RouDi. Its flight
// log must replay bit-exactly; unusable profiles exit with 78 (EX_CONFIG),
// which the unit does not restart.

#include <cstdlib>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "estimator/io/log_replay.h"
#include "firmware/runtime/process/child_process.h"
#include "tests/support/temp_dir.h"

namespace rover {
namespace {

namespace fs = std::filesystem;

struct RoverdRun {
  runtime::ExitStatus status;
  std::string output;
};

RoverdRun RunRoverd(const fs::path& dir, const std::string& yaml) {
  const fs::path config = dir / "board.yaml";
  std::ofstream(config) << yaml;
  const fs::path output = dir / "roverd.txt";
  runtime::ChildProcess p =
      runtime::ChildProcess::Spawn({.argv = {ROVER_ROVERD, "--config", config.string(), "--no-ipc"},
                                    .output_file = output.string()});
  const auto status = p.WaitFor(Duration::Seconds(300));
  return {status.value_or(p.Terminate(Duration::Seconds(1))), testing::ReadTextFile(output)};
}

std::string Dataset() {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return (fs::path(shared ? shared : "") / "data/euroc_v1_01_micro").string();
}

TEST(RoverdMainTest, ReplaysADatasetIntoALogThatReplaysBitExactly) {
  const rover::testing::TempDir dir;
  const fs::path logs = dir.path() / "logs";
  const RoverdRun run = RunRoverd(dir.path(),
                                  "board: {name: bench, profile: replay}\n"
                                  "replay:\n"
                                  "  dataset: " +
                                      Dataset() +
                                      "\n"
                                      "  estimator_config: " ROVER_SOURCE_DIR_STR
                                      "/host/eval/config/euroc_mav.yaml\n"
                                      "  lockstep: true\n"
                                      "realtime: {lock_memory: false}\n"
                                      "log: {folder: " +
                                      logs.string() + ", images: none}\n");
  ASSERT_TRUE(run.status.ok()) << run.status.Describe() << "\n" << run.output;
  EXPECT_NE(run.output.find("IMU     29120 samples, 0 dropped"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("imu ok 200.0 Hz"), std::string::npos) << run.output;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(logs)) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(files[0].filename().string().rfind("roverd-", 0), 0u) << files[0];
  const estimator::io::ReplayResult replay = estimator::io::ReplayLog(files[0].string());
  EXPECT_TRUE(replay.bit_exact) << replay.first_difference;
  EXPECT_GT(replay.states_compared, 20000u);
}

TEST(RoverdMainTest, UnusableProfilesExitWithExConfig) {
  const rover::testing::TempDir dir;
  RoverdRun run = RunRoverd(dir.path(), "board: {name: sim, profile: sim}\nlog: {folder: /tmp}\n");
  EXPECT_EQ(run.status.exit_code, 78) << run.output;
  EXPECT_NE(run.output.find("expected hardware or replay"), std::string::npos) << run.output;
  // Hardware: a device that is not there is named, before any thread starts.
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  run = RunRoverd(dir.path(), "board: {name: b, profile: hardware}\nhardware: {calibration: " +
                                  std::string(source != nullptr ? source : ".") +
                                  "/firmware/config/bench_calibration, imu: {driver: xsens, "
                                  "device: /dev/rover-no-such-tty}}\nlog: {folder: /tmp}\n");
  EXPECT_EQ(run.status.exit_code, 78) << run.output;
  EXPECT_NE(run.output.find("/dev/rover-no-such-tty"), std::string::npos) << run.output;
  // A calibration for another image size than the camera's is refused
  // before any device is opened.
  run = RunRoverd(dir.path(), "board: {name: b, profile: hardware}\nhardware: {calibration: " +
                                  std::string(source != nullptr ? source : ".") +
                                  "/firmware/config/bench_calibration, imu: {driver: xsens, "
                                  "device: /dev/rover-no-such-tty}, camera: {driver: v4l2, "
                                  "cam0: /dev/video0, "
                                  "cam1: /dev/video1, width_px: 752, height_px: 480}}\n"
                                  "log: {folder: /tmp}\n");
  EXPECT_EQ(run.status.exit_code, 78) << run.output;
  EXPECT_NE(run.output.find("calibrates cam0 at 640x480 (resolution), expected the camera's "
                            "752x480"),
            std::string::npos)
      << run.output;
  run = RunRoverd(dir.path(),
                  "board: {name: b, profile: replay}\nreplay: {dataset: /nonexistent}\n"
                  "log: {folder: /tmp}\n");
  EXPECT_EQ(run.status.exit_code, 78) << run.output;
  EXPECT_NE(run.output.find("/nonexistent"), std::string::npos) << run.output;
  run = RunRoverd(dir.path(),
                  "board: {name: b, profile: replay}\nreplay: {dataset: x}\n"
                  "log: {folder: /tmp}\nspeed: 3\n");
  EXPECT_EQ(run.status.exit_code, 78) << run.output;
  EXPECT_NE(run.output.find("speed"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace rover
