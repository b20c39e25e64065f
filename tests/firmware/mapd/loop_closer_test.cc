// mapd's loop closer on synthetic submaps (tests/mapping/loop/loop_test_scene.h:
// rocks on sloped ground, stereo noise growing with range): a revisit is
// matched once its origin estimate is known and found close to the truth
// despite the drift in the estimates, successive and far-apart submaps are
// never paired, match data spilled to disk and read back give the same
// match, a submap without structure is counted as unsuitable, and stopping
// with work queued returns.

#include "firmware/mapd/loop_closer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tests/mapping/loop/loop_test_scene.h"
#include "tests/support/temp_dir.h"

namespace rover::mapd {
namespace {

using mapping::testing::LoopWorld;
using mapping::testing::SyntheticSubmap;

constexpr double kDeg = M_PI / 180.0;

SyntheticSubmap Drive(const LoopWorld& world, const Eigen::Vector2d& start, double yaw,
                      uint64_t seed, uint32_t frame) {
  return mapping::testing::BuildSubmap(
      world, mapping::testing::StraightDrive(world, start, yaw, 12, 0.5), seed, {}, frame);
}

// The origin estimate: the truth moved by the drift, with a covariance that
// covers it.
OptimisedOrigin Estimate(const Eigen::Isometry3d& truth, const Eigen::Vector3d& drift_m,
                         double drift_yaw_rad, double sigma_m, double sigma_yaw_rad) {
  OptimisedOrigin o;
  o.T_world_origin = truth * GravityAlignedTransform(drift_m, drift_yaw_rad);
  o.covariance.setZero();
  o.covariance.diagonal() << sigma_m * sigma_m, sigma_m * sigma_m, sigma_m * sigma_m, 1e-6, 1e-6,
      sigma_yaw_rad * sigma_yaw_rad;
  return o;
}

// The drives: frame 1 and its revisit 3 cover the first rock field; 2
// drives through the second field in between.
struct DriveSpec {
  Eigen::Vector2d start;
  double yaw_rad;
  uint64_t seed;
};
const std::map<uint32_t, DriveSpec>& Drives() {
  static const std::map<uint32_t, DriveSpec> drives = {
      {1, {{0.0, 0.0}, 0.0, 11}}, {2, {{0.0, 40.0}, 0.0, 12}}, {3, {{1.0, 0.5}, 0.2, 13}}};
  return drives;
}

// The finished submap, handed over as mapd does.
std::shared_ptr<const mapping::Submap> Take(SyntheticSubmap s) {
  return std::shared_ptr<const mapping::Submap>(std::move(s.submap));
}

// Another rover's submap, as the team link delivers it (octree and cloud).
void HandOverAsTeamSubmap(LoopCloser* closer, int robot, uint32_t frame, SyntheticSubmap s) {
  closer->AddTeamSubmap({robot, frame}, std::make_shared<const octomap::OcTree>(s.submap->octree()),
                        std::make_shared<const mapping::PointCloud>(s.submap->cloud()));
}

class LoopCloserTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new LoopWorld;
    mapping::testing::ScatterRocks(-2, 22, -8, 8, 0.25, 1, world_);
    mapping::testing::ScatterRocks(-2, 22, 32, 48, 0.25, 2, world_);
  }
  static void TearDownTestSuite() { delete world_; }

  static SyntheticSubmap Render(uint32_t frame) {
    const DriveSpec& d = Drives().at(frame);
    return Drive(*world_, d.start, d.yaw_rad, d.seed, frame);
  }

  static Eigen::Isometry3d Truth(uint32_t frame) {
    const DriveSpec& d = Drives().at(frame);
    return mapping::testing::SubmapFrameAt(
        mapping::testing::StraightDrive(*world_, d.start, d.yaw_rad, 12, 0.5).front());
  }

  // Origins as the graph would give them after some drift: frame 1 exact,
  // the later ones off by up to 0.3 m and 2 deg.
  static std::map<int64_t, OptimisedOrigin> DriftedOrigins() {
    std::map<int64_t, OptimisedOrigin> origins;
    origins[1] = Estimate(Truth(1), {0, 0, 0}, 0.0, 0.01, 0.1 * kDeg);
    origins[2] = Estimate(Truth(2), {0.1, -0.1, 0.0}, 1.0 * kDeg, 0.3, 1.5 * kDeg);
    origins[3] = Estimate(Truth(3), {0.3, -0.2, 0.05}, 2.0 * kDeg, 0.5, 3.0 * kDeg);
    return origins;
  }

  // Rover 1's view of a team: it drove frames 1 and 2, and rover 0's frame
  // 3 (from the team link) revisits its frame 1; the graph has placed all
  // three.
  static void HandOverTeamScene(LoopCloser* closer) {
    for (uint32_t frame : {1u, 2u}) closer->AddSubmap(Take(Render(frame)));
    HandOverAsTeamSubmap(closer, 0, 3, Render(3));
    std::map<int64_t, OptimisedOrigin> own = DriftedOrigins();
    const std::map<mapping::SubmapId, OptimisedOrigin> team = {
        {mapping::SubmapId{0, 3}, own.at(3)}};
    own.erase(3);
    closer->UpdateOrigins(own, team);
  }

  static LoopWorld* world_;
};

LoopWorld* LoopCloserTest::world_ = nullptr;

TEST_F(LoopCloserTest, ARevisitIsMatchedNearTheTruthOnceItsOriginIsKnown) {
  LoopCloser closer({}, 0);
  for (uint32_t frame : {1u, 2u, 3u}) closer.AddSubmap(Take(Render(frame)));
  closer.Flush();
  // No origin known yet: nothing can be paired.
  EXPECT_TRUE(closer.TakeMatches().empty());
  EXPECT_EQ(closer.Stats().submaps, 3u);

  closer.UpdateOrigins(DriftedOrigins());
  closer.Flush();
  const std::vector<LoopMatch> matches = closer.TakeMatches();
  ASSERT_EQ(matches.size(), 1u) << "only the revisit overlaps a non-successive submap";
  const LoopMatch& m = matches.front();
  EXPECT_EQ(std::min(m.a.index, m.b.index), 1);
  EXPECT_EQ(std::max(m.a.index, m.b.index), 3);
  ASSERT_TRUE(m.accepted) << m.rejection;
  const Eigen::Isometry3d truth =
      Truth(static_cast<uint32_t>(m.a.index)).inverse() * Truth(static_cast<uint32_t>(m.b.index));
  const mapping::testing::PoseError e = mapping::testing::ErrorOf(m.T_a_b, truth);
  // A valid loop closure (the matcher's own accuracy is tested with it).
  EXPECT_LT(e.translation_m, 0.2);
  EXPECT_LT(e.rotation_rad, 1.0 * kDeg);
  // The prior carried the drift; the match removes it.
  const mapping::testing::PoseError prior = mapping::testing::ErrorOf(m.prior.T_a_b, truth);
  EXPECT_GT(prior.translation_m, 0.2);
  EXPECT_TRUE(m.covariance.allFinite());
  EXPECT_GT(m.covariance.determinant(), 0.0);
  EXPECT_GT(m.match_ms, 0.0);

  const LoopCloserStats stats = closer.Stats();
  EXPECT_EQ(stats.pairs_matched, 1u);
  EXPECT_EQ(stats.matches_accepted, 1u);
  EXPECT_EQ(stats.data_ms.size(), 3u);
  EXPECT_EQ(stats.match_ms.size(), 1u);

  // A pair is matched once: new origins do not bring it back.
  closer.UpdateOrigins(DriftedOrigins());
  closer.Flush();
  EXPECT_TRUE(closer.TakeMatches().empty());
}

TEST_F(LoopCloserTest, MatchDataSpilledToDiskGiveTheSameMatchAsInMemory) {
  std::vector<std::shared_ptr<const mapping::Submap>> submaps;
  for (uint32_t frame : {1u, 2u, 3u}) submaps.push_back(Take(Render(frame)));
  auto run = [&](int resident, const std::string& directory) {
    LoopCloserOptions options;
    options.store.resident_submaps = resident;
    options.store.spill_directory = directory;
    LoopCloser closer(options, 0);
    for (const auto& submap : submaps) closer.AddSubmap(submap);
    closer.Flush();  // every submap's data made, the older ones spilled
    closer.UpdateOrigins(DriftedOrigins());
    closer.Flush();
    return std::pair(closer.TakeMatches(), closer.Stats());
  };
  rover::testing::TempDir dir;
  const auto [in_memory, memory_stats] = run(0, "");
  const auto [spilled, spill_stats] = run(1, dir.path().string());
  EXPECT_EQ(memory_stats.store.spill_writes, 0u);
  EXPECT_GT(spill_stats.store.spill_writes, 0u);
  EXPECT_GT(spill_stats.store.spill_reads, 0u) << "the revisit's pair was not read back";
  EXPECT_LE(spill_stats.store.resident, 1u);
  ASSERT_EQ(in_memory.size(), 1u);
  ASSERT_EQ(spilled.size(), 1u);
  EXPECT_EQ(spilled[0].a, in_memory[0].a);
  EXPECT_EQ(spilled[0].b, in_memory[0].b);
  EXPECT_EQ(spilled[0].accepted, in_memory[0].accepted);
  EXPECT_EQ(spilled[0].T_a_b.matrix(), in_memory[0].T_a_b.matrix());
  EXPECT_EQ(spilled[0].inliers, in_memory[0].inliers);
}

TEST_F(LoopCloserTest, ASubmapWithoutStructureIsCountedAndNeverPaired) {
  LoopWorld flat;  // sloped ground, no rock
  SyntheticSubmap first = Drive(flat, {0.0, 0.0}, 0.0, 21, 1);
  SyntheticSubmap revisit = Drive(flat, {1.0, 0.5}, 0.2, 23, 3);
  std::map<int64_t, OptimisedOrigin> origins;
  origins[1] = Estimate(first.T_world_submap, {0, 0, 0}, 0.0, 0.01, 0.1 * kDeg);
  origins[3] = Estimate(revisit.T_world_submap, {0.3, 0, 0}, 0.0, 0.5, 3.0 * kDeg);
  LoopCloser closer({}, 0);
  closer.AddSubmap(Take(std::move(first)));
  closer.AddSubmap(Take(std::move(revisit)));
  closer.UpdateOrigins(origins);
  closer.Flush();
  EXPECT_TRUE(closer.TakeMatches().empty());
  const LoopCloserStats stats = closer.Stats();
  EXPECT_EQ(stats.submaps, 2u);
  EXPECT_EQ(stats.submaps_suitable, 0u);
  EXPECT_EQ(stats.pairs_matched, 0u);
}

TEST_F(LoopCloserTest, AnEmptySubmapOrANullHandOverIsHarmless) {
  LoopCloser closer({}, 0);
  closer.AddSubmap(nullptr);
  auto empty = std::make_shared<mapping::Submap>(5, 5, mapping::SubmapOptions{});
  empty->Finish();
  closer.AddSubmap(empty);
  closer.Flush();
  const LoopCloserStats stats = closer.Stats();
  EXPECT_EQ(stats.submaps, 1u);
  EXPECT_EQ(stats.submaps_suitable, 0u);
}

TEST_F(LoopCloserTest, StoppingWithWorkQueuedReturns) {
  auto closer = std::make_unique<LoopCloser>(LoopCloserOptions{}, 0);
  closer->AddSubmap(Take(Render(1)));
  closer->AddSubmap(Take(Render(3)));
  closer->UpdateOrigins(DriftedOrigins());
  closer->Stop();
  closer->Stop();  // idempotent
  closer.reset();  // and the destructor after it
  SUCCEED();
}

TEST(LoopCloserOptionsTest, InvalidOptionsNameTheKey) {
  LoopCloserOptions o;
  o.max_queued_pairs = 0;
  try {
    o.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("LoopCloserOptions.max_queued_pairs"), std::string::npos)
        << e.what();
  }
  o = {};
  o.matcher.min_sigma_m = -1.0;
  EXPECT_THROW(LoopCloser(o, 0), std::invalid_argument);
  const ConfigNode node = ConfigNode::LoadString(
      "max_queued_pairs: 4\nnice_increment: 5\nmatcher: {mode: six_dof}\n"
      "store: {resident_submaps: 7, spill_directory: /var/log/rover}\n",
      "test");
  const LoopCloserOptions loaded = LoopCloserOptions::Load(node);
  EXPECT_EQ(loaded.store.resident_submaps, 7);
  EXPECT_EQ(loaded.store.spill_directory, "/var/log/rover");
  EXPECT_EQ(loaded.max_queued_pairs, 4);
  EXPECT_EQ(loaded.nice_increment, 5);
  EXPECT_EQ(loaded.matcher.mode, mapping::MatchMode::kSixDof);
  // Keys a child map does not name keep mapd's defaults.
  EXPECT_EQ(loaded.matcher.min_bound_m, LoopCloserOptions{}.matcher.min_bound_m);
  EXPECT_GT(loaded.matcher.min_bound_m, mapping::SubmapMatcherOptions{}.min_bound_m);
  EXPECT_EQ(loaded.matcher.max_yaw_innovation_sigmas, 3.0);
  EXPECT_EQ(loaded.matcher.icp.robust_scale_m, 0.03);
  EXPECT_EQ(loaded.matcher.icp.max_normal_angle_deg, 30.0);
  // ... and a key it names is taken as given (0: the gate off); the same
  // holds for the pairing's child map.
  const LoopCloserOptions ungated = LoopCloserOptions::Load(ConfigNode::LoadString(
      "matcher: {max_yaw_innovation_sigmas: 0}\npairing: {alpha: 0.25}\n", "test"));
  EXPECT_EQ(ungated.matcher.max_yaw_innovation_sigmas, 0.0);
  const LoopCloserOptions plain_icp = LoopCloserOptions::Load(
      ConfigNode::LoadString("matcher: {icp: {robust_scale_m: 0}}\n", "test"));
  EXPECT_EQ(plain_icp.matcher.icp.robust_scale_m, 0.0);
  EXPECT_EQ(plain_icp.matcher.icp.max_normal_angle_deg, 30.0);
  EXPECT_EQ(ungated.matcher.min_bound_m, LoopCloserOptions{}.matcher.min_bound_m);
  EXPECT_EQ(ungated.pairing.alpha, 0.25);
  EXPECT_EQ(ungated.pairing.view_distance_m, LoopCloserOptions{}.pairing.view_distance_m);
  EXPECT_NE(ungated.pairing.view_distance_m, mapping::SubmapPairingOptions{}.view_distance_m);
}

}  // namespace
}  // namespace rover::mapd

namespace rover::mapd {
namespace {

TEST_F(LoopCloserTest, AnotherRoversSubmapIsMatchedWithThisRoversFirstAndClaimed) {
  LoopCloser closer({}, 1);
  HandOverTeamScene(&closer);
  closer.Flush();
  const std::vector<LoopMatch> matches = closer.TakeMatches();
  ASSERT_EQ(matches.size(), 1u);
  const LoopMatch& m = matches.front();
  EXPECT_EQ(m.a, (mapping::SubmapId{1, 1})) << "this rover's submap first";
  EXPECT_EQ(m.b, (mapping::SubmapId{0, 3}));
  ASSERT_TRUE(m.accepted) << m.rejection;
  const mapping::testing::PoseError e =
      mapping::testing::ErrorOf(m.T_a_b, Truth(1).inverse() * Truth(3));
  EXPECT_LT(e.translation_m, 0.2);
  EXPECT_LT(e.rotation_rad, 1.0 * kDeg);
  const auto claims = closer.TakeClaims();
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0], (std::pair{mapping::SubmapId{0, 3}, mapping::SubmapId{1, 1}}));
  const LoopCloserStats stats = closer.Stats();
  EXPECT_EQ(stats.team_submaps, 1u);
  EXPECT_EQ(stats.team_pairs_matched, 1u);
  EXPECT_EQ(stats.team_matches_accepted, 1u);
}

TEST_F(LoopCloserTest, APairAnotherRoverClaimedIsLeftToIt) {
  LoopCloser closer({}, 1);
  closer.AddClaim({1, 1}, {0, 3}, 0);
  HandOverTeamScene(&closer);
  closer.Flush();
  EXPECT_TRUE(closer.TakeMatches().empty());
  EXPECT_TRUE(closer.TakeClaims().empty());
  EXPECT_EQ(closer.Stats().pairs_claimed_by_others, 1u);
}

TEST_F(LoopCloserTest, TwoOtherRoversSubmapsAreTheirsToMatch) {
  LoopCloser closer({}, 2);
  HandOverAsTeamSubmap(&closer, 0, 1, Render(1));
  HandOverAsTeamSubmap(&closer, 1, 3, Render(3));
  const std::map<int64_t, OptimisedOrigin> drifted = DriftedOrigins();
  closer.UpdateOrigins(
      {}, {{mapping::SubmapId{0, 1}, drifted.at(1)}, {mapping::SubmapId{1, 3}, drifted.at(3)}});
  closer.Flush();
  EXPECT_TRUE(closer.TakeMatches().empty());
  EXPECT_EQ(closer.Stats().pairs_matched, 0u);
}

}  // namespace
}  // namespace rover::mapd
