#include "mapping/submap/submap_codec.h"

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "mapping/submap/submap.h"
#include "tests/mapping/submap/submap_test_scene.h"

namespace rover::mapping {
namespace {

// A finished submap of two images of the rocky scene.
const Submap& Sample() {
  static const Submap submap = [] {
    Submap s(0, 0, SubmapOptions{});
    const RectifiedStereo head = testing::SimulatorHead(4);
    for (int i = 0; i < 2; ++i) {
      const Eigen::Isometry3d T = testing::CameraPose(0.3 * i, 0.0, 0.7, 0.0, 20.0);
      s.Integrate(testing::RenderDepth(head, T, testing::RockyGround(), 1.0), {}, T);
    }
    s.Finish();
    return s;
  }();
  return submap;
}

void ExpectError(const std::function<void()>& decode, const std::string& part) {
  try {
    decode();
    ADD_FAILURE() << "no error, expected one with \"" << part << "\"";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

std::string ReplaceFirst(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(SubmapCodecTest, BinaryRoundTripKeepsEveryVoxelsState) {
  const octomap::OcTree& tree = Sample().octree();
  const std::string bytes = EncodeOctreeBinary(tree);
  ASSERT_EQ(bytes.rfind("# Octomap OcTree binary file", 0), 0u);
  const auto decoded = DecodeOctreeBinary(bytes);
  ASSERT_NE(decoded, nullptr);
  EXPECT_DOUBLE_EQ(decoded->getResolution(), tree.getResolution());
  EXPECT_EQ(decoded->size(), tree.size());
  const auto a = testing::LeafVoxels(tree);
  const auto b = testing::LeafVoxels(*decoded);
  EXPECT_GT(a.occupied.size(), 100u);
  EXPECT_EQ(b.occupied, a.occupied);
  EXPECT_EQ(b.free, a.free);
  // Binary keeps the state only: free and occupied leaves at the bounds.
  for (const auto& [key, value] : b.log_odds) {
    ASSERT_EQ(value, a.occupied.count(key) ? decoded->getClampingThresMaxLog()
                                           : decoded->getClampingThresMinLog());
  }
}

TEST(SubmapCodecTest, FullRoundTripKeepsEveryLogOdds) {
  const octomap::OcTree& tree = Sample().octree();
  const auto decoded = DecodeOctreeFull(EncodeOctreeFull(tree));
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(decoded->size(), tree.size());
  const auto a = testing::LeafVoxels(tree);
  const auto b = testing::LeafVoxels(*decoded);
  EXPECT_EQ(b.log_odds, a.log_odds);
  EXPECT_EQ(b.occupied, a.occupied);
}

TEST(SubmapCodecTest, EmptyTreesRoundTrip) {
  const octomap::OcTree empty(0.1);
  EXPECT_EQ(DecodeOctreeBinary(EncodeOctreeBinary(empty))->size(), 0u);
  EXPECT_EQ(DecodeOctreeFull(EncodeOctreeFull(empty))->size(), 0u);
}

TEST(SubmapCodecTest, MalformedBinaryStreamsSayWhatIsWrong) {
  const std::string good = EncodeOctreeBinary(Sample().octree());
  const auto decode = [](std::string bytes) { return [bytes] { DecodeOctreeBinary(bytes); }; };
  ExpectError(decode(""), "empty input");
  ExpectError(decode("hello world\n"), "not an OctoMap stream");
  ExpectError(decode(EncodeOctreeFull(Sample().octree())), "use DecodeOctreeFull");
  ExpectError(decode(good.substr(0, good.find("data"))), "truncated header");
  ExpectError(decode(good.substr(0, good.size() - 7)), "truncated data");
  ExpectError(decode(good + "xyz"), "3 unexpected bytes");
  ExpectError(decode(ReplaceFirst(good, "id OcTree", "id ColorOcTree")), "expected an OcTree");
  ExpectError(decode(ReplaceFirst(good, "res 0.1", "res -1")), "res");
  ExpectError(decode(ReplaceFirst(good, "size ", "size 1")), "nodes");
  ExpectError(decode(ReplaceFirst(good, "size ", "size x")), "not a node count");
  // Every child "has children", forever: the walk stops at depth 16
  // instead of recursing through memory.
  const std::string header = good.substr(0, good.find("data\n") + 5);
  ExpectError(decode(header + std::string(64, '\xff')), "inner node below depth 15");
}

TEST(SubmapCodecTest, MalformedFullStreamsSayWhatIsWrong) {
  const std::string good = EncodeOctreeFull(Sample().octree());
  const auto decode = [](std::string bytes) { return [bytes] { DecodeOctreeFull(bytes); }; };
  ExpectError(decode(""), "empty input");
  ExpectError(decode(EncodeOctreeBinary(Sample().octree())), "use DecodeOctreeBinary");
  ExpectError(decode(good.substr(0, good.size() - 3)), "truncated data");
  ExpectError(decode(ReplaceFirst(good, "size ", "size 9")), "nodes");
  std::string nan = good;
  const float value = std::numeric_limits<float>::quiet_NaN();
  nan.replace(good.find("data\n") + 5, sizeof(value), reinterpret_cast<const char*>(&value),
              sizeof(value));
  ExpectError(decode(nan), "not finite");
}

}  // namespace
}  // namespace rover::mapping
