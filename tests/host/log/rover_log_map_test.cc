// rover-log map: synthetic mapd logs (written here with McapWriter, as mapd's
// own writer is firmware-only) and roverd frame switches, composed into the
// global map and read back from the exported files.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"
#include "core/log/msgs/all_msgs.h"
#include "host/log/commands.h"
#include "host/log/submap_chain.h"
#include "mapping/compose/map_export.h"
#include "mapping/compose/submap_log.h"
#include "mapping/submap/submap_messages.h"
#include "tests/support/temp_dir.h"

namespace rover::host {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kPi = 3.14159265358979323846;

std::span<const std::byte> AsBytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

template <typename T>
uint16_t AddChannel(log::McapWriter* writer, const std::string& topic) {
  using Traits = log::MessageTraits<T>;
  const uint16_t schema =
      writer->AddSchema(Traits::kName, log::kRos2MsgSchemaEncoding, AsBytes(Traits::Definition()));
  return writer->AddChannel(schema, topic, log::kCdrMessageEncoding);
}

// One submap of a synthetic log: a few occupied voxels and cloud points in
// its own frame.
struct TestSubmap {
  uint32_t index = 0;
  uint32_t frame_id = 0;
  bool has_origin = false;
  uint32_t previous_frame_id = 0;
  Eigen::Vector3d p_previous_origin_m = Eigen::Vector3d::Zero();
  double yaw_previous_origin_rad = 0.0;
  std::vector<Eigen::Vector3d> occupied;  // voxel centres, submap frame
  std::vector<Eigen::Vector3f> obstacles;
};

octomap::OcTree MakeTree(const std::vector<Eigen::Vector3d>& occupied) {
  octomap::OcTree tree(0.1);
  for (const Eigen::Vector3d& p : occupied) {
    for (int i = 0; i < 3; ++i) {
      tree.updateNode(octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                       static_cast<float>(p.z())),
                      true);
    }
  }
  return tree;
}

// Writes a mapd log the way mapd does: per submap its info, octomap and
// cloud with one header. Small chunks, so that a cut file keeps whole
// submaps.
class MapdLogWriter {
 public:
  explicit MapdLogWriter(const std::string& path) : writer_(Options()) {
    writer_.Open(path);
    info_ = AddChannel<log::rover_msgs::SubmapInfo>(&writer_, mapping::kSubmapInfoTopic);
    octomap_ = AddChannel<log::octomap_msgs::Octomap>(&writer_, mapping::kSubmapOctomapTopic);
    cloud_ = AddChannel<log::sensor_msgs::PointCloud2>(&writer_, mapping::kSubmapCloudTopic);
  }

  void Add(const TestSubmap& s, bool with_cloud = true) {
    const int64_t t = 1'000'000'000 + int64_t{s.index} * 1'000'000'000;
    log::std_msgs::Header header;
    header.stamp = log::ToRosTime(Time::FromNanoseconds(t));
    header.frame_id = log::FrameId::Truncated("local/r1/" + std::to_string(s.frame_id));
    const octomap::OcTree tree = MakeTree(s.occupied);
    mapping::PointCloud cloud;
    for (const Eigen::Vector3d& p : s.occupied) cloud.push_back({p.cast<float>(), false});
    for (const Eigen::Vector3f& p : s.obstacles) cloud.push_back({p, true});
    const log::octomap_msgs::Octomap octomap = mapping::ToOctomapMsg(tree, header);
    const log::sensor_msgs::PointCloud2 points = mapping::ToPointCloud2(cloud, header);

    log::rover_msgs::SubmapInfo info;
    info.header = header;
    info.index = s.index;
    info.frame_id = s.frame_id;
    info.has_origin = s.has_origin;
    info.previous_frame_id = s.previous_frame_id;
    info.p_previous_origin_m = {s.p_previous_origin_m.x(), s.p_previous_origin_m.y(),
                                s.p_previous_origin_m.z()};
    info.yaw_previous_origin_rad = s.yaw_previous_origin_rad;
    info.images = 10 + s.index;
    info.distance_m = 1.5 * s.index;
    info.octree_bytes = log::SerializedSize(octomap);
    info.cloud_bytes = log::SerializedSize(points);
    const uint64_t time = static_cast<uint64_t>(t);
    writer_.WriteMessage(info_, sequence_++, time, time, log::SerializeMessage(info));
    writer_.WriteMessage(octomap_, sequence_++, time, time, log::SerializeMessage(octomap));
    if (with_cloud) {
      writer_.WriteMessage(cloud_, sequence_++, time, time, log::SerializeMessage(points));
    }
  }

  void Close() {
    writer_.WriteMetadata("mapd_statistics", {{"submaps", "?"}});
    writer_.Close();
  }

 private:
  static log::McapWriterOptions Options() {
    log::McapWriterOptions options;
    options.chunk_size_bytes = 256;
    return options;
  }

  log::McapWriter writer_;
  uint16_t info_ = 0;
  uint16_t octomap_ = 0;
  uint16_t cloud_ = 0;
  uint32_t sequence_ = 0;
};

void WriteRoverdLog(const std::string& path,
                    const std::vector<log::rover_msgs::EstimatorFrameSwitch>& switches) {
  log::McapWriter writer;
  writer.Open(path);
  const uint16_t channel =
      AddChannel<log::rover_msgs::EstimatorFrameSwitch>(&writer, "/estimator/frame_switch_record");
  uint32_t sequence = 0;
  for (const log::rover_msgs::EstimatorFrameSwitch& s : switches) {
    const uint64_t t = static_cast<uint64_t>(s.stamp_ns);
    writer.WriteMessage(channel, sequence++, t, t, log::SerializeMessage(s));
  }
  writer.Close();
}

log::rover_msgs::EstimatorFrameSwitch Switch(uint32_t from, uint32_t to, double x, double y,
                                             double yaw_rad) {
  log::rover_msgs::EstimatorFrameSwitch s;
  s.stamp_ns = 1'500'000'000 + int64_t{to} * 1'000'000'000;
  s.old_frame_id = from;
  s.new_frame_id = to;
  s.p_old_new_m = {x, y, 0.0};
  s.yaw_old_new_rad = yaw_rad;
  return s;
}

TestSubmap Submap(uint32_t index, uint32_t frame, std::vector<Eigen::Vector3d> occupied) {
  TestSubmap s;
  s.index = index;
  s.frame_id = frame;
  s.occupied = std::move(occupied);
  return s;
}

TestSubmap ChainedSubmap(uint32_t index, uint32_t frame, uint32_t previous, double x,
                         double yaw_rad, std::vector<Eigen::Vector3d> occupied) {
  TestSubmap s = Submap(index, frame, std::move(occupied));
  s.has_origin = true;
  s.previous_frame_id = previous;
  s.p_previous_origin_m = Eigen::Vector3d(x, 0.0, 0.0);
  s.yaw_previous_origin_rad = yaw_rad;
  return s;
}

bool OccupiedAt(const octomap::OcTree& tree, double x, double y, double z) {
  const octomap::OcTreeNode* node = tree.search(x, y, z);
  return node != nullptr && tree.isNodeOccupied(node);
}

bool CloudHasPointNear(const mapping::PointCloud& cloud, const Eigen::Vector3f& p,
                       std::optional<bool> obstacle = std::nullopt) {
  for (const mapping::CloudPoint& c : cloud) {
    if ((c.p_submap_m - p).norm() < 1e-3f && (!obstacle || c.obstacle == *obstacle)) return true;
  }
  return false;
}

class RoverLogMapTest : public ::testing::Test {
 protected:
  std::string File(std::string_view name) const { return dir_.File(name).string(); }

  testing::TempDir dir_{"rover_log_map"};
  std::ostringstream out_, err_;
};

TEST_F(RoverLogMapTest, PlacesSubmapsOfTwoMapdLogsAtRoverdFrameOrigins) {
  // mapd ran, was restarted during frame 2: its second log has frame 2's
  // submap without an origin; roverd's log has every switch.
  const std::string first = File("mapd-1-100.mcap");
  const std::string second = File("mapd-2-200.mcap");
  {
    MapdLogWriter log(first);
    log.Add(Submap(0, 0, {{1.05, 0.05, 0.05}, {1.15, 0.05, 0.05}}));
    TestSubmap s1 = ChainedSubmap(1, 1, 0, 2.0, kPi / 2, {{0.55, 0.05, 0.05}});
    s1.obstacles = {Eigen::Vector3f(0.5f, 0.0f, 0.3f)};
    log.Add(s1);
    log.Close();
  }
  {
    MapdLogWriter log(second);
    log.Add(Submap(0, 2, {{0.25, 0.25, 0.05}}));
    log.Close();
  }
  const std::string roverd = File("flight.mcap");
  WriteRoverdLog(roverd, {Switch(0, 1, 2.0, 0.0, kPi / 2), Switch(1, 2, 1.0, 0.0, 0.0)});

  MapOptions options;
  options.mapd_logs = {first, second};
  options.roverd_log = roverd;
  options.out_stem = File("out/mission");
  options.progress_min_submaps = 1;
  EXPECT_EQ(RunMap(options, out_, err_), 0) << out_.str() << err_.str();
  const std::string report = out_.str();

  // Frame 1 is 2 m ahead, turned left by 90 deg: its (0.55, 0.05) is at
  // (1.95, 0.55); frame 2 is 1 m further along frame 1's x.
  const octomap::OcTree bt(File("out/mission.bt"));
  EXPECT_TRUE(OccupiedAt(bt, 1.05, 0.05, 0.05));
  EXPECT_TRUE(OccupiedAt(bt, 1.15, 0.05, 0.05));
  EXPECT_TRUE(OccupiedAt(bt, 1.95, 0.55, 0.05));
  EXPECT_FALSE(OccupiedAt(bt, 0.55, 0.05, 0.05)) << "frame 1's voxel left untransformed";
  EXPECT_TRUE(OccupiedAt(bt, 1.75, 1.25, 0.05));
  EXPECT_FALSE(OccupiedAt(bt, 0.25, 0.25, 0.05));

  std::unique_ptr<octomap::AbstractOcTree> ot(
      octomap::AbstractOcTree::read(File("out/mission.ot")));
  ASSERT_NE(ot, nullptr);
  const auto* ot_tree = dynamic_cast<const octomap::OcTree*>(ot.get());
  ASSERT_NE(ot_tree, nullptr);
  EXPECT_TRUE(OccupiedAt(*ot_tree, 1.95, 0.55, 0.05));

  const mapping::PointCloud cloud = mapping::ReadPly(File("out/mission.ply"));
  EXPECT_EQ(cloud.size(), 5u);
  EXPECT_TRUE(CloudHasPointNear(cloud, {1.95f, 0.55f, 0.05f}, false));
  EXPECT_TRUE(CloudHasPointNear(cloud, {2.0f, 0.5f, 0.3f}, true)) << "obstacle placed and kept";
  EXPECT_TRUE(CloudHasPointNear(cloud, {1.75f, 1.25f, 0.05f}));

  EXPECT_THAT(report, HasSubstr("log 1: " + first));
  EXPECT_THAT(report, HasSubstr("log 2: " + second));
  EXPECT_THAT(report, HasSubstr("submaps: 2,"));
  EXPECT_THAT(report, HasSubstr("submaps: 1,"));
  EXPECT_THAT(report, ::testing::ContainsRegex("\n +1 +1 +11 +1\\.50 .* yes\n"));
  EXPECT_THAT(report, HasSubstr("frame 0 of " + roverd + " (3 frame(s) placed)"));
  EXPECT_THAT(report, HasSubstr("unplaced submaps: 0"));
  EXPECT_THAT(report, HasSubstr("submaps placed:   3 of 3"));
  EXPECT_THAT(report, HasSubstr("occupied voxels:  4\n"));
  EXPECT_THAT(report, HasSubstr("cloud points:     5\n"));
  EXPECT_THAT(report, HasSubstr("obstacle points:  1\n"));
  EXPECT_THAT(report, HasSubstr("compose time:"));
  EXPECT_THAT(report, HasSubstr(File("out/mission.bt")));
  EXPECT_THAT(report, HasSubstr(File("out/mission.ply")));
  EXPECT_THAT(report, HasSubstr("octovis " + File("out/mission.bt")));
  EXPECT_THAT(report, Not(HasSubstr("problems:")));
  EXPECT_THAT(err_.str(), HasSubstr("composing: 3/3 submaps"));
}

TEST_F(RoverLogMapTest, FormatsSelectTheFilesAndNoCloudSkipsThePly) {
  const std::string path = File("mapd.mcap");
  {
    MapdLogWriter log(path);
    log.Add(Submap(0, 3, {{0.05, 0.05, 0.05}}));
    log.Close();
  }
  MapOptions options;
  options.mapd_logs = {path};
  options.out_stem = File("m");
  options.write_ot = false;
  options.write_ply = false;
  options.compose_cloud = false;
  EXPECT_EQ(RunMap(options, out_, err_), 0) << err_.str();
  EXPECT_TRUE(std::filesystem::exists(File("m.bt")));
  EXPECT_FALSE(std::filesystem::exists(File("m.ot")));
  EXPECT_FALSE(std::filesystem::exists(File("m.ply")));
  EXPECT_THAT(out_.str(), HasSubstr("not composed (--no-cloud)"));

  options.write_ply = true;  // --no-cloud --format ply: nothing to write
  EXPECT_EQ(RunMap(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr("--no-cloud"));
}

TEST_F(RoverLogMapTest, WithoutRoverdLogChainsBySubmapOriginsAndReportsWhatDoesNotChain) {
  const std::string path = File("mapd.mcap");
  {
    MapdLogWriter log(path);
    // The first submap's frame is the map frame, whatever its own origin.
    log.Add(ChainedSubmap(0, 5, 4, 9.0, 1.0, {{0.05, 0.05, 0.05}}));
    log.Add(ChainedSubmap(1, 6, 5, 1.0, kPi, {{0.35, 0.05, 0.05}}));
    log.Add(ChainedSubmap(2, 8, 7, 1.0, 0.0, {{2.05, 2.05, 0.05}}));  // frame 7 has no submap
    log.Add(Submap(3, 9, {{3.05, 3.05, 0.05}}));                      // mapd joined half-way
    log.Add(ChainedSubmap(4, 10, 6, 1.0, 0.0, {{0.05, 0.05, 0.05}}));
    log.Close();
  }
  MapOptions options;
  options.mapd_logs = {path};
  options.out_stem = File("chained");
  EXPECT_EQ(RunMap(options, out_, err_), 1) << "submaps were left out";
  const std::string report = out_.str();

  const octomap::OcTree bt(File("chained.bt"));
  EXPECT_TRUE(OccupiedAt(bt, 0.05, 0.05, 0.05));
  // Frame 6: 1 m ahead, turned around: its (0.35, 0.05) is at (0.65, -0.05).
  EXPECT_TRUE(OccupiedAt(bt, 0.65, -0.05, 0.05));
  // Frame 10: 1 m ahead along frame 6's x, i.e. back at x = 0, its (0.05,
  // 0.05) at (-0.05, -0.05).
  EXPECT_TRUE(OccupiedAt(bt, -0.05, -0.05, 0.05));
  EXPECT_FALSE(OccupiedAt(bt, 2.05, 2.05, 0.05));
  EXPECT_FALSE(OccupiedAt(bt, 3.05, 3.05, 0.05));
  EXPECT_EQ(mapping::ReadPly(File("chained.ply")).size(), 3u);

  EXPECT_THAT(report, HasSubstr("the first submap's frame"));
  EXPECT_THAT(report, HasSubstr("unplaced submaps: 2"));
  EXPECT_THAT(report, HasSubstr("submap 2 (frame 8): its origin starts in frame 7"));
  EXPECT_THAT(report, HasSubstr("submap 3 (frame 9): no origin recorded"));
  EXPECT_THAT(report, HasSubstr("submaps placed:   3 of 5"));
  EXPECT_THAT(err_.str(), HasSubstr("2 submap(s) left out"));
}

TEST(SubmapChainTest, ChainsFromTheFirstSubmapsFrameInAnyOrder) {
  const auto info = [](uint32_t frame, uint32_t previous, double x) {
    mapping::LoggedSubmap s;
    s.info.frame_id = frame;
    s.info.has_origin = true;
    s.info.previous_frame_id = previous;
    s.info.p_previous_origin_m = {x, 0.0, 0.0};
    return s;
  };
  // Frame 3 is logged before frame 2, which it builds on.
  const std::vector<mapping::LoggedSubmap> submaps = {info(1, 0, 5.0), info(3, 2, 2.0),
                                                      info(2, 1, 1.0), info(5, 4, 1.0)};
  const auto origins = ChainSubmapOrigins(submaps);
  ASSERT_EQ(origins.size(), 3u);
  EXPECT_TRUE(origins.at(1).isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_NEAR(origins.at(2).translation().x(), 1.0, 1e-12);
  EXPECT_NEAR(origins.at(3).translation().x(), 3.0, 1e-12);
  EXPECT_EQ(origins.count(5), 0u);
  EXPECT_THAT(WhyUnplaced(submaps[3].info, origins), HasSubstr("starts in frame 4"));
  EXPECT_TRUE(ChainSubmapOrigins({}).empty());
}

TEST_F(RoverLogMapTest, SeveralMapdLogsNeedTheRoverdLog) {
  MapOptions options;
  options.mapd_logs = {File("a.mcap"), File("b.mcap")};
  options.out_stem = File("x");
  EXPECT_EQ(RunMap(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr("--roverd-log"));
}

TEST_F(RoverLogMapTest, TruncatedMapdLogYieldsItsIntactSubmapsAndReportsTheDamage) {
  const std::string path = File("mapd-cut.mcap");
  {
    MapdLogWriter log(path);
    for (uint32_t i = 0; i < 8; ++i) {
      log.Add(Submap(i, 0, {{0.05 + 0.2 * i, 0.05, 0.05}}));
    }
    log.Close();
  }
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);  // power loss

  MapOptions options;
  options.mapd_logs = {path};
  options.out_stem = File("cut");
  EXPECT_EQ(RunMap(options, out_, err_), 1) << err_.str();
  const std::string report = out_.str();
  EXPECT_THAT(report, HasSubstr("problems:"));
  EXPECT_THAT(report, HasSubstr(path + ": damaged at byte"));
  EXPECT_THAT(report, HasSubstr("mapd statistics: absent"));
  EXPECT_THAT(err_.str(), HasSubstr("the map is incomplete"));

  const mapping::SubmapLog log = mapping::ReadSubmapLog(path);
  ASSERT_GE(log.submaps.size(), 2u);
  ASSERT_LT(log.submaps.size(), 8u);
  const octomap::OcTree bt(File("cut.bt"));
  for (const mapping::LoggedSubmap& s : log.submaps) {
    EXPECT_TRUE(OccupiedAt(bt, 0.05 + 0.2 * s.info.index, 0.05, 0.05)) << s.info.index;
  }
  EXPECT_FALSE(OccupiedAt(bt, 0.05 + 0.2 * 7, 0.05, 0.05)) << "the last submap was cut off";
  EXPECT_THAT(report, HasSubstr("submaps placed:   " + std::to_string(log.submaps.size())));
}

TEST_F(RoverLogMapTest, StreamedReadingHandsOnEachSubmapOnceCompleteAndReportsTheRest) {
  const std::string path = File("stream.mcap");
  MapdLogWriter writer(path);
  for (uint32_t i = 0; i < 5; ++i) writer.Add(Submap(i, i, {{0.05 + 0.2 * i, 0.05, 0.05}}), i != 3);
  writer.Close();

  std::vector<uint32_t> seen;
  const mapping::SubmapLog rest =
      mapping::ForEachLoggedSubmap(path, [&](mapping::LoggedSubmap&& s) {
        ASSERT_NE(s.octree, nullptr);
        ASSERT_NE(s.cloud, nullptr);
        EXPECT_TRUE(OccupiedAt(*s.octree, 0.05 + 0.2 * s.info.index, 0.05, 0.05));
        seen.push_back(s.info.index);
      });
  EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1, 2, 4}));
  EXPECT_TRUE(rest.submaps.empty());
  ASSERT_EQ(rest.problems.size(), 1u);
  EXPECT_THAT(rest.problems[0], HasSubstr("submap 3"));
  EXPECT_THAT(rest.problems[0], HasSubstr("cloud message is missing"));
  EXPECT_EQ(rest.statistics.at("submaps"), "?");
  // The whole-log reader gives the same.
  const mapping::SubmapLog all = mapping::ReadSubmapLog(path);
  ASSERT_EQ(all.submaps.size(), 4u);
  EXPECT_EQ(all.submaps[3].info.index, 4u);
  EXPECT_EQ(all.problems, rest.problems);

  // What the callback throws ends the reading and is not taken for damage.
  int calls = 0;
  EXPECT_THROW(mapping::ForEachLoggedSubmap(path,
                                            [&](mapping::LoggedSubmap&&) {
                                              if (++calls == 2) throw std::logic_error("enough");
                                            }),
               std::logic_error);
  EXPECT_EQ(calls, 2);
}

TEST_F(RoverLogMapTest, NonMcapFileIsExit2NamingTheFile) {
  const std::string path = File("notes.txt");
  std::ofstream(path) << "not a mapd log\n";
  MapOptions options;
  options.mapd_logs = {path};
  options.out_stem = File("x");
  EXPECT_EQ(RunMap(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr(path));
  EXPECT_FALSE(std::filesystem::exists(File("x.bt")));
}

TEST_F(RoverLogMapTest, LogWithoutSubmapsIsExit2NamingTheFile) {
  const std::string roverd = File("flight.mcap");
  WriteRoverdLog(roverd, {Switch(0, 1, 1.0, 0.0, 0.0)});
  MapOptions options;
  options.mapd_logs = {roverd};  // roverd's log given by mistake
  options.out_stem = File("x");
  EXPECT_EQ(RunMap(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr("no submaps in " + roverd));
}

TEST_F(RoverLogMapTest, UnreadableRoverdLogIsExit2NamingTheFile) {
  const std::string path = File("mapd.mcap");
  {
    MapdLogWriter log(path);
    log.Add(Submap(0, 0, {{0.05, 0.05, 0.05}}));
    log.Close();
  }
  MapOptions options;
  options.mapd_logs = {path};
  options.roverd_log = File("missing.mcap");
  options.out_stem = File("x");
  EXPECT_EQ(RunMap(options, out_, err_), 2);
  EXPECT_THAT(err_.str(), HasSubstr(options.roverd_log));
}

}  // namespace
}  // namespace rover::host
