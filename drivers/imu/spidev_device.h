#ifndef ROVER_DRIVERS_IMU_SPIDEV_DEVICE_H_
#define ROVER_DRIVERS_IMU_SPIDEV_DEVICE_H_

#include <cstdint>
#include <span>
#include <string>

#include "drivers/imu/spi_device.h"

namespace rover::drivers {

struct SpidevOptions {
  std::string path = "/dev/spidev0.0";  ///< /dev/spidevB.C: bus B, chip select C
  /// SPI mode 0..3 (CPOL << 1 | CPHA). ADIS16448: mode 3.
  uint8_t mode = 3;
  /// Clock. ADIS16448: at most 2 MHz for register access, 1 MHz for bursts.
  uint32_t speed_hz = 1'000'000;
  /// Bits per word, 8 or 16. With 8 the buffers are the bytes on the wire
  /// in order; with 16 spidev takes them as native-endian 16-bit words, so
  /// byte-oriented protocols (all drivers here) use 8.
  uint8_t bits_per_word = 8;

  /// Throws std::invalid_argument naming the field, what was expected and
  /// what was found.
  void Validate() const;
};

/// A Linux spidev character device. Each Transfer() is one SPI_IOC_MESSAGE
/// of one segment, so chip select frames exactly one transfer.
class SpidevDevice final : public SpiDevice {
 public:
  /// Opens `options.path` and sets mode, bits per word and maximum speed
  /// (SPI_IOC_WR_MODE, SPI_IOC_WR_BITS_PER_WORD, SPI_IOC_WR_MAX_SPEED_HZ).
  /// Throws ImuDeviceError naming the path, the step and strerror(errno) (no
  /// such device, permission denied, not an SPI device) and
  /// std::invalid_argument for invalid options.
  explicit SpidevDevice(const SpidevOptions& options);
  ~SpidevDevice() override;
  SpidevDevice(const SpidevDevice&) = delete;
  SpidevDevice& operator=(const SpidevDevice&) = delete;

  bool Transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) override;
  const char* name() const override { return options_.path.c_str(); }
  int last_error() const override { return last_error_; }

 private:
  SpidevOptions options_;
  int fd_ = -1;
  int last_error_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_SPIDEV_DEVICE_H_
