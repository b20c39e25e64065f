#include "drivers/imu/spidev_device.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "drivers/imu/imu_device_error.h"

namespace rover::drivers {
namespace {

std::string OpenError(const std::string& path) {
  SpidevOptions options;
  options.path = path;
  try {
    SpidevDevice device(options);
  } catch (const ImuDeviceError& e) {
    return e.what();
  }
  return "";
}

TEST(SpidevDeviceTest, NamesThePathAndTheSystemError) {
  const std::string missing = OpenError("/dev/spidev-does-not-exist");
  EXPECT_NE(missing.find("/dev/spidev-does-not-exist"), std::string::npos) << missing;
  EXPECT_NE(missing.find("No such file or directory"), std::string::npos) << missing;
  // /dev/null opens but refuses the SPI ioctls.
  const std::string not_spi = OpenError("/dev/null");
  EXPECT_NE(not_spi.find("/dev/null"), std::string::npos) << not_spi;
  EXPECT_NE(not_spi.find("SPI_IOC_WR_MODE"), std::string::npos) << not_spi;
  EXPECT_NE(not_spi.find("Inappropriate ioctl"), std::string::npos) << not_spi;
}

TEST(SpidevDeviceTest, ValidatesItsOptions) {
  SpidevOptions options;
  options.Validate();  // the defaults: mode 3, 1 MHz, 8 bits
  options.mode = 4;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
  options.mode = 3;
  options.bits_per_word = 12;
  try {
    options.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bits_per_word"), std::string::npos);
  }
  options.bits_per_word = 8;
  options.speed_hz = 0;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::drivers
