#include "mapping/tags/tag_ambiguity_resolver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace rover::mapping {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d TrueTag() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).matrix();
  T.translation() = Eigen::Vector3d(12.0, -2.0, 0.8);
  return T;
}

// The wrong solution: the tag turned about its vertical axis by `angle`,
// nearly in place (the two solutions share the tag's centre to a few cm).
Eigen::Isometry3d Wrong(double angle_rad) {
  Eigen::Isometry3d T = TrueTag();
  T.linear() = T.linear() * Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitY()).matrix();
  T.translation() += Eigen::Vector3d(0.0, 0.02, 0.0);
  return T;
}

// The camera drives past the tag along x, 1 m per sighting, 6 m to its
// side: the line of sight turns by 5-10 deg per sighting.
Eigen::Vector3d CameraAt(uint64_t key) {
  return Eigen::Vector3d(2.0 + static_cast<double>(key), -8.0, 0.8);
}

TagPlacements Ambiguous(uint64_t key, const Eigen::Isometry3d& best,
                        const Eigen::Isometry3d& alternative, uint32_t frame = 3) {
  return {.key = key,
          .stamp_ns = static_cast<int64_t>(key) * 500'000'000,
          .tag_id = 7,
          .frame_id = frame,
          .T_local_tag = {best, alternative},
          .p_local_cam = CameraAt(key)};
}

TEST(TagAmbiguityResolverTest, TheSolutionThatStaysPutWinsOverTheOneThatSwings) {
  TagAmbiguityResolver resolver;
  std::vector<TagDecision> decisions;
  // As the rover drives past, the wrong solution swings by 3 deg per image;
  // which of the two fits better changes from image to image.
  for (uint64_t k = 1; k <= 8; ++k) {
    const Eigen::Isometry3d wrong = Wrong((40.0 + 3.0 * static_cast<double>(k)) * kDeg);
    const TagPlacements s =
        k % 2 == 0 ? Ambiguous(k, wrong, TrueTag()) : Ambiguous(k, TrueTag(), wrong);
    for (const TagDecision& d : resolver.Add(s)) decisions.push_back(d);
  }
  ASSERT_EQ(decisions.size(), 8u) << "all decided once enough agree";
  for (const TagDecision& d : decisions) {
    EXPECT_EQ(d.solution, d.key % 2 == 0 ? 1 : 0) << "sighting " << d.key;
    EXPECT_GE(d.support, 4);
  }
  EXPECT_EQ(resolver.waiting(), 0u);
  // A later sighting of the same tag is decided at once.
  const std::vector<TagDecision> late = resolver.Add(Ambiguous(9, Wrong(80.0 * kDeg), TrueTag()));
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0].solution, 1);
}

TEST(TagAmbiguityResolverTest, WideRotationSigmasDoNotLetTheSwingingSolutionAgree) {
  // Far away the rotation sigmas are several degrees: 2.5 sigma (28 deg)
  // would span the wrong solution's swing of 6 deg per image, so it would
  // gather as much support as the right one and nothing would be decided.
  // The cap at 10 deg keeps the wrong solutions apart.
  // Eight sightings, each with 8 deg rotation sigmas, the wrong solution
  // swinging 6 deg per sighting.
  const auto feed = [](TagAmbiguityResolver* resolver) {
    std::vector<TagDecision> decisions;
    for (uint64_t k = 1; k <= 8; ++k) {
      TagPlacements s =
          Ambiguous(k, TrueTag(), Wrong((24.0 + 6.0 * static_cast<double>(k)) * kDeg));
      s.rotation_sigma_rad = {8.0 * kDeg, 8.0 * kDeg};
      s.position_sigma_m = {0.05, 0.05};
      for (const TagDecision& d : resolver->Add(s)) decisions.push_back(d);
    }
    return decisions;
  };
  TagAmbiguityResolver resolver;
  const std::vector<TagDecision> decisions = feed(&resolver);
  ASSERT_EQ(decisions.size(), 8u);
  for (const TagDecision& d : decisions) EXPECT_EQ(d.solution, 0) << "sighting " << d.key;
  TagAmbiguityOptions options;
  options.max_agree_rad = 0.9;  // uncapped: 2.5 x hypot(8, 8) deg = 28 deg
  TagAmbiguityResolver uncapped(options);
  const std::vector<TagDecision> uncapped_decisions = feed(&uncapped);
  EXPECT_TRUE(uncapped_decisions.empty()) << "the rival has as much support";
  EXPECT_EQ(uncapped.waiting(), 8u);
}

TEST(TagAmbiguityResolverTest, SightingsAlongOneLineOfSightDecideNothing) {
  // Driving straight at the tag, the wrong solution stays put as the right
  // one does, so agreement cannot tell them apart. Here the right one is
  // noisier (6 deg apart from sighting to sighting) and the wrong one
  // gathers all the support: without the view change it would be taken.
  const Eigen::Vector3d towards_tag = (TrueTag().translation() - CameraAt(0)).normalized();
  // Sighting k, k = 1..8: the right solution turned by 6k deg, the camera
  // 0.5 k m closer along one line of sight.
  const auto sighting = [&](uint64_t k) {
    Eigen::Isometry3d noisy = TrueTag();
    noisy.linear() =
        noisy.linear() *
        Eigen::AngleAxisd(6.0 * static_cast<double>(k) * kDeg, Eigen::Vector3d::UnitZ()).matrix();
    TagPlacements s = Ambiguous(k, Wrong(40.0 * kDeg), noisy);
    s.p_local_cam = CameraAt(0) + 0.5 * static_cast<double>(k) * towards_tag;
    return s;
  };
  TagAmbiguityResolver resolver;
  for (uint64_t k = 1; k <= 8; ++k) {
    EXPECT_TRUE(resolver.Add(sighting(k)).empty()) << "sighting " << k;
  }
  EXPECT_EQ(resolver.waiting(), 8u);
  TagAmbiguityOptions blind;
  blind.min_view_change_rad = 0.0;
  TagAmbiguityResolver without_view_change(blind);
  std::vector<TagDecision> wrong;
  for (uint64_t k = 1; k <= 8; ++k) {
    for (const TagDecision& d : without_view_change.Add(sighting(k))) wrong.push_back(d);
  }
  ASSERT_FALSE(wrong.empty()) << "the case the view change guards against";
  EXPECT_EQ(wrong[0].solution, 0) << "the wrong solution";
}

TEST(TagAmbiguityResolverTest, TwoStillSolutionsAreNeverDecided) {
  // Head-on along the line of sight the wrong solution does not move: the
  // sightings cannot tell, so nothing is decided and all are refused.
  TagAmbiguityResolver resolver;
  for (uint64_t k = 1; k <= 10; ++k) {
    EXPECT_TRUE(resolver.Add(Ambiguous(k, TrueTag(), Wrong(40.0 * kDeg))).empty());
  }
  const std::vector<TagDecision> expired = resolver.Expire(0, true);
  ASSERT_EQ(expired.size(), 10u);
  for (const TagDecision& d : expired) {
    EXPECT_EQ(d.solution, -1);
    EXPECT_TRUE(d.undecided);
    EXPECT_NE(d.refusal.find("undecided"), std::string::npos) << d.refusal;
  }
}

TEST(TagAmbiguityResolverTest, AcceptedSightingsVoteAndMisfitsAreRefused) {
  TagAmbiguityResolver resolver;
  EXPECT_TRUE(resolver.Add(Ambiguous(1, Wrong(50.0 * kDeg), TrueTag())).empty());
  std::vector<TagDecision> d;
  for (int k = 0; k < 3; ++k) {
    d = resolver.Add({.key = 0, .tag_id = 7, .frame_id = 3, .T_local_tag = {TrueTag()}});
  }
  // The third accepted sighting makes four that agree.
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].key, 1u);
  EXPECT_EQ(d[0].solution, 1);
  EXPECT_EQ(d[0].support, 4);
  // A sighting whose solutions are both elsewhere (a misread pose).
  Eigen::Isometry3d far = TrueTag();
  far.translation().x() += 1.0;
  d = resolver.Add(Ambiguous(4, far, Wrong(70.0 * kDeg)));
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].key, 4u);
  EXPECT_EQ(d[0].solution, -1);
  EXPECT_FALSE(d[0].undecided) << "decided against both";
  EXPECT_NE(d[0].refusal.find("neither"), std::string::npos) << d[0].refusal;
  // Another tag, or the same tag in another frame, is another matter.
  EXPECT_TRUE(resolver.Add(Ambiguous(5, TrueTag(), Wrong(50.0 * kDeg), 5)).empty());
}

TEST(TagAmbiguityResolverTest, ANewFrameOrALongWaitRefusesTheUndecided) {
  TagAmbiguityResolver resolver;
  resolver.Add(Ambiguous(1, TrueTag(), Wrong(45.0 * kDeg), 3));
  // Frame 4's first sighting ends frame 3's wait.
  const std::vector<TagDecision> ended =
      resolver.Add(Ambiguous(2, TrueTag(), Wrong(50.0 * kDeg), 4));
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].key, 1u);
  EXPECT_NE(ended[0].refusal.find("frame ended"), std::string::npos) << ended[0].refusal;
  EXPECT_EQ(resolver.waiting(), 1u);
  EXPECT_TRUE(resolver.Expire(2 * 500'000'000 + 29'000'000'000).empty());
  const std::vector<TagDecision> old = resolver.Expire(2 * 500'000'000 + 31'000'000'000);
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].key, 2u);
}

TEST(TagAmbiguityResolverTest, BadInputIsRefused) {
  TagAmbiguityResolver resolver;
  EXPECT_THROW(resolver.Add({.key = 1, .tag_id = 7, .frame_id = 3}), std::invalid_argument);
  TagAmbiguityOptions o;
  o.min_support = 1;
  EXPECT_THROW(TagAmbiguityResolver{o}, std::invalid_argument);
  o = {};
  o.agree_rad = std::nan("");
  EXPECT_THROW(TagAmbiguityResolver{o}, std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
