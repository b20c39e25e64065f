#include "drivers/imu/adis16448_driver.h"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>

#include "core/time/posix_time.h"
#include "drivers/imu/adis16448_registers.h"
#include "drivers/imu/imu_device_error.h"

namespace rover::drivers {
namespace {

std::string Hex16(uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%04X", value);
  return text;
}

}  // namespace

int Adis16448Options::DecimationExponent() const {
  for (int d = 0; d <= adis16448::kMaxDecimationExponent; ++d) {
    const double rate = adis16448::kInternalSampleRateHz / static_cast<double>(1 << d);
    if (std::abs(rate - rate_hz) <= 1e-9 * rate) return d;
  }
  return -1;
}

void Adis16448Options::Validate() const {
  if (DecimationExponent() < 0) {
    throw std::invalid_argument(
        "Adis16448Options: rate_hz must be 819.2 / 2^D for D in [0, 10] (819.2, 409.6, 204.8, "
        "102.4, ...), found " +
        std::to_string(rate_hz));
  }
  if (data_ready_line != 1 && data_ready_line != 2) {
    throw std::invalid_argument(
        "Adis16448Options: data_ready_line must be 1 (DIO1) or 2 (DIO2), "
        "found " +
        std::to_string(data_ready_line));
  }
  if (register_stall < Duration::Zero() || register_stall > Duration::Milliseconds(10)) {
    throw std::invalid_argument("Adis16448Options: register_stall must be in [0, 10 ms], found " +
                                register_stall.ToString());
  }
}

Adis16448Driver::Adis16448Driver(SpiDevice& spi, GpioEdgeSource& data_ready,
                                 const Adis16448Options& options)
    : spi_(spi), data_ready_(data_ready), options_(options) {
  options_.Validate();
  period_ = Duration::FromSeconds(1.0 / options_.rate_hz);
  burst_bytes_ = 2 + Adis16448Burst::Bytes(options_.burst_crc);
  tx_[0] = static_cast<uint8_t>(adis16448::kBurstCommand >> 8);
  tx_[1] = static_cast<uint8_t>(adis16448::kBurstCommand & 0xFFu);

  const uint16_t product = ReadRegister(adis16448::kProdId);
  if (product != adis16448::kProductId) {
    throw ImuDeviceError(std::string("ADIS16448 on ") + spi_.name() + ": PROD_ID reads " +
                         Hex16(product) + ", expected " + Hex16(adis16448::kProductId) +
                         " (ADIS16448): no device, another device, or wrong SPI mode or wiring");
  }
  const auto smpl_prd =
      static_cast<uint16_t>((options_.DecimationExponent() << adis16448::kSmplPrdDecimationShift) |
                            adis16448::kSmplPrdInternalClock);
  uint16_t msc_ctrl = adis16448::kMscDataReadyEnable;
  if (options_.data_ready_active_high) msc_ctrl |= adis16448::kMscDataReadyActiveHigh;
  if (options_.data_ready_line == 2) msc_ctrl |= adis16448::kMscDataReadyDio2;
  if (options_.burst_crc) msc_ctrl |= adis16448::kMscBurstCrc;
  WriteRegister(adis16448::kSmplPrd, smpl_prd);
  WriteRegister(adis16448::kMscCtrl, msc_ctrl);
  // Read back: a write that did not take (wiring, mode) would otherwise show
  // up only as a wrong rate or missing CRC words.
  const struct {
    uint8_t address;
    const char* name;
    uint16_t value;
  } checks[] = {{adis16448::kSmplPrd, "SMPL_PRD", smpl_prd},
                {adis16448::kMscCtrl, "MSC_CTRL", msc_ctrl}};
  for (const auto& check : checks) {
    const uint16_t value = ReadRegister(check.address);
    if (value != check.value) {
      throw ImuDeviceError(std::string("ADIS16448 on ") + spi_.name() + ": " + check.name +
                           " reads " + Hex16(value) + " after writing " + Hex16(check.value));
    }
  }
  (void)ReadRegister(adis16448::kDiagStat);  // clears flags left from power-up
}

void Adis16448Driver::Frame(uint16_t word, uint16_t* answer, const char* step) {
  const std::array<uint8_t, 2> tx = {static_cast<uint8_t>(word >> 8),
                                     static_cast<uint8_t>(word & 0xFFu)};
  std::array<uint8_t, 2> rx{};
  if (!spi_.Transfer(tx, rx)) {
    throw ImuDeviceError(std::string("ADIS16448 on ") + spi_.name() + ": " + step +
                         ": SPI transfer failed: " + std::strerror(spi_.last_error()));
  }
  if (answer != nullptr) *answer = static_cast<uint16_t>((rx[0] << 8) | rx[1]);
  SleepFor(options_.register_stall);
}

uint16_t Adis16448Driver::ReadRegister(uint8_t address) {
  const std::string step = "reading register " + Hex16(address);
  uint16_t value = 0;
  Frame(static_cast<uint16_t>(address << 8), nullptr, step.c_str());
  // The answer to a read arrives during the next frame; send a harmless
  // read of the same register meanwhile.
  Frame(static_cast<uint16_t>(address << 8), &value, step.c_str());
  return value;
}

void Adis16448Driver::WriteRegister(uint8_t address, uint16_t value) {
  const std::string step = "writing register " + Hex16(address);
  const unsigned write = adis16448::kWriteBit;
  const auto low =
      static_cast<uint16_t>(((address | write) << 8u) | (static_cast<unsigned>(value) & 0xFFu));
  const auto high = static_cast<uint16_t>((((address + 1u) | write) << 8u) |
                                          (static_cast<unsigned>(value) >> 8u));
  Frame(low, nullptr, step.c_str());
  Frame(high, nullptr, step.c_str());
}

ReadStatus Adis16448Driver::Read(ImuSample* sample, Duration timeout) {
  const Time deadline = Time::Now() + std::min(timeout, Duration::Seconds(86'400));
  for (bool first = true;; first = false) {
    const Duration left = deadline - Time::Now();
    if (!first && left <= Duration::Zero()) {
      ++stats_.timeouts;
      return ReadStatus::kTimeout;
    }
    GpioEdge edge;
    const ReadStatus status = data_ready_.Wait(&edge, std::max(left, Duration::Zero()));
    if (status == ReadStatus::kTimeout) {
      ++stats_.timeouts;
      return ReadStatus::kTimeout;
    }
    if (status != ReadStatus::kOk) {
      ++stats_.edge_errors;
      return status;
    }
    if (edge.rising != options_.data_ready_active_high) continue;  // the pulse's other edge

    if (have_edge_) {
      const Duration gap = edge.stamp - last_edge_;
      int64_t periods = 1;
      if (gap * 2 > period_ * 3) {
        periods = std::llround(gap / period_);
        stats_.missed_edges += static_cast<uint64_t>(periods - 1);
      }
      sequence_ += static_cast<uint64_t>(std::max<int64_t>(periods, 1));
    }
    have_edge_ = true;
    last_edge_ = edge.stamp;

    const std::span<uint8_t> rx(rx_.data(), burst_bytes_);
    if (!spi_.Transfer(std::span<const uint8_t>(tx_.data(), burst_bytes_), rx)) {
      ++stats_.transfer_errors;
      continue;
    }
    Adis16448Burst burst;
    burst.Decode(rx.subspan(2));
    if (options_.burst_crc && burst.crc != burst.ComputeCrc()) {
      ++stats_.crc_errors;
      continue;
    }
    if ((burst.diag_stat & adis16448::kDiagInertialErrors) != 0) {
      ++stats_.diag_errors;
      continue;
    }
    burst_ = burst;
    burst_.ToSample(sample);
    sample->stamp = edge.stamp;
    sample->sequence = sequence_;
    ++stats_.samples;
    return ReadStatus::kOk;
  }
}

void Adis16448Driver::Start() {
  // Bounded: the kernel queues 16 line events; more can only be new ones.
  constexpr int kMaxQueuedEdges = 64;
  GpioEdge edge;
  for (int i = 0; i < kMaxQueuedEdges; ++i) {
    if (data_ready_.Wait(&edge, Duration::Zero()) != ReadStatus::kOk) break;
  }
  have_edge_ = false;
  lost_edges_before_start_ = data_ready_.lost_edges();
}

Adis16448Stats Adis16448Driver::stats() const {
  Adis16448Stats s = stats_;
  s.lost_edges = data_ready_.lost_edges() - lost_edges_before_start_;
  return s;
}

}  // namespace rover::drivers
