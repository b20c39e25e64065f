#include "hil/sim/devices/simulated_mti.h"

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>

#include "core/time/posix_time.h"
#include "drivers/imu/xbus_protocol.h"
#include "hil/sim/seed.h"

namespace rover::sim {
namespace {

namespace xbus = drivers::xbus;

constexpr std::size_t kCounter = 0, kTime = 1, kAccel = 2, kGyro = 3;

// Uniform in [-1, 1) from a hash: noise that depends only on (seed, k, axis).
double HashNoise(uint64_t seed, uint64_t k, uint64_t axis) {
  const uint64_t h = StreamSeed(seed, k * 8 + axis);
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

std::runtime_error PtyError(const std::string& step) {
  return std::runtime_error("SimulatedMti: " + step + ": " + std::strerror(errno));
}

}  // namespace

void SimulatedMtiOptions::Validate() const {
  const auto probability = [](double p, const char* name) {
    if (!(p >= 0.0 && p <= 1.0)) {
      throw std::invalid_argument(std::string("SimulatedMtiOptions: ") + name +
                                  " must be in [0, 1], found " + std::to_string(p));
    }
  };
  probability(drop_probability, "drop_probability");
  probability(flip_probability, "flip_probability");
  probability(garbage_probability, "garbage_probability");
  if (garbage_max_bytes < 1 || garbage_max_bytes > 4096) {
    throw std::invalid_argument(
        "SimulatedMtiOptions: garbage_max_bytes must be in [1, 4096], found " +
        std::to_string(garbage_max_bytes));
  }
  if (max_rate_hz < 1 || max_rate_hz > 2000) {
    throw std::invalid_argument("SimulatedMtiOptions: max_rate_hz must be in [1, 2000], found " +
                                std::to_string(max_rate_hz));
  }
  if (start_rate_hz < 1 || start_rate_hz > max_rate_hz) {
    throw std::invalid_argument(
        "SimulatedMtiOptions: start_rate_hz must be in [1, max_rate_hz], found " +
        std::to_string(start_rate_hz));
  }
  if (!(std::abs(clock_drift_ppm) <= 1000.0)) {
    throw std::invalid_argument(
        "SimulatedMtiOptions: clock_drift_ppm must be in [-1000, 1000], found " +
        std::to_string(clock_drift_ppm));
  }
}

drivers::MtData2Packet SimulatedMti::PacketAt(uint64_t seed, uint64_t k, int rate_hz) {
  const double t = static_cast<double>(k) / rate_hz;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  drivers::MtData2Packet p;
  p.has_packet_counter = p.has_sample_time_fine = p.has_acceleration = p.has_rate_of_turn = true;
  p.packet_counter = static_cast<uint16_t>(k);
  p.sample_time_fine =
      static_cast<uint32_t>(k * xbus::kSampleTimeFineHz / static_cast<uint64_t>(rate_hz));
  // A rover rocking on its suspension: slow rates, gravity mostly on z.
  const double ax = 0.3 * std::sin(kTwoPi * 0.5 * t);
  const double ay = 0.2 * std::cos(kTwoPi * 0.3 * t);
  const double az = 9.81 + 0.1 * std::sin(kTwoPi * 1.1 * t);
  const double gx = 0.05 * std::sin(kTwoPi * 0.7 * t);
  const double gy = 0.04 * std::cos(kTwoPi * 0.9 * t);
  const double gz = 0.2 * std::sin(kTwoPi * 0.2 * t);
  const double accel[3] = {ax, ay, az};
  const double gyro[3] = {gx, gy, gz};
  for (std::size_t i = 0; i < 3; ++i) {
    p.acceleration_m_s2[i] = static_cast<float>(accel[i] + 0.01 * HashNoise(seed, k, i));
    p.rate_of_turn_rad_s[i] = static_cast<float>(gyro[i] + 0.002 * HashNoise(seed, k, 3 + i));
  }
  return p;
}

SimulatedMti::SimulatedMti(const SimulatedMtiOptions& options)
    : options_((options.Validate(), options)),
      power_up_(Time::Now()),
      faults_(StreamSeed(options.seed, 0x4D5449)) {
  master_fd_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd_ < 0) throw PtyError("posix_openpt");
  char name[128];
  if (grantpt(master_fd_) != 0 || unlockpt(master_fd_) != 0 ||
      ptsname_r(master_fd_, name, sizeof name) != 0) {
    const auto error = PtyError("grantpt/unlockpt/ptsname");
    close(master_fd_);
    throw error;
  }
  slave_path_ = name;
  // Holding the slave open keeps the pty alive between driver sessions (a
  // master reads EIO while no slave is open), and setting it raw here keeps
  // the line discipline from echoing or translating bytes before the
  // driver opens it.
  slave_fd_ = open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  termios tio{};
  if (slave_fd_ < 0 || tcgetattr(slave_fd_, &tio) != 0) {
    const auto error = PtyError("opening the slave " + slave_path_);
    if (slave_fd_ >= 0) close(slave_fd_);
    close(master_fd_);
    throw error;
  }
  cfmakeraw(&tio);
  tcsetattr(slave_fd_, TCSANOW, &tio);
  fcntl(master_fd_, F_SETFL, fcntl(master_fd_, F_GETFL) | O_NONBLOCK);
  if (options_.start_in_measurement && options_.answer) {
    rate_hz_ = options_.start_rate_hz;
    StartMeasurement(power_up_);
  }
  thread_ = std::thread([this] { Run(); });
}

SimulatedMti::~SimulatedMti() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  close(slave_fd_);
  close(master_fd_);
}

void SimulatedMti::StopStreaming() { streaming_ = false; }

SimulatedMtiStats SimulatedMti::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::vector<uint16_t> SimulatedMti::intact_counters() const {
  std::lock_guard lock(mutex_);
  return intact_;
}

uint32_t SimulatedMti::DeviceTicks(Time t) const {
  const double seconds = (t - power_up_).ToSeconds() * (1.0 + options_.clock_drift_ppm * 1e-6);
  return options_.first_sample_time_fine +
         static_cast<uint32_t>(
             std::llround(seconds * static_cast<double>(xbus::kSampleTimeFineHz)));
}

void SimulatedMti::StartMeasurement(Time now) {
  measurement_start_ = now;
  measurement_ticks_ = DeviceTicks(now);
  next_packet_ = 0;
  measuring_ = true;
}

void SimulatedMti::Run() {
  while (!stop_) {
    if (measuring_ && streaming_) {
      // Packet k is sampled and sent when the device clock has advanced k
      // periods since the measurement started.
      const double period_s = 1.0 / (rate_hz_.load() * (1.0 + options_.clock_drift_ppm * 1e-6));
      const auto due = [&] {
        return measurement_start_ +
               Duration::FromSeconds(period_s * static_cast<double>(next_packet_));
      };
      SleepUntil(due());
      HandleInput();
      // A late thread catches up with a burst, as the device's UART queue would.
      while (measuring_ && streaming_ && !stop_ && due() <= Time::Now()) SendPacket();
    } else {
      pollfd p{master_fd_, POLLIN, 0};
      poll(&p, 1, 10);
      HandleInput();
    }
  }
}

void SimulatedMti::HandleInput() {
  for (;;) {
    const std::span<uint8_t> space = parser_.WritableSpace();
    const ssize_t n = read(master_fd_, space.data(), space.size());
    if (n <= 0) break;
    parser_.Commit(static_cast<std::size_t>(n));
    xbus::Message message;
    while (parser_.Next(&message)) Handle(message);
  }
}

void SimulatedMti::Handle(const xbus::Message& message) {
  {
    std::lock_guard lock(mutex_);
    ++stats_.messages;
  }
  if (!options_.answer) return;
  switch (message.mid) {
    case xbus::mid::kGoToConfig:
      measuring_ = false;
      Send(xbus::mid::kGoToConfigAck, {});
      return;
    case xbus::mid::kReqDid: {
      uint8_t id[4];
      xbus::WriteU32(options_.device_id, id);
      Send(xbus::mid::kDeviceId, id);
      return;
    }
    case xbus::mid::kSetOutputConfiguration: {
      const std::span<const uint8_t> p = message.payload;
      if (measuring_ || p.empty() || p.size() % 4 != 0) break;
      std::array<bool, 4> items = {false, false, false, false};
      int rate = 0;
      for (std::size_t i = 0; i < p.size(); i += 4) {
        const uint16_t id = xbus::ReadU16(&p[i]);
        const uint16_t frequency = xbus::ReadU16(&p[i + 2]);
        std::size_t item = 0;
        if (id == xbus::data_id::kPacketCounter) {
          item = kCounter;
        } else if (id == xbus::data_id::kSampleTimeFine) {
          item = kTime;
        } else if (id == xbus::data_id::kAcceleration) {
          item = kAccel;
        } else if (id == xbus::data_id::kRateOfTurn) {
          item = kGyro;
        } else {
          SendError(xbus::error_code::kInvalidMessage);
          return;
        }
        items[item] = true;
        if (item == kAccel || item == kGyro) {
          const int hz = frequency == xbus::kEveryPacket ? options_.max_rate_hz : frequency;
          if (hz < 1 || hz > options_.max_rate_hz) {
            SendError(xbus::error_code::kInvalidPeriod);
            return;
          }
          rate = std::max(rate, hz);
        }
      }
      if (rate == 0) break;
      configured_ = items;
      rate_hz_ = rate;
      Send(xbus::mid::kSetOutputConfigurationAck, p);
      return;
    }
    case xbus::mid::kGoToMeasurement:
      if (rate_hz_.load() == 0) break;  // nothing configured yet
      // Measuring before the acknowledge leaves: a driver that has it sees
      // measuring() true. The first packet still follows the acknowledge,
      // since this thread sends both.
      StartMeasurement(Time::Now());
      Send(xbus::mid::kGoToMeasurementAck, {});
      return;
    case xbus::mid::kWakeUpAck:
      return;
    default:
      break;
  }
  SendError(xbus::error_code::kInvalidMessage);
}

void SimulatedMti::Send(uint8_t mid, std::span<const uint8_t> payload) {
  std::vector<uint8_t> frame(xbus::FrameBytes(payload.size()));
  xbus::EncodeMessage(mid, payload, frame);
  WriteBytes(frame);
}

void SimulatedMti::SendError(uint8_t code) {
  {
    std::lock_guard lock(mutex_);
    ++stats_.errors_sent;
  }
  const uint8_t payload[1] = {code};
  Send(xbus::mid::kError, payload);
}

void SimulatedMti::WriteBytes(std::span<const uint8_t> bytes) {
  const Time give_up = Time::Now() + Duration::Milliseconds(20);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(master_fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (Time::Now() >= give_up || (n < 0 && errno != EAGAIN && errno != EINTR)) {
      std::lock_guard lock(mutex_);
      ++stats_.write_overflows;
      return;
    }
    pollfd p{master_fd_, POLLOUT, 0};
    poll(&p, 1, 2);
  }
}

void SimulatedMti::SendPacket() {
  const uint64_t k = next_packet_++;
  const int rate = rate_hz_.load();
  drivers::MtData2Packet packet = PacketAt(options_.seed, k, rate);
  if (options_.packet_source) {
    const drivers::MtData2Packet measured = options_.packet_source(k, rate);
    packet.acceleration_m_s2 = measured.acceleration_m_s2;
    packet.rate_of_turn_rad_s = measured.rate_of_turn_rad_s;
  }
  packet.packet_counter = static_cast<uint16_t>(options_.first_packet_counter + k);
  packet.sample_time_fine = measurement_ticks_ + packet.sample_time_fine;
  packet.has_packet_counter = configured_[kCounter];
  packet.has_sample_time_fine = configured_[kTime];
  packet.has_acceleration = configured_[kAccel];
  packet.has_rate_of_turn = configured_[kGyro];

  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const bool drop = uniform(faults_) < options_.drop_probability;
  const bool flip = uniform(faults_) < options_.flip_probability;
  const bool garbage = uniform(faults_) < options_.garbage_probability;
  {
    std::lock_guard lock(mutex_);
    ++stats_.packets;
  }
  if (drop) {
    std::lock_guard lock(mutex_);
    ++stats_.dropped_packets;
    return;
  }
  uint8_t payload[drivers::kMtData2CompletePayloadBytes];
  const std::size_t payload_bytes = drivers::EncodeMtData2(packet, payload);
  std::vector<uint8_t> bytes;
  if (garbage) {
    std::uniform_int_distribution<int> count(1, options_.garbage_max_bytes);
    std::uniform_int_distribution<int> value(0, 255);
    const int n = count(faults_);
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<uint8_t>(value(faults_)));
  }
  const std::size_t garbage_bytes = bytes.size();
  bytes.resize(garbage_bytes + xbus::FrameBytes(payload_bytes));
  xbus::EncodeMessage(xbus::mid::kMtData2, std::span<const uint8_t>(payload, payload_bytes),
                      std::span<uint8_t>(bytes).subspan(garbage_bytes));
  if (flip) {
    // A byte of the payload or the checksum: the packet's content is
    // damaged, its framing is not. (A damaged length byte is a framing fault
    // whose outcome can depend on the bytes behind it; the parser's own
    // tests cover those with truncated and shortened frames.)
    const std::size_t frame_bytes = bytes.size() - garbage_bytes;
    std::uniform_int_distribution<std::size_t> where(xbus::kHeaderBytes, frame_bytes - 1);
    std::uniform_int_distribution<int> mask(1, 255);
    bytes[garbage_bytes + where(faults_)] ^= static_cast<uint8_t>(mask(faults_));
  }
  {
    std::lock_guard lock(mutex_);
    stats_.garbage_bytes += garbage_bytes;
    if (flip) {
      ++stats_.flipped_packets;
    } else {
      ++stats_.intact_packets;
      intact_.push_back(packet.packet_counter);
    }
  }
  WriteBytes(bytes);
}

}  // namespace rover::sim
