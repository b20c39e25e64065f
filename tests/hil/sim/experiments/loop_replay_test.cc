// Loop closing replayed offline on logged submaps (synthetic: rocks on
// sloped ground, tests/mapping/loop/loop_test_scene.h): a drive, a drive far
// away, and a revisit of the first whose chained origin is 0.3 m and 2 deg
// off. The replay must match the revisit, accept it, and pull the revisit's
// origin back to the truth; without the revisit's submap nothing is matched.

#include "hil/sim/experiments/loop_replay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>

#include "core/geometry/yaw.h"
#include "tests/mapping/loop/loop_test_scene.h"

namespace rover::sim::experiments {
namespace {

using mapping::testing::LoopWorld;

constexpr double kDeg = M_PI / 180.0;

struct Drive {
  Eigen::Vector2d start;
  double yaw_rad;
  uint64_t seed;
};

class LoopReplayTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new LoopWorld;
    mapping::testing::ScatterRocks(-2, 22, -8, 8, 0.25, 1, world_);
    mapping::testing::ScatterRocks(-2, 22, 32, 48, 0.25, 2, world_);
    // Frame 3 revisits frame 1's ground; frame 4 has no submap (the drive
    // ends there).
    drives_ = new std::map<uint32_t, Drive>{{1, {{0.0, 0.0}, 0.0, 11}},
                                            {2, {{0.0, 40.0}, 0.0, 12}},
                                            {3, {{1.0, 0.5}, 0.2, 13}},
                                            {4, {{20.0, 0.0}, 0.0, 14}}};
  }
  static void TearDownTestSuite() {
    delete world_;
    delete drives_;
  }

  static std::vector<Eigen::Isometry3d> Cameras(uint32_t frame) {
    const Drive& d = drives_->at(frame);
    return mapping::testing::StraightDrive(*world_, d.start, d.yaw_rad, 12, 0.5);
  }
  static Eigen::Isometry3d Truth(uint32_t frame) {
    return mapping::testing::SubmapFrameAt(Cameras(frame).front());
  }

  // The graph as mapd logs it: the prior on frame 1 and the switches, the
  // one into frame 3 carrying 0.3 m and 2 deg of drift with a covariance
  // that covers it; origins chained from them.
  static mapping::GraphLogContents LoggedGraph() {
    mapping::GraphLogContents g;
    mapping::Matrix6d prior = mapping::Matrix6d::Identity() * 1e-8;
    g.factors.push_back(mapping::OriginPriorFactor(0, 1, Truth(1), prior));
    Eigen::Isometry3d T_world_origin = Truth(1);
    log::rover_msgs::SubmapOrigins origins;
    auto add_origin = [&](uint32_t frame) {
      log::rover_msgs::SubmapOrigin o;
      o.submap = frame;
      o.pose = mapping::ToPoseMsg(T_world_origin);
      origins.origins.push_back(o);
    };
    add_origin(1);
    for (uint32_t old_frame : {1u, 2u, 3u}) {
      Eigen::Isometry3d T_old_new = Truth(old_frame).inverse() * Truth(old_frame + 1);
      if (old_frame == 2)
        T_old_new = T_old_new * GravityAlignedTransform({0.2, -0.2, 0.05}, 2 * kDeg);
      Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
      covariance.diagonal() << 0.04, 0.04, 0.01, std::pow(2.0 * kDeg, 2);
      g.factors.push_back(mapping::FrameSwitchFactor(0, old_frame, T_old_new.translation(),
                                                     YawOf(T_old_new.linear()), covariance));
      T_world_origin = T_world_origin * T_old_new;
      add_origin(old_frame + 1);
    }
    g.last_origins = origins;
    return g;
  }

  static mapping::SubmapLog Submaps(std::initializer_list<uint32_t> frames) {
    mapping::SubmapLog log;
    for (uint32_t frame : frames) {
      const Drive& d = drives_->at(frame);
      mapping::testing::SyntheticSubmap s =
          mapping::testing::BuildSubmap(*world_, Cameras(frame), d.seed, {}, frame);
      mapping::LoggedSubmap logged;
      logged.info.frame_id = frame;
      logged.octree = std::make_shared<octomap::OcTree>(s.submap->octree());
      logged.cloud = std::make_shared<mapping::PointCloud>(s.submap->cloud());
      log.submaps.push_back(std::move(logged));
    }
    return log;
  }

  static Eigen::Isometry3d Origin(const mapping::GraphLogContents& g, int64_t frame) {
    for (const log::rover_msgs::SubmapOrigin& o : g.last_origins->origins) {
      if (o.submap == frame) return mapping::FromPoseMsg(o.pose);
    }
    ADD_FAILURE() << "no origin " << frame;
    return Eigen::Isometry3d::Identity();
  }

  static LoopWorld* world_;
  static std::map<uint32_t, Drive>* drives_;
};

LoopWorld* LoopReplayTest::world_ = nullptr;
std::map<uint32_t, Drive>* LoopReplayTest::drives_ = nullptr;

TEST_F(LoopReplayTest, TheRevisitIsMatchedAndPullsItsOriginBackToTheTruth) {
  const mapping::GraphLogContents logged = LoggedGraph();
  const double drift_m = mapping::testing::ErrorOf(Origin(logged, 3), Truth(3)).translation_m;
  ASSERT_GT(drift_m, 0.25);

  LoopReplayOptions options;
  for (uint32_t frame : {1u, 2u, 3u, 4u}) options.true_origins[frame] = Truth(frame);
  std::ostringstream report;
  const LoopReplayResult r = ReplayLoopClosing(logged, Submaps({1, 2, 3}), options, report);
  EXPECT_EQ(r.submaps_suitable, 3) << report.str();
  EXPECT_EQ(r.pairs_matched, 1) << "only 1-3 overlap:\n" << report.str();
  EXPECT_EQ(r.matches_accepted, 1) << report.str();
  EXPECT_EQ(r.matches_valid, 1) << report.str();
  int matches = 0;
  for (const mapping::GraphFactorRecord& f : r.graph.factors) {
    matches += f.kind == mapping::FactorKind::kSubmapMatch ? 1 : 0;
  }
  EXPECT_EQ(matches, 1);
  const mapping::testing::PoseError e = mapping::testing::ErrorOf(Origin(r.graph, 3), Truth(3));
  EXPECT_LT(e.translation_m, 0.1) << report.str();
  EXPECT_LT(e.rotation_rad, 1.0 * kDeg) << "the drift was 2 deg";
}

TEST_F(LoopReplayTest, ExplainedPairsSayWhetherTheyWereMatchedOrWhichRuleKeptThemOut) {
  const mapping::GraphLogContents logged = LoggedGraph();
  LoopReplayOptions options;
  for (uint32_t frame : {1u, 2u, 3u, 4u}) options.true_origins[frame] = Truth(frame);
  options.explain_pairs = true;
  std::ostringstream report;
  ReplayLoopClosing(logged, Submaps({1, 2, 3}), options, report);
  // 1-3 is the only revisit (1-2 and 2-3 are far apart).
  EXPECT_NE(report.str().find("pair 1-3: true obstacle-box overlap"), std::string::npos)
      << report.str();
  EXPECT_NE(report.str().find("matched: accepted"), std::string::npos) << report.str();
  EXPECT_EQ(report.str().find("pair 1-2:"), std::string::npos) << report.str();
  EXPECT_NE(report.str().find("pairs: 1 pairs"), std::string::npos) << report.str();

  // An overlap threshold no pair reaches: the same pair, and the rule.
  options.loop.pairing.min_overlap_m2 = 1e6;
  std::ostringstream strict;
  const LoopReplayResult r = ReplayLoopClosing(logged, Submaps({1, 2, 3}), options, strict);
  EXPECT_EQ(r.pairs_matched, 0);
  EXPECT_NE(strict.str().find("obstacle boxes overlap too little"), std::string::npos)
      << strict.str();
}

TEST_F(LoopReplayTest, WithoutTheRevisitsSubmapNothingIsMatchedAndTheOriginsStay) {
  const mapping::GraphLogContents logged = LoggedGraph();
  std::ostringstream report;
  const LoopReplayResult r = ReplayLoopClosing(logged, Submaps({1, 2}), {}, report);
  EXPECT_EQ(r.pairs_matched, 0) << report.str();
  EXPECT_TRUE(Origin(r.graph, 3).isApprox(Origin(logged, 3), 1e-6));
}

TEST_F(LoopReplayTest, AGraphWithoutOriginsIsRefusedByName) {
  mapping::GraphLogContents logged = LoggedGraph();
  logged.last_origins.reset();
  std::ostringstream report;
  try {
    ReplayLoopClosing(logged, {}, {}, report);
    FAIL() << "a graph without origins was replayed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no optimised origins"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::sim::experiments
