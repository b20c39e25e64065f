#ifndef ROVER_DRIVERS_IMU_SPI_DEVICE_H_
#define ROVER_DRIVERS_IMU_SPI_DEVICE_H_

#include <cstdint>
#include <span>

namespace rover::drivers {

/// One SPI peripheral (bus + chip select) as a sensor driver uses it. The
/// bus settings (mode, clock, word size) belong to the implementation.
/// Implementations: spidev (SpidevDevice) and simulated devices in tests.
class SpiDevice {
 public:
  virtual ~SpiDevice() = default;

  /// One full-duplex transfer with chip select asserted for its whole
  /// length and released after it: shifts out tx (MSB first) while shifting
  /// the same number of bytes into rx. Returns false if the sizes differ or
  /// the transfer failed (last_error() holds the errno). Never allocates,
  /// throws or locks; it may block for the transfer's duration.
  virtual bool Transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) = 0;

  /// What to call the device in messages, e.g. its path "/dev/spidev0.0".
  virtual const char* name() const = 0;
  /// errno of the last failed transfer, 0 if none failed.
  virtual int last_error() const = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_SPI_DEVICE_H_
