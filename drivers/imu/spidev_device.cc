#include "drivers/imu/spidev_device.h"

#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include "drivers/imu/imu_device_error.h"

namespace rover::drivers {

void SpidevOptions::Validate() const {
  if (path.empty()) throw std::invalid_argument("SpidevOptions: path must not be empty");
  if (mode > 3) {
    throw std::invalid_argument("SpidevOptions: mode must be 0, 1, 2 or 3, found " +
                                std::to_string(mode));
  }
  if (speed_hz < 1'000 || speed_hz > 100'000'000) {
    throw std::invalid_argument("SpidevOptions: speed_hz must be in [1 kHz, 100 MHz], found " +
                                std::to_string(speed_hz));
  }
  if (bits_per_word != 8 && bits_per_word != 16) {
    throw std::invalid_argument("SpidevOptions: bits_per_word must be 8 or 16, found " +
                                std::to_string(bits_per_word));
  }
}

SpidevDevice::SpidevDevice(const SpidevOptions& options) : options_(options) {
  options_.Validate();
  const std::string& path = options_.path;
  fd_ = open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) {
    throw ImuDeviceError("spidev " + path + ": cannot open: " + std::strerror(errno));
  }
  const auto fail = [&](const std::string& step) {
    const std::string message = "spidev " + path + ": " + step + ": " + std::strerror(errno) +
                                " (expected an SPI device, /dev/spidevB.C)";
    close(fd_);
    fd_ = -1;
    throw ImuDeviceError(message);
  };
  uint8_t mode = options_.mode;
  if (ioctl(fd_, SPI_IOC_WR_MODE, &mode) != 0) {
    fail("SPI_IOC_WR_MODE " + std::to_string(options_.mode));
  }
  uint8_t bits = options_.bits_per_word;
  if (ioctl(fd_, SPI_IOC_WR_BITS_PER_WORD, &bits) != 0) {
    fail("SPI_IOC_WR_BITS_PER_WORD " + std::to_string(options_.bits_per_word));
  }
  uint32_t speed = options_.speed_hz;
  if (ioctl(fd_, SPI_IOC_WR_MAX_SPEED_HZ, &speed) != 0) {
    fail("SPI_IOC_WR_MAX_SPEED_HZ " + std::to_string(options_.speed_hz));
  }
}

SpidevDevice::~SpidevDevice() {
  if (fd_ >= 0) close(fd_);
}

bool SpidevDevice::Transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) {
  if (tx.size() != rx.size() || tx.empty()) {
    last_error_ = EINVAL;
    return false;
  }
  spi_ioc_transfer segment{};
  segment.tx_buf = reinterpret_cast<uintptr_t>(tx.data());
  segment.rx_buf = reinterpret_cast<uintptr_t>(rx.data());
  segment.len = static_cast<uint32_t>(tx.size());
  segment.speed_hz = options_.speed_hz;
  segment.bits_per_word = options_.bits_per_word;
  if (ioctl(fd_, SPI_IOC_MESSAGE(1), &segment) < 0) {
    last_error_ = errno;
    return false;
  }
  return true;
}

}  // namespace rover::drivers
