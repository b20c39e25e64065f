#include "drivers/gpio/libgpiod_chip.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

// The machine running the tests has no GPIO chip (Debian's kernel ships no
// gpio-sim or gpio-mockup); the errors a user meets first must be clear.
// Edges and pulses on real lines are checked with rover-gpio-loopback.

std::string OpenError(const std::string& chip) {
  try {
    LibgpiodChip opened(chip);
  } catch (const GpioError& e) {
    return e.what();
  }
  return "";
}

TEST(LibgpiodChipTest, AMissingChipPathIsNamedWithTheSystemError) {
  const std::string message = OpenError("/dev/gpiochip99");
  EXPECT_THAT(message, HasSubstr("'/dev/gpiochip99'"));
  EXPECT_THAT(message, HasSubstr("expected a GPIO character device"));
  EXPECT_THAT(message, HasSubstr(std::strerror(ENOENT)));
}

TEST(LibgpiodChipTest, MissingChipNamesAndLabelsAreNamed) {
  EXPECT_THAT(OpenError("gpiochip99"), HasSubstr("'gpiochip99' (by device name)"));
  EXPECT_THAT(OpenError("no-such-gpio-label"), HasSubstr("'no-such-gpio-label' (by label)"));
  EXPECT_THAT(OpenError(""), HasSubstr("cannot open"));
}

TEST(LibgpiodChipTest, ANonGpioDeviceIsRefused) {
  const std::string message = OpenError("/dev/null");
  EXPECT_THAT(message, HasSubstr("'/dev/null'"));
  EXPECT_THAT(message, HasSubstr("cannot open"));
}

TEST(LibgpiodChipTest, EventStampsAreMonotonicFromLinux57) {
  EXPECT_FALSE(LibgpiodChip::KernelStampsAreMonotonic("4.19.0-26-amd64"));
  EXPECT_FALSE(LibgpiodChip::KernelStampsAreMonotonic("5.6.19"));
  EXPECT_TRUE(LibgpiodChip::KernelStampsAreMonotonic("5.7.0"));
  EXPECT_TRUE(LibgpiodChip::KernelStampsAreMonotonic("5.10.0-28-arm64"));
  EXPECT_TRUE(LibgpiodChip::KernelStampsAreMonotonic("6.1.0-18-amd64"));
  EXPECT_FALSE(LibgpiodChip::KernelStampsAreMonotonic("garbage"));
  EXPECT_FALSE(LibgpiodChip::KernelStampsAreMonotonic(""));
}

}  // namespace
}  // namespace rover::drivers
