// Per-frame cost of the whole stereo VO (StereoOdometry::Process) on one core,
// broken down by stage as OpenVINS reports its timing, over the frames of an
// EuRoC-layout dataset (default: the real 752 x 480 EuRoC excerpt; pass a
// simulator dataset for rover-like motion). Images are decoded before timing.
//
// Target: <= 25 ms per frame at 752 x 480 on one core. For a
// reference measured in the same run (the shared machines drift), the bench
// also times a bare KLT front-end step on the same frames: remap of both
// images, pyramids, and forward + backward pyramidal KLT of 300 features, the
// part every KLT-based VO pays; the VO's cost is printed relative to it.
//
// usage: bench_stereo_odometry [DATASET_DIR] [--frames N] [--passes N]

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "core/stats/percentile.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/stereo_odometry.h"
#include "tests/estimator/vo/euroc_vo_util.h"

namespace rover::estimator::vo {
namespace {

struct Options {
  std::string dataset = ROVER_VO_BENCH_DATA;
  size_t frames = 0;  // 0: all
  int passes = 3;
};

Options Parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) {
      o.frames = std::stoul(argv[++i]);
    } else if (a == "--passes" && i + 1 < argc) {
      o.passes = std::max(1, std::stoi(argv[++i]));
    } else if (a == "--help" || a == "-h") {
      std::printf("usage: bench_stereo_odometry [DATASET_DIR] [--frames N] [--passes N]\n");
      std::exit(0);
    } else {
      o.dataset = a;
    }
  }
  return o;
}

// Remap, pyramids and forward-backward KLT of `features` from frame a to b [ms].
double ReferenceKltMs(const calib::StereoRectifier& rectifier, const StereoImages& a,
                      const StereoImages& b, const std::vector<cv::Point2f>& features) {
  const auto t0 = std::chrono::steady_clock::now();
  cv::Mat a0, a1, b0, b1;
  rectifier.Rectify(a.cam0, a.cam1, &a0, &a1);
  rectifier.Rectify(b.cam0, b.cam1, &b0, &b1);
  std::vector<cv::Mat> pa, pb;
  const cv::Size window(21, 21);
  cv::buildOpticalFlowPyramid(a0, pa, window, 3);
  cv::buildOpticalFlowPyramid(b0, pb, window, 3);
  std::vector<cv::Point2f> fwd, back;
  std::vector<unsigned char> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(pa, pb, features, fwd, status, error, window, 3);
  cv::calcOpticalFlowPyrLK(pb, pa, fwd, back, status, error, window, 3);
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int Run(const Options& o) {
  cv::setNumThreads(1);  // one core, as the VO thread gets on the rover
  const drivers::EurocDataset d = drivers::EurocDataset::Load(o.dataset);
  std::vector<StereoImages> frames;
  for (const auto& f : d.stereo_frames()) {
    if (o.frames != 0 && frames.size() >= o.frames) break;
    frames.push_back({f.stamp, frames.size(), cv::imread(f.cam0_path, cv::IMREAD_GRAYSCALE),
                      cv::imread(f.cam1_path, cv::IMREAD_GRAYSCALE)});
  }
  if (frames.size() < 2) {
    std::fprintf(stderr, "%s: expected at least 2 stereo frames, found %zu\n", o.dataset.c_str(),
                 frames.size());
    return 2;
  }
  StereoOdometryOptions options;
  options.checks.nominal_rate_hz = d.cam0().rate_hz;
  std::vector<VoStageTimes> times;
  VoHealth health;
  for (int pass = 0; pass < o.passes; ++pass) {
    std::string error;
    auto vo = StereoOdometry::Create(d.cam0(), d.cam1(), options, &error);
    if (!vo) {
      std::fprintf(stderr, "%s: %s\n", o.dataset.c_str(), error.c_str());
      return 2;
    }
    for (const StereoImages& f : frames) times.push_back(vo->Process(f).times);
    health = vo->health();
  }
  // Reference: the bare KLT step over consecutive frames, 300 features of the first.
  auto rectifier = calib::StereoRectifier::Create(d.cam0(), d.cam1());
  cv::Mat r0, r1;
  rectifier->Rectify(frames[0].cam0, frames[0].cam1, &r0, &r1);
  std::vector<cv::Point2f> features = FeatureDetector().Detect(r0);
  if (features.size() > 300) features.resize(300);
  std::vector<double> reference;
  for (int pass = 0; pass < o.passes; ++pass) {
    for (size_t i = 1; i < frames.size(); ++i) {
      reference.push_back(ReferenceKltMs(*rectifier, frames[i - 1], frames[i], features));
    }
  }

  const auto column = [&](double VoStageTimes::*field) {
    std::vector<double> v;
    for (const VoStageTimes& t : times) v.push_back(t.*field);
    return v;
  };
  struct Stage {
    const char* name;
    double VoStageTimes::*field;
  };
  const Stage stages[] = {
      {"check", &VoStageTimes::check_ms},     {"rectify", &VoStageTimes::rectify_ms},
      {"pyramid", &VoStageTimes::pyramid_ms}, {"track", &VoStageTimes::track_ms},
      {"stereo", &VoStageTimes::stereo_ms},   {"detect", &VoStageTimes::detect_ms},
      {"ransac", &VoStageTimes::ransac_ms},   {"refine", &VoStageTimes::refine_ms},
      {"total", &VoStageTimes::total_ms}};
  std::printf("bench_stereo_odometry: %s\n", o.dataset.c_str());
  std::printf(
      "  %zu frames x %d passes, %d x %d, one OpenCV thread; %llu measurements, %llu keyframes per "
      "pass\n",
      frames.size(), o.passes, frames[0].cam0.cols, frames[0].cam0.rows,
      static_cast<unsigned long long>(health.measurements),
      static_cast<unsigned long long>(health.keyframes));
  std::printf("  %-8s %8s %8s %8s %8s\n", "stage", "mean", "median", "p99", "max");
  for (const Stage& s : stages) {
    const std::vector<double> v = column(s.field);
    double sum = 0.0;
    for (double x : v) sum += x;
    std::printf("  %-8s %8.2f %8.2f %8.2f %8.2f   ms\n", s.name,
                sum / static_cast<double>(v.size()), stats::Percentile(v, 50.0),
                stats::Percentile(v, 99.0), stats::Percentile(v, 100.0));
  }
  const std::vector<double> total = column(&VoStageTimes::total_ms);
  const double ref_p50 = stats::Percentile(reference, 50.0);
  std::printf("  reference (remap + pyramids + fwd/bwd KLT of %zu features): median %.2f ms\n",
              features.size(), ref_p50);
  std::printf(
      "RESULT vo_ms_p50=%.2f vo_ms_p99=%.2f budget_ms=25 p99_over_budget=%.2f "
      "reference_ms_p50=%.2f vo_over_reference=%.2f\n",
      stats::Percentile(total, 50.0), stats::Percentile(total, 99.0),
      stats::Percentile(total, 99.0) / 25.0, ref_p50, stats::Percentile(total, 50.0) / ref_p50);
  return 0;
}

}  // namespace
}  // namespace rover::estimator::vo

int main(int argc, char** argv) {
  try {
    return rover::estimator::vo::Run(rover::estimator::vo::Parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_stereo_odometry: %s\n", e.what());
    return 2;
  }
}
