// A landmark seen through a tag at the start of a loop and again at its end
// closes the loop in the rover graph, as posts re-seen after a long drive
// do where submap matching cannot.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/geometry/yaw.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {
namespace {

// Origins every 5 m along a square loop of 20 m sides, back at the start
// (17 origins); the filter's switches drift in yaw by 0.3 deg each.
struct Drive {
  std::vector<Eigen::Isometry3d> origins;  // truth, T_world_origin
  std::vector<GraphFactorRecord> factors;
};

Drive MakeDrive() {
  Drive d;
  const Eigen::Vector3d corners[4] = {{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}};
  const Eigen::Vector3d dirs[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  for (int k = 0; k <= 16; ++k) {
    const int side = std::min(k / 4, 3);
    const double s = k == 16 ? 5.0 * 4 : 5.0 * (k % 4);
    d.origins.push_back(GravityAlignedTransform(corners[side] + s * dirs[side], side * M_PI / 2.0));
  }
  d.factors.push_back(OriginPriorFactor(0, 0, d.origins[0], 1e-10 * Matrix6d::Identity()));
  for (std::size_t k = 0; k < 16; ++k) {
    const Eigen::Isometry3d T = d.origins[k].inverse() * d.origins[k + 1];
    const double drift = 0.3 * M_PI / 180.0;
    Eigen::Matrix4d cov = Eigen::Matrix4d::Identity() * 1e-4;
    cov(3, 3) = drift * drift;
    d.factors.push_back(FrameSwitchFactor(0, static_cast<int64_t>(k), T.translation(),
                                          YawOf(T.linear()) + drift, cov));
  }
  return d;
}

double EndError(const std::vector<GraphFactorRecord>& factors, const Drive& d) {
  RoverGraph graph;
  for (const GraphFactorRecord& f : factors) AddToGraph(f, &graph);
  graph.Optimize();
  return (graph.Origin(0, 16).translation() - d.origins[16].translation()).norm();
}

TEST(LandmarkObservationTest, ALandmarkSeenAgainClosesTheLoop) {
  const Drive d = MakeDrive();
  // A post 2 m ahead of the start carries a tag facing back towards the
  // rover; the camera looks forward (x body = z camera).
  const Eigen::Isometry3d T_world_landmark = GravityAlignedTransform({2.0, 0.3, 0.0}, 0.0);
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_body_cam.translation() = Eigen::Vector3d(0.2, 0.0, 0.8);
  Eigen::Isometry3d T_landmark_tag = Eigen::Isometry3d::Identity();
  T_landmark_tag.linear() << 0, 0, -1, 1, 0, 0, 0, -1, 0;  // tag z into the post, away from -x
  T_landmark_tag.translation() = Eigen::Vector3d(0.0, 0.0, 0.8);
  std::vector<GraphFactorRecord> with = d.factors;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (const int submap : {0, 16}) {
    const int64_t pose = submap;  // a pose at each origin
    const Eigen::Isometry3d T_world_body = d.origins[static_cast<std::size_t>(submap)];
    with.push_back(FilterPoseFactor(0, submap, pose, Eigen::Isometry3d::Identity(),
                                    1e-8 * Matrix6d::Identity()));
    Eigen::Isometry3d T_cam_tag =
        (T_world_body * T_body_cam).inverse() * T_world_landmark * T_landmark_tag;
    Matrix6d cov = Matrix6d::Zero();
    cov.diagonal() << 0.01, 0.01, 0.02, 0.02, 0.02, 0.02;
    cov = cov.array().square().matrix();
    T_cam_tag.translation() += 0.005 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const GraphFactorRecord o =
        LandmarkObservationFactor(0, pose, 7, T_body_cam, T_cam_tag, cov, T_landmark_tag);
    EXPECT_EQ(o.kind, FactorKind::kLandmarkObservation);
    EXPECT_TRUE(o.robust);
    EXPECT_EQ(o.b->ToString(), "l7");
    // The composed measurement is the landmark in the body frame.
    EXPECT_LT(
        (o.T_a_b.translation() - (T_world_body.inverse() * T_world_landmark).translation()).norm(),
        0.05);
    EXPECT_GT(o.covariance.ldlt().vectorD().minCoeff(), 0.0);
    // What mapd logs is what a restart rebuilds.
    const GraphFactorRecord back = FromMsg(ToMsg(o, "local/r0/0"));
    EXPECT_EQ(back.kind, o.kind);
    EXPECT_TRUE(back.T_a_b.isApprox(o.T_a_b, 1e-12));
    with.push_back(o);
  }
  const double without_m = EndError(d.factors, d);
  const double with_m = EndError(with, d);
  EXPECT_GT(without_m, 0.5) << "the drift opens the loop";
  EXPECT_LT(with_m, 0.2 * without_m) << "without " << without_m << " m, with " << with_m << " m";
}

}  // namespace
}  // namespace rover::mapping
