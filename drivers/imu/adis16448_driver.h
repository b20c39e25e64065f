#ifndef ROVER_DRIVERS_IMU_ADIS16448_DRIVER_H_
#define ROVER_DRIVERS_IMU_ADIS16448_DRIVER_H_

#include <array>
#include <cstdint>

#include "core/time/time.h"
#include "drivers/gpio/gpio_edge_source.h"
#include "drivers/imu/adis16448_burst.h"
#include "drivers/imu/imu_driver.h"
#include "drivers/imu/spi_device.h"

namespace rover::drivers {

struct Adis16448Options {
  /// Output rate: 819.2 SPS / 2^D for D in [0, 10] (819.2, 409.6, 204.8, ...
  /// Hz), set through SMPL_PRD. The board runs 409.6 Hz.
  double rate_hz = 409.6;
  /// Have the device append its CRC-16 to every burst (MSC_CTRL bit 4) and
  /// reject bursts that fail it. Off only for early units without it.
  bool burst_crc = true;
  /// The data-ready pin: DIO1 (1) or DIO2 (2).
  int data_ready_line = 1;
  /// Data-ready polarity. Active high: the rising edge marks new data, and
  /// only rising edges are used (falling ones only if active low).
  bool data_ready_active_high = true;
  /// Chip-select-high time between register-access frames (start-up only;
  /// the data sheet's stall time is 9 us).
  Duration register_stall = Duration::Microseconds(10);

  /// Throws std::invalid_argument naming the field, the expected values and
  /// the value found.
  void Validate() const;
  /// D of SMPL_PRD for rate_hz.
  int DecimationExponent() const;
};

/// Health counters of an Adis16448Driver (cumulative since start-up).
struct Adis16448Stats {
  uint64_t samples = 0;          ///< samples delivered
  uint64_t crc_errors = 0;       ///< bursts whose CRC-16 failed (dropped)
  uint64_t diag_errors = 0;      ///< bursts with inertial error flags in DIAG_STAT (dropped)
  uint64_t missed_edges = 0;     ///< data-ready periods without an edge (gap > 1.5 periods)
  uint64_t lost_edges = 0;       ///< edges the edge source reports it dropped
  uint64_t transfer_errors = 0;  ///< failed SPI transfers (dropped)
  uint64_t timeouts = 0;         ///< Read() calls that returned kTimeout
  uint64_t edge_errors = 0;      ///< the edge source failed
};

/// An ADIS16448-class IMU on SPI with its data-ready line on a GPIO.
///
/// Construction checks PROD_ID (0x4040), sets SMPL_PRD for rate_hz and
/// MSC_CTRL (data ready on the chosen DIO with the chosen polarity, CRC-16 on
/// bursts), and reads both back. Read() waits for the data-ready edge, takes
/// its kernel timestamp as the sample time (the edge is the sample instant
/// to within the edge latency; a serial stamp would add the transfer time),
/// burst-reads the outputs, checks CRC-16 and DIAG_STAT, and converts to SI
/// units in the sensor's axes. The sequence counts data-ready periods since
/// the first edge, so missed edges and dropped bursts leave gaps in it.
///
/// After construction Read() never allocates, throws or locks; it blocks
/// at most `timeout` plus one burst transfer.
class Adis16448Driver final : public ImuDriver {
 public:
  /// `spi` and `data_ready` must outlive the driver. Throws ImuDeviceError
  /// naming the SPI device, the step and the cause (failed transfer with
  /// strerror, wrong PROD_ID, register read-back mismatch);
  /// std::invalid_argument for bad options.
  Adis16448Driver(SpiDevice& spi, GpioEdgeSource& data_ready, const Adis16448Options& options);

  /// Waits up to `timeout` for a data-ready edge and delivers its burst.
  /// Bursts failing the CRC or DIAG_STAT check, and failed transfers, are
  /// counted and skipped: the call then waits for the next edge in the time
  /// left. kTimeout if no good sample came in time; kError if the edge
  /// source failed.
  ReadStatus Read(ImuSample* sample, Duration timeout) override;
  /// Forgets the data-ready edges queued since construction (and the edges
  /// the kernel lost among them). The sensor keeps only its newest sample:
  /// a burst read for a queued edge would pair old stamps with new data.
  void Start() override;

  /// Health counters so far. Call from the reading thread.
  Adis16448Stats stats() const;
  /// The most recent good burst (magnetometer, barometer, temperature).
  const Adis16448Burst& last_burst() const { return burst_; }
  Duration period() const { return period_; }

 private:
  uint16_t ReadRegister(uint8_t address);
  void WriteRegister(uint8_t address, uint16_t value);
  void Frame(uint16_t word, uint16_t* answer, const char* step);

  SpiDevice& spi_;
  GpioEdgeSource& data_ready_;
  Adis16448Options options_;
  Duration period_;
  std::size_t burst_bytes_;
  std::array<uint8_t, 2 + Adis16448Burst::Bytes(true)> tx_{};
  std::array<uint8_t, 2 + Adis16448Burst::Bytes(true)> rx_{};
  Adis16448Burst burst_;
  bool have_edge_ = false;
  uint64_t lost_edges_before_start_ = 0;
  Time last_edge_;
  uint64_t sequence_ = 0;
  Adis16448Stats stats_{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_ADIS16448_DRIVER_H_
