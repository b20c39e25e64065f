// Stereo rendering throughput, printed as figures (never a timed test):
// stereo pairs per second at the configured resolution (default 752 x 480)
// along a short drive over a default-size generated world, with the split
// into GL work (draw + rasterise), read-back and CPU post-processing
// (distortion remap, depth, sensor effects). The dataset generator needs
// >= 10-20 pairs/s to keep up with real time.
//
// usage: bench_render [--frames N] [--width W --height H --fx F]
//                     [--full-res METRES] [--max-error PX] [--supersample S] [--anisotropy A]
//                     [--no-effects]
//                     [--dump PREFIX]   (PREFIX_cam0.png, _cam1.png, _depth.png)

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/world/world.h"

namespace {

using namespace rover::sim;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// CPU time of the whole process (all llvmpipe threads included): a figure
// that other load on the machine disturbs less than wall time.
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 200;
  std::string dump_prefix;  // writes the last pair and its depth as PNG
  StereoCameraOptions camera;
  RenderOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> double {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "missing value after %s\n", arg.c_str());
        std::exit(2);
      }
      return std::atof(argv[++i]);
    };
    if (arg == "--frames") {
      frames = static_cast<int>(next());
    } else if (arg == "--width") {
      camera.width_px = static_cast<int>(next());
      camera.cx_px = 0.5 * (camera.width_px - 1);
    } else if (arg == "--height") {
      camera.height_px = static_cast<int>(next());
      camera.cy_px = 0.5 * (camera.height_px - 1);
    } else if (arg == "--fx") {
      camera.fx_px = camera.fy_px = next();
    } else if (arg == "--full-res") {
      options.full_resolution_distance_m = next();
    } else if (arg == "--max-error") {
      options.max_terrain_error_px = next();
    } else if (arg == "--supersample") {
      options.supersample = next();
    } else if (arg == "--anisotropy") {
      options.max_anisotropy = next();
    } else if (arg == "--detail") {
      options.detail_strength = next();
    } else if (arg == "--dump") {
      if (i + 1 >= argc) return 2;
      dump_prefix = argv[++i];
    } else if (arg == "--no-effects") {
      options.apply_effects = false;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", arg.c_str());
      return 2;
    }
  }

  const auto t0 = std::chrono::steady_clock::now();
  const World world = World::Generate(WorldOptions(), 1);
  const auto t1 = std::chrono::steady_clock::now();
  StereoRenderer renderer(world, camera, options);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf(
      "world: %d x %d heights at %.3f m, albedo %d x %d, %zu carriers (generated in %.2f s)\n",
      world.terrain.cols(), world.terrain.rows(), world.terrain.resolution_m(), world.albedo.cols,
      world.albedo.rows, world.carriers.size(), Seconds(t1 - t0));
  std::printf("GL renderer: %s\n", renderer.gl_renderer().c_str());
  std::printf("output %d x %d per camera, rasterised %d x %d per camera; set-up %.2f s\n",
              camera.width_px, camera.height_px, renderer.render_width_px(),
              renderer.render_height_px(), Seconds(t2 - t1));

  // A gentle S-curve from the origin at 0.5 m/s, 10 Hz: 20 m in 200 frames.
  std::vector<Eigen::Isometry3d> carrier_poses;
  for (const TagCarrier& c : world.carriers) {
    if (!c.is_static) carrier_poses.push_back(c.T_world_carrier);
  }
  RenderedStereoFrame frame;
  double gl_s = 0.0;
  double readback_s = 0.0;
  double post_s = 0.0;
  double total_s = 0.0;
  double triangles = 0.0;
  double patches = 0.0;
  double worst_s = 0.0;
  double cpu_start_s = 0.0;
  // One warm-up frame: shader variants are compiled on first use.
  for (int i = -1; i < frames; ++i) {
    const double s = 0.05 * std::max(i, 0);
    const double x = s;
    const double y = 2.0 * std::sin(s / 4.0);
    const double yaw = std::atan2(0.5 * std::cos(s / 4.0), 1.0);
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    T_world_body.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_world_body.translation() = Eigen::Vector3d(x, y, world.terrain.HeightAt(x, y) + 0.15);
    if (i == 0) cpu_start_s = ProcessCpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    renderer.Render(T_world_body, carrier_poses, static_cast<uint64_t>(std::max(i, 0)), &frame);
    const double elapsed = Seconds(std::chrono::steady_clock::now() - start);
    if (i < 0) continue;
    total_s += elapsed;
    worst_s = std::max(worst_s, elapsed);
    gl_s += renderer.last_timings().gl_s;
    readback_s += renderer.last_timings().readback_s;
    post_s += renderer.last_timings().post_s;
    triangles += static_cast<double>(renderer.last_triangle_count());
    patches += renderer.last_patch_count();
  }
  const double cpu_s = ProcessCpuSeconds() - cpu_start_s;
  std::printf("last pair: cam0 mean %.1f DN, %.2f %% saturated; depth valid on %.1f %% of pixels\n",
              cv::mean(frame.cam0)[0],
              100.0 * cv::countNonZero(frame.cam0 == 255) / static_cast<double>(frame.cam0.total()),
              100.0 * cv::countNonZero(frame.depth0_m > 0.0f) /
                  static_cast<double>(frame.depth0_m.total()));
  if (!dump_prefix.empty()) {
    cv::imwrite(dump_prefix + "_cam0.png", frame.cam0);
    cv::imwrite(dump_prefix + "_cam1.png", frame.cam1);
    cv::Mat depth_cm;  // 16-bit, centimetres
    frame.depth0_m.convertTo(depth_cm, CV_16U, 100.0);
    cv::imwrite(dump_prefix + "_depth.png", depth_cm);
  }
  const double n = frames;
  std::printf("%d stereo pairs: %.1f pairs/s (%.1f renders/s), mean %.1f ms, worst %.1f ms\n",
              frames, n / total_s, 2.0 * n / total_s, 1e3 * total_s / n, 1e3 * worst_s);
  std::printf(
      "  per pair: GL draw+raster %.1f ms, read-back %.1f ms, remap+depth+effects %.1f ms\n",
      1e3 * gl_s / n, 1e3 * readback_s / n, 1e3 * post_s / n);
  std::printf("  per pair: %.0f terrain patches, %.0f k triangles submitted (both cameras)\n",
              patches / n, triangles / n / 1e3);
  std::printf("  CPU time (all threads) %.1f ms per pair: %.1f pairs/s per core\n", 1e3 * cpu_s / n,
              n / cpu_s);
  std::printf("  real-time factor at 10 Hz: %.2f, at 20 Hz: %.2f\n", n / total_s / 10.0,
              n / total_s / 20.0);
  return 0;
}
