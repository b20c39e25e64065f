// bench_sgbm: DisparityEstimator::Compute (OpenCV StereoSGBM, default
// DisparityOptions) on rectified 752x480 mono8 pairs, and
// DepthImage::FromDisparity on its output, per frame.
//
// The pairs are rendered analytically (exact ray casts, no noise, as in
// mapd's end-to-end test, tests/firmware/mapd/stereo_scene.h): a flat ground
// plane textured with smooth value noise at two scales, seen by a head
// 0.7 m above it pitched down 25 deg, f = 460 px, b = 0.11 m, driving 5 cm
// per frame with a slow turn. Compute is timed on one core
// (cv::setNumThreads(1)) and with OpenCV's default thread count, in the same
// run since the machines are shared; ms per frame as median and p90 after a
// warm-up. As a sanity check of what was timed: the fraction of pixels with
// a disparity and with a kValid point, and the fraction of kValid points
// whose depth is within 3 sigma_z (StereoErrorModel, 0.5 px) of the
// analytic depth of that pixel.
//
// usage: bench_sgbm [--frames N] [--warmup N]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/stats/percentile.h"
#include "mapping/depth/depth_image.h"
#include "mapping/depth/disparity_estimator.h"
#include "mapping/depth/stereo_error_model.h"
#include "tests/firmware/mapd/stereo_scene.h"

namespace {

namespace mapping = rover::mapping;
namespace stats = rover::stats;
using rover::mapd::testing::StereoScene;

constexpr int kWidth = 752;
constexpr int kHeight = 480;
constexpr double kFocalPx = 460.0;
constexpr double kBaselineM = 0.11;

struct Frame {
  cv::Mat left;
  cv::Mat right;
  /// Analytic depth (left camera z) per pixel; NaN where the ray hits nothing.
  std::vector<double> depth_m;
};

double NowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

StereoScene Scene() {
  StereoScene scene;
  scene.width_px = kWidth;
  scene.height_px = kHeight;
  scene.focal_px = kFocalPx;
  scene.baseline_m = kBaselineM;
  scene.ground_z_m = -0.7;  // the head is at body z = 0: 0.7 m above the ground
  // Ground only: the box is moved beyond the 40 m the renderer casts to.
  scene.box_min_xy = {1000.0, 1000.0};
  scene.box_max_xy = {1001.0, 1001.0};
  return scene;
}

// Body pose of frame i: 5 cm per frame forward, turning 0.5 deg per frame.
Eigen::Isometry3d BodyPose(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180.0 * i, Eigen::Vector3d::UnitZ()).matrix();
  T.translation() = Eigen::Vector3d(0.05 * i, 0.0, 0.0);
  return T;
}

Frame Render(const StereoScene& scene, const Eigen::Isometry3d& T_local_body) {
  Frame f;
  f.left.create(kHeight, kWidth, CV_8UC1);
  f.right.create(kHeight, kWidth, CV_8UC1);
  scene.Render(0, T_local_body, f.left.ptr<uint8_t>(0));
  scene.Render(1, T_local_body, f.right.ptr<uint8_t>(0));
  // The same rays as StereoScene::Render (pixel centres at u + 0.5).
  const Eigen::Isometry3d T_local_cam = T_local_body * scene.Camera(0).T_body_cam;
  f.depth_m.assign(static_cast<std::size_t>(kWidth) * kHeight, std::nan(""));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const Eigen::Vector3d ray_cam((u + 0.5 - kWidth / 2.0) / kFocalPx,
                                    (v + 0.5 - kHeight / 2.0) / kFocalPx, 1.0);
      const Eigen::Vector3d dir = (T_local_cam.linear() * ray_cam).normalized();
      const std::optional<Eigen::Vector3d> p = scene.Cast(T_local_cam.translation(), dir);
      if (p) {
        f.depth_m[static_cast<std::size_t>(v) * kWidth + static_cast<std::size_t>(u)] =
            (T_local_cam.inverse() * *p).z();
      }
    }
  }
  return f;
}

// Times fn(i) for frames 0..frames-1 after `warmup` untimed calls.
std::vector<double> TimeEach(int frames, int warmup, const std::function<void(int)>& fn) {
  for (int i = 0; i < warmup; ++i) fn(i % frames);
  std::vector<double> ms;
  for (int i = 0; i < frames; ++i) {
    const double t0 = NowMs();
    fn(i);
    ms.push_back(NowMs() - t0);
  }
  return ms;
}

void PrintTimes(const char* what, const std::vector<double>& ms) {
  const double median = stats::Percentile(ms, 50.0);
  std::printf("  %-34s median %7.2f ms   p90 %7.2f ms   %6.1f fps\n", what, median,
              stats::Percentile(ms, 90.0), 1000.0 / median);
}

int Run(int frames, int warmup) {
  const StereoScene scene = Scene();
  std::printf("rendering %d analytic %dx%d pairs (f = %.0f px, b = %.2f m, 0.7 m high, 25 deg)\n",
              frames, kWidth, kHeight, kFocalPx, kBaselineM);
  std::vector<Frame> pairs;
  for (int i = 0; i < frames; ++i) pairs.push_back(Render(scene, BodyPose(i)));

  const mapping::DisparityOptions options;
  const mapping::DisparityEstimator estimator(options);
  mapping::RectifiedStereo head;
  head.width_px = kWidth;
  head.height_px = kHeight;
  head.focal_px = kFocalPx;
  head.cx_px = kWidth / 2.0 - 0.5;  // the renderer's pixel centres
  head.cy_px = kHeight / 2.0 - 0.5;
  head.baseline_m = kBaselineM;
  const mapping::StereoErrorModel model(head);
  const mapping::DepthImageOptions depth_options;

  std::vector<cv::Mat> disparity(static_cast<std::size_t>(frames));
  const auto compute = [&](int i) {
    const Frame& f = pairs[static_cast<std::size_t>(i)];
    estimator.Compute(f.left, f.right, &disparity[static_cast<std::size_t>(i)]);
  };
  const int default_threads = cv::getNumThreads();
  std::printf(
      "DisparityEstimator::Compute, default options (%s, %d disparities, block %d), "
      "%d frames after %d warm-up:\n",
      options.mode.c_str(), options.num_disparities_px, options.block_size_px, frames, warmup);
  cv::setNumThreads(default_threads);
  const std::vector<double> t_default = TimeEach(frames, warmup, compute);
  cv::setNumThreads(1);
  const std::vector<double> t_single = TimeEach(frames, warmup, compute);
  char label[64];
  std::snprintf(label, sizeof label, "default threads (%d)", default_threads);
  PrintTimes(label, t_default);
  PrintTimes("one thread (setNumThreads(1))", t_single);

  std::vector<mapping::DepthImage> depth(static_cast<std::size_t>(frames));
  const std::vector<double> t_depth = TimeEach(frames, warmup, [&](int i) {
    depth[static_cast<std::size_t>(i)] = mapping::DepthImage::FromDisparity(
        disparity[static_cast<std::size_t>(i)], model, depth_options);
  });
  std::printf("DepthImage::FromDisparity (one thread):\n");
  PrintTimes("FromDisparity", t_depth);
  std::vector<double> t_both;
  for (std::size_t i = 0; i < t_single.size(); ++i) t_both.push_back(t_single[i] + t_depth[i]);
  PrintTimes("Compute + FromDisparity, one core", t_both);

  // Sanity: what SGBM found, against the analytic depth.
  long pixels = 0, matched = 0, valid = 0, uncertain = 0, infinite = 0;
  long valid_with_truth = 0, valid_within_3sigma = 0, points = 0, points_within_3sigma = 0;
  std::vector<double> disparity_error_px;
  std::vector<double> signed_disparity_error_px;  // a bias shifts every point along its ray
  for (int i = 0; i < frames; ++i) {
    const mapping::DepthImage& d = depth[static_cast<std::size_t>(i)];
    const Frame& f = pairs[static_cast<std::size_t>(i)];
    const mapping::DepthImageCounts& c = d.counts();
    pixels += static_cast<long>(kWidth) * kHeight;
    matched += c.valid + c.uncertain + c.infinite;
    valid += c.valid;
    uncertain += c.uncertain;
    infinite += c.infinite;
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const mapping::DepthState s = d.state(u, v);
        if (s != mapping::DepthState::kValid && s != mapping::DepthState::kUncertain) continue;
        const double truth =
            f.depth_m[static_cast<std::size_t>(v) * kWidth + static_cast<std::size_t>(u)];
        const double z = static_cast<double>(d.point(u, v).z());
        // A point where the ray hits nothing counts as wrong.
        const bool within =
            std::isfinite(truth) && std::abs(z - truth) < 3.0 * model.DepthSigma(truth);
        ++points;
        points_within_3sigma += within ? 1 : 0;
        if (s == mapping::DepthState::kValid) {
          ++valid_with_truth;
          valid_within_3sigma += within ? 1 : 0;
          if (std::isfinite(truth)) {
            const double error_px = kFocalPx * kBaselineM / z - kFocalPx * kBaselineM / truth;
            disparity_error_px.push_back(std::abs(error_px));
            signed_disparity_error_px.push_back(error_px);
          }
        }
      }
    }
  }
  const auto frac = [](long a, long b) {
    return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : 0.0;
  };
  std::printf("disparity and depth over all %d frames (%ld pixels):\n", frames, pixels);
  std::printf(
      "  pixels with a disparity     %6.1f %%   (kValid %.1f %%, kUncertain %.1f %%, "
      "kInfinite %.1f %%)\n",
      100.0 * frac(matched, pixels), 100.0 * frac(valid, pixels), 100.0 * frac(uncertain, pixels),
      100.0 * frac(infinite, pixels));
  std::printf("  kValid within 3 sigma_z of the analytic depth   %6.2f %%  (%ld of %ld)\n",
              100.0 * frac(valid_within_3sigma, valid_with_truth), valid_within_3sigma,
              valid_with_truth);
  std::printf("  kValid + kUncertain within 3 sigma_z            %6.2f %%  (%ld of %ld)\n",
              100.0 * frac(points_within_3sigma, points), points_within_3sigma, points);
  if (!disparity_error_px.empty()) {
    std::printf(
        "  kValid |disparity error|: median %.3f px, p90 %.3f px, p99 %.3f px "
        "(3 sigma_z = %.2f px of disparity)\n",
        stats::Percentile(disparity_error_px, 50.0), stats::Percentile(disparity_error_px, 90.0),
        stats::Percentile(disparity_error_px, 99.0), 3.0 * std::sqrt(2.0) * model.pixel_error_px());
    std::printf("  kValid signed disparity error: median %+.3f px, p10 %+.3f px, p90 %+.3f px\n",
                stats::Percentile(signed_disparity_error_px, 50.0),
                stats::Percentile(signed_disparity_error_px, 10.0),
                stats::Percentile(signed_disparity_error_px, 90.0));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 20;
  int warmup = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--frames") == 0) {
      frames = std::max(1, std::atoi(argv[i + 1]));
    } else if (std::strcmp(argv[i], "--warmup") == 0) {
      warmup = std::max(0, std::atoi(argv[i + 1]));
    } else {
      std::fprintf(stderr, "usage: bench_sgbm [--frames N] [--warmup N]\n");
      return 2;
    }
  }
  try {
    return Run(frames, warmup);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
