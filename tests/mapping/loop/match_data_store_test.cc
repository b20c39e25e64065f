// Match data out of memory and back: SubmapMatchData's spill bytes give the
// same data and the same match, damaged bytes are refused with what is
// wrong; the MatchDataStore keeps the most recently used in memory, reads
// the others back, and keeps everything when it cannot spill.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mapping/loop/match_data_store.h"
#include "mapping/loop/submap_matcher.h"
#include "tests/mapping/loop/loop_test_scene.h"
#include "tests/support/temp_dir.h"

namespace rover::mapping {
namespace {

using Eigen::Isometry3d;
using testing::LoopWorld;

struct Drive {
  testing::SyntheticSubmap submap;
  std::shared_ptr<const SubmapMatchData> data;
};

class MatchDataStoreTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new LoopWorld;
    testing::ScatterRocks(-2, 22, -8, 8, 0.25, 1, world_);
    drives_ = new std::vector<Drive>;
    for (const auto& [start, yaw, seed] :
         {std::tuple{Eigen::Vector2d(0.0, 0.0), 0.0, 11}, {Eigen::Vector2d(1.0, 0.5), 0.2, 12}}) {
      Drive d;
      d.submap = testing::BuildSubmap(*world_, testing::StraightDrive(*world_, start, yaw, 12, 0.5),
                                      static_cast<uint64_t>(seed));
      d.data = SubmapMatchData::Build(d.submap.submap->cloud(), d.submap.submap->octree(), {});
      drives_->push_back(std::move(d));
    }
  }
  static void TearDownTestSuite() {
    delete drives_;
    delete world_;
  }
  static const Drive& At(int i) { return (*drives_)[static_cast<std::size_t>(i)]; }
  // A small unsuitable submap's data (too few points), distinct per `n`.
  static std::shared_ptr<const SubmapMatchData> Tiny(int n) {
    PointCloud cloud;
    for (int i = 0; i < 10 + n; ++i) {
      CloudPoint p;
      p.p_submap_m = Eigen::Vector3f(0.1f * static_cast<float>(i), static_cast<float>(n), 0.0f);
      p.obstacle = i % 2 == 0;
      cloud.push_back(p);
    }
    return SubmapMatchData::Build(cloud, octomap::OcTree(0.1), {});
  }

  static LoopWorld* world_;
  static std::vector<Drive>* drives_;
};

LoopWorld* MatchDataStoreTest::world_ = nullptr;
std::vector<Drive>* MatchDataStoreTest::drives_ = nullptr;

void ExpectSameData(const SubmapMatchData& a, const SubmapMatchData& b) {
  EXPECT_EQ(a.suitability(), b.suitability());
  EXPECT_EQ(a.suitability_reason(), b.suitability_reason());
  EXPECT_EQ(a.keypoints(), b.keypoints());
  EXPECT_EQ(a.descriptors().descriptors(), b.descriptors().descriptors());
  EXPECT_EQ(a.descriptors().search(), b.descriptors().search());
  EXPECT_EQ(a.yaw_reference_rad(), b.yaw_reference_rad());
  EXPECT_EQ(a.yaw_reference_strength(), b.yaw_reference_strength());
  EXPECT_EQ(a.cloud().points(), b.cloud().points());
  EXPECT_EQ(a.normals(), b.normals());
  EXPECT_EQ(a.obstacle(), b.obstacle());
  EXPECT_EQ(a.icp_points(), b.icp_points());
  EXPECT_EQ(a.icp_normals(), b.icp_normals());
  EXPECT_EQ(a.icp_obstacle(), b.icp_obstacle());
  EXPECT_EQ(a.obstacle_box_xy().min(), b.obstacle_box_xy().min());
  EXPECT_EQ(a.obstacle_box_xy().max(), b.obstacle_box_xy().max());
  EXPECT_EQ(a.obstacle_point_count(), b.obstacle_point_count());
  EXPECT_EQ(a.keypoints_before_filter(), b.keypoints_before_filter());
  EXPECT_EQ(a.keypoints_dropped_unknown(), b.keypoints_dropped_unknown());
  EXPECT_EQ(a.keypoints_dropped_support(), b.keypoints_dropped_support());
  EXPECT_EQ(a.keypoints_off_line(), b.keypoints_off_line());
  EXPECT_EQ(a.build_ms(), b.build_ms());
  EXPECT_EQ(a.Serialize(), b.Serialize());
}

TEST_F(MatchDataStoreTest, SpilledDataReadBackGiveTheSameMatchBitForBit) {
  ASSERT_TRUE(At(0).data->suitable()) << At(0).data->suitability_reason();
  ASSERT_TRUE(At(1).data->suitable()) << At(1).data->suitability_reason();
  const auto a = SubmapMatchData::Deserialize(At(0).data->Serialize(), {});
  const auto b = SubmapMatchData::Deserialize(At(1).data->Serialize(), {});
  ExpectSameData(*At(0).data, *a);
  ExpectSameData(*At(1).data, *b);
  // The rebuilt k-d trees answer as the originals: the match is identical.
  const Isometry3d truth = At(0).submap.T_world_submap.inverse() * At(1).submap.T_world_submap;
  MatchPrior prior;
  prior.T_a_b = truth;
  prior.covariance = Matrix6d::Identity() * 0.25;
  const SubmapMatcher matcher;
  const SubmapMatchResult original = matcher.Match(*At(0).data, *At(1).data, prior);
  const SubmapMatchResult copy = matcher.Match(*a, *b, prior);
  ASSERT_TRUE(original.accepted) << original.rejection;
  EXPECT_EQ(copy.accepted, original.accepted);
  EXPECT_EQ(copy.T_a_b.matrix(), original.T_a_b.matrix());
  EXPECT_EQ(copy.covariance, original.covariance);
  EXPECT_EQ(copy.inliers.size(), original.inliers.size());
}

TEST_F(MatchDataStoreTest, UnsuitableDataRoundTripToo) {
  const auto tiny = Tiny(3);
  ASSERT_EQ(tiny->suitability(), SubmapSuitability::kTooFewPoints);
  ExpectSameData(*tiny, *SubmapMatchData::Deserialize(tiny->Serialize(), {}));
}

TEST_F(MatchDataStoreTest, DamagedBytesAreRefusedSayingWhat) {
  const std::string bytes = At(0).data->Serialize();
  for (const std::size_t keep :
       {std::size_t{0}, std::size_t{3}, std::size_t{40}, bytes.size() / 2, bytes.size() - 1}) {
    try {
      SubmapMatchData::Deserialize(std::string_view(bytes).substr(0, keep), {});
      ADD_FAILURE() << "a stream cut at " << keep << " bytes was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("SubmapMatchData::Deserialize"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("bytes"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(SubmapMatchData::Deserialize(bytes + "x", {}), std::runtime_error);
  std::string bad_magic = bytes;
  bad_magic[0] ^= 0x5a;
  EXPECT_THROW(SubmapMatchData::Deserialize(bad_magic, {}), std::runtime_error);
}

TEST_F(MatchDataStoreTest, KeepsTheMostRecentInMemoryAndReadsTheRestBack) {
  rover::testing::TempDir dir;
  MatchDataStoreOptions options;
  options.resident_submaps = 2;
  options.spill_directory = dir.path().string();
  MatchDataStore store(options, {});
  std::vector<std::shared_ptr<const SubmapMatchData>> put = {At(0).data, At(1).data, Tiny(1),
                                                             Tiny(2), Tiny(3)};
  for (std::size_t i = 0; i < put.size(); ++i) store.Put(static_cast<int64_t>(i), put[i]);
  MatchDataStoreStats s = store.Stats();
  EXPECT_EQ(s.submaps, 5u);
  EXPECT_EQ(s.resident, 2u);
  EXPECT_EQ(s.spill_writes, 3u);
  EXPECT_GT(s.spilled_bytes, 0u);
  EXPECT_EQ(s.spill_reads, 0u);
  EXPECT_EQ(store.spill_directory(), dir.path().string());
  // The resident ones come from memory (the same object), the rest read back.
  EXPECT_EQ(store.Get(4).get(), put[4].get());
  for (int64_t key : {0, 1, 2}) {
    const auto back = store.Get(key);
    ASSERT_NE(back, nullptr);
    EXPECT_NE(back.get(), put[static_cast<std::size_t>(key)].get());
    ExpectSameData(*put[static_cast<std::size_t>(key)], *back);
  }
  s = store.Stats();
  EXPECT_EQ(s.spill_reads, 3u);
  EXPECT_EQ(s.resident, 2u);
  // 3 and 4 were written as 0 and 1 came back; 0 went out again for 2
  // without a write, as its bytes were in the file already.
  EXPECT_EQ(s.spill_writes, 5u);
  EXPECT_EQ(store.Get(99), nullptr);
  store.Erase(1);
  EXPECT_FALSE(store.Contains(1));
  EXPECT_EQ(store.Get(1), nullptr);
  EXPECT_EQ(store.Stats().submaps, 4u);
}

TEST_F(MatchDataStoreTest, ResidentZeroKeepsEverythingInMemory) {
  MatchDataStoreOptions options;
  options.resident_submaps = 0;
  MatchDataStore store(options, {});
  for (int i = 0; i < 6; ++i) store.Put(i, Tiny(i));
  EXPECT_EQ(store.Stats().resident, 6u);
  EXPECT_EQ(store.Stats().spill_writes, 0u);
  EXPECT_TRUE(store.spill_directory().empty());
}

TEST_F(MatchDataStoreTest, WithoutASpillDirectoryTheDataStayAndTheErrorSaysWhere) {
  MatchDataStoreOptions options;
  options.resident_submaps = 1;
  options.spill_directory = "/nonexistent/rover-spill";
  MatchDataStore store(options, {});
  const auto first = Tiny(1);
  const auto second = Tiny(2);
  store.Put(1, first);
  try {
    store.Put(2, second);
    ADD_FAILURE() << "spilling into a missing directory did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/rover-spill"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(store.Get(1).get(), first.get());
  EXPECT_EQ(store.Get(2).get(), second.get());
}

TEST_F(MatchDataStoreTest, RefusesNullDataAndNegativeBounds) {
  MatchDataStore store({}, {});
  EXPECT_THROW(store.Put(1, nullptr), std::invalid_argument);
  MatchDataStoreOptions negative;
  negative.resident_submaps = -1;
  try {
    MatchDataStore bad(negative, {});
    ADD_FAILURE() << "a negative bound was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("MatchDataStoreOptions.resident_submaps"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace rover::mapping
