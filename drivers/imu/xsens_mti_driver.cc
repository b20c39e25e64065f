#include "drivers/imu/xsens_mti_driver.h"

#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "core/time/posix_time.h"
#include "drivers/imu/imu_device_error.h"
#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers {
namespace {

constexpr int64_t kNanosecondsPerTick = 1'000'000'000 / xbus::kSampleTimeFineHz;

// Every message this driver needs fits a short frame (the configured MTData2
// payload is 42 bytes, acknowledges and DeviceID less). Refusing longer lengths
// bounds the cost of a false frame start in corrupted bytes: the parser
// waits for at most 259 bytes before the checksum rejects it, instead of up
// to 2055 with extended lengths, which would hold back the packets behind
// it for as long.
constexpr std::size_t kMaxPayloadBytes = xbus::kExtendedLength - 1;

std::string Hex(uint64_t value, int digits) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%0*llX", digits, static_cast<unsigned long long>(value));
  return text;
}

SerialPortOptions PortOptions(const XsensMtiOptions& options) {
  options.Validate();
  SerialPortOptions port;
  port.path = options.port;
  port.baud_rate = options.baud_rate;
  return port;
}

}  // namespace

void XsensMtiOptions::Validate() const {
  if (port.empty()) throw std::invalid_argument("XsensMtiOptions: port must not be empty");
  if (!(rate_hz >= 1.0 && rate_hz <= 2000.0 && std::floor(rate_hz) == rate_hz)) {
    throw std::invalid_argument("XsensMtiOptions: rate_hz must be an integer in [1, 2000], found " +
                                std::to_string(rate_hz));
  }
  if (ack_timeout <= Duration::Zero() || ack_timeout > Duration::Seconds(60)) {
    throw std::invalid_argument("XsensMtiOptions: ack_timeout must be in (0, 60 s], found " +
                                ack_timeout.ToString());
  }
  if (attempts < 1 || attempts > 100) {
    throw std::invalid_argument("XsensMtiOptions: attempts must be in [1, 100], found " +
                                std::to_string(attempts));
  }
  if (latency_correction < Duration::Zero() || latency_correction > Duration::Seconds(1)) {
    throw std::invalid_argument("XsensMtiOptions: latency_correction must be in [0, 1 s], found " +
                                latency_correction.ToString());
  }
  clock.Validate();
  SerialPortOptions serial;
  serial.path = port;
  serial.baud_rate = baud_rate;
  serial.Validate();
}

XsensMtiDriver::XsensMtiDriver(const XsensMtiOptions& options)
    : options_(options),
      port_(PortOptions(options)),
      parser_(kMaxPayloadBytes),
      clock_(options.clock) {
  Configure();
}

bool XsensMtiDriver::ReadInto(Time deadline, bool* timed_out) {
  *timed_out = false;
  for (;;) {
    const Duration left = deadline - Time::Now();
    if (left <= Duration::Zero()) {
      *timed_out = true;
      return true;
    }
    pollfd p{port_.fd(), POLLIN, 0};
    const timespec ts = ToTimespec(left);
    const int ready = ppoll(&p, 1, &ts, nullptr);
    if (ready == 0) {
      *timed_out = true;
      return true;
    }
    if (ready < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    const std::span<uint8_t> space = parser_.WritableSpace();
    const ssize_t n = read(port_.fd(), space.data(), space.size());
    if (n > 0) {
      parser_.Commit(static_cast<std::size_t>(n));
      last_read_time_ = Time::Now();
      return true;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n == 0) errno = 0;  // end of file: the other side hung up
    return false;
  }
}

std::vector<uint8_t> XsensMtiDriver::Request(uint8_t mid, std::span<const uint8_t> payload,
                                             uint8_t ack_mid, const char* step) {
  std::vector<uint8_t> frame(xbus::FrameBytes(payload.size()));
  xbus::EncodeMessage(mid, payload, frame);
  const std::string where = "Xsens MTi on " + port_.path() + ": " + step;
  for (int attempt = 0; attempt < options_.attempts; ++attempt) {
    if (!port_.WriteAll(frame, options_.ack_timeout)) {
      throw ImuDeviceError(where + ": cannot write the request: " + std::strerror(errno));
    }
    const Time deadline = Time::Now() + options_.ack_timeout;
    for (;;) {
      xbus::Message message;
      bool answered = false;
      while (parser_.Next(&message)) {
        if (message.mid == ack_mid) {
          answered = true;
          break;
        }
        if (message.mid == xbus::mid::kError) {
          const uint8_t code = message.payload.empty() ? 0 : message.payload[0];
          throw ImuDeviceError(where + ": the device answered Error (0x42) with code " +
                               Hex(code, 2) + " (" + xbus::ErrorCodeName(code) + ")");
        }
        // Anything else (MTData2 still streaming, WakeUp) is not the answer.
      }
      if (answered) return {message.payload.begin(), message.payload.end()};
      bool timed_out = false;
      if (!ReadInto(deadline, &timed_out)) {
        throw ImuDeviceError(where + ": cannot read the answer: " +
                             (errno != 0 ? std::strerror(errno) : "the port hung up"));
      }
      if (timed_out) break;
    }
  }
  throw ImuDeviceError(where + ": no acknowledge (message " + Hex(ack_mid, 2) + ") after " +
                       std::to_string(options_.attempts) + " attempt(s) of " +
                       options_.ack_timeout.ToString() +
                       ": the device does not answer (check power, wiring and that it runs at " +
                       std::to_string(options_.baud_rate) + " baud)");
}

void XsensMtiDriver::Configure() {
  port_.DiscardInput();
  Request(xbus::mid::kGoToConfig, {}, xbus::mid::kGoToConfigAck, "GoToConfig");

  const std::vector<uint8_t> id = Request(xbus::mid::kReqDid, {}, xbus::mid::kDeviceId, "ReqDID");
  if (id.size() == 4) {
    device_id_ = xbus::ReadU32(id.data());
  } else if (id.size() == 8) {
    device_id_ = (static_cast<uint64_t>(xbus::ReadU32(id.data())) << 32) | xbus::ReadU32(&id[4]);
  } else {
    throw ImuDeviceError("Xsens MTi on " + port_.path() + ": ReqDID: DeviceID has " +
                         std::to_string(id.size()) + " bytes, expected 4 or 8");
  }

  const auto rate = static_cast<uint16_t>(options_.rate_hz);
  std::array<uint8_t, 16> config{};
  const std::array<std::pair<uint16_t, uint16_t>, 4> items = {{
      {xbus::data_id::kPacketCounter, xbus::kEveryPacket},
      {xbus::data_id::kSampleTimeFine, xbus::kEveryPacket},
      {xbus::data_id::kAcceleration, rate},
      {xbus::data_id::kRateOfTurn, rate},
  }};
  for (std::size_t i = 0; i < items.size(); ++i) {
    xbus::WriteU16(items[i].first, &config[4 * i]);
    xbus::WriteU16(items[i].second, &config[4 * i + 2]);
  }
  const std::vector<uint8_t> echo =
      Request(xbus::mid::kSetOutputConfiguration, config, xbus::mid::kSetOutputConfigurationAck,
              "SetOutputConfiguration");
  // The acknowledge echoes the configuration the device took. An empty one
  // says nothing; otherwise the inertial items must be there at our rate.
  if (!echo.empty()) {
    for (const uint16_t wanted : {xbus::data_id::kAcceleration, xbus::data_id::kRateOfTurn}) {
      bool found = false;
      for (std::size_t i = 0; i + 4 <= echo.size(); i += 4) {
        if (xbus::ReadU16(&echo[i]) == wanted && xbus::ReadU16(&echo[i + 2]) == rate) found = true;
      }
      if (!found) {
        throw ImuDeviceError("Xsens MTi on " + port_.path() +
                             ": SetOutputConfiguration: the device did not take data id " +
                             Hex(wanted, 4) + " at " + std::to_string(rate) + " Hz");
      }
    }
  }

  if (!options_.defer_measurement) GoToMeasurement();

  const std::string line = "Xsens MTi on " + port_.path() + ": device id " + Hex(device_id_, 8) +
                           (measuring_ ? ", measuring at " : ", configured for ") +
                           std::to_string(rate) + " Hz";
  if (options_.log) {
    options_.log(line);
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
}

void XsensMtiDriver::GoToMeasurement() {
  Request(xbus::mid::kGoToMeasurement, {}, xbus::mid::kGoToMeasurementAck, "GoToMeasurement");
  measuring_ = true;
}

void XsensMtiDriver::Start() {
  if (!measuring_) GoToMeasurement();
}

bool XsensMtiDriver::ToSample(const MtData2Packet& packet, ImuSample* sample) {
  if (!packet.complete()) {
    ++stats_.malformed_packets;
    return false;
  }
  if (!have_packet_) {
    sequence_ = packet.packet_counter;
    device_ticks_ = packet.sample_time_fine;
  } else {
    const auto delta = static_cast<uint16_t>(packet.packet_counter - last_counter_);
    if (delta == 0) {
      ++stats_.duplicate_packets;
      return false;
    }
    if (delta < 0x8000) {
      stats_.lost_samples += static_cast<uint64_t>(delta) - 1;
      sequence_ += delta;
    } else {
      // A counter half a wrap back is a restart, not 32768 lost samples.
      ++stats_.counter_resets;
      sequence_ += 1;
    }
    const uint32_t ticks = packet.sample_time_fine - last_sample_time_fine_;
    if (ticks < 0x8000'0000u) {
      device_ticks_ += ticks;
    } else {
      ++stats_.clock_resets;
      clock_.Reset();
    }
  }
  have_packet_ = true;
  last_counter_ = packet.packet_counter;
  last_sample_time_fine_ = packet.sample_time_fine;

  Time stamp = clock_.Update(device_ticks_ * kNanosecondsPerTick, last_read_time_) -
               options_.latency_correction;
  if (stats_.samples > 0 && stamp <= last_stamp_) {
    ++stats_.non_monotonic_stamps;
    stamp = last_stamp_ + Duration::Microseconds(1);
  }
  last_stamp_ = stamp;

  sample->stamp = stamp;
  sample->sequence = sequence_;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    sample->angular_velocity_rad_s[i] = static_cast<double>(packet.rate_of_turn_rad_s[k]);
    sample->linear_acceleration_m_s2[i] = static_cast<double>(packet.acceleration_m_s2[k]);
  }
  ++stats_.samples;
  return true;
}

ReadStatus XsensMtiDriver::Read(ImuSample* sample, Duration timeout) {
  // Clamped so that a "forever" timeout (Duration::Max()) cannot overflow.
  const Time deadline = Time::Now() + std::min(timeout, Duration::Seconds(86'400));
  for (;;) {
    xbus::Message message;
    while (parser_.Next(&message)) {
      if (message.mid == xbus::mid::kMtData2) {
        MtData2Packet packet;
        if (!DecodeMtData2(message.payload, &packet)) {
          ++stats_.malformed_packets;
          continue;
        }
        if (ToSample(packet, sample)) return ReadStatus::kOk;
      } else if (message.mid == xbus::mid::kError) {
        ++stats_.device_errors;
      }
    }
    bool timed_out = false;
    if (!ReadInto(deadline, &timed_out)) {
      // A port that hung up (device unplugged, pty closed) stays readable
      // with an error: without a wait the caller's loop would spin. One
      // error per timeout is enough to notice, and leaves the CPU to others.
      ++stats_.read_errors;
      SleepUntil(deadline);
      return ReadStatus::kError;
    }
    if (timed_out) {
      ++stats_.timeouts;
      return ReadStatus::kTimeout;
    }
  }
}

XsensMtiStats XsensMtiDriver::stats() const {
  XsensMtiStats s = stats_;
  const XbusParserStats& p = parser_.stats();
  s.checksum_errors = p.checksum_errors;
  s.garbage_bytes = p.garbage_bytes;
  s.resyncs = p.resyncs;
  s.oversize_frames = p.oversize_frames;
  return s;
}

}  // namespace rover::drivers
