#ifndef ROVER_HIL_SIM_DEVICES_SIMULATED_ADIS16448_H_
#define ROVER_HIL_SIM_DEVICES_SIMULATED_ADIS16448_H_

// An ADIS16448 behind the SpiDevice interface, for testing the real SPI
// driver (drivers/imu/adis16448_driver.h) without hardware.

#include <array>
#include <cstdint>

#include "drivers/imu/adis16448_burst.h"
#include "drivers/imu/spi_device.h"

namespace rover::sim {

struct SimulatedAdis16448Options {
  uint64_t seed = 1;               ///< signal noise
  uint16_t product_id = 0x4040;    ///< PROD_ID; another value plays a wrong device
  uint64_t bad_crc_period = 0;     ///< every n-th burst carries a wrong CRC (0: never)
  uint64_t diag_error_period = 0;  ///< every n-th burst flags an SPI failure in DIAG_STAT
  bool fail_transfers = false;     ///< every transfer fails (EIO), as with no device
};

/// The register file and SPI protocol of an ADIS16448 (16-bit frames, read
/// answers one frame late, byte writes, burst read with optional CRC-16),
/// with deterministic output samples. LatchSample(k) plays the data-ready
/// moment: it loads sample k's outputs into the output registers; the next
/// burst reads them. Not thread-safe: use it from the thread that reads.
class SimulatedAdis16448 final : public drivers::SpiDevice {
 public:
  explicit SimulatedAdis16448(const SimulatedAdis16448Options& options = {});

  bool Transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) override;
  const char* name() const override { return "simulated ADIS16448"; }
  int last_error() const override { return last_error_; }

  /// Loads the outputs of sample k (SampleAt) into the output registers.
  void LatchSample(uint64_t k);
  /// The raw outputs of sample k: a rover at rest with slow rocking, plus
  /// seeded noise of a few LSB; identical for the same seed and k. DIAG_STAT
  /// 0 and the correct CRC.
  drivers::Adis16448Burst SampleAt(uint64_t k) const;

  /// A register's current value (address even, < 0x80).
  uint16_t register_value(uint8_t address) const { return registers_[address / 2]; }
  /// Output rate set by SMPL_PRD: 819.2 / 2^D Hz.
  double output_rate_hz() const;
  uint64_t bursts() const { return bursts_; }
  uint64_t corrupted_crcs() const { return corrupted_crcs_; }
  uint64_t injected_diag_errors() const { return injected_diag_errors_; }

 private:
  uint16_t Answer(uint16_t word);  // one non-burst 16-bit frame

  SimulatedAdis16448Options options_;
  std::array<uint16_t, 64> registers_{};
  uint16_t pending_ = 0;  // what the next frame shifts out
  drivers::Adis16448Burst latched_;
  uint64_t bursts_ = 0;
  uint64_t corrupted_crcs_ = 0;
  uint64_t injected_diag_errors_ = 0;
  int last_error_ = 0;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_DEVICES_SIMULATED_ADIS16448_H_
