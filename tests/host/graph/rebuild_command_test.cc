// `rover-graph rebuild`: a mission's graph from mapd's logs, as g2o.

#include <gtest/gtest.h>

#include <sstream>

#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/message_traits.h"
#include "host/graph/commands.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/slam/graph_log.h"
#include "tests/support/temp_dir.h"

namespace rover::host {
namespace {

// A chain of `switches` frame switches closed by one submap match.
void WriteMapdLog(const std::string& path, int switches) {
  std::vector<mapping::GraphFactorRecord> factors;
  factors.push_back(mapping::OriginPriorFactor(0, 0, Eigen::Isometry3d::Identity(),
                                               1e-12 * mapping::Matrix6d::Identity()));
  for (int i = 0; i < switches; ++i) {
    factors.push_back(mapping::FrameSwitchFactor(0, i, Eigen::Vector3d(7.0, 0.0, 0.0), 1.5708,
                                                 Eigen::Matrix4d::Identity() * 1e-3));
  }
  Eigen::Isometry3d loop = Eigen::Isometry3d::Identity();
  loop.translation() = Eigen::Vector3d(0.1, -0.05, 0.0);
  factors.push_back(mapping::SubmapMatchFactor(mapping::GraphKey::Origin(0, switches),
                                               mapping::GraphKey::Origin(0, 0), loop,
                                               1e-4 * mapping::Matrix6d::Identity()));
  log::McapWriter writer;
  writer.Open(path);
  using Traits = log::MessageTraits<log::rover_msgs::GraphFactor>;
  const std::string_view definition = Traits::Definition();
  const uint16_t schema = writer.AddSchema(
      Traits::kName, "ros2msg", std::as_bytes(std::span(definition.data(), definition.size())));
  const uint16_t channel = writer.AddChannel(schema, mapping::kGraphFactorTopic, "cdr");
  for (std::size_t k = 0; k < factors.size(); ++k) {
    factors[k].id = k + 1;
    writer.WriteMessage(channel, static_cast<uint32_t>(k), k, k,
                        log::SerializeMessage(mapping::ToMsg(factors[k], "graph/rover")));
  }
  writer.Close();
}

TEST(RebuildCommandTest, WritesTheMissionGraphAsG2o) {
  const testing::TempDir dir;
  const std::string log_path = (dir.path() / "mapd-1.mcap").string();
  WriteMapdLog(log_path, 4);  // a square: the match closes it
  RebuildCommandOptions options;
  options.mapd_logs = {log_path};
  options.output = (dir.path() / "graph.g2o").string();
  options.keys_output = (dir.path() / "keys.csv").string();
  std::ostringstream out, err;
  ASSERT_EQ(RunRebuild(options, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("RESULT factors=6 loop_closures=1 variables=5"), std::string::npos)
      << out.str();
  const mapping::PoseGraph g = mapping::ReadG2oFile(options.output);
  EXPECT_EQ(g.vertices.size(), 5u);
  EXPECT_EQ(g.edges.size(), 5u);  // 4 switches and the match; the prior is vertex 0
  EXPECT_LT((g.vertices.front().pose.matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-9)
      << "vertex 0 is the anchor";
  // The loop pulled the chain: s0_4 ends near s0_0 (the switches alone put
  // it at the origin too, a square; the match asks for 0.1 m off).
  EXPECT_LT(g.vertices.back().pose.translation().norm(), 0.2);
  EXPECT_EQ(testing::ReadTextFile(options.keys_output).substr(0, 21), "g2o_id,key\n0,s0_0\n1,s");
}

TEST(RebuildCommandTest, ALogWithoutFactorsIsBadInput) {
  const testing::TempDir dir;
  const std::string path = (dir.path() / "empty.mcap").string();
  log::McapWriter writer;
  writer.Open(path);
  writer.Close();
  RebuildCommandOptions options;
  options.mapd_logs = {path};
  options.output = (dir.path() / "graph.g2o").string();
  std::ostringstream out, err;
  EXPECT_EQ(RunRebuild(options, out, err), 1);
  EXPECT_NE(err.str().find("no graph factors"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace rover::host
