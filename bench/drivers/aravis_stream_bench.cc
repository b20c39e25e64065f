// AravisCamera figures against a real GigE Vision stream: Aravis's simulator
// arv-fake-gv-camera-0.8, started here on 127.0.0.1 (package aravis-tools).
//
// For each configuration (pixel format, frame rate) it streams for
// --seconds through AravisCamera::Next()/Release() and prints
//   - frames per second delivered (wall clock), incomplete and dropped frames;
//   - CPU time per frame: this process (user + system, getrusage: Aravis's
//     receive thread reassembling ~220 UDP packets per 640x480 frame, plus
//     the camera thread), the camera thread alone (CLOCK_THREAD_CPUTIME_ID:
//     Next/Release), and the simulator process (/proc/PID/stat), which on
//     loopback shares the same cores;
//   - the hand-over latency: the stream's pop returning to Next() returning
//     (AravisCameraStats::last_handover_ns: frame id, clock fit, counters,
//     Mono16 conversion), p50/p99/max;
//   - the delivery latency: the frame's mapped stamp to Next()'s return
//     (the simulator's timestamp is taken when it generates the frame, so
//     this includes its packet sending and our reassembly);
// and the cost of one DeviceClockFit::Add (256 slots of 50 ms, the refit).
//
// usage: bench_aravis_stream [--seconds 5] [--config FORMAT@FPS]...
//        (default: Mono8@30 Mono8@100 Mono8@400 Mono16@100)

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/stats/percentile.h"
#include "core/time/time.h"
#include "drivers/camera/aravis_camera.h"
#include "drivers/camera/device_clock_fit.h"
#include "hil/sim/devices/fake_gv_camera_process.h"

namespace {

using rover::Duration;
using rover::Time;
using rover::drivers::AravisCamera;
using rover::drivers::AravisCameraOptions;
using rover::drivers::AravisCameraStats;
using rover::drivers::CameraFrame;
using rover::drivers::DeviceClockFit;
using rover::drivers::ReadStatus;

struct Config {
  std::string format = "Mono8";
  double rate_hz = 100.0;
};

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// utime + stime of another process, from /proc/PID/stat (fields 14, 15).
double ChildCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(in, line);
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(line.substr(close + 2));
  std::string field;
  double ticks = 0.0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i >= 14) ticks += std::strtod(field.c_str(), nullptr);
  }
  return ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
}

void RunConfig(const std::string& serial, pid_t fake_pid, const Config& config, double seconds) {
  AravisCameraOptions options;
  options.serial = serial;
  options.width_px = 640;
  options.height_px = 480;
  options.pixel_format = config.format;
  options.frame_rate_hz = config.rate_hz;
  options.buffer_count = 16;
  AravisCamera camera(options);
  CameraFrame frame;
  const Time warm_end = Time::Now() + Duration::Seconds(1);
  while (Time::Now() < warm_end) {
    if (camera.Next(&frame, Duration::Milliseconds(200)) == ReadStatus::kOk) camera.Release(frame);
  }
  const AravisCameraStats before = camera.stats();
  std::vector<double> handover_us;
  std::vector<double> delivery_us;
  handover_us.reserve(static_cast<std::size_t>(seconds * config.rate_hz * 1.2) + 16);
  delivery_us.reserve(handover_us.capacity());
  const double process_cpu0 = ProcessCpuSeconds();
  const double thread_cpu0 = ThreadCpuSeconds();
  const double fake_cpu0 = ChildCpuSeconds(fake_pid);
  const Time start = Time::Now();
  const Time end = start + Duration::FromSeconds(seconds);
  uint64_t frames = 0;
  while (Time::Now() < end) {
    if (camera.Next(&frame, Duration::Milliseconds(200)) != ReadStatus::kOk) continue;
    const Time returned = Time::Now();
    ++frames;
    handover_us.push_back(static_cast<double>(camera.stats().last_handover_ns) * 1e-3);
    delivery_us.push_back((returned - frame.stamp).ToMicroseconds());
    camera.Release(frame);
  }
  const double wall = (Time::Now() - start).ToSeconds();
  const double process_cpu = ProcessCpuSeconds() - process_cpu0;
  const double thread_cpu = ThreadCpuSeconds() - thread_cpu0;
  const double fake_cpu = ChildCpuSeconds(fake_pid) - fake_cpu0;
  const AravisCameraStats after = camera.stats();
  const double n = static_cast<double>(std::max<uint64_t>(frames, 1));
  std::printf("%s 640x480 @ %.0f Hz requested, %.1f s, %d-byte packets:\n", config.format.c_str(),
              config.rate_hz, wall, camera.packet_size_bytes());
  std::printf(
      "  delivered %.1f frames/s (%llu frames), incomplete %llu, dropped %llu, "
      "underruns %llu\n",
      static_cast<double>(frames) / wall, static_cast<unsigned long long>(frames),
      static_cast<unsigned long long>(after.incomplete - before.incomplete),
      static_cast<unsigned long long>(after.dropped_frames - before.dropped_frames),
      static_cast<unsigned long long>(after.underruns - before.underruns));
  std::printf(
      "  CPU per frame: process %.1f us (receive thread + camera thread), camera thread "
      "%.1f us, simulator %.1f us\n",
      process_cpu / n * 1e6, thread_cpu / n * 1e6, fake_cpu / n * 1e6);
  std::printf("  hand-over pop -> Next() return: p50 %.1f us, p99 %.1f us, max %.1f us\n",
              rover::stats::Percentile(handover_us, 50.0),
              rover::stats::Percentile(handover_us, 99.0),
              rover::stats::Percentile(handover_us, 100.0));
  std::printf("  delivery stamp -> Next() return: p50 %.0f us, p99 %.0f us, max %.0f us\n",
              rover::stats::Percentile(delivery_us, 50.0),
              rover::stats::Percentile(delivery_us, 99.0),
              rover::stats::Percentile(delivery_us, 100.0));
  std::printf("  clock fit: drift %.1f ppm, mean excess latency %.0f us, resets %llu\n",
              after.clock_drift_ppm, static_cast<double>(after.clock_mean_residual_ns) * 1e-3,
              static_cast<unsigned long long>(after.clock_resets));
}

void BenchClockFit() {
  DeviceClockFit fit;  // default window: 256 slots of 50 ms
  std::mt19937_64 rng(1);
  std::exponential_distribution<double> latency(1.0 / 400e3);
  constexpr int kAdds = 20000;
  std::vector<int64_t> device(kAdds);
  std::vector<Time> host(kAdds);
  for (int k = 0; k < kAdds; ++k) {
    device[static_cast<std::size_t>(k)] = int64_t{k} * 33'333'333;
    host[static_cast<std::size_t>(k)] = Time::FromNanoseconds(device[static_cast<std::size_t>(k)] +
                                                              150'000 + std::llround(latency(rng)));
  }
  const Time start = Time::Now();
  int64_t sink = 0;
  for (int k = 0; k < kAdds; ++k) {
    fit.Add(device[static_cast<std::size_t>(k)], host[static_cast<std::size_t>(k)]);
    sink += fit.ToHost(device[static_cast<std::size_t>(k)]).nanoseconds() & 1;
  }
  const double per_add_us = (Time::Now() - start).ToMicroseconds() / kAdds;
  std::printf(
      "DeviceClockFit::Add + ToHost, default window, 30 Hz pairs: %.2f us per frame (%lld)\n",
      per_add_us, static_cast<long long>(sink % 2));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"AravisCamera figures against arv-fake-gv-camera-0.8 on 127.0.0.1"};
  double seconds = 5.0;
  std::vector<std::string> config_strings;
  app.add_option("--seconds", seconds, "measured streaming time per configuration")
      ->check(CLI::PositiveNumber);
  app.add_option("--config", config_strings, "FORMAT@FPS, e.g. Mono8@100 or Mono16@30");
  CLI11_PARSE(app, argc, argv);
  std::vector<Config> configs;
  for (const std::string& s : config_strings) {
    const std::size_t at = s.find('@');
    if (at == std::string::npos) {
      std::fprintf(stderr, "bad --config '%s': expected FORMAT@FPS\n", s.c_str());
      return 2;
    }
    configs.push_back(Config{s.substr(0, at), std::strtod(s.c_str() + at + 1, nullptr)});
  }
  if (configs.empty()) {
    configs = {{"Mono8", 30.0}, {"Mono8", 100.0}, {"Mono8", 400.0}, {"Mono16", 100.0}};
  }

  BenchClockFit();
  rover::sim::FakeGvCameraProcess fake({.serial = "BENCH" + std::to_string(getpid())});
  try {
    fake.Start();
    for (const Config& c : configs) RunConfig(fake.serial(), fake.pid(), c, seconds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
