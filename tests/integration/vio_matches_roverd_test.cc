// roverd and `rover-eval vio` compute the same estimates from the same
// inputs: roverd's replay board in lockstep on the real EuRoC excerpt, and
// rover-eval vio on the same dataset with the same option file and VO
// latency, build the filter and the VO from the calibration by the same
// rule, feed them through the same input merger and restart the VO at the
// filter's start by the same rule. Every state rover-eval vio computes must
// be in roverd's flight log, bit for bit.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/all_msgs.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/io/estimator_log_records.h"
#include "firmware/runtime/process/child_process.h"
#include "host/eval/vio_run.h"
#include "tests/support/temp_dir.h"

namespace rover {
namespace {

namespace fs = std::filesystem;
namespace msgs = log::rover_msgs;

std::string Dataset() {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return (fs::path(shared ? shared : "") / "data/euroc_v1_01_micro").string();
}

const char* kFilterConfig = ROVER_SOURCE_DIR_STR "/host/eval/config/euroc_mav.yaml";

// Runs roverd's replay board over the dataset in lockstep; returns its log.
fs::path RunRoverd(const fs::path& dir) {
  const fs::path logs = dir / "logs";
  const fs::path config = dir / "board.yaml";
  std::ofstream(config) << "board: {name: bench, profile: replay}\n"
                           "replay:\n"
                           "  dataset: "
                        << Dataset() << "\n  estimator_config: " << kFilterConfig
                        << "\n  lockstep: true\n"
                           "realtime: {lock_memory: false}\n"
                           "log: {folder: "
                        << logs.string() << ", images: none}\n";
  const fs::path output = dir / "roverd.txt";
  runtime::ChildProcess p =
      runtime::ChildProcess::Spawn({.argv = {ROVER_ROVERD, "--config", config.string(), "--no-ipc"},
                                    .output_file = output.string()});
  const auto status = p.WaitFor(Duration::Seconds(300));
  const runtime::ExitStatus exit = status.value_or(p.Terminate(Duration::Seconds(1)));
  const std::string text = testing::ReadTextFile(output);
  EXPECT_TRUE(exit.ok()) << exit.Describe() << "\n" << text;
  // In lockstep every input is handed over before the filter passes its
  // stamp; a late one would be applied out of order and break the identity.
  EXPECT_NE(text.find("late inputs 0,"), std::string::npos) << text;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(logs)) files.push_back(e.path());
  EXPECT_EQ(files.size(), 1u);
  return files.empty() ? fs::path() : files.front();
}

struct LoggedRun {
  std::map<int64_t, msgs::EstimatorState> states_by_stamp;  ///< frame 0 only
  uint64_t relative_poses = 0;
  std::string options_yaml;
};

LoggedRun ReadLog(const fs::path& path) {
  LoggedRun run;
  log::McapReader reader = log::McapReader::Open(path.string());
  for (const log::Metadata& m : reader.metadata()) {
    if (m.name == estimator::io::kOptionsMetadata) run.options_yaml = m.metadata.at("yaml");
  }
  std::map<uint16_t, std::string> topic_of;
  for (const auto& [id, channel] : reader.channels()) topic_of[id] = channel.topic;
  reader.ForEachMessage([&](const log::MessageView& m) {
    const std::string& topic = topic_of[m.channel_id];
    if (topic == estimator::io::kStateTopic) {
      msgs::EstimatorState s;
      EXPECT_TRUE(log::DeserializeMessage(m.data, &s));
      if (s.frame_id == 0) run.states_by_stamp[s.stamp_ns] = s;
    } else if (topic == estimator::io::kRelativePoseInputTopic) {
      ++run.relative_poses;
    }
    return true;
  });
  return run;
}

TEST(VioMatchesRoverdTest, EveryEstimateOfRoverEvalVioIsRoverdsBitForBit) {
  const testing::TempDir dir;
  const LoggedRun roverd = ReadLog(RunRoverd(dir.path()));
  ASSERT_FALSE(roverd.states_by_stamp.empty());

  host::eval::VioCommandOptions options;
  options.dataset_dir = Dataset();
  options.filter_config_path = kFilterConfig;
  options.vo_latency_s = 0.1;  // roverd's lockstep VO latency
  std::ostringstream progress;
  const host::eval::VioRun vio = host::eval::RunVioExperiment(options, progress);

  // The same filter, built by the same rule from the same calibration.
  EXPECT_EQ(estimator::ToYaml(vio.filter_options), roverd.options_yaml);
  ASSERT_TRUE(vio.filter_init_stamp.has_value());
  ASSERT_GT(vio.states.size(), 500u);
  // The VO fused from the start: relative poses reached the filter.
  EXPECT_GT(vio.measurements.size(), 50u);
  EXPECT_GE(roverd.relative_poses, vio.measurements.size());

  std::size_t compared = 0;
  for (const host::eval::VioState& s : vio.states) {
    const auto it = roverd.states_by_stamp.find(s.stamp.nanoseconds());
    ASSERT_NE(it, roverd.states_by_stamp.end()) << "no roverd state at " << s.stamp.nanoseconds();
    const msgs::EstimatorState& r = it->second;
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      ASSERT_EQ(s.p_local_body[i], r.p_local_body_m[k]) << "p at " << s.stamp.nanoseconds();
      ASSERT_EQ(s.v_local_m_s[i], r.v_local_m_s[k]) << "v at " << s.stamp.nanoseconds();
    }
    ASSERT_EQ(s.q_local_body.x(), r.q_local_body_xyzw[0]) << s.stamp.nanoseconds();
    ASSERT_EQ(s.q_local_body.y(), r.q_local_body_xyzw[1]) << s.stamp.nanoseconds();
    ASSERT_EQ(s.q_local_body.z(), r.q_local_body_xyzw[2]) << s.stamp.nanoseconds();
    ASSERT_EQ(s.q_local_body.w(), r.q_local_body_xyzw[3]) << s.stamp.nanoseconds();
    ++compared;
  }
  EXPECT_EQ(compared, vio.states.size());
}

}  // namespace
}  // namespace rover
