#include "hil/sim/devices/simulated_adis16448.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <numbers>

#include "drivers/imu/adis16448_registers.h"
#include "hil/sim/seed.h"

namespace rover::sim {
namespace {

namespace adis = drivers::adis16448;

int16_t Clamp16(double v) {
  return static_cast<int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
}

// Uniform in [-1, 1) from a hash of (seed, k, channel).
double HashNoise(uint64_t seed, uint64_t k, uint64_t channel) {
  const uint64_t h = StreamSeed(seed, k * 16 + channel);
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

}  // namespace

SimulatedAdis16448::SimulatedAdis16448(const SimulatedAdis16448Options& options)
    : options_(options) {
  // Power-on defaults of the registers the driver touches.
  registers_[adis::kProdId / 2] = options_.product_id;
  registers_[adis::kSmplPrd / 2] = adis::kSmplPrdInternalClock;
  registers_[adis::kMscCtrl / 2] = adis::kMscDataReadyEnable | adis::kMscDataReadyActiveHigh;
  registers_[adis::kSensAvg / 2] = 0x0402;
  registers_[adis::kLotId1 / 2] = 0x1824;
  registers_[adis::kSerialNum / 2] = 0x0123;
  LatchSample(0);
}

double SimulatedAdis16448::output_rate_hz() const {
  const int d = (registers_[adis::kSmplPrd / 2] >> adis::kSmplPrdDecimationShift) & 0x1F;
  return adis::kInternalSampleRateHz / static_cast<double>(1 << std::min(d, 30));
}

drivers::Adis16448Burst SimulatedAdis16448::SampleAt(uint64_t k) const {
  const double t = static_cast<double>(k) / output_rate_hz();
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  // Rates in LSB (0.04 deg/s): +-2 deg/s of rocking; specific force in LSB
  // (0.833 mg): gravity on z (1 g = 1200.5 LSB) plus a little sway.
  const double gyro[3] = {50.0 * std::sin(kTwoPi * 0.7 * t), 40.0 * std::cos(kTwoPi * 0.9 * t),
                          -30.0 * std::sin(kTwoPi * 0.2 * t)};
  const double accel[3] = {36.0 * std::sin(kTwoPi * 0.5 * t), -24.0 * std::cos(kTwoPi * 0.3 * t),
                           1.0 / adis::kAccelGPerLsb + 12.0 * std::sin(kTwoPi * 1.1 * t)};
  drivers::Adis16448Burst b;
  for (std::size_t i = 0; i < 3; ++i) {
    b.gyro[i] = Clamp16(gyro[i] + 3.0 * HashNoise(options_.seed, k, i));
    b.accel[i] = Clamp16(accel[i] + 3.0 * HashNoise(options_.seed, k, 3 + i));
    b.mag[i] = Clamp16((i == 2 ? -3000.0 : 500.0) + 5.0 * HashNoise(options_.seed, k, 6 + i));
  }
  b.baro = static_cast<uint16_t>(49'450 + std::lround(4.0 * HashNoise(options_.seed, k, 9)));
  b.temp = static_cast<uint16_t>(static_cast<int16_t>(-148)) & 0x0FFFu;  // about 20 degC
  b.diag_stat = 0;
  b.crc = b.ComputeCrc();
  return b;
}

void SimulatedAdis16448::LatchSample(uint64_t k) {
  latched_ = SampleAt(k);
  registers_[adis::kDiagStat / 2] = latched_.diag_stat;
  for (std::size_t i = 0; i < 3; ++i) {
    registers_[(adis::kXgyroOut / 2) + i] = static_cast<uint16_t>(latched_.gyro[i]);
    registers_[(adis::kXgyroOut / 2) + 3 + i] = static_cast<uint16_t>(latched_.accel[i]);
    registers_[(adis::kXgyroOut / 2) + 6 + i] = static_cast<uint16_t>(latched_.mag[i]);
  }
}

uint16_t SimulatedAdis16448::Answer(uint16_t word) {
  const uint16_t out = pending_;
  const auto address = static_cast<uint8_t>((word >> 8) & 0x7F);
  if ((word & 0x8000u) != 0) {
    // Byte write: the even address takes the low byte, the odd one the high.
    uint16_t& reg = registers_[address / 2];
    const unsigned byte = word & 0xFFu;
    reg = (address & 1u) != 0 ? static_cast<uint16_t>((reg & 0x00FFu) | (byte << 8u))
                              : static_cast<uint16_t>((reg & 0xFF00u) | byte);
    pending_ = 0;
  } else {
    pending_ = registers_[address / 2];
  }
  return out;
}

bool SimulatedAdis16448::Transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) {
  if (options_.fail_transfers) {
    last_error_ = EIO;
    return false;
  }
  if (tx.size() != rx.size() || tx.size() % 2 != 0 || tx.empty()) {
    last_error_ = EINVAL;
    return false;
  }
  const auto word_at = [&](std::size_t i) {
    return static_cast<uint16_t>((tx[2 * i] << 8) | tx[2 * i + 1]);
  };
  const auto put = [&](std::size_t i, uint16_t w) {
    rx[2 * i] = static_cast<uint8_t>(w >> 8);
    rx[2 * i + 1] = static_cast<uint8_t>(w & 0xFFu);
  };
  const std::size_t words = tx.size() / 2;
  if (word_at(0) == drivers::adis16448::kBurstCommand) {
    ++bursts_;
    put(0, pending_);
    drivers::Adis16448Burst b = latched_;
    if (options_.diag_error_period != 0 && bursts_ % options_.diag_error_period == 0) {
      b.diag_stat |= drivers::adis16448::kDiagSpiFailure;
      ++injected_diag_errors_;
    }
    if (options_.bad_crc_period != 0 && bursts_ % options_.bad_crc_period == 0) {
      b.crc = static_cast<uint16_t>(b.crc ^ 0x5A5Au);
      ++corrupted_crcs_;
    }
    const bool with_crc = (registers_[adis::kMscCtrl / 2] & adis::kMscBurstCrc) != 0;
    std::array<uint8_t, drivers::Adis16448Burst::Bytes(true)> out{};
    const std::size_t n = drivers::Adis16448Burst::Bytes(with_crc);
    b.Encode(with_crc, std::span<uint8_t>(out.data(), n));
    // Words past the burst read as zero.
    for (std::size_t i = 2; i < rx.size(); ++i) rx[i] = i - 2 < n ? out[i - 2] : 0;
    pending_ = 0;
    return true;
  }
  for (std::size_t i = 0; i < words; ++i) put(i, Answer(word_at(i)));
  return true;
}

}  // namespace rover::sim
