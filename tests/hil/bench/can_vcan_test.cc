// SocketCAN scenarios on the HIL bench: run inside the bench VM (Debian's
// kernel, real vcan0/vcan1 and the can-raw protocol; see hil/bench/README.md)
// by ctest through rover_add_hil_vm_test. Every frame crosses the kernel: a
// sender socket writes, vcan loops it back, the driver's socket receives it
// with its kernel timestamp.

#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/can/canopen_wheel_protocol.h"
#include "drivers/can/socket_can_bus.h"
#include "drivers/can/wheel_speed_decoder.h"
#include "hil/sim/motion/route.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/sensors/wheel_odometry_model.h"
#include "tests/hil/sim/motion/test_terrain.h"
#include "tests/support/malloc_counter.h"

namespace rover::drivers {
namespace {

const Time kSimStart = Time::FromNanoseconds(10'000'000'000);

std::string SourcePath(const std::string& relative) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  return std::string(source != nullptr ? source : ".") + "/" + relative;
}

/// The simulator's four wheel drives (hil/sim's WheelOdometryModel with the
/// shipped wheels.yaml: slip, noise, staggered TPDOs, heartbeats) over a
/// drive with turns on rough ground: every frame of `duration_s`.
std::vector<CanFrame> SimulatorRun(double duration_s) {
  static const sim::Heightfield terrain = sim::testing::MakeRoughTerrain(40.0, 7);
  sim::Route route;
  route.start_hold_s = 0.5;
  route.end_hold_s = 0.5;
  route.DriveTo({4.0, 0.0}, 0.4).DriveTo({4.0, 4.0}, 0.3).DriveTo({0.0, 4.0}, 0.5).Revisit(-1, 0.4);
  const sim::RoverTrajectory trajectory(route, terrain);
  const sim::WheelOdometryModelOptions options =
      sim::WheelOdometryModelOptions::LoadFile(SourcePath("hil/config/wheels.yaml"));
  sim::WheelOdometryModel model(options, trajectory, terrain, kSimStart);
  std::vector<CanFrame> frames;
  model.Advance(kSimStart + Duration::FromSeconds(std::min(duration_s, trajectory.duration_s())),
                &frames, nullptr);
  return frames;
}

/// Decodes frames directly, without any bus: the reference.
std::vector<WheelSpeeds> DecodeAll(const std::vector<CanFrame>& frames) {
  WheelSpeedDecoder decoder;
  std::vector<WheelSpeeds> out;
  for (const CanFrame& f : frames) {
    if (auto speeds = decoder.Feed(f)) out.push_back(*speeds);
  }
  return out;
}

bool SamePayload(const CanFrame& a, const CanFrame& b) {
  return a.id == b.id && a.dlc == b.dlc && std::memcmp(a.data.data(), b.data.data(), a.dlc) == 0;
}

/// Sends `frames` on `bus` from its own thread. With `window` > 0 it never
/// runs more than `window` frames ahead of `*consumed` (flow control, so the
/// receiver's queue cannot overflow on a one-CPU guest); with `pace` it
/// keeps the frames' original spacing in real time.
class Replayer {
 public:
  Replayer(SocketCanBus& bus, const std::vector<CanFrame>& frames,
           const std::atomic<uint64_t>* consumed, uint64_t window, bool pace)
      : thread_([this, &bus, &frames, consumed, window, pace] {
          const Time wall_start = Time::Now();
          for (const CanFrame& f : frames) {
            if (pace) {
              const Time due = wall_start + (f.stamp - frames.front().stamp);
              while (Time::Now() < due && !stop_) {
                std::this_thread::sleep_for(std::chrono::microseconds(200));
              }
            }
            while (window > 0 && sent_ >= consumed->load() + window && !stop_) {
              std::this_thread::yield();
            }
            while (!bus.Send(f) && !stop_)
              std::this_thread::sleep_for(std::chrono::microseconds(100));
            if (stop_) return;
            ++sent_;
          }
        }) {}
  /// Stops early if the receiving side gave up (a failed assertion).
  ~Replayer() {
    stop_ = true;
    thread_.join();
  }
  uint64_t sent() const { return sent_.load(); }

 private:
  std::atomic<uint64_t> sent_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Writes a raw frame (error frames included, which SocketCanBus::Send never
/// produces) through a plain socket on `interface`.
void SendRaw(const char* interface, uint32_t can_id, std::initializer_list<uint8_t> data) {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  ASSERT_GE(fd, 0);
  ifreq request{};
  std::strncpy(request.ifr_name, interface, IFNAMSIZ - 1);
  ASSERT_EQ(ioctl(fd, SIOCGIFINDEX, &request), 0);
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  can_frame raw{};
  raw.can_id = can_id;
  raw.len = static_cast<uint8_t>(data.size());
  std::copy(data.begin(), data.end(), raw.data);
  ASSERT_EQ(write(fd, &raw, sizeof raw), static_cast<ssize_t>(sizeof raw));
  close(fd);
}

void Shell(const std::string& command) { ASSERT_EQ(std::system(command.c_str()), 0) << command; }

// A simulator run of 40 s (about 20,000 frames) replayed on vcan0 is
// received frame for frame and decodes to exactly the wheel speeds the
// frames themselves decode to; stamps are kernel receive times on
// CLOCK_MONOTONIC.
TEST(CanVcanTest, SimulatorRunReplayedAndDecodedExactly) {
  const std::vector<CanFrame> frames = SimulatorRun(40.0);
  ASSERT_GT(frames.size(), 15000u);
  const std::vector<WheelSpeeds> expected = DecodeAll(frames);
  ASSERT_GT(expected.size(), 3500u);

  SocketCanOptions options;
  options.interface = "vcan0";
  options.filters = SocketCanOptions::WheelDriveFilters();
  SocketCanBus rx(options);
  SocketCanBus tx("vcan0");
  std::atomic<uint64_t> consumed{0};
  WheelSpeedDecoder decoder;
  std::vector<CanFrame> received;
  received.reserve(frames.size());
  std::vector<WheelSpeeds> decoded;
  decoded.reserve(expected.size());
  {
    Replayer replay(tx, frames, &consumed, 256, false);
    CanFrame f;
    while (received.size() < frames.size()) {
      const ReadStatus status = rx.Receive(&f, Duration::Seconds(5));
      ASSERT_EQ(status, ReadStatus::kOk) << "after " << received.size() << " frames";
      const Time now = Time::Now();
      ASSERT_LE(f.stamp, now);
      ASSERT_GT(f.stamp, now - Duration::Seconds(2)) << "stamp not on CLOCK_MONOTONIC";
      if (!received.empty()) {
        ASSERT_GE(f.stamp, received.back().stamp);
      }
      received.push_back(f);
      if (auto speeds = decoder.Feed(f)) decoded.push_back(*speeds);
      consumed.store(received.size());
    }
  }
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_TRUE(SamePayload(received[i], frames[i])) << "frame " << i;
  }
  ASSERT_EQ(decoded.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(decoded[i].wheel_rate_rad_s, expected[i].wheel_rate_rad_s) << "period " << i;
  }
  EXPECT_EQ(decoder.stats().incomplete, 0u);
  const SocketCanStats s = rx.stats();
  EXPECT_EQ(s.frames, frames.size());
  EXPECT_EQ(s.kernel_drops, 0u);
  EXPECT_EQ(s.error_frames, 0u);
  EXPECT_EQ(rx.health(), CanBusHealth::kActive);
}

// Drive 3 falls silent 1.5 s into a real-time replay: the decoder reports it
// missing once its last heartbeat is older than the 2.5 s timeout (not
// before), its periods are counted incomplete, and the other drives are
// never reported.
TEST(CanVcanTest, MissingDriveDetectedByHeartbeatTimeout) {
  std::vector<CanFrame> frames = SimulatorRun(5.5);
  const Time silent_from = kSimStart + Duration::Milliseconds(1500);
  std::erase_if(frames, [&](const CanFrame& f) {
    return f.stamp >= silent_from &&
           (f.id == kCanTpdo1BaseId + 3 || f.id == kCanHeartbeatBaseId + 3);
  });
  SocketCanOptions options;
  options.interface = "vcan0";
  options.filters = SocketCanOptions::WheelDriveFilters();
  SocketCanBus rx(options);
  SocketCanBus tx("vcan0");
  WheelSpeedDecoder decoder(Duration::Milliseconds(2500));
  std::optional<Time> last_heartbeat_3;
  std::optional<Time> reported_missing;
  std::optional<Time> first_rx;
  uint64_t received = 0;
  {
    std::atomic<uint64_t> consumed{0};
    Replayer replay(tx, frames, &consumed, 0, true);
    CanFrame f;
    while (received < frames.size()) {
      ASSERT_EQ(rx.Receive(&f, Duration::Seconds(5)), ReadStatus::kOk);
      ++received;
      decoder.Feed(f);
      if (f.id == kCanHeartbeatBaseId + 3) last_heartbeat_3 = f.stamp;
      // Every drive has sent its first heartbeat 1 s into the run.
      if (!first_rx) first_rx = f.stamp;
      if (f.stamp - *first_rx < Duration::Seconds(1)) continue;
      const uint8_t missing = decoder.MissingDrives(f.stamp);
      ASSERT_EQ(missing & 0b1011, 0) << "a live drive reported missing";
      if (received > 500 && (missing & 0b0100) != 0 && !reported_missing)
        reported_missing = f.stamp;
    }
  }
  ASSERT_TRUE(last_heartbeat_3.has_value());
  ASSERT_TRUE(reported_missing.has_value()) << "drive 3 never reported missing";
  const Duration after = *reported_missing - *last_heartbeat_3;
  EXPECT_GT(after, Duration::Milliseconds(2500));
  EXPECT_LT(after, Duration::Milliseconds(3000));  // within a few SYNC periods
  EXPECT_GT(decoder.stats().incomplete, 250u);     // drive 3's periods from 1.5 s on
}

// A flood of junk (other nodes' ids, 29-bit frames, remote frames) sent as
// fast as the guest can while a simulator run is replayed: with the wheel
// filters in the kernel, the decoder sees none of it and decodes every
// period; without filters it sees the junk as ignored frames and still
// decodes every period. Without filters the junk reaches the receive buffer,
// so the flood keeps at most kJunkInFlight frames ahead of the receiver:
// an unpaced flood on the guest's one vCPU can preempt the receiver long
// enough to overflow any buffer, and that is a drop counted by design
// (StalledReceiverCountsKernelDropsAndRecovers), not starvation.
void RunJunkFlood(bool kernel_filters) {
  const std::vector<CanFrame> frames = SimulatorRun(10.0);
  const std::vector<WheelSpeeds> expected = DecodeAll(frames);
  SocketCanOptions options;
  options.interface = "vcan0";
  if (kernel_filters) options.filters = SocketCanOptions::WheelDriveFilters();
  options.receive_buffer_bytes = 4 << 20;
  SocketCanBus rx(options);
  // As root in the guest the buffer is forced past rmem_max.
  ASSERT_GE(rx.receive_buffer_bytes(), options.receive_buffer_bytes);
  SocketCanBus tx("vcan0");
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> junk_sent{0};
  std::atomic<uint64_t> junk_received{0};
  constexpr uint64_t kJunkInFlight = 1024;  // far below the 4 MiB buffer
  std::thread flood([&] {
    const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    ifreq request{};
    std::strncpy(request.ifr_name, "vcan0", IFNAMSIZ - 1);
    ioctl(fd, SIOCGIFINDEX, &request);
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = request.ifr_ifindex;
    bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
    std::mt19937 rng(42);
    std::uniform_int_distribution<uint32_t> junk_id(0x200, 0x5FF);
    while (!stop.load()) {
      if (!kernel_filters && junk_sent.load() >= junk_received.load() + kJunkInFlight) {
        std::this_thread::yield();
        continue;
      }
      can_frame raw{};
      switch (rng() % 4) {
        case 0:
          raw.can_id = 0x181 | CAN_EFF_FLAG;
          break;  // 29-bit, looks like a TPDO id
        case 1:
          raw.can_id = 0x182 | CAN_RTR_FLAG;
          break;  // remote request for a TPDO
        default:
          raw.can_id = junk_id(rng);
          break;
      }
      raw.len = 8;
      if (write(fd, &raw, sizeof raw) == static_cast<ssize_t>(sizeof raw)) ++junk_sent;
    }
    close(fd);
  });
  WheelSpeedDecoder decoder;
  std::vector<WheelSpeeds> decoded;
  std::atomic<uint64_t> consumed{0};
  {
    Replayer replay(tx, frames, &consumed, 128, false);
    CanFrame f;
    uint64_t wheel_frames = 0;
    uint64_t junk_delivered = 0;
    while (wheel_frames < frames.size()) {
      ASSERT_EQ(rx.Receive(&f, Duration::Seconds(5)), ReadStatus::kOk);
      if (f.id == kCanSyncId || (f.id & 0x780) == kCanTpdo1BaseId ||
          (f.id & 0x780) == kCanHeartbeatBaseId) {
        ++wheel_frames;
        consumed.store(wheel_frames);
      } else {
        ++junk_delivered;
      }
      // The bus drops 29-bit and remote frames itself; they were received too.
      junk_received.store(junk_delivered + rx.stats().ignored);
      if (auto speeds = decoder.Feed(f)) decoded.push_back(*speeds);
    }
  }
  stop.store(true);
  flood.join();
  ASSERT_EQ(decoded.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(decoded[i].wheel_rate_rad_s, expected[i].wheel_rate_rad_s) << "period " << i;
  }
  EXPECT_GT(junk_sent.load(), frames.size() / 4) << "the flood did not flood";
  EXPECT_EQ(rx.stats().kernel_drops, 0u);
  if (kernel_filters) {
    EXPECT_EQ(decoder.stats().ignored, 0u) << "junk passed the kernel filters";
    EXPECT_EQ(rx.stats().ignored, 0u);
  } else {
    EXPECT_GT(decoder.stats().ignored + rx.stats().ignored, 0u);
  }
  std::printf("junk flood (%s): %llu junk frames against %zu wheel frames\n",
              kernel_filters ? "kernel filters" : "no filters",
              static_cast<unsigned long long>(junk_sent.load()), frames.size());
}

TEST(CanVcanTest, JunkFloodDoesNotStarveTheDecoderWithKernelFilters) { RunJunkFlood(true); }
TEST(CanVcanTest, JunkFloodDoesNotStarveTheDecoderWithoutFilters) { RunJunkFlood(false); }

// Error frames from the controller move the health through warning,
// passive, bus-off and back to active on the restart notice; a data frame
// after a bus-off also means the controller is back.
TEST(CanVcanTest, ErrorFramesDriveTheHealthAndCounters) {
  SocketCanBus rx("vcan0");
  CanFrame f;
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_WARNING, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(rx.Receive(&f, Duration::Milliseconds(300)), ReadStatus::kTimeout);
  EXPECT_EQ(rx.health(), CanBusHealth::kErrorWarning);
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(rx.Receive(&f, Duration::Milliseconds(300)), ReadStatus::kTimeout);
  EXPECT_EQ(rx.health(), CanBusHealth::kErrorPassive);
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(rx.Receive(&f, Duration::Milliseconds(300)), ReadStatus::kTimeout);
  EXPECT_EQ(rx.health(), CanBusHealth::kBusOff);
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_RESTARTED, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(rx.Receive(&f, Duration::Milliseconds(300)), ReadStatus::kTimeout);
  EXPECT_EQ(rx.health(), CanBusHealth::kActive);
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_PROT | CAN_ERR_ACK, {0, 0, 0, 0, 0, 0, 0, 0});
  SendRaw("vcan0", CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});
  SendRaw("vcan0", 0x181, {1, 2, 3, 4, 5, 6, 7, 8});
  ASSERT_EQ(rx.Receive(&f, Duration::Seconds(2)), ReadStatus::kOk);
  EXPECT_EQ(f.id, 0x181u);
  EXPECT_EQ(rx.health(), CanBusHealth::kActive);
  const SocketCanStats s = rx.stats();
  EXPECT_EQ(s.error_frames, 6u);
  EXPECT_EQ(s.controller_problems, 2u);
  EXPECT_EQ(s.bus_off, 2u);
  EXPECT_EQ(s.restarts, 2u);
  EXPECT_EQ(s.protocol_errors, 1u);
  EXPECT_EQ(s.frames, 1u);
}

// The interface goes down under the driver: Receive reports errors (never
// blocking past its timeout) and the health says down; once it is up again,
// the driver reopens and frames flow. The same after the interface is
// deleted and created anew (a new interface index).
TEST(CanVcanTest, InterfaceDownAndRemovedAreRecovered) {
  SocketCanOptions options;
  options.interface = "vcan1";
  options.reopen_backoff_initial = Duration::Milliseconds(20);
  options.reopen_backoff_max = Duration::Milliseconds(200);
  SocketCanBus rx(options);
  CanFrame f;
  auto expect_flowing = [&] {
    for (int attempt = 0; attempt < 50; ++attempt) {
      SocketCanBus tx("vcan1");
      ASSERT_TRUE(tx.Send(EncodeSync(Time::Now())));
      if (rx.Receive(&f, Duration::Milliseconds(200)) == ReadStatus::kOk) return;
    }
    FAIL() << "no frame after the interface came back";
  };
  expect_flowing();
  Shell("ip link set vcan1 down");
  bool saw_error = false;
  for (int i = 0; i < 5; ++i) {
    const Time t0 = Time::Now();
    const ReadStatus status = rx.Receive(&f, Duration::Milliseconds(100));
    EXPECT_LT(Time::Now() - t0, Duration::Milliseconds(600)) << "Receive blocked past its timeout";
    saw_error |= status == ReadStatus::kError;
  }
  EXPECT_TRUE(saw_error);
  EXPECT_EQ(rx.health(), CanBusHealth::kDown);
  Shell("ip link set vcan1 up");
  expect_flowing();
  EXPECT_EQ(rx.health(), CanBusHealth::kActive);
  EXPECT_EQ(rx.stats().reopens, 1u);

  Shell("ip link del vcan1");
  for (int i = 0; i < 3; ++i) rx.Receive(&f, Duration::Milliseconds(100));
  EXPECT_EQ(rx.health(), CanBusHealth::kDown);
  Shell("ip link add dev vcan1 type vcan && ip link set vcan1 up");
  expect_flowing();
  EXPECT_EQ(rx.stats().reopens, 2u);
}

// A receiver that stops reading while the bus keeps going: the kernel drops
// what its queue cannot hold, the driver counts it (SO_RXQ_OVFL), and
// frames flow again once it reads.
TEST(CanVcanTest, StalledReceiverCountsKernelDropsAndRecovers) {
  SocketCanOptions options;
  options.interface = "vcan0";
  options.receive_buffer_bytes = 1;  // the kernel's minimum: a few frames
  SocketCanBus rx(options);
  SocketCanBus tx("vcan0");
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(tx.Send(EncodeSync(Time::Now())));
  CanFrame f;
  uint64_t got = 0;
  while (rx.Receive(&f, Duration::Milliseconds(200)) == ReadStatus::kOk) ++got;
  EXPECT_LT(got, 100u) << "the queue held more than a minimal buffer can";
  // The kernel reports drops with the next frame it queues after them.
  ASSERT_TRUE(tx.Send(EncodeSync(Time::Now())));
  ASSERT_EQ(rx.Receive(&f, Duration::Seconds(2)), ReadStatus::kOk);
  ++got;
  const SocketCanStats s = rx.stats();
  EXPECT_GT(s.kernel_drops, 0u);
  EXPECT_EQ(got + s.kernel_drops, 501u) << "every frame either received or counted as dropped";
  ASSERT_TRUE(tx.Send(EncodeSync(Time::Now())));
  EXPECT_EQ(rx.Receive(&f, Duration::Seconds(2)), ReadStatus::kOk);
  EXPECT_EQ(rx.stats().kernel_drops, s.kernel_drops);
}

// Start() forgets what queued up, and overflowed, while the process was
// still starting: the reader gets exactly the frames sent after it, and no
// drops from before.
TEST(CanVcanTest, StartForgetsTheBacklogAndItsDrops) {
  SocketCanOptions options;
  options.interface = "vcan0";
  options.receive_buffer_bytes = 1;  // a few frames: 500 overflow it
  SocketCanBus rx(options);
  SocketCanBus tx("vcan0");
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(tx.Send(EncodeSync(Time::Now())));
  rx.Start();
  for (uint8_t i = 0; i < 3; ++i) {
    CanFrame sent;
    sent.id = kCanTpdo1BaseId + 1;
    sent.dlc = 8;
    sent.data[0] = i;
    ASSERT_TRUE(tx.Send(sent));
  }
  CanFrame f;
  for (uint8_t i = 0; i < 3; ++i) {
    ASSERT_EQ(rx.Receive(&f, Duration::Seconds(2)), ReadStatus::kOk);
    EXPECT_EQ(f.id, kCanTpdo1BaseId + 1) << "a frame from before Start()";
    EXPECT_EQ(f.data[0], i);
  }
  EXPECT_EQ(rx.Receive(&f, Duration::Milliseconds(100)), ReadStatus::kTimeout);
  EXPECT_EQ(rx.stats().kernel_drops, 0u);
  EXPECT_EQ(rx.stats().frames, 3u);
  EXPECT_EQ(rx.health(), CanBusHealth::kActive);
}

// After start-up the receive path does not touch the heap.
TEST(CanVcanTest, ReceiveDoesNotAllocate) {
  SocketCanOptions options;
  options.interface = "vcan0";
  options.filters = SocketCanOptions::WheelDriveFilters();
  SocketCanBus rx(options);
  SocketCanBus tx("vcan0");
  CanFrame f;
  for (int i = 0; i < 10; ++i) tx.Send(EncodeSync(Time::Now()));
  rover::testing::ScopedMallocCheck check;
  int received = 0;
  for (int i = 0; i < 10; ++i) received += rx.Receive(&f, Duration::Seconds(1)) == ReadStatus::kOk;
  rx.Receive(&f, Duration::Milliseconds(20));  // and a timeout
  EXPECT_EQ(received, 10);
  EXPECT_EQ(check.mallocs(), 0u);
}

}  // namespace
}  // namespace rover::drivers
