// bench_can_decode: how many wheel-drive CAN frames per second roverd's CAN
// path takes (SocketCanBus::Receive with kernel filters and timestamps, then
// WheelSpeedDecoder), with a sender thread writing SYNC + 4 TPDO1 periods
// as fast as the interface accepts them. The reference, in the same run, is
// the decoder alone on the same frames in memory: the ratio says how much of
// the cost is the kernel and the socket.
//
//   bench_can_decode [--interface vcan0] [--seconds 5]
//
// On the HIL bench:
//   hil/bench/run_in_vm.sh --initramfs build/release/hil/bench/hil_bench_initramfs.cpio.gz
//       --out /tmp/bench_can -- build/release/bench/drivers/bench_can_decode

#include <CLI/CLI.hpp>

#include <sys/resource.h>

#include <atomic>
#include <cstdio>
#include <thread>
#include <vector>

#include "drivers/can/canopen_wheel_protocol.h"
#include "drivers/can/socket_can_bus.h"
#include "drivers/can/wheel_speed_decoder.h"

namespace {

using rover::Duration;
using rover::Time;
namespace d = rover::drivers;

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// One SYNC period: SYNC then the four drives' TPDO1s.
std::vector<d::CanFrame> Period(uint64_t k) {
  std::vector<d::CanFrame> frames{d::EncodeSync(Time::Zero())};
  for (uint8_t node = 1; node <= d::kWheelNodeCount; ++node) {
    d::WheelTpdo1 tpdo;
    tpdo.node_id = node;
    tpdo.velocity_mrad_s = static_cast<int32_t>(k % 5000) + node;
    tpdo.position_ticks = static_cast<int32_t>(k * 37u);
    frames.push_back(d::EncodeWheelTpdo1(Time::Zero(), tpdo));
  }
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_can_decode: wheel-drive CAN frames received + decoded per second"};
  std::string interface = "vcan0";
  double seconds = 5.0;
  app.add_option("--interface", interface, "CAN interface (vcan0 on the HIL bench)")
      ->capture_default_str();
  app.add_option("--seconds", seconds, "how long to stream")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  // Reference: the decoder alone.
  std::vector<d::CanFrame> memory;
  for (uint64_t k = 0; k < 20000; ++k) {
    for (const d::CanFrame& f : Period(k)) memory.push_back(f);
  }
  d::WheelSpeedDecoder alone;
  const double cpu0 = ThreadCpuSeconds();
  uint64_t periods_alone = 0;
  for (int repeat = 0; repeat < 20; ++repeat) {
    for (const d::CanFrame& f : memory) periods_alone += alone.Feed(f).has_value();
  }
  const double alone_s = ThreadCpuSeconds() - cpu0;
  const double alone_fps = 20.0 * static_cast<double>(memory.size()) / alone_s;

  d::SocketCanOptions options;
  options.interface = interface;
  options.filters = d::SocketCanOptions::WheelDriveFilters();
  options.receive_buffer_bytes = 8 << 20;
  d::SocketCanBus rx(options);
  d::SocketCanBus tx(interface);
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> sent{0};
  std::thread sender([&] {
    uint64_t k = 0;
    while (!stop.load(std::memory_order_relaxed)) {
      for (const d::CanFrame& f : Period(k++)) {
        while (!tx.Send(f) && !stop.load()) std::this_thread::yield();
        sent.fetch_add(1, std::memory_order_relaxed);
      }
    }
  });
  d::WheelSpeedDecoder decoder;
  d::CanFrame frame;
  uint64_t received = 0;
  uint64_t periods = 0;
  const Time start = Time::Now();
  const double rx_cpu0 = ThreadCpuSeconds();
  const Time end = start + Duration::FromSeconds(seconds);
  while (Time::Now() < end) {
    if (rx.Receive(&frame, Duration::Milliseconds(100)) != d::ReadStatus::kOk) continue;
    ++received;
    periods += decoder.Feed(frame).has_value();
  }
  const double wall_s = (Time::Now() - start).ToSeconds();
  const double rx_cpu_s = ThreadCpuSeconds() - rx_cpu0;
  stop.store(true);
  sender.join();
  const d::SocketCanStats s = rx.stats();
  const double fps = static_cast<double>(received) / wall_s;
  std::printf("bench_can_decode on %s, %.1f s\n", interface.c_str(), wall_s);
  std::printf(
      "  received + decoded   %.0f frames/s (%llu frames, %llu periods complete, %llu "
      "incomplete)\n",
      fps, static_cast<unsigned long long>(received), static_cast<unsigned long long>(periods),
      static_cast<unsigned long long>(decoder.stats().incomplete));
  std::printf("  receiver CPU         %.2f us per frame (%.0f %% of one core)\n",
              1e6 * rx_cpu_s / static_cast<double>(received), 100.0 * rx_cpu_s / wall_s);
  std::printf("  kernel drops         %llu (sender wrote %llu)\n",
              static_cast<unsigned long long>(s.kernel_drops),
              static_cast<unsigned long long>(sent.load()));
  std::printf("  decoder alone        %.0f frames/s (%.1f ns per frame, %llu periods)\n", alone_fps,
              1e9 / alone_fps, static_cast<unsigned long long>(periods_alone));
  std::printf("  bus load of 4 drives at 100 Hz: 500 frames/s = %.4f of the measured rate\n",
              500.0 / fps);
  return 0;
}
