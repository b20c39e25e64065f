// The quality contract on `short`, end to end as `./rover run` does
// it: rover-launch runs RouDi, mapd and roverd-sim (lockstep), then scores
// the mission's map against the simulator's ground truth and extends the
// RESULT line. Occupied voxels: precision >= 0.9, recall >= 0.8; obstacle
// recall >= 0.9; submaps at most 1 % of the raw stereo bytes.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "firmware/runtime/process/child_process.h"
#include "tests/support/roudi_process.h"
#include "tests/support/temp_dir.h"

namespace rover {
namespace {

namespace fs = std::filesystem;

// key=value fields of the last RESULT line of `text`.
std::map<std::string, std::string> LastResult(const std::string& text) {
  std::map<std::string, std::string> fields;
  const std::size_t at = text.rfind("RESULT ");
  if (at == std::string::npos) return fields;
  std::istringstream line(text.substr(at + 7, text.find('\n', at) - at - 7));
  std::string field;
  while (line >> field) {
    const std::size_t eq = field.find('=');
    if (eq != std::string::npos) fields[field.substr(0, eq)] = field.substr(eq + 1);
  }
  return fields;
}

TEST(MissionMapTest, ShortMissionMapMeetsTheQualityAndBandwidthTargets) {
  std::string reason;
  auto roudi = testing::RouDiProcess::Start({.config_file = ROVER_ROUDI_CONFIG}, &reason);
  if (roudi == nullptr) {
    if (testing::OwnRouDiRequired()) FAIL() << reason;
    GTEST_SKIP() << reason;
  }
  const testing::TempDir dir;
  const fs::path output = dir.path() / "launch.txt";
  runtime::ChildProcess launcher = runtime::ChildProcess::Spawn(
      {.argv = {ROVER_LAUNCH, "--mapd", ROVER_MAPD, "--roverd-sim", ROVER_ROVERD_SIM, "--run-dir",
                (dir.path() / "run").string(), "--evaluate-map", dir.path().string(), "--", "--sim",
                "short", "--seed", "1", "--out", dir.path().string()},
       .output_file = output.string()});
  const auto status = launcher.WaitFor(Duration::Seconds(400));
  ASSERT_TRUE(status.has_value()) << testing::ReadTextFile(output);
  const std::string text = testing::ReadTextFile(output);
  ASSERT_TRUE(status->ok()) << status->Describe() << "\n" << text;
  const auto r = LastResult(text);
  for (const char* key : {"map_precision", "map_recall", "obstacle_precision", "obstacle_recall",
                          "submaps", "submap_bytes_per_s", "raw_stereo_bytes_per_s"}) {
    ASSERT_TRUE(r.count(key)) << key << " missing\n" << text;
  }
  const auto num = [&r](const char* key) { return std::strtod(r.at(key).c_str(), nullptr); };
  EXPECT_GE(num("map_precision"), 0.9) << text;
  EXPECT_GE(num("map_recall"), 0.8) << text;
  EXPECT_GE(num("obstacle_recall"), 0.9) << text;
  EXPECT_GE(num("obstacle_precision"), 0.5) << "reported; measured 0.86\n" << text;
  EXPECT_GE(num("submaps"), 2.0) << text;
  EXPECT_GT(num("raw_stereo_bytes_per_s"), 1e6) << text;
  EXPECT_LE(num("submap_bytes_per_s"), 0.01 * num("raw_stereo_bytes_per_s")) << text;
  // mapd's exports are there for octovis and point-cloud viewers.
  int exports = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) {
    const std::string ext = e.path().extension().string();
    if (e.path().filename().string().rfind("mapd-", 0) == 0 &&
        (ext == ".bt" || ext == ".ot" || ext == ".ply")) {
      ++exports;
    }
  }
  EXPECT_EQ(exports, 3) << text;
}

}  // namespace
}  // namespace rover
