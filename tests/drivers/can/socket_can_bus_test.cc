#include "drivers/can/socket_can_bus.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

// Frames on a live bus are tested on the HIL bench (vcan in qemu); here the
// errors a user meets first must be clear.
TEST(SocketCanBusTest, MissingInterfaceIsAClearError) {
  try {
    SocketCanBus bus("rovercan9");
    FAIL() << "expected CanError";
  } catch (const CanError& e) {
    EXPECT_THAT(e.what(), HasSubstr("rovercan9"));
    EXPECT_THAT(e.what(), HasSubstr("no such interface"));
  }
}

TEST(SocketCanBusTest, OverlongNameIsRejectedBeforeTheKernelSeesIt) {
  EXPECT_THROW(SocketCanBus("an-interface-name-far-too-long"), std::invalid_argument);
  EXPECT_THROW(SocketCanBus(""), std::invalid_argument);
}

TEST(SocketCanBusTest, OptionsAreValidated) {
  SocketCanOptions o;
  o.interface = "can0";
  o.filters = {CanFilter{0x800, 0x7FF, false}};
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o.filters = SocketCanOptions::WheelDriveFilters();
  EXPECT_NO_THROW(o.Validate());
  o.reopen_backoff_max = Duration::Milliseconds(1);
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::drivers
