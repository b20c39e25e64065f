// The rover graph's factors as log records: exact round trip, the same graph
// rebuilt from a log, and bad or cut logs that lose only what is damaged.

#include "mapping/slam/graph_log.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "core/geometry/so3.h"
#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/message_traits.h"
#include "mapping/graph/rover_graph.h"
#include "tests/support/temp_dir.h"

namespace rover::mapping {
namespace {

Matrix6d RandomCovariance(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = n(rng);
  return A * A.transpose() * 1e-3 + 1e-6 * Matrix6d::Identity();
}

Eigen::Isometry3d RandomPose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSO3(Eigen::Vector3d(n(rng), n(rng), n(rng)));
  T.translation() = Eigen::Vector3d(n(rng), n(rng), n(rng)) * 10.0;
  return T;
}

// A chain of frame switches with a loop closure, as mapd would log it.
std::vector<GraphFactorRecord> Mission(std::mt19937& rng, int switches) {
  std::vector<GraphFactorRecord> out;
  out.push_back(
      OriginPriorFactor(0, 0, Eigen::Isometry3d::Identity(), 1e-8 * Matrix6d::Identity()));
  for (int i = 0; i < switches; ++i) {
    Eigen::Matrix4d C = Eigen::Matrix4d::Identity() * 1e-3;
    out.push_back(FrameSwitchFactor(0, i, Eigen::Vector3d(7.0, 0.5 * i, 0.1), 0.3 * i, C));
  }
  out.push_back(SubmapMatchFactor(GraphKey::Origin(0, switches), GraphKey::Origin(0, 0),
                                  RandomPose(rng), RandomCovariance(rng)));
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].id = k + 1;
    out[k].stamp_ns = 1'000'000'000 * static_cast<int64_t>(k);
  }
  return out;
}

void WriteLog(const std::string& path, const std::vector<GraphFactorRecord>& factors,
              bool flush_each) {
  log::McapWriter writer;
  writer.Open(path);
  using Traits = log::MessageTraits<log::rover_msgs::GraphFactor>;
  const std::string_view definition = Traits::Definition();
  const uint16_t schema = writer.AddSchema(
      Traits::kName, "ros2msg", std::as_bytes(std::span(definition.data(), definition.size())));
  const uint16_t channel = writer.AddChannel(schema, kGraphFactorTopic, "cdr");
  uint32_t sequence = 0;
  for (const GraphFactorRecord& f : factors) {
    const auto bytes = log::SerializeMessage(ToMsg(f, "graph/rover"));
    const auto t = static_cast<uint64_t>(f.stamp_ns);
    writer.WriteMessage(channel, sequence++, t, t, bytes);
    if (flush_each) writer.FlushChunk();
  }
  writer.Close();
}

void ExpectSameRecord(const GraphFactorRecord& a, const GraphFactorRecord& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.a, b.a);
  EXPECT_EQ(a.b, b.b);
  EXPECT_LT((a.T_a_b.matrix() - b.T_a_b.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(a.covariance, b.covariance);
  EXPECT_EQ(a.robust, b.robust);
}

TEST(GraphFactorRecordTest, KeysParseBackFromTheirNames) {
  for (const GraphKey& k : {GraphKey::Origin(0, 3), GraphKey::Origin(7, 123456789012),
                            GraphKey::Pose(1, 17), GraphKey::Landmark(4)}) {
    EXPECT_EQ(ParseGraphKey(k.ToString()), k) << k.ToString();
  }
  for (const char* bad : {"", "s", "s0", "s_3", "s0_", "q0_3", "s0_3x", "l", "x-1_2", "s0_3_4"}) {
    EXPECT_FALSE(ParseGraphKey(bad).has_value()) << bad;
  }
}

TEST(GraphFactorRecordTest, MessagesRoundTrip) {
  std::mt19937 rng(3);
  for (const GraphFactorRecord& f : Mission(rng, 5)) {
    const auto bytes = log::SerializeMessage(ToMsg(f, "graph/rover"));
    log::rover_msgs::GraphFactor msg;
    ASSERT_TRUE(log::DeserializeMessage(bytes, &msg));
    ExpectSameRecord(FromMsg(msg), f);
  }
}

TEST(GraphFactorRecordTest, MalformedMessagesNameTheFactorAndField) {
  std::mt19937 rng(4);
  const log::rover_msgs::GraphFactor good = ToMsg(Mission(rng, 1)[1], "graph/rover");
  const auto expect_error = [](log::rover_msgs::GraphFactor m, const std::string& field) {
    try {
      FromMsg(m);
      ADD_FAILURE() << "accepted a factor with a bad " << field;
    } catch (const GraphError& e) {
      EXPECT_NE(std::string(e.what()).find("graph factor 2"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  auto m = good;
  m.kind = 9;
  expect_error(m, "kind");
  m = good;
  m.key_a = "origin3";
  expect_error(m, "key_a");
  m = good;
  m.q_a_b_wxyz = {0.0, 0.0, 0.0, 0.0};
  expect_error(m, "q_a_b_wxyz");
  m = good;
  m.covariance[7] = std::nan("");
  expect_error(m, "covariance");
}

TEST(GraphFactorRecordTest, KeysThatDoNotFitTheKindAreRefused) {
  RoverGraph graph;
  GraphFactorRecord w =
      FrameSwitchFactor(0, 2, Eigen::Vector3d(1, 0, 0), 0.0, Eigen::Matrix4d::Identity() * 1e-3);
  w.b = GraphKey::Origin(0, 5);
  EXPECT_THROW(AddToGraph(w, &graph), GraphError);
}

// The graph rebuilt from the log is, bit for bit, the graph built live from
// the logged form of each factor (what mapd adds; the quaternion in the log
// rounds the rotation, so the log's form is the one both must use).
TEST(GraphLogTest, RebuildsTheSameGraph) {
  const testing::TempDir dir;
  std::mt19937 rng(5);
  const std::vector<GraphFactorRecord> factors = Mission(rng, 8);
  const std::string path = (dir.path() / "mapd.mcap").string();
  WriteLog(path, factors, /*flush_each=*/true);
  const GraphLogContents read = ReadGraphLogs({path});
  EXPECT_TRUE(read.problems.empty());
  ASSERT_EQ(read.factors.size(), factors.size());
  RoverGraph live;
  RoverGraph rebuilt;
  for (std::size_t k = 0; k < factors.size(); ++k) {
    ExpectSameRecord(read.factors[k], factors[k]);
    AddToGraph(FromMsg(ToMsg(factors[k], "graph/rover")), &live);
    AddToGraph(read.factors[k], &rebuilt);
  }
  live.Optimize();
  rebuilt.Optimize();
  for (int64_t i = 0; i <= 8; ++i) {
    EXPECT_EQ(live.Origin(0, i).matrix(), rebuilt.Origin(0, i).matrix()) << i;
  }
}

// Two logs of one mission (mapd restarted and logged the graph again) give
// every factor once.
TEST(GraphLogTest, FactorsInSeveralLogsAreReadOnce) {
  const testing::TempDir dir;
  std::mt19937 rng(6);
  const std::vector<GraphFactorRecord> factors = Mission(rng, 6);
  const std::string first = (dir.path() / "a.mcap").string();
  const std::string second = (dir.path() / "b.mcap").string();
  WriteLog(first, {factors.begin(), factors.begin() + 4}, true);
  WriteLog(second, factors, true);
  const GraphLogContents read = ReadGraphLogs({first, second});
  EXPECT_EQ(read.factors.size(), factors.size());
  EXPECT_EQ(read.duplicates, 4u);
}

// mapd killed mid-write: every factor before the cut is kept, the cut is
// reported, nothing throws.
TEST(GraphLogTest, ALogCutMidFactorKeepsEveryEarlierFactor) {
  const testing::TempDir dir;
  std::mt19937 rng(7);
  const std::vector<GraphFactorRecord> factors = Mission(rng, 6);
  const std::string path = (dir.path() / "cut.mcap").string();
  WriteLog(path, factors, true);
  const GraphLogContents whole = ReadGraphLogs({path});
  ASSERT_EQ(whole.factors.size(), factors.size());
  // Cut inside the last factor's chunk: find the size at which the last
  // factor is lost but the one before is kept.
  const auto size = std::filesystem::file_size(path);
  std::size_t kept = 0;
  bool truncated = false;
  std::vector<std::string> problems;
  for (auto cut = size - 1; cut > 0; --cut) {
    std::filesystem::resize_file(path, cut);
    const GraphLogContents read = ReadGraphLogs({path});
    if (read.factors.size() < factors.size()) {
      kept = read.factors.size();
      truncated = read.truncated;
      problems = read.problems;
      break;
    }
  }
  EXPECT_EQ(kept, factors.size() - 1);
  EXPECT_TRUE(truncated);
  ASSERT_FALSE(problems.empty());
  EXPECT_NE(problems.front().find("cut.mcap"), std::string::npos) << problems.front();
}

// The graph's origins replace the switch chain's, expressed in the chain's
// map frame through the graph's anchor frame.
TEST(GraphLogTest, GraphOriginsPlaceFramesInTheMapFrameThroughTheAnchor) {
  std::mt19937 rng(8);
  std::map<uint32_t, Eigen::Isometry3d> origins;  // the chain, map frame = frame 2
  for (uint32_t f = 2; f <= 5; ++f) origins[f] = RandomPose(rng);
  log::rover_msgs::SubmapOrigins graph;
  std::map<int64_t, Eigen::Isometry3d> truth_in_graph;
  for (int64_t f = 3; f <= 6; ++f) {  // anchored at frame 3
    truth_in_graph[f] = RandomPose(rng);
    log::rover_msgs::SubmapOrigin o;
    o.submap = f;
    o.pose = ToPoseMsg(truth_in_graph[f]);
    graph.origins.push_back(o);
  }
  const Eigen::Isometry3d T_map_graph = origins.at(3) * truth_in_graph.at(3).inverse();
  const std::map<uint32_t, Eigen::Isometry3d> chain = origins;
  EXPECT_EQ(PlaceAtGraphOrigins(graph, &origins), 4u);
  EXPECT_EQ(origins.at(2).matrix(), chain.at(2).matrix()) << "not in the graph: kept";
  EXPECT_LT((origins.at(3).matrix() - chain.at(3).matrix()).norm(), 1e-12) << "the anchor stays";
  for (int64_t f = 4; f <= 6; ++f) {
    const Eigen::Isometry3d expected = T_map_graph * truth_in_graph.at(f);
    EXPECT_LT((origins.at(static_cast<uint32_t>(f)).matrix() - expected.matrix()).norm(), 1e-9)
        << f;
  }
  // A graph whose anchor the chain does not know places nothing.
  std::map<uint32_t, Eigen::Isometry3d> elsewhere = {{9, Eigen::Isometry3d::Identity()}};
  EXPECT_EQ(PlaceAtGraphOrigins(graph, &elsewhere), 0u);
  EXPECT_FALSE(GraphInMap(graph, elsewhere).has_value());
}

}  // namespace
}  // namespace rover::mapping
