// The loop-closure building blocks on small exact inputs: rigid transforms
// from point pairs (4D eq. 6.5-6.7, 4D and 6D least squares), the line
// spread check, both k-d tree indexes against brute force, the known-space
// ratio against OctoMap's own search, the descriptor's yaw invariance, ICP
// and the options' validation.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "core/config/config.h"
#include "core/geometry/yaw.h"
#include "mapping/loop/gravity_descriptor.h"
#include "mapping/loop/line_spread.h"
#include "mapping/loop/point_kd_tree.h"
#include "mapping/loop/rigid_estimation.h"
#include "mapping/loop/submap_icp.h"
#include "mapping/loop/submap_match_data.h"
#include "mapping/loop/submap_matcher.h"
#include "mapping/loop/submap_pairing.h"
#include "mapping/loop/surface_normals.h"

namespace rover::mapping {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;
using Eigen::Vector3f;

Isometry3d Tilted(const Vector3d& p, double yaw, double roll) {
  Isometry3d T = GravityAlignedTransform(p, yaw);
  T.linear() = T.linear() * Eigen::AngleAxisd(roll, Vector3d::UnitX()).toRotationMatrix();
  return T;
}

double Distance(const Isometry3d& A, const Isometry3d& B) {
  return (A.matrix() - B.matrix()).norm();
}

TEST(RigidEstimation, TwoPointYawTransformIsExactForExactPairs) {
  const Isometry3d T = GravityAlignedTransform({1.5, -2.0, 0.3}, 0.7);
  const Vector3d b1(0.2, 0.1, 0.0), b2(2.0, -1.0, 0.4);
  Isometry3d est;
  ASSERT_TRUE(TwoPointYawTransform(T * b1, T * b2, b1, b2, 0.5, &est));
  EXPECT_LT(Distance(est, T), 1e-12);
  // Roll and pitch are zero by construction, whatever the heights.
  EXPECT_NEAR(est.linear()(2, 2), 1.0, 1e-15);
  // A pair shorter than the minimum separation in xy has no direction.
  EXPECT_FALSE(TwoPointYawTransform(T * b1, T * (b1 + Vector3d(0.1, 0.0, 1.0)), b1,
                                    b1 + Vector3d(0.1, 0.0, 1.0), 0.5, &est));
}

TEST(RigidEstimation, LeastSquaresFitsRecoverTheTransform) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Vector3d> a, b;
  const Isometry3d T4 = GravityAlignedTransform({0.4, 1.0, -0.2}, -2.5);
  for (int i = 0; i < 20; ++i) {
    b.push_back({u(rng), u(rng), 0.3 * u(rng)});
    a.push_back(T4 * b.back());
  }
  Isometry3d est;
  ASSERT_TRUE(FitYawTransform(a, b, &est));
  EXPECT_LT(Distance(est, T4), 1e-9);
  const Isometry3d T6 = Tilted({0.4, 1.0, -0.2}, -2.5, 0.3);
  for (std::size_t i = 0; i < b.size(); ++i) a[i] = T6 * b[i];
  ASSERT_TRUE(FitRigidTransform(a, b, &est));
  EXPECT_LT(Distance(est, T6), 1e-9);
  EXPECT_NEAR(TiltOf(est.linear()), 0.3, 1e-9);
  // Collinear points leave a rotation free.
  const std::vector<Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_FALSE(FitRigidTransform(line, line, &est));
}

TEST(LineSpread, CountsPointsOffTheBestLine) {
  std::vector<Vector3f> wall;
  for (int i = 0; i < 200; ++i) {
    // A wall along a diagonal, 1 m tall, 10 cm thick.
    const float s = 0.05f * static_cast<float>(i);
    wall.push_back(
        {s, 0.5f * s + 0.1f * static_cast<float>(i % 2), 0.01f * static_cast<float>(i % 100)});
  }
  EXPECT_EQ(CountOffLine(wall, 0.5, 2000, 1), 0);
  std::vector<Vector3f> field = wall;
  // Ten rocks' worth of points well off the wall.
  for (int i = 0; i < 10; ++i) field.push_back({1.0f + 0.3f * static_cast<float>(i), -2.0f, 0.0f});
  EXPECT_EQ(CountOffLine(field, 0.5, 100000, 1), 10);
  EXPECT_EQ(CountOffLine(field, 0.5, 300, 7), CountOffLine(field, 0.5, 300, 7));
  EXPECT_EQ(CountOffLine({}, 0.5, 10, 1), 0);
}

TEST(PointKdTree, AgreesWithBruteForce) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  std::vector<Vector3f> points(2000);
  for (Vector3f& p : points) p = {u(rng), u(rng), u(rng)};
  const PointKdTree tree(points);
  std::vector<Neighbour> found;
  for (int q = 0; q < 50; ++q) {
    const Vector3f query(u(rng), u(rng), u(rng));
    tree.Radius(query, 1.0f, &found);
    std::size_t brute = 0;
    std::size_t nearest = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      brute += (points[i] - query).norm() <= 1.0f;
      if ((points[i] - query).norm() < (points[nearest] - query).norm()) nearest = i;
    }
    EXPECT_EQ(found.size(), brute);
    Neighbour n;
    ASSERT_TRUE(tree.Nearest(query, 100.0f, &n));
    EXPECT_EQ(n.index, nearest);
    tree.Nearest(query, 3, &found);
    ASSERT_EQ(found.size(), 3u);
    EXPECT_EQ(found[0].index, nearest);
  }
  EXPECT_THROW(PointKdTree({{0.0f, NAN, 0.0f}}), std::invalid_argument);
}

TEST(DescriptorIndex, KdTreeAndBruteForceFindTheSameNeighbours) {
  std::mt19937_64 rng(3);
  std::normal_distribution<float> n(0.0f, 1.0f);
  Eigen::MatrixXf data(300, 40), queries(30, 40);
  for (Eigen::Index i = 0; i < data.size(); ++i) data.data()[i] = n(rng);
  for (Eigen::Index i = 0; i < queries.size(); ++i) queries.data()[i] = n(rng);
  data.rowwise().normalize();
  queries.rowwise().normalize();
  const DescriptorIndex kd(data, DescriptorSearch::kKdTree);
  const DescriptorIndex brute(data, DescriptorSearch::kBruteForce);
  const auto a = kd.Nearest(queries, 3);
  const auto b = brute.Nearest(queries, 3);
  for (std::size_t q = 0; q < a.size(); ++q) {
    ASSERT_EQ(a[q].size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(a[q][k].index, b[q][k].index);
      EXPECT_NEAR(a[q][k].distance_sq, b[q][k].distance_sq, 1e-4f);
    }
  }
  EXPECT_THROW(kd.Nearest(Eigen::MatrixXf::Zero(1, 7), 1), std::invalid_argument);
}

TEST(KnownRatios, MatchesOctreeSearchAndTreatsSolidGroundAsKnown) {
  octomap::OcTree tree(0.1);
  // Ground: occupied at z = 0 over a 4x4 m patch, free 1 m of air above;
  // nothing observed below (as stereo never sees under the surface). The
  // half x > 1 m has no air observed (a shadow).
  for (double x = -2.0; x < 2.0; x += 0.1) {
    for (double y = -2.0; y < 2.0; y += 0.1) {
      tree.updateNode(
          octomap::point3d(static_cast<float>(x + 0.05), static_cast<float>(y + 0.05), 0.05f),
          true);
      if (x > 1.0) continue;
      for (double z = 0.1; z < 1.0; z += 0.1) {
        tree.updateNode(octomap::point3d(static_cast<float>(x + 0.05), static_cast<float>(y + 0.05),
                                         static_cast<float>(z + 0.05)),
                        false);
      }
    }
  }
  tree.prune();
  const std::vector<Vector3f> queries = {{0.0f, 0.0f, 0.1f}, {1.5f, 0.0f, 0.1f}};
  const std::vector<float> solid = KnownRatios(tree, queries, 0.5, true);
  const std::vector<float> plain = KnownRatios(tree, queries, 0.5, false);
  // Brute force with OctoMap's search over the same voxel centres.
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const octomap::OcTreeKey k = tree.coordToKey(queries[q].x(), queries[q].y(), queries[q].z());
    const octomap::point3d c = tree.keyToCoord(k);
    int known = 0, total = 0;
    for (int dx = -6; dx <= 6; ++dx) {
      for (int dy = -6; dy <= 6; ++dy) {
        for (int dz = -6; dz <= 6; ++dz) {
          const octomap::point3d v(c.x() + 0.1f * static_cast<float>(dx),
                                   c.y() + 0.1f * static_cast<float>(dy),
                                   c.z() + 0.1f * static_cast<float>(dz));
          const Vector3f d = Vector3f(v.x(), v.y(), v.z()) - queries[q];
          if (d.norm() > 0.5f) continue;
          ++total;
          known += tree.search(v) != nullptr;
        }
      }
    }
    EXPECT_NEAR(plain[q], static_cast<float>(known) / static_cast<float>(total), 1e-6f) << q;
  }
  // Under the observed ground everything is solid: known in full where the
  // air was seen, about half known in the shadow.
  EXPECT_GT(solid[0], 0.99f);
  EXPECT_LT(plain[0], 0.7f);
  EXPECT_LT(solid[1], 0.7f);
}

// A lumpy rock on a plane, as a point cloud.
std::vector<Vector3f> RockPatch(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.005f);
  std::vector<Vector3f> points;
  for (float x = -1.0f; x <= 1.0f; x += 0.05f) {
    for (float y = -1.0f; y <= 1.0f; y += 0.05f) {
      // An elongated, asymmetric bump: no symmetry about the vertical axis.
      const float h =
          0.35f * std::exp(-(x - 0.1f) * (x - 0.1f) / 0.08f - y * y / 0.02f) +
          0.15f * std::exp(-(x + 0.3f) * (x + 0.3f) / 0.02f - (y - 0.25f) * (y - 0.25f) / 0.03f);
      points.push_back({x, y, h + noise(rng)});
    }
  }
  return points;
}

TEST(GravityDescriptor, IsInvariantToYaw) {
  const std::vector<Vector3f> points = RockPatch(1);
  const Isometry3d T = GravityAlignedTransform({3.0, -1.0, 0.5}, 0.61);  // not a sector multiple
  std::vector<Vector3f> turned;
  for (const Vector3f& p : points) turned.push_back((T * p.cast<double>()).cast<float>());
  const PointKdTree tree(points), tree_turned(turned);
  const auto normals = ComputeSurfaceNormals(tree, 0.15f);
  const auto normals_turned = ComputeSurfaceNormals(tree_turned, 0.15f);
  const std::vector<Vector3f> keys = {{0.25f, 0.1f, 0.2f}, {-0.3f, 0.25f, 0.1f}};
  std::vector<Vector3f> keys_turned;
  for (const Vector3f& k : keys) keys_turned.push_back((T * k.cast<double>()).cast<float>());
  for (GravityDescriptorKind kind :
       {GravityDescriptorKind::kFourier, GravityDescriptorKind::kOriented}) {
    GravityDescriptorOptions o;
    o.kind = kind;
    const KeypointDescriptors d = ComputeGravityDescriptors(tree, normals, keys, o);
    const KeypointDescriptors dt =
        ComputeGravityDescriptors(tree_turned, normals_turned, keys_turned, o);
    ASSERT_TRUE(d.valid[0] && d.valid[1] && dt.valid[0] && dt.valid[1]);
    const float same = (d.descriptors.row(0) - dt.descriptors.row(0)).norm();
    const float other = (d.descriptors.row(0) - dt.descriptors.row(1)).norm();
    EXPECT_LT(same, 0.1f) << static_cast<int>(kind);
    EXPECT_GT(other, 2.0f * same) << static_cast<int>(kind);
    // The yaw reference turns with the cloud.
    EXPECT_NEAR(
        std::remainder(static_cast<double>(dt.yaw_reference_rad[0] - d.yaw_reference_rad[0]) - 0.61,
                       2.0 * M_PI),
        0.0, 0.02);
  }
  EXPECT_THROW(ComputeGravityDescriptors(tree, {}, keys, {}), std::invalid_argument);
}

TEST(SubmapIcp, RecoversAFourDofOffsetOnItsOwnCloud) {
  // The rock patch repeated on a 3x3 grid with different yaws: structure in
  // every direction.
  PointCloud cloud;
  for (int i = 0; i < 9; ++i) {
    const Isometry3d place = GravityAlignedTransform({2.2 * (i % 3), 2.2 * (i / 3), 0.0}, 0.7 * i);
    for (const Vector3f& p : RockPatch(static_cast<uint64_t>(i))) {
      cloud.push_back({(place * p.cast<double>()).cast<float>(), p.z() > 0.05f});
    }
  }
  octomap::OcTree tree(0.1);
  SubmapMatchDataOptions o;
  o.min_known_ratio = 0.0;
  const SubmapMatchData data(cloud, tree, o);
  const Isometry3d offset = GravityAlignedTransform({0.08, -0.05, 0.03}, 0.02);
  for (const bool four : {true, false}) {
    const SubmapIcpResult r = AlignSubmaps(data, data, offset, four, SubmapIcpOptions{});
    ASSERT_TRUE(r.ok);
    EXPECT_LT(r.T_a_b.translation().norm(), 0.01) << four;
    EXPECT_LT(Eigen::AngleAxisd(r.T_a_b.linear()).angle(), 0.002) << four;
    EXPECT_LT(r.rmse_m, 0.01);
    // [dp; dtheta]: positive translation and yaw variances; in 4D roll and
    // pitch are not estimated.
    EXPECT_GT(r.covariance(0, 0), 0.0);
    EXPECT_GT(r.covariance(5, 5), 0.0);
    if (four) {
      EXPECT_EQ(r.covariance(3, 3), 0.0);
    } else {
      EXPECT_GT(r.covariance(3, 3), 0.0);
    }
  }
}

TEST(LoopOptions, ValidateNamesTheKey) {
  SubmapMatcherOptions m;
  m.max_icp_rmse_m = -1.0;
  try {
    m.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("SubmapMatcherOptions.max_icp_rmse_m"), std::string::npos);
  }
  SubmapMatchDataOptions d;
  d.min_known_ratio = 1.5;
  EXPECT_THROW(d.Validate(), std::invalid_argument);
  d = {};
  d.descriptor.azimuth_sectors = 1;
  try {
    d.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("GravityDescriptorOptions.azimuth_sectors"),
              std::string::npos);
  }
  SubmapPairingOptions p;
  p.focal_px = 0.0;
  EXPECT_THROW(p.Validate(), std::invalid_argument);
  EXPECT_THROW(SubmapMatcher{m}, std::invalid_argument);
}

TEST(LoopOptions, LoadFromYaml) {
  const ConfigNode node = ConfigNode::LoadString(
      "mode: six_dof\nmax_descriptor_distance: 0.3\n"
      "icp: {metric: point_to_point, robust_scale_m: 0.04}\n",
      "test");
  const SubmapMatcherOptions m = SubmapMatcherOptions::Load(node);
  EXPECT_EQ(m.mode, MatchMode::kSixDof);
  EXPECT_EQ(m.max_descriptor_distance, 0.3);
  EXPECT_EQ(m.icp.metric, IcpMetric::kPointToPoint);
  EXPECT_EQ(m.icp.robust_scale_m, 0.04);
  const SubmapMatchDataOptions d = SubmapMatchDataOptions::Load(
      ConfigNode::LoadString("descriptor: {kind: oriented, radius_m: 0.4}\n", "test"));
  EXPECT_EQ(d.descriptor.kind, GravityDescriptorKind::kOriented);
  EXPECT_EQ(d.descriptor.radius_m, 0.4);
  EXPECT_THROW(SubmapPairingOptions::Load(ConfigNode::LoadString("alpha: -1\n", "test")),
               std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
