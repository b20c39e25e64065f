// V4L2 camera figures against a real kernel capture driver: run it inside
// the HIL bench VM, where /dev/video0 is vivid (hil/bench/README.md):
//
//   hil/bench/run_in_vm.sh --out /tmp/v4l2_bench
//     --initramfs build/dev/hil/bench/hil_bench_initramfs.cpio.gz
//     -- build/dev/bench/drivers/bench_v4l2_vivid
// (one command line)
//
// For each configuration (format, size, frame rate) it streams --frames
// frames through V4l2Camera::Next()/Release() and prints
//   - frames per second, from the frames' stamps and from the wall clock;
//   - CPU time per frame of this process (user + system: the ioctls, the
//     conversion) and of vivid's kernel thread, which draws the frames
//     (/proc/PID/schedstat: the scheduler's exact run time);
//   - the hand-over latency: VIDIOC_DQBUF's return to Next()'s return,
//     conversion included (V4l2CameraStats::last_handover_ns), p50/p99/max;
//   - the delivery latency: the frame's stamp to Next()'s return. vivid is
//     switched to start-of-exposure stamps, which it sets to the frame's
//     nominal start (its end-of-frame stamps are the nominal end, taken
//     before the frame is drawn, so they lie in the future);
//   - frames lost (sequence gaps) and error buffers.
// Under TCG (software emulation, no KVM) every figure is that of an
// emulated CPU: several times slower than the host, and noisy.
//
// usage: bench_v4l2_vivid [--device /dev/video0] [--frames 150] [--buffers 4]
//                         [--config FOURCC:WxH@FPS]...
// e.g. --config GREY:640x480@25 --config YUYV:1280x720@12.5

#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/stats/percentile.h"
#include "core/time/time.h"
#include "drivers/camera/v4l2_camera.h"

namespace {

using rover::Duration;
using rover::Time;
using rover::drivers::CameraFrame;
using rover::drivers::ReadStatus;
using rover::drivers::V4l2Camera;
using rover::drivers::V4l2CameraOptions;
using rover::drivers::V4l2CameraStats;

struct Config {
  std::string fourcc = "GREY";
  int width_px = 640;
  int height_px = 480;
  double rate_hz = 25.0;
};

/// "GREY:640x480@25" -> Config; false if malformed.
bool ParseConfig(const std::string& text, Config* config) {
  const auto colon = text.find(':');
  const auto x = text.find('x', colon == std::string::npos ? 0 : colon);
  const auto at = text.find('@');
  if (colon == std::string::npos || x == std::string::npos || at == std::string::npos ||
      !(colon < x && x < at)) {
    return false;
  }
  try {
    config->fourcc = text.substr(0, colon);
    config->width_px = std::stoi(text.substr(colon + 1, x - colon - 1));
    config->height_px = std::stoi(text.substr(x + 1, at - x - 1));
    config->rate_hz = std::stod(text.substr(at + 1));
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

/// CPU time of this process (CLOCK_PROCESS_CPUTIME_ID: the scheduler's
/// exact run time, not tick samples).
Duration ProcessCpu() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return Duration::Nanoseconds(int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec);
}

/// The pid of vivid's capture kernel thread ("vivid-000-vid-cap"), which
/// draws every frame; 0 if there is none (not vivid, or not streaming).
int VividThreadPid() {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream comm(entry.path() / "comm");
    std::string line;
    if (std::getline(comm, line) && line.starts_with("vivid-") && line.ends_with("-vid-cap")) {
      return std::stoi(name);
    }
  }
  return 0;
}

/// Run time of thread `pid` from /proc/PID/schedstat (exact, in ns); zero
/// if unknown.
Duration ThreadCpu(int pid) {
  if (pid <= 0) return Duration::Zero();
  std::ifstream stat("/proc/" + std::to_string(pid) + "/schedstat");
  int64_t ns = 0;
  stat >> ns;
  return Duration::Nanoseconds(ns);
}

/// Streams one configuration and prints its row; false if it could not run.
bool Run(const std::string& device, const Config& config, int frames, int buffers) {
  V4l2CameraOptions options;
  options.device = device;
  options.pixel_format = config.fourcc;
  options.width_px = config.width_px;
  options.height_px = config.height_px;
  options.frame_rate_hz = config.rate_hz;
  options.buffer_count = buffers;
  try {
    V4l2Camera camera(options);
    std::vector<int64_t> handover_ns, delivery_ns;
    handover_ns.reserve(static_cast<std::size_t>(frames));
    delivery_ns.reserve(static_cast<std::size_t>(frames));
    // vivid stamps the nominal end of a frame it has not finished drawing
    // yet; its start-of-exposure stamp (the nominal frame start) makes the
    // delivery latency meaningful.
    if (camera.GetControl("timestamp_source").has_value()) camera.SetControl("timestamp_source", 1);
    CameraFrame frame;
    // Warm-up: the first frames carry start-up effects (page faults on the
    // conversion buffers, the stream settling).
    for (int i = 0; i < 5; ++i) {
      if (camera.Next(&frame, Duration::Seconds(5)) == ReadStatus::kOk) camera.Release(frame);
    }
    const int vivid_pid = VividThreadPid();
    const V4l2CameraStats before = camera.stats();
    const Duration vivid_before = ThreadCpu(vivid_pid);
    const Duration cpu_before = ProcessCpu();
    const Time wall_start = Time::Now();
    Time first_stamp, last_stamp;
    int got = 0;
    uint64_t checksum = 0;
    while (got < frames) {
      const ReadStatus status = camera.Next(&frame, Duration::Seconds(5));
      const Time now = Time::Now();
      if (status != ReadStatus::kOk) {
        std::fprintf(stderr, "bench_v4l2_vivid: Next() returned %d after %d frames\n",
                     static_cast<int>(status), got);
        return false;
      }
      handover_ns.push_back(camera.stats().last_handover_ns);
      delivery_ns.push_back((now - frame.stamp).nanoseconds());
      checksum +=
          frame.image
              .data[frame.image.stride_bytes * static_cast<std::size_t>(frame.image.height_px / 2)];
      if (got == 0) first_stamp = frame.stamp;
      last_stamp = frame.stamp;
      camera.Release(frame);
      ++got;
    }
    const Duration wall = Time::Now() - wall_start;
    const Duration cpu = ProcessCpu() - cpu_before;
    const Duration vivid_cpu = ThreadCpu(vivid_pid) - vivid_before;
    const V4l2CameraStats after = camera.stats();
    const double stamp_fps = got > 1 ? (got - 1) / (last_stamp - first_stamp).ToSeconds() : 0.0;
    const double wall_fps = got / wall.ToSeconds();
    const double cpu_ms = cpu.ToMilliseconds() / got;
    const double vivid_ms = vivid_pid > 0 ? vivid_cpu.ToMilliseconds() / got : std::nan("");
    const uint64_t dropped = after.dropped_frames - before.dropped_frames;
    std::printf(
        "%-4s %5dx%-5d %6.2f | %7.2f %7.2f | %8.3f %8.2f | %7.1f %7.1f %7.1f | %7.2f %7.2f | "
        "%5" PRIu64 " %5" PRIu64 "\n",
        config.fourcc.c_str(), config.width_px, config.height_px, camera.frame_rate_hz(), stamp_fps,
        wall_fps, cpu_ms, vivid_ms, rover::stats::Percentile(handover_ns, 50.0) * 1e-3,
        rover::stats::Percentile(handover_ns, 99.0) * 1e-3,
        static_cast<double>(*std::max_element(handover_ns.begin(), handover_ns.end())) * 1e-3,
        rover::stats::Percentile(delivery_ns, 50.0) * 1e-6,
        rover::stats::Percentile(delivery_ns, 99.0) * 1e-6, dropped,
        after.error_buffers - before.error_buffers);
    std::printf(
        "RESULT bench=v4l2_vivid format=%s size=%dx%d rate_hz=%.2f fps=%.2f cpu_ms_per_frame=%.3f "
        "vivid_cpu_ms_per_frame=%.2f handover_us_p50=%.1f handover_us_p99=%.1f "
        "delivery_ms_p50=%.2f "
        "delivery_ms_p99=%.2f dropped=%" PRIu64 " checksum=%" PRIu64 "\n",
        config.fourcc.c_str(), config.width_px, config.height_px, config.rate_hz, stamp_fps, cpu_ms,
        vivid_ms, rover::stats::Percentile(handover_ns, 50.0) * 1e-3,
        rover::stats::Percentile(handover_ns, 99.0) * 1e-3,
        rover::stats::Percentile(delivery_ns, 50.0) * 1e-6,
        rover::stats::Percentile(delivery_ns, 99.0) * 1e-6, dropped, checksum);
    std::fflush(stdout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_v4l2_vivid: %s\n", e.what());
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"V4L2 camera figures against vivid (run inside the HIL bench VM)"};
  std::string device = "/dev/video0";
  int frames = 150;
  int buffers = 4;
  std::vector<std::string> config_texts;
  app.add_option("--device", device, "capture device node");
  app.add_option("--frames", frames, "frames measured per configuration")
      ->check(CLI::Range(2, 100000));
  app.add_option("--buffers", buffers, "mmap buffers")->check(CLI::Range(2, 32));
  app.add_option("--config", config_texts, "FOURCC:WxH@FPS, repeatable");
  CLI11_PARSE(app, argc, argv);
  if (config_texts.empty()) {
    config_texts = {"GREY:640x480@25", "YUYV:640x480@25", "Y16:640x480@25", "GREY:1280x720@12.5"};
  }
  std::vector<Config> configs;
  for (const std::string& text : config_texts) {
    Config config;
    if (!ParseConfig(text, &config)) {
      std::fprintf(stderr, "bench_v4l2_vivid: --config expects FOURCC:WxH@FPS, found '%s'\n",
                   text.c_str());
      return 2;
    }
    configs.push_back(config);
  }
  std::printf(
      "V4L2 capture from %s, %d frames per row, %d buffers (under TCG emulation: emulated-CPU "
      "figures)\n",
      device.c_str(), frames, buffers);
  std::printf("%-4s %11s %6s | %7s %7s | %8s %8s | %7s %7s %7s | %7s %7s | %5s %5s\n", "fmt",
              "size", "set", "fps", "wall", "cpu ms", "vivid ms", "ho p50", "ho p99", "ho max",
              "dl p50", "dl p99", "drop", "err");
  std::printf("%-4s %11s %6s | %7s %7s | %8s %8s | %7s %7s %7s | %7s %7s | %5s %5s\n", "", "",
              "fps", "stamps", "", "/frame", "/frame", "us", "us", "us", "ms", "ms", "", "");
  int failures = 0;
  for (const Config& config : configs) failures += Run(device, config, frames, buffers) ? 0 : 1;
  return failures == 0 ? 0 : 1;
}
