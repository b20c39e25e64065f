// A camera driving past a tag, so that the line of sight sweeps through the
// tag's normal (the fronto-parallel pose, where the planar ambiguity is at
// its worst): the observer's detections as mapd takes them (accepted ones
// vote, ambiguous ones wait for the resolver, undecided ones keep their
// rotation open) never claim the wrong solution.

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "mapping/tags/tag_ambiguity_resolver.h"
#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_observer.h"
#include "mapping/tags/tag_pattern.h"
#include "mapping/tags/tag_pose_errors.h"
#include "tests/mapping/tags/synthetic_tag_image.h"

namespace rover::mapping {
namespace {

using testing::TestCamera;

constexpr double kDeg = M_PI / 180.0;
constexpr double kChi2Six95 = 12.592;

TagErrorTable SweepTable() {
  TagErrorTableSpec spec;
  spec.camera = TestCamera();
  spec.distance_steps = 12;
  spec.tilt_steps = 13;
  return TagErrorTable::Build(spec);
}

struct Claim {
  Eigen::Isometry3d T_camera_tag;
  Matrix6d covariance;
  Eigen::Isometry3d truth;
};

TEST(TagSweepTest, NoWrongSolutionIsClaimedWhileTheLineOfSightSweepsThroughTheNormal) {
  TagObserverOptions options;
  TagMarker post;
  post.id = 5;
  post.size_m = 0.16;
  options.markers = {post};
  TagObserver observer(options, TestCamera(), cv::Size(752, 480), {SweepTable()});
  TagAmbiguityResolver resolver;
  // The tag faces the camera's path head-on from 4.5 m; the camera drives
  // 3 m along its x axis, 5 cm per image, the tag ahead and to the side.
  Eigen::Isometry3d T_local_tag = Eigen::Isometry3d::Identity();
  T_local_tag.translation() = Eigen::Vector3d(0.0, 0.0, 4.5);
  TagRenderOptions render;
  render.blur_sigma_px = 0.7;
  render.noise_sigma_dn = 2.0;
  std::map<uint64_t, std::pair<TagObservation, Eigen::Isometry3d>>
      waiting;  // key -> (o, T_local_cam)
  std::vector<Claim> claims;
  int ambiguous = 0;
  uint64_t key = 1;
  const auto settle = [&](const std::vector<TagDecision>& decisions) {
    for (const TagDecision& d : decisions) {
      auto it = waiting.find(d.key);
      ASSERT_NE(it, waiting.end());
      TagObservation& o = it->second.first;
      const Eigen::Isometry3d truth = it->second.second.inverse() * T_local_tag;
      if (d.solution >= 0) {
        const TagPoseSolution& s = d.solution == 0 ? o.pose->best : o.pose->alternative;
        claims.push_back(
            {s.T_camera_tag, o.solutions[static_cast<std::size_t>(d.solution)].covariance, truth});
      } else if (d.undecided) {
        claims.push_back({o.pose->best.T_camera_tag, o.inflated.covariance, truth});
      }
      waiting.erase(it);
    }
  };
  for (int k = 0; k <= 60; ++k) {
    Eigen::Isometry3d T_local_cam = Eigen::Isometry3d::Identity();
    T_local_cam.translation().x() = -1.5 + 0.05 * k;
    const Eigen::Isometry3d truth = T_local_cam.inverse() * T_local_tag;
    render.noise_seed = static_cast<uint64_t>(k + 1);
    const cv::Mat image = RenderTagImage(MakeTagPattern("tag36h11", 5), 0.16, truth, TestCamera(),
                                         cv::Size(752, 480), render);
    for (TagObservation& o : observer.Observe(image)) {
      if (o.accepted) {
        claims.push_back({o.pose->best.T_camera_tag, o.uncertainty.covariance, truth});
        settle(resolver.Add(PlacementsOf(o, T_local_cam, 0, k * 100'000'000LL, 0)));
      } else if (o.uncertainty.ambiguous) {
        ++ambiguous;
        const TagPlacements p = PlacementsOf(o, T_local_cam, key, k * 100'000'000LL, 0);
        waiting.emplace(key++, std::pair{std::move(o), T_local_cam});
        settle(resolver.Add(p));
      }
    }
  }
  settle(resolver.Expire(0, true));
  EXPECT_GT(ambiguous, 5) << "the sweep should hit the ambiguity";
  ASSERT_GT(claims.size(), 40u);
  int wrong = 0;
  int wrong_claimed = 0;
  int in_bound = 0;
  for (const Claim& c : claims) {
    const TagPoseErrors e = TagPoseError(c.T_camera_tag, c.truth);
    const double nees = e.dot(c.covariance.ldlt().solve(e));
    in_bound += nees <= kChi2Six95;
    if (e.tail<3>().norm() > 20.0 * kDeg) {
      ++wrong;
      wrong_claimed += nees > kChi2Six95;
    }
  }
  EXPECT_EQ(wrong_claimed, 0) << wrong << " wrong solutions among " << claims.size();
  // Noisier than the table's renderings (2 DN, blur 0.7 px): 84 % within the
  // bound when this was written.
  EXPECT_GE(in_bound, static_cast<int>(0.8 * static_cast<double>(claims.size())));
}

}  // namespace
}  // namespace rover::mapping
