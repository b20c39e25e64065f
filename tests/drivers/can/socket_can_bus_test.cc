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
  EXPECT_THROW(SocketCanBus("an-interface-name-far-too-long"), CanError);
  EXPECT_THROW(SocketCanBus(""), CanError);
}

}  // namespace
}  // namespace rover::drivers
