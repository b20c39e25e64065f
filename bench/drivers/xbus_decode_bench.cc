// Cost of turning serial bytes into IMU packets: XbusParser (preamble
// search, length, checksum) plus DecodeMtData2, on a stream of MTData2
// packets as the Xsens driver configures them (PacketCounter,
// SampleTimeFine, Acceleration, RateOfTurn: 47-byte frames), fed in 256-byte
// reads as from a UART. Three streams: clean; 5 % of packets preceded by
// garbage; 2 % with a flipped byte. Prints packets per second and ns per
// packet (best of several runs; one core, wall clock).
//
// For scale: at 400 Hz the driver decodes 400 packets per second, so
// anything above a few million per second is noise next to the read()
// syscall that brings the bytes in.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>
#include <vector>

#include "drivers/imu/mt_data2_packet.h"
#include "drivers/imu/xbus_parser.h"
#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers {
namespace {

std::vector<uint8_t> MakeStream(int packets, double garbage_p, double flip_p, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<uint8_t> stream;
  for (int k = 0; k < packets; ++k) {
    MtData2Packet p;
    p.has_packet_counter = p.has_sample_time_fine = p.has_acceleration = p.has_rate_of_turn = true;
    p.packet_counter = static_cast<uint16_t>(k);
    p.sample_time_fine = static_cast<uint32_t>(25 * k);
    p.acceleration_m_s2 = {0.1f * static_cast<float>(k % 7), -0.2f, 9.81f};
    p.rate_of_turn_rad_s = {0.01f, 0.02f * static_cast<float>(k % 5), -0.03f};
    uint8_t payload[kMtData2CompletePayloadBytes];
    const std::size_t n = EncodeMtData2(p, payload);
    std::vector<uint8_t> frame(xbus::FrameBytes(n));
    xbus::EncodeMessage(xbus::mid::kMtData2, std::span<const uint8_t>(payload, n), frame);
    if (u(rng) < garbage_p) {
      for (int i = 0; i < 8; ++i) stream.push_back(static_cast<uint8_t>(byte(rng)));
    }
    if (u(rng) < flip_p) frame[10] ^= 0x5A;
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  return stream;
}

struct Result {
  double ns_per_packet = 0.0;
  uint64_t packets = 0;
};

Result Run(const std::vector<uint8_t>& stream) {
  constexpr std::size_t kRead = 256;
  XbusParser parser(254);
  uint64_t packets = 0;
  float sink = 0.0f;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < stream.size(); i += kRead) {
    const std::size_t n = std::min(kRead, stream.size() - i);
    parser.Feed(std::span<const uint8_t>(stream.data() + i, n));
    xbus::Message m;
    while (parser.Next(&m)) {
      MtData2Packet p;
      if (m.mid == xbus::mid::kMtData2 && DecodeMtData2(m.payload, &p) && p.complete()) {
        ++packets;
        sink += p.acceleration_m_s2[0];
      }
    }
  }
  const auto end = std::chrono::steady_clock::now();
  volatile float keep = sink;
  (void)keep;
  const double ns = static_cast<double>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(end - start).count());
  return {ns / static_cast<double>(packets), packets};
}

void Report(const char* name, const std::vector<uint8_t>& stream) {
  Result best{1e30, 0};
  for (int run = 0; run < 7; ++run) {
    const Result r = Run(stream);
    if (r.ns_per_packet < best.ns_per_packet) best = r;
  }
  std::printf("%-28s %9llu packets  %8.1f ns/packet  %7.2f M packets/s  (%.1f MB/s)\n", name,
              static_cast<unsigned long long>(best.packets), best.ns_per_packet,
              1e3 / best.ns_per_packet,
              static_cast<double>(stream.size()) /
                  (best.ns_per_packet * 1e-9 * static_cast<double>(best.packets)) / 1e6);
}

}  // namespace
}  // namespace rover::drivers

int main() {
  using rover::drivers::MakeStream;
  using rover::drivers::Report;
  constexpr int kPackets = 400'000;  // 1000 s of a 400 Hz stream
  std::printf("Xbus MTData2 decode (XbusParser + DecodeMtData2, 256-byte reads)\n");
  Report("clean", MakeStream(kPackets, 0.0, 0.0, 1));
  Report("5% garbage before packets", MakeStream(kPackets, 0.05, 0.0, 2));
  Report("2% flipped bytes", MakeStream(kPackets, 0.0, 0.02, 3));
  return 0;
}
