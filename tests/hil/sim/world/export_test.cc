// Ground-truth export: files present, contents consistent, bytes reproducible.

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "hil/sim/world/world.h"
#include "tests/hil/sim/world/test_worlds.h"

namespace rover::sim {
namespace {

using testing::SmallWorld;

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("rover_world_export_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

const char* const kFiles[] = {"world.yaml",   "heightfield.bin", "heightfield.yaml", "albedo.png",
                              "albedo.yaml",  "obstacles.png",   "obstacles.yaml",   "tags.csv",
                              "carriers.csv", "boxes.csv",       "rocks.csv",        "craters.csv"};

TEST(ExportTest, WritesEveryFileAndTheSameBytesTwice) {
  const World& world = SmallWorld();
  const std::filesystem::path a = TempDir("a");
  const std::filesystem::path b = TempDir("b");
  ExportWorldGroundTruth(world, a.string());
  ExportWorldGroundTruth(world, b.string());
  // A world generated again from the seed exports the same bytes as well.
  const std::filesystem::path c = TempDir("c");
  ExportWorldGroundTruth(World::Generate(testing::SmallWorldOptions(), 42), c.string());
  for (const char* name : kFiles) {
    ASSERT_TRUE(std::filesystem::exists(a / name)) << name;
    const std::string bytes = ReadFile(a / name);
    EXPECT_FALSE(bytes.empty()) << name;
    EXPECT_EQ(bytes, ReadFile(b / name)) << name;
    EXPECT_EQ(bytes, ReadFile(c / name)) << name;
  }

  // The heightfield bytes are the heights, little-endian float32, row-major.
  const std::string heights = ReadFile(a / "heightfield.bin");
  ASSERT_EQ(heights.size(), world.terrain.heights_m().size() * 4);
  const int ix = 123;
  const int iy = 456;
  float value = 0.0F;
  const std::size_t offset = 4 * (static_cast<std::size_t>(iy) * 801 + ix);
  uint32_t bits = 0;
  for (int k = 3; k >= 0; --k) {
    bits = (bits << 8) | static_cast<uint8_t>(heights[offset + static_cast<std::size_t>(k)]);
  }
  std::memcpy(&value, &bits, 4);
  EXPECT_EQ(value, world.terrain.HeightAtCell(ix, iy));

  const std::string yaml = ReadFile(a / "heightfield.yaml");
  EXPECT_NE(yaml.find("cols: 801"), std::string::npos);
  EXPECT_NE(yaml.find("rows: 801"), std::string::npos);
  EXPECT_NE(yaml.find("resolution_m: 0.05"), std::string::npos);
  EXPECT_NE(yaml.find("origin_xy_m: [-20, -20]"), std::string::npos);
  EXPECT_NE(yaml.find("frame: world"), std::string::npos);
  EXPECT_NE(yaml.find("layout: row-major float32 little-endian"), std::string::npos);

  const std::string obstacles = ReadFile(a / "obstacles.yaml");
  EXPECT_NE(obstacles.find("rule: |"), std::string::npos);
  EXPECT_NE(obstacles.find("negative_drop_m: 0.3"), std::string::npos);

  // One row per tag plus the header; static tags in the world frame.
  std::istringstream tags(ReadFile(a / "tags.csv"));
  std::string line;
  std::getline(tags, line);
  EXPECT_EQ(line, "carrier,is_static,tag_id,size_m,frame,px,py,pz,qw,qx,qy,qz");
  int rows = 0;
  int world_rows = 0;
  while (std::getline(tags, line)) {
    ++rows;
    world_rows += line.find(",world,") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(rows, 4 * 4 + 2 * 5);
  EXPECT_EQ(world_rows, 4 * 4);

  std::istringstream rocks(ReadFile(a / "rocks.csv"));
  int rock_rows = -1;
  while (std::getline(rocks, line)) ++rock_rows;
  EXPECT_EQ(rock_rows, static_cast<int>(world.rocks.size()));

  for (const auto& dir : {a, b, c}) std::filesystem::remove_all(dir);
}

TEST(ExportTest, FailsLoudlyOnAnUnwritableDirectory) {
  const std::filesystem::path file = TempDir("file");
  std::ofstream(file.string()) << "not a directory";
  EXPECT_THROW(ExportWorldGroundTruth(SmallWorld(), (file / "sub").string()), std::runtime_error);
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace rover::sim
