#include "firmware/runtime/rt/rt_thread_options.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <thread>

#include "core/config/config.h"

namespace rover::runtime {
namespace {

// Loads threads.imu from `yaml` and returns the ConfigError text ("" if none).
std::string LoadError(const std::string& yaml) {
  try {
    const ConfigNode root = ConfigNode::LoadString(yaml, "board.yaml");
    RtThreadOptions::Load(root.Child("threads").Child("imu"), "imu");
    return "";
  } catch (const ConfigError& e) {
    return e.what();
  }
}

TEST(RtThreadOptionsTest, LoadsEveryKey) {
  const ConfigNode root = ConfigNode::LoadString(
      "imu:\n  name: imu_loop\n  priority: 80\n  nice: -5\n  cpus: [0]\n"
      "  stack_prefault_bytes: 131072\n",
      "board.yaml");
  const RtThreadOptions o = RtThreadOptions::Load(root.Child("imu"));
  EXPECT_EQ(o.name, "imu_loop");
  EXPECT_EQ(o.priority, 80);
  EXPECT_EQ(o.nice, -5);
  EXPECT_EQ(o.cpus, std::vector<int>{0});
  EXPECT_EQ(o.stack_prefault_bytes, 131072u);
  root.CheckNoUnknownKeysRecursive();
}

TEST(RtThreadOptionsTest, AbsentKeysTakeDefaultsAndTheDefaultName) {
  const ConfigNode root = ConfigNode::LoadString("imu: {}\n", "board.yaml");
  const RtThreadOptions o = RtThreadOptions::Load(root.Child("imu"), "imu");
  EXPECT_EQ(o.name, "imu");
  EXPECT_EQ(o.priority, 0);
  EXPECT_TRUE(o.cpus.empty());
  EXPECT_EQ(o.stack_prefault_bytes, RtThreadOptions{}.stack_prefault_bytes);
}

TEST(RtThreadOptionsTest, PriorityOutOfRangeNamesTheKey) {
  const std::string error = LoadError("threads:\n  imu:\n    priority: 100\n");
  EXPECT_EQ(error, "board.yaml:3: threads.imu.priority: expected an integer in [0, 99], found 100")
      << error;
}

TEST(RtThreadOptionsTest, CpuBeyondThisMachineNamesTheKey) {
  const int n = static_cast<int>(std::thread::hardware_concurrency());
  ASSERT_GT(n, 0);
  const std::string error =
      LoadError("threads:\n  imu:\n    cpus: [0, " + std::to_string(n) + "]\n");
  EXPECT_EQ(error, "board.yaml:3: threads.imu.cpus: expected CPU ids in [0, " + std::to_string(n) +
                       ") (this machine's CPUs), found " + std::to_string(n));
}

TEST(RtThreadOptionsTest, NegativeAndDuplicateCpusAreErrors) {
  EXPECT_NE(LoadError("threads:\n  imu:\n    cpus: [-1]\n").find("threads.imu.cpus: expected CPU"),
            std::string::npos);
  EXPECT_NE(LoadError("threads:\n  imu:\n    cpus: [0, 0]\n")
                .find("threads.imu.cpus: expected each CPU id once, found 0 twice"),
            std::string::npos);
}

TEST(RtThreadOptionsTest, NameLongerThanTheKernelKeepsIsAnError) {
  const std::string error = LoadError("threads:\n  imu:\n    name: imu_estimator_loop\n");
  EXPECT_EQ(error,
            "board.yaml:3: threads.imu.name: expected 1 to 15 characters, found "
            "\"imu_estimator_loop\" (18)");
}

TEST(RtThreadOptionsTest, NiceAndPrefaultRangesNameTheKey) {
  EXPECT_NE(LoadError("threads:\n  imu:\n    nice: -21\n").find("threads.imu.nice: expected"),
            std::string::npos);
  EXPECT_NE(LoadError("threads:\n  imu:\n    stack_prefault_bytes: 99999999\n")
                .find("threads.imu.stack_prefault_bytes: expected"),
            std::string::npos);
}

TEST(RtThreadOptionsTest, ValidateNamesTheField) {
  RtThreadOptions o;
  o.name = "can";
  o.priority = -1;
  try {
    o.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "RtThreadOptions.priority: expected a SCHED_FIFO priority in [0, 99] "
                 "(0 = SCHED_OTHER), found -1");
  }
  o.priority = 60;
  EXPECT_NO_THROW(o.Validate());
  o.name.clear();
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::runtime
