#include "mapping/compose/map_export.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>

#include "mapping/compose/map_composer.h"
#include "tests/mapping/compose/compose_test_util.h"

namespace rover::mapping {
namespace {

using testing::FinestVoxels;
using ::testing::HasSubstr;
using testing::KeyTuple;
using testing::Pose;
using testing::RandomSubmapTree;

namespace fs = std::filesystem;

class MapExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("map_export_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A composed map of two yawed random submaps.
  static const octomap::OcTree& Map(MapComposer* composer) {
    std::mt19937 rng(21);
    composer->SetSubmap(1, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0),
                        std::make_shared<PointCloud>(), Pose(0, 0, 0, 0.3));
    composer->SetSubmap(2, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0),
                        std::make_shared<PointCloud>(), Pose(0.7, 0.4, 0, -0.5));
    return composer->Compose();
  }

  static PointCloud RandomCloud(std::size_t n) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
    std::bernoulli_distribution obstacle(0.3);
    PointCloud cloud(n);
    for (CloudPoint& point : cloud) {
      point.p_submap_m = Eigen::Vector3f(coordinate(rng), coordinate(rng), coordinate(rng));
      point.obstacle = obstacle(rng);
    }
    return cloud;
  }

  static std::set<KeyTuple> Occupied(const octomap::OcTree& tree) {
    std::set<KeyTuple> keys;
    for (const auto& [key, log_odds] : FinestVoxels(tree)) {
      if (log_odds >= tree.getOccupancyThresLog()) keys.insert(key);
    }
    return keys;
  }

  static std::set<KeyTuple> Known(const octomap::OcTree& tree) {
    std::set<KeyTuple> keys;
    for (const auto& entry : FinestVoxels(tree)) keys.insert(entry.first);
    return keys;
  }

  static std::string Contents(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  std::string ReadPlyError(const fs::path& path) {
    try {
      ReadPly(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    ADD_FAILURE() << "ReadPly accepted " << path;
    return "";
  }

  fs::path dir_;
};

TEST_F(MapExportTest, BtRoundTripKeepsOccupiedAndFreeVoxels) {
  MapComposer composer;
  const octomap::OcTree& map = Map(&composer);
  ASSERT_GT(Occupied(map).size(), 100u);
  const fs::path path = dir_ / "map.bt";
  WriteOctreeBt(map, path);
  EXPECT_FALSE(fs::exists(dir_ / "map.bt.tmp"));

  octomap::OcTree read(0.1);
  ASSERT_TRUE(read.readBinary(path.string()));
  EXPECT_DOUBLE_EQ(read.getResolution(), map.getResolution());
  EXPECT_EQ(Occupied(read), Occupied(map));
  EXPECT_EQ(Known(read), Known(map));
}

TEST_F(MapExportTest, OtRoundTripKeepsLogOdds) {
  MapComposer composer;
  const octomap::OcTree& map = Map(&composer);
  const fs::path path = dir_ / "map.ot";
  WriteOctreeOt(map, path);
  EXPECT_FALSE(fs::exists(dir_ / "map.ot.tmp"));

  std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(path.string()));
  ASSERT_NE(read, nullptr);
  const auto* tree = dynamic_cast<const octomap::OcTree*>(read.get());
  ASSERT_NE(tree, nullptr);
  EXPECT_EQ(FinestVoxels(*tree), FinestVoxels(map));  // exact floats
}

TEST_F(MapExportTest, PlyRoundTripIsExact) {
  const PointCloud cloud = RandomCloud(10000);
  const fs::path path = dir_ / "map.ply";
  WritePly(cloud, path);
  EXPECT_FALSE(fs::exists(dir_ / "map.ply.tmp"));
  const std::string contents = Contents(path);
  EXPECT_TRUE(contents.starts_with("ply\nformat binary_little_endian 1.0\n"));
  EXPECT_THAT(contents, HasSubstr("element vertex 10000\n"));
  EXPECT_THAT(contents, HasSubstr("property uchar obstacle\nend_header\n"));
  const std::size_t header = contents.find("end_header\n") + 11;
  EXPECT_EQ(contents.size(), header + 10000 * 16);
  // Colours: obstacles red, the rest grey.
  const std::size_t first_obstacle = static_cast<std::size_t>(
      std::find_if(cloud.begin(), cloud.end(), [](const CloudPoint& p) { return p.obstacle; }) -
      cloud.begin());
  EXPECT_EQ(static_cast<unsigned char>(contents[header + 16 * first_obstacle + 12]), 255u);
  EXPECT_EQ(static_cast<unsigned char>(contents[header + 16 * first_obstacle + 13]), 0u);

  const PointCloud read = ReadPly(path);
  ASSERT_EQ(read.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(read[i].p_submap_m, cloud[i].p_submap_m) << i;
    ASSERT_EQ(read[i].obstacle, cloud[i].obstacle) << i;
  }
  // An empty cloud is a valid file too.
  WritePly({}, dir_ / "empty.ply");
  EXPECT_TRUE(ReadPly(dir_ / "empty.ply").empty());
}

TEST_F(MapExportTest, TruncatedPlyNamesTheVertexCounts) {
  const fs::path path = dir_ / "cut.ply";
  WritePly(RandomCloud(10), path);
  fs::resize_file(path, fs::file_size(path) - 20);  // 8 whole vertices and a half
  const std::string error = ReadPlyError(path);
  EXPECT_THAT(error, HasSubstr(path.string()));
  EXPECT_THAT(error, HasSubstr("truncated"));
  EXPECT_THAT(error, HasSubstr("declares 10 vertices"));
  EXPECT_THAT(error, HasSubstr("holds 8 complete vertices"));
}

TEST_F(MapExportTest, MalformedPlyHeadersAreRejected) {
  const auto write = [this](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  };
  EXPECT_THAT(ReadPlyError(write("text.ply", "hello\n")), HasSubstr("bad header"));
  EXPECT_THAT(ReadPlyError(write("no_end.ply", "ply\nformat binary_little_endian 1.0\n")),
              HasSubstr("end_header"));
  std::string ascii = Contents([&] {
    WritePly({}, dir_ / "ok.ply");
    return dir_ / "ok.ply";
  }());
  ascii.replace(ascii.find("binary_little_endian"), 20, "ascii");
  EXPECT_THAT(ReadPlyError(write("ascii.ply", ascii)), HasSubstr("format"));
  std::string renamed = Contents(dir_ / "ok.ply");
  renamed.replace(renamed.find("obstacle"), 8, "label");
  EXPECT_THAT(ReadPlyError(write("label.ply", renamed)), HasSubstr("property uchar obstacle"));
  std::string bad_count = Contents(dir_ / "ok.ply");
  bad_count.replace(bad_count.find("vertex 0"), 8, "vertex -3");
  EXPECT_THAT(ReadPlyError(write("count.ply", bad_count)), HasSubstr("element vertex"));

  // Data beyond what the header declares.
  WritePly(RandomCloud(3), dir_ / "long.ply");
  std::ofstream(dir_ / "long.ply", std::ios::binary | std::ios::app) << "extra";
  EXPECT_THAT(ReadPlyError(dir_ / "long.ply"), HasSubstr("trailing data"));
  EXPECT_THAT(ReadPlyError(dir_ / "missing.ply"), HasSubstr("cannot open"));
}

TEST_F(MapExportTest, FailedWritesNameThePathAndLeaveTheOldFile) {
  const fs::path path = dir_ / "map.ply";
  WritePly(RandomCloud(5), path);
  const std::string before = Contents(path);
  // The temporary file's name is taken by a directory: it cannot be opened.
  fs::create_directory(dir_ / "map.ply.tmp");
  try {
    WritePly(RandomCloud(7), path);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string()));
    EXPECT_THAT(e.what(), HasSubstr("cannot open"));
  }
  EXPECT_EQ(Contents(path), before);

  octomap::OcTree tree(0.1);
  EXPECT_THROW(WriteOctreeBt(tree, dir_ / "no_such_dir" / "map.bt"), std::runtime_error);
  EXPECT_THROW(WriteOctreeOt(tree, dir_ / "no_such_dir" / "map.ot"), std::runtime_error);
}

}  // namespace
}  // namespace rover::mapping
