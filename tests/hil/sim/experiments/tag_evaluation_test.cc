#include "hil/sim/experiments/tag_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/log/msgs/builtin_interfaces.h"
#include "mapping/slam/graph_log.h"

namespace rover::sim::experiments {
namespace {

// One post 4 m ahead of a camera at the origin that looks along world x.
World OnePostWorld() {
  World world;
  Eigen::Isometry3d T_world_post = Eigen::Isometry3d::Identity();
  T_world_post.translation() = Eigen::Vector3d(4.0, 0.0, 0.0);
  world.carriers.push_back(MakeLandmarkPost("post_0", 0, 0.16, T_world_post));
  return world;
}

Eigen::Isometry3d T_world_cam() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // OpenCV axes: z along world x
  T.translation() = Eigen::Vector3d(0.0, 0.0, 0.8);
  return T;
}

log::rover_msgs::TagDetection Detection(const World& world, int id, const Eigen::Isometry3d& error,
                                        double sigma) {
  const TagCarrier& post = world.carriers[0];
  const Eigen::Isometry3d T_cam_tag = T_world_cam().inverse() * post.T_world_carrier *
                                      post.tags[static_cast<std::size_t>(id)].T_carrier_tag;
  log::rover_msgs::TagDetection d;
  d.header.stamp = log::ToRosTime(Time::FromNanoseconds(1'000'000'000));
  d.id = id;
  d.accepted = true;
  d.pose = mapping::ToPoseMsg(T_cam_tag * error);
  for (int i = 0; i < 6; ++i) d.covariance[static_cast<std::size_t>(7 * i)] = sigma * sigma;
  return d;
}

TEST(TagEvaluationTest, ScoresAcceptedLandmarkDetectionsAgainstTheTruth) {
  const World world = OnePostWorld();
  Eigen::Isometry3d off_5cm = Eigen::Isometry3d::Identity();
  off_5cm.translation() = Eigen::Vector3d(0.05, 0.0, 0.0);
  Eigen::Isometry3d flipped = Eigen::Isometry3d::Identity();
  flipped.linear() = Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
  std::vector<log::rover_msgs::TagDetection> detections = {
      Detection(world, 2, Eigen::Isometry3d::Identity(), 0.01),  // exact: NEES 0
      Detection(world, 2, off_5cm, 0.01),                        // 5 sigma off: NEES 25
      Detection(world, 2, flipped, 0.01),                        // the wrong solution
  };
  log::rover_msgs::TagDetection refused = detections[0];
  refused.accepted = false;
  detections.push_back(refused);
  log::rover_msgs::TagDetection unknown = detections[0];
  unknown.id = 99;  // not on any post
  detections.push_back(unknown);

  const TagScore s = ScoreTagDetections(detections, world, [](Time) { return T_world_cam(); });
  EXPECT_EQ(s.decoded, 5u);
  EXPECT_EQ(s.accepted, 4u);
  EXPECT_EQ(s.scored, 3u);
  EXPECT_EQ(s.nees_in_bound, 1u);
  EXPECT_NEAR(s.nees_in_bound_pct, 100.0 / 3.0, 1e-9);
  EXPECT_NEAR(s.nees_median, 25.0, 1e-6);
  EXPECT_EQ(s.wrong_solutions, 1u);
  EXPECT_EQ(s.wrong_solutions_claimed, 1u) << "0.01 rad sigma does not cover 40 deg";
  EXPECT_NEAR(s.position_error_pct_median, 0.0, 1e-9);  // of 0, 1.3 and 0 %
  // The wrong one is listed, and the report names it.
  ASSERT_EQ(s.wrong.size(), 1u);
  EXPECT_EQ(s.wrong[0].id, 2);
  EXPECT_NEAR(s.wrong[0].rotation_error_deg, 40.0, 1e-6);
  EXPECT_NEAR(s.wrong[0].rotation_nees, std::pow(40.0 * M_PI / 180.0 / 0.01, 2), 1e-3);
  std::ostringstream report;
  ReportTagScore(s, report);
  EXPECT_NE(report.str().find("wrong solution: tag 2 at 1.000 s"), std::string::npos)
      << report.str();
  EXPECT_NE(report.str().find("rotation off by 40.0 deg"), std::string::npos) << report.str();
  EXPECT_NE(report.str().find("(claimed)"), std::string::npos) << report.str();
}

TEST(TagEvaluationTest, AWrongRotationLeftOpenIsNotClaimed) {
  const World world = OnePostWorld();
  Eigen::Isometry3d flipped = Eigen::Isometry3d::Identity();
  flipped.linear() = Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
  log::rover_msgs::TagDetection open = Detection(world, 2, flipped, 0.01);
  for (int i = 3; i < 6; ++i) open.covariance[static_cast<std::size_t>(7 * i)] = 1.0;  // 57 deg
  const TagScore s = ScoreTagDetections({open}, world, [](Time) { return T_world_cam(); });
  EXPECT_EQ(s.wrong_solutions, 1u);
  EXPECT_EQ(s.wrong_solutions_claimed, 0u);
}

TEST(TagEvaluationTest, NothingScoredGivesNan) {
  const TagScore s = ScoreTagDetections({}, OnePostWorld(), [](Time) { return T_world_cam(); });
  EXPECT_EQ(s.scored, 0u);
  EXPECT_TRUE(std::isnan(s.nees_in_bound_pct));
}

}  // namespace
}  // namespace rover::sim::experiments
