// Disparity to depth: SGBM on a synthetic textured plane recovers its
// depth; invalid, infinitely far, too uncertain and valid pixels stay apart;
// the texture filter counts sensor noise, also where the image was brightened;
// the flipped second pass cancels SGBM's pull on slanted surfaces.

#include "mapping/depth/depth_image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/stats/percentile.h"
#include "mapping/depth/disparity_estimator.h"

namespace rover::mapping {
namespace {

RectifiedStereo Head(int w, int h) {
  RectifiedStereo s;
  s.width_px = w;
  s.height_px = h;
  s.focal_px = 400.0;
  s.cx_px = w / 2.0;
  s.cy_px = h / 2.0;
  s.baseline_m = 0.1;
  return s;
}

TEST(DepthImageTest, ClassifiesEachKindOfPixel) {
  const RectifiedStereo s = Head(4, 1);
  const StereoErrorModel model(s, 0.5);
  cv::Mat disparity(1, 4, CV_16SC1);
  disparity.at<int16_t>(0, 0) = -16;      // no match
  disparity.at<int16_t>(0, 1) = 0;        // zero disparity: beyond range
  disparity.at<int16_t>(0, 2) = 16 * 2;   // 2 px: z = 20 m, sigma_z = 1.4 m
  disparity.at<int16_t>(0, 3) = 16 * 40;  // 40 px: z = 1 m, sigma_z = 1.8 cm
  const DepthImage depth = DepthImage::FromDisparity(disparity, model, {});
  EXPECT_EQ(depth.state(0, 0), DepthState::kInvalid);
  EXPECT_EQ(depth.state(1, 0), DepthState::kInfinite);
  EXPECT_EQ(depth.state(2, 0), DepthState::kUncertain);
  EXPECT_EQ(depth.state(3, 0), DepthState::kValid);
  EXPECT_NEAR(depth.point(3, 0).z(), 1.0f, 1e-6f);
  EXPECT_NEAR(depth.depth_sigma(3, 0), 0.5 * 1.0 / 40.0 * std::sqrt(2.0), 1e-6);
  EXPECT_EQ(depth.counts().invalid, 1);
  EXPECT_EQ(depth.counts().infinite, 1);
  EXPECT_EQ(depth.counts().uncertain, 1);
  EXPECT_EQ(depth.counts().valid, 1);
  EXPECT_THROW(DepthImage::FromDisparity(cv::Mat(2, 4, CV_16SC1), model, {}),
               std::invalid_argument);
}

TEST(DepthImageTest, SgbmRecoversATexturedPlane) {
  const int w = 320, h = 240;
  const double disparity_px = 20.0;  // z = 400 * 0.1 / 20 = 2 m
  cv::Mat texture(h, w + 64, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  // A fronto-parallel plane: a texture column c is at u_l = c - 32 in the
  // left image and at u_r = u_l - d in the right one.
  const cv::Mat left = texture(cv::Rect(32, 0, w, h)).clone();
  const cv::Mat right = texture(cv::Rect(32 + static_cast<int>(disparity_px), 0, w, h)).clone();
  const DisparityEstimator sgbm({});
  cv::Mat disparity;
  sgbm.Compute(left, right, &disparity);
  const RectifiedStereo s = Head(w, h);
  const DepthImage depth = DepthImage::FromDisparity(disparity, StereoErrorModel(s), {});
  int good = 0, inside = 0;
  for (int v = 10; v < h - 10; ++v) {
    for (int u = 80; u < w - 10; ++u) {  // left border: no match by construction
      ++inside;
      if (depth.state(u, v) == DepthState::kValid &&
          std::abs(depth.point(u, v).z() - 2.0f) < 0.02f) {
        ++good;
      }
    }
  }
  EXPECT_GT(static_cast<double>(good) / inside, 0.95) << good << " of " << inside;
  EXPECT_THROW(sgbm.Compute(left, cv::Mat(), &disparity), std::invalid_argument);
}

// A textured plane 20 px of disparity away with a band of flat grey plus
// faint noise (a sky: 1 DN) across its top third, the sky brightened by
// `sky_gain` after capture; left and right images of w x h.
struct SkyScene {
  static constexpr int w = 320, h = 240;
  cv::Mat left, right;
};

SkyScene MakeSkyScene(double sky_gain = 1.0) {
  SkyScene scene;
  const int w = SkyScene::w, h = SkyScene::h;
  cv::Mat texture(h, w + 64, CV_8UC1);
  cv::RNG rng(5);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  cv::Mat sky = texture.rowRange(0, h / 3);
  rng.fill(sky, cv::RNG::NORMAL, 30, 1);
  if (sky_gain != 1.0) sky.convertTo(sky, CV_8U, sky_gain);
  scene.left = texture(cv::Rect(32, 0, w, h)).clone();
  scene.right = texture(cv::Rect(52, 0, w, h)).clone();
  return scene;
}

// Pixels of rows [row0, row1) x columns [col0, col1) with a disparity.
int MatchedPixels(const cv::Mat& d, int row0, int row1, int col0, int col1) {
  int n = 0;
  for (int v = row0; v < row1; ++v) {
    for (int u = col0; u < col1; ++u) n += d.at<int16_t>(v, u) >= 0 ? 1 : 0;
  }
  return n;
}

TEST(DisparityEstimatorTest, TexturelessRegionsAndTheBorderGetNoDisparity) {
  // The textured plane of the test above, with a sky across its top third.
  const SkyScene scene = MakeSkyScene();
  const int w = SkyScene::w, h = SkyScene::h;
  const cv::Mat& left = scene.left;
  const cv::Mat& right = scene.right;
  const DisparityEstimator filtered({});
  DisparityOptions unfiltered_options;
  unfiltered_options.min_texture_dn = 0.0;
  const DisparityEstimator unfiltered(unfiltered_options);
  cv::Mat with, without;
  filtered.Compute(left, right, &with);
  unfiltered.Compute(left, right, &without);
  EXPECT_GT(MatchedPixels(without, 10, h / 3 - 10, 80, w - 10), 100) << "SGBM matches the noise";
  EXPECT_EQ(MatchedPixels(with, 10, h / 3 - 10, 80, w - 10), 0);
  EXPECT_GT(MatchedPixels(with, h / 3 + 10, h - 10, 80, w - 10), 0.95 * (h - h / 3 - 20) * (w - 90))
      << "the textured part keeps its disparities";
  // Half a block (5 px: 2) plus one around the border: none.
  EXPECT_EQ(MatchedPixels(with, 0, h, w - 3, w), 0);
  EXPECT_EQ(MatchedPixels(with, h - 3, h, 0, w), 0);
}

TEST(DisparityEstimatorTest, TheTextureThresholdScalesWithTheLeftImagesGain) {
  // The sky of the test above brightened 4x after capture, as a flat field
  // brightens a vignetted corner: its noise (about 0.35 DN/px) now measures
  // 1.4 DN/px in the image, but still 0.35 in sensor counts.
  constexpr float kSkyGain = 4.0f;
  const SkyScene scene = MakeSkyScene(kSkyGain);
  const int w = SkyScene::w, h = SkyScene::h;
  const cv::Mat& left = scene.left;
  const cv::Mat& right = scene.right;
  cv::Mat gain(h, w, CV_32FC1, cv::Scalar(1.0f));
  gain.rowRange(0, h / 3).setTo(kSkyGain);
  const DisparityEstimator with_gain({}, gain);
  const DisparityEstimator without_gain({});
  cv::Mat with, without;
  with_gain.Compute(left, right, &with);
  without_gain.Compute(left, right, &without);
  EXPECT_GT(MatchedPixels(without, 10, h / 3 - 10, 80, w - 10), 100)
      << "a threshold in image counts passes the brightened noise";
  EXPECT_EQ(MatchedPixels(with, 10, h / 3 - 10, 80, w - 10), 0);
  EXPECT_GT(MatchedPixels(with, h / 3 + 10, h - 10, 80, w - 10), 0.95 * (h - h / 3 - 20) * (w - 90))
      << "the textured part keeps its disparities";
}

TEST(DisparityEstimatorTest, RejectsABadLeftGainNamingIt) {
  EXPECT_THROW(DisparityEstimator({}, cv::Mat(4, 4, CV_16UC1, cv::Scalar(256))),
               std::invalid_argument);
  EXPECT_THROW(DisparityEstimator({}, cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.0f))),
               std::invalid_argument);
  const DisparityEstimator sgbm({}, cv::Mat(4, 4, CV_32FC1, cv::Scalar(1.5f)));
  const cv::Mat image(240, 320, CV_8UC1, cv::Scalar(0));
  cv::Mat disparity;
  try {
    sgbm.Compute(image, image, &disparity);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("left gain's size 4x4, found 320x240"), std::string::npos)
        << e.what();
  }
}

// A plane whose disparity grows by `slope_px_per_row` down the image, as the
// ground does (from 12 px at the top; from 44 px if it shrinks): a smooth
// random texture resampled (box-integrated, linear between texels) at each
// row's sub-pixel shift.
struct SlantedPair {
  static constexpr int w = 320, h = 240;
  cv::Mat left, right;
  double Disparity(int v) const {
    return (slope_px_per_row > 0.0 ? 12.0 : 44.0) + slope_px_per_row * v;
  }
  double slope_px_per_row = 0.0;
};

SlantedPair MakeSlantedPair(double slope_px_per_row) {
  SlantedPair pair;
  pair.slope_px_per_row = slope_px_per_row;
  constexpr int kOversample = 4;
  cv::Mat texture(SlantedPair::h, (SlantedPair::w + 128) * kOversample, CV_32FC1);
  cv::RNG rng(11);
  rng.fill(texture, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 4.0);
  cv::normalize(texture, texture, 0.0, 255.0, cv::NORM_MINMAX);
  // Mean of the texture over the pixel [x, x + 1) of row v.
  const auto pixel = [&](int v, double x) {
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) {
      const double t = (x + (k + 0.5) / 8.0) * kOversample;
      const int i = static_cast<int>(t);
      const double a = t - i;
      sum += (1.0 - a) * static_cast<double>(texture.at<float>(v, i)) +
             a * static_cast<double>(texture.at<float>(v, i + 1));
    }
    return sum / 8.0;
  };
  pair.left.create(SlantedPair::h, SlantedPair::w, CV_8UC1);
  pair.right.create(SlantedPair::h, SlantedPair::w, CV_8UC1);
  for (int v = 0; v < SlantedPair::h; ++v) {
    for (int u = 0; u < SlantedPair::w; ++u) {
      pair.left.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(pixel(v, u + 64.0));
      pair.right.at<uint8_t>(v, u) =
          cv::saturate_cast<uint8_t>(pixel(v, u + 64.0 + pair.Disparity(v)));
    }
  }
  return pair;
}

// Median of (measured - true) disparity over the matched interior [px].
double MedianDisparityError(const SlantedPair& pair, const DisparityEstimator& sgbm) {
  cv::Mat disparity;
  sgbm.Compute(pair.left, pair.right, &disparity);
  std::vector<double> errors;
  for (int v = 10; v < SlantedPair::h - 10; ++v) {
    for (int u = 80; u < SlantedPair::w - 10; ++u) {
      const int d = disparity.at<int16_t>(v, u);
      if (d >= 0) errors.push_back(d / 16.0 - pair.Disparity(v));
    }
  }
  EXPECT_GT(errors.size(), 0.8 * (SlantedPair::h - 20) * (SlantedPair::w - 90));
  return stats::Percentile(errors, 50.0);
}

TEST(DisparityEstimatorTest, TheFlipPassRemovesTheSlantedSurfaceBias) {
  DisparityOptions one_pass;
  one_pass.flip_pass = false;
  for (const double slope : {0.13, -0.13}) {
    const SlantedPair pair = MakeSlantedPair(slope);
    // Aggregated from the top down only, a one-pass disparity is pulled
    // towards the rows above: below the truth when it grows down the image.
    const double one_pass_error = MedianDisparityError(pair, DisparityEstimator(one_pass));
    EXPECT_GT(std::abs(one_pass_error), 0.04) << "slope " << slope;
    EXPECT_LT(one_pass_error * slope, 0.0) << "slope " << slope;
    // Both passes together: what is left is SGBM's sub-pixel interpolation
    // (+0.02 px here, as on a fronto-parallel plane).
    EXPECT_LT(std::abs(MedianDisparityError(pair, DisparityEstimator({}))), 0.03)
        << "slope " << slope;
  }
}

TEST(DisparityOptionsTest, RejectsBadValuesNamingThem) {
  DisparityOptions o;
  o.num_disparities_px = 60;
  try {
    o.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("num_disparities_px"), std::string::npos);
  }
  o = {};
  o.mode = "fast";
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.min_texture_dn = -1.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.max_flip_diff_px = std::nan("");
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
