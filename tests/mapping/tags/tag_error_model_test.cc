#include "mapping/tags/tag_error_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "mapping/tags/tag_detector.h"
#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pattern.h"
#include "tests/mapping/tags/synthetic_tag_image.h"

namespace rover::mapping {
namespace {

using testing::TagAt;
using testing::TestCamera;

constexpr double kTagSizeM = 0.16;
constexpr double kChi2Six95 = 12.592;

TagErrorTableSpec CoarseSpec() {
  TagErrorTableSpec spec;
  spec.camera = TestCamera();
  spec.tag_size_m = kTagSizeM;
  spec.distance_steps = 14;
  spec.tilt_steps = 15;
  return spec;
}

TagErrorModelOptions TableOptions() {
  TagErrorModelOptions o;
  o.kind = TagErrorModelKind::kTable;
  return o;
}

TagErrorModelOptions AnalyticOptions() {
  TagErrorModelOptions o;
  o.kind = TagErrorModelKind::kAnalytic;
  return o;
}

const TagErrorTable& Table() {
  static const TagErrorTable table = TagErrorTable::Build(CoarseSpec());
  return table;
}

TEST(TagPerturbationTest, ANearObliqueTagIsStableAndAFarHeadOnOneFlips) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  const auto near = ProjectTagCorners(TagAt(1.0, 0.6, 0.1), kTagSizeM, camera);
  const CornerPerturbation stable = PerturbCorners(near, kTagSizeM, camera, 0.3);
  EXPECT_EQ(stable.solved, 257);
  EXPECT_EQ(stable.flipped, 0);
  EXPECT_GT(stable.max_deviation[2], 1e-4) << "the corners moved, so does the pose";
  EXPECT_LT(stable.max_deviation[2], 0.01);
  const auto far = ProjectTagCorners(TagAt(6.0, 0.05), kTagSizeM, camera);
  const CornerPerturbation unstable = PerturbCorners(far, kTagSizeM, camera, 0.3);
  EXPECT_GT(unstable.flipped, 10);
  EXPECT_GT(unstable.max_deviation.tail<3>().maxCoeff(), 0.2);
}

TEST(TagErrorModelTest, AnalyticCovarianceMatchesTheSpreadOfNoisyPoses) {
  // The Jacobian-propagated covariance against Monte Carlo: PnP on corners
  // with Gaussian noise of the same sigma.
  const calib::RectifiedIntrinsics camera = TestCamera();
  const Eigen::Isometry3d T = TagAt(1.5, 0.7, -0.2);
  const auto corners = ProjectTagCorners(T, kTagSizeM, camera);
  constexpr double kSigmaPx = 0.2;
  const Matrix6d analytic = AnalyticTagCovariance(T, kTagSizeM, camera, kSigmaPx);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kSigmaPx);
  Matrix6d sum = Matrix6d::Zero();
  constexpr int kSamples = 3000;
  for (int n = 0; n < kSamples; ++n) {
    auto c = corners;
    for (auto& p : c) p += Eigen::Vector2d(noise(rng), noise(rng));
    std::string error;
    const auto pose = EstimateTagPose(c, kTagSizeM, camera, &error);
    ASSERT_TRUE(pose.has_value()) << error;
    const TagPoseErrors e = TagPoseError(T, pose->best.T_camera_tag);
    sum += e * e.transpose();
  }
  const Matrix6d empirical = sum / kSamples;
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(std::sqrt(analytic(k, k)), std::sqrt(empirical(k, k)),
                0.15 * std::sqrt(empirical(k, k)))
        << "dof " << k;
  }
}

TEST(TagErrorModelTest, TheTableModelTakesTheLargerOfTableAndSpread) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  const TagErrorModel model(TableOptions(), Table());
  const auto corners = ProjectTagCorners(TagAt(1.2, 0.5, 0.1), kTagSizeM, camera);
  std::string error;
  const auto pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  const TagUncertainty u = model.Evaluate(corners, *pose, kTagSizeM, camera);
  ASSERT_TRUE(u.accepted) << u.refusal;
  const TagPoseErrors expected =
      TagErrorModelOptions{}.sigma_per_max_error *
      Table().Lookup(pose->distance_m, pose->tilt_rad).cwiseMax(u.perturbation.max_deviation);
  EXPECT_TRUE(u.sigma.isApprox(expected));
  // Position sigmas across and along the line of sight, turned into the
  // camera frame: along the line of sight the variance is the third.
  const Eigen::Vector3d ray = pose->best.T_camera_tag.translation().normalized();
  const Eigen::Matrix3d position_cov = u.covariance.topLeftCorner(3, 3);
  EXPECT_NEAR(ray.dot(position_cov * ray), expected(2) * expected(2), 1e-12);
  EXPECT_TRUE(LineOfSightRotation(ray).col(2).isApprox(ray));
  const Eigen::Matrix3d position = u.covariance.topLeftCorner(3, 3);
  EXPECT_TRUE(position.isApprox(position.transpose()));
  const Eigen::Matrix3d rotation = u.covariance.bottomRightCorner(3, 3);
  const Eigen::Vector3d rotation_variance = expected.tail(3).array().square();
  EXPECT_TRUE(rotation.isApprox(Eigen::Matrix3d(rotation_variance.asDiagonal())));
  EXPECT_TRUE(u.covariance.topRightCorner(3, 3).isZero());
}

TEST(TagErrorModelTest, ALineOfSightFrameIsARotationAlongTheLineOfSight) {
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d(1.0, -0.4, 2.0),
                                   Eigen::Vector3d(-2.0, 0.5, 0.5)}) {
    const Eigen::Matrix3d R = LineOfSightRotation(p);
    EXPECT_TRUE((R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_TRUE(R.col(2).isApprox(p.normalized()));
    // x lies in the plane of the camera's x and the line of sight.
    EXPECT_NEAR(R.col(0).dot(Eigen::Vector3d::UnitX().cross(p)), 0.0, 1e-12);
  }
  EXPECT_TRUE(LineOfSightRotation(Eigen::Vector3d(0, 0, 1)).isApprox(Eigen::Matrix3d::Identity()));
}

TEST(TagErrorModelTest, AnInflatedUncertaintyCoversBothSolutions) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  const TagErrorModel model(TableOptions(), Table());
  // Small and far, nearly head-on: the two solutions are far apart in
  // rotation and close in position.
  const auto corners = ProjectTagCorners(TagAt(4.5, 0.2, 0.1), kTagSizeM, camera);
  std::string error;
  const auto pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  const TagUncertainty best = model.ForSolution(pose->best.T_camera_tag, kTagSizeM, camera);
  ASSERT_TRUE(best.accepted);
  const TagUncertainty inflated = TagErrorModel::Inflated(*pose, best);
  ASSERT_TRUE(inflated.accepted);
  EXPECT_TRUE(inflated.ambiguous);
  const TagPoseErrors d = TagPoseError(pose->best.T_camera_tag, pose->alternative.T_camera_tag);
  ASSERT_GT(d.tail<3>().norm(), 0.1) << "the two solutions should differ";
  // The alternative lies within half a sigma along the difference ...
  EXPECT_LE(d.dot(inflated.covariance.ldlt().solve(d)), 0.25 + 1e-9);
  EXPECT_GT(d.dot(best.covariance.ldlt().solve(d)), 12.6) << "not covered before";
  // ... and the position keeps its sigma across the line of sight.
  EXPECT_LT(inflated.sigma(0), 3.0 * best.covariance(0, 0) / std::sqrt(best.covariance(0, 0)));
  // With the alternative's own rotation covariance: at least that much in
  // every rotation direction, the position as before.
  const TagUncertainty alternative =
      model.ForSolution(pose->alternative.T_camera_tag, kTagSizeM, camera);
  ASSERT_TRUE(alternative.accepted);
  const TagUncertainty both = TagErrorModel::Inflated(*pose, best, &alternative);
  const Eigen::Matrix3d extra =
      both.covariance.bottomRightCorner<3, 3>() - inflated.covariance.bottomRightCorner<3, 3>();
  EXPECT_TRUE(extra.isApprox(alternative.covariance.bottomRightCorner<3, 3>()));
  const Eigen::Matrix3d position = inflated.covariance.topLeftCorner<3, 3>();
  const Eigen::Matrix3d position_both = both.covariance.topLeftCorner<3, 3>();
  EXPECT_TRUE(position_both.isApprox(position));
}

TEST(TagErrorModelTest, AnUnstablePoseIsRefusedAsAmbiguous) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  for (const TagErrorModelOptions& options : {TableOptions(), AnalyticOptions()}) {
    const TagErrorModel model(options, Table());
    const auto corners = ProjectTagCorners(TagAt(6.0, 0.05), kTagSizeM, camera);
    std::string error;
    const auto pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
    ASSERT_TRUE(pose.has_value()) << error;
    const TagUncertainty u = model.Evaluate(corners, *pose, kTagSizeM, camera);
    EXPECT_FALSE(u.accepted);
    EXPECT_TRUE(u.ambiguous);
    EXPECT_NE(u.refusal.find("ambiguous"), std::string::npos) << u.refusal;
  }
}

TEST(TagErrorModelTest, ATagSeenNearlyEdgeOnIsRefusedWithItsTilt) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  const TagErrorModel model(AnalyticOptions(), std::nullopt);
  const auto corners = ProjectTagCorners(TagAt(1.0, 78.0 * M_PI / 180.0), kTagSizeM, camera);
  std::string error;
  const auto pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  const TagUncertainty u = model.Evaluate(corners, *pose, kTagSizeM, camera);
  EXPECT_FALSE(u.accepted);
  EXPECT_FALSE(u.ambiguous) << "no other sighting can help";
  EXPECT_NE(u.refusal.find("edge-on: tilt 78"), std::string::npos) << u.refusal;
  EXPECT_NE(u.refusal.find("at most 75"), std::string::npos) << u.refusal;
}

TEST(TagErrorModelTest, CornersThatAreNotASquareAreRefused) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  const TagErrorModel model(TableOptions(), Table());
  auto corners = ProjectTagCorners(TagAt(1.1, 0.4), kTagSizeM, camera);
  std::string error;
  auto pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  EXPECT_TRUE(model.Evaluate(corners, *pose, kTagSizeM, camera).accepted);
  // One corner 20 px off, as where the image border cuts the tag (10 px
  // the pose mostly absorbs: 0.65 px RMSE).
  corners[1].y() -= 20.0;
  pose = EstimateTagPose(corners, kTagSizeM, camera, &error);
  ASSERT_TRUE(pose.has_value()) << error;
  const TagUncertainty u = model.Evaluate(corners, *pose, kTagSizeM, camera);
  EXPECT_FALSE(u.accepted);
  EXPECT_FALSE(u.ambiguous);
  EXPECT_NE(u.refusal.find("do not fit a square"), std::string::npos)
      << u.refusal << " rmse " << pose->best.reprojection_rmse_px;
}

TEST(TagErrorModelTest, TheCornerNoiseGrowsObliquelySmallAndNearTheAmbiguity) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  TagErrorModelOptions o = AnalyticOptions();
  o.aligned_edge_sigma_px = 0.0;  // independent corners: a scaled sigma^2 (J^T J)^-1
  const double head_on_px = (1.0 + o.frontal_sigma_gain) * o.corner_sigma_px;
  // Head-on and large (about 100 px across at 1 m): the options' noise with
  // the near-frontal gain.
  EXPECT_NEAR(CornerSigmaPx(o, TagAt(1.0, 0.0), kTagSizeM, camera, 0), head_on_px, 1e-9);
  // Halfway to frontal_tilt_deg: half the gain (and the tilt's growth).
  const double half_rad = 0.5 * o.frontal_tilt_deg * M_PI / 180.0;
  EXPECT_NEAR(CornerSigmaPx(o, TagAt(1.0, half_rad), kTagSizeM, camera, 0),
              (1.0 + 0.5 * o.frontal_sigma_gain) * o.corner_sigma_px *
                  std::pow(1.0 / std::cos(half_rad), o.tilt_sigma_exponent),
              1e-6);
  // 60 degrees, beyond the near-frontal range: 2^exponent as much.
  EXPECT_NEAR(CornerSigmaPx(o, TagAt(1.0, M_PI / 3.0), kTagSizeM, camera, 0),
              std::pow(2.0, o.tilt_sigma_exponent) * o.corner_sigma_px, 1e-6);
  // A flipping detection: by the flip factor.
  EXPECT_NEAR(CornerSigmaPx(o, TagAt(1.0, 0.0), kTagSizeM, camera, 3),
              o.flip_sigma_factor * head_on_px, 1e-9);
  // Half the reference side: 2^0.75 as much.
  const auto c = ProjectTagCorners(TagAt(1.0, 0.0), kTagSizeM, camera);
  const double side_at_1m_px = (c[1] - c[0]).norm();
  const double distance_m = 2.0 * side_at_1m_px / o.small_tag_side_px;
  EXPECT_NEAR(CornerSigmaPx(o, TagAt(distance_m, 0.0), kTagSizeM, camera, 0),
              std::pow(2.0, 0.75) * head_on_px, 1e-3 * head_on_px);
  // The analytic covariance follows it: 2^(2 exponent) times the variance at
  // 60 degrees as with the options' noise.
  const TagErrorModel model(o, std::nullopt);
  const Eigen::Isometry3d T = TagAt(1.0, M_PI / 3.0);
  const TagUncertainty u = model.ForSolution(T, kTagSizeM, camera);
  ASSERT_TRUE(u.accepted);
  const Matrix6d head_on_noise = AnalyticTagCovariance(T, kTagSizeM, camera, o.corner_sigma_px);
  EXPECT_TRUE(u.covariance.isApprox(std::pow(4.0, o.tilt_sigma_exponent) * o.flip_sigma_factor *
                                        o.flip_sigma_factor * head_on_noise,
                                    1e-6))
      << "a solution chosen between two counts as flipping";
}

struct Coverage {
  int accepted = 0;
  int in_bound = 0;
  int wrong_accepted = 0;
  double median_nees = 0.0;
};

// Tags rendered with other blur, noise and contrast than the table's,
// anywhere in the view, upright (their edges along the pixel rows and
// columns, as a level rover sees a post's tag): the accepted detections'
// NEES under `model`.
Coverage CoverageOfRenderedDetections(const TagErrorModel& model) {
  const calib::RectifiedIntrinsics camera = TestCamera();
  std::vector<double> nees;
  TagDetector detector(TagDetectorOptions{});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Coverage c;
  for (int n = 0; n < 80; ++n) {
    const double d = 0.4 + 4.0 * unit(rng);
    const double tilt = (unit(rng) - 0.5) * 140.0 * M_PI / 180.0;
    const Eigen::Isometry3d T = TagAt(d, tilt, (unit(rng) - 0.5) * 0.5 * d);
    TagRenderOptions render;
    render.blur_sigma_px = 0.4 + 0.6 * unit(rng);
    render.noise_sigma_dn = 2.0 * unit(rng);
    render.noise_seed = static_cast<uint64_t>(n) + 1;
    const cv::Mat image = RenderTagImage(MakeTagPattern("tag36h11", n), kTagSizeM, T, camera,
                                         cv::Size(752, 480), render);
    const auto found = detector.Detect(image);
    if (found.size() != 1) continue;
    std::string error;
    const auto pose = EstimateTagPose(found[0].corners_px, kTagSizeM, camera, &error);
    if (!pose) continue;
    const TagUncertainty u = model.Evaluate(found[0].corners_px, *pose, kTagSizeM, camera);
    if (!u.accepted) continue;
    ++c.accepted;
    const TagPoseErrors e = TagPoseError(pose->best.T_camera_tag, T);
    c.wrong_accepted += e.tail<3>().norm() > 20.0 * M_PI / 180.0;
    nees.push_back(e.dot(u.covariance.ldlt().solve(e)));
    c.in_bound += nees.back() <= kChi2Six95;
  }
  if (!nees.empty()) {
    std::nth_element(nees.begin(), nees.begin() + static_cast<std::ptrdiff_t>(nees.size() / 2),
                     nees.end());
    c.median_nees = nees[nees.size() / 2];
  }
  return c;
}

// At least 90 % of the NEES within the chi^2(6) 95 % bound, the median not
// above chi^2(6)'s (5.35: not overconfident), and no pose on the wrong side
// of the ambiguity accepted.
void ExpectCovered(const Coverage& c) {
  EXPECT_GT(c.accepted, 40);
  EXPECT_GE(c.in_bound, 0.9 * c.accepted) << c.in_bound << " of " << c.accepted;
  EXPECT_EQ(c.wrong_accepted, 0);
  EXPECT_LT(c.median_nees, 5.3) << "not overconfident";
}

TEST(TagErrorModelTest, OnlyEdgesAlongThePixelGridShareAnOffset) {
  // A square 40 px across with its edges along the rows and columns: each
  // edge's offset moves its two corners together along its normal.
  const std::array<Eigen::Vector2d, 4> square = {
      Eigen::Vector2d(100, 100), Eigen::Vector2d(140, 100), Eigen::Vector2d(140, 140),
      Eigen::Vector2d(100, 140)};
  const Matrix8d C = AlignedEdgeCovariance(square, 0.1);
  // Corner 0's y and corner 1's y (the edge 0 -> 1 along x): fully shared.
  EXPECT_NEAR(C(1, 1), 0.01, 1e-12);
  EXPECT_NEAR(C(1, 3), 0.01, 1e-12);
  EXPECT_NEAR(C(0, 2), 0.0, 1e-12) << "x of corners 0 and 1 lie on different vertical edges";
  EXPECT_NEAR(C(0, 6), 0.01, 1e-12) << "corners 0 and 3 share the vertical edge x = 100";
  // Rolled by 10 degrees the phase sweeps 7 px along each edge: nothing shared.
  std::array<Eigen::Vector2d, 4> rolled;
  const Eigen::Rotation2Dd R(10.0 * M_PI / 180.0);
  for (std::size_t k = 0; k < 4; ++k) rolled[k] = R * square[k];
  EXPECT_TRUE(AlignedEdgeCovariance(rolled, 0.1).isZero(1e-15));
  // By 0.5 degree (0.35 px): partly.
  const Eigen::Rotation2Dd r(0.5 * M_PI / 180.0);
  for (std::size_t k = 0; k < 4; ++k) rolled[k] = r * square[k];
  const double shared = AlignedEdgeCovariance(rolled, 0.1)(1, 3);
  EXPECT_GT(shared, 0.3 * 0.01);
  EXPECT_LT(shared, 0.8 * 0.01);
}

TEST(TagErrorModelTest, TheTableCoversTheTrueErrorOfRenderedDetections) {
  ExpectCovered(CoverageOfRenderedDetections(TagErrorModel(TableOptions(), Table())));
}

TEST(TagErrorModelTest, TheAnalyticModelCoversUprightTagsByTheirAlignedEdges) {
  const TagErrorModelOptions with_edges = AnalyticOptions();
  ASSERT_GT(with_edges.aligned_edge_sigma_px, 0.0);
  ExpectCovered(CoverageOfRenderedDetections(TagErrorModel(with_edges, std::nullopt)));
  // Independent corners alone are overconfident on these tags.
  TagErrorModelOptions independent = with_edges;
  independent.aligned_edge_sigma_px = 0.0;
  const Coverage c = CoverageOfRenderedDetections(TagErrorModel(independent, std::nullopt));
  EXPECT_LT(c.in_bound, 0.8 * c.accepted) << c.in_bound << " of " << c.accepted;
}

TEST(TagErrorModelTest, OptionsAreChecked) {
  EXPECT_THROW(TagErrorModel(TableOptions(), std::nullopt), std::invalid_argument);
  TagErrorModelOptions o;
  o.max_tilt_deg = 90.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagErrorModelOptions{};
  o.flip_sigma_factor = 0.5;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagErrorModelOptions{};
  o.sigma_per_max_error = 0.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagErrorModelOptions{};
  o.max_flipped_fraction = 1.5;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = TagErrorModelOptions{};
  o.kind = TagErrorModelKind::kAnalytic;
  EXPECT_NO_THROW(TagErrorModel(o, std::nullopt));
}

}  // namespace
}  // namespace rover::mapping
