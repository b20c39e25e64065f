#include "drivers/imu/serial_port.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/imu/imu_device_error.h"

namespace rover::drivers {
namespace {

// The master side of a fresh pty pair; the slave is what SerialPort opens.
class PtyMaster {
 public:
  PtyMaster() {
    fd_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    char name[128];
    if (fd_ >= 0 && grantpt(fd_) == 0 && unlockpt(fd_) == 0 &&
        ptsname_r(fd_, name, sizeof name) == 0) {
      slave_ = name;
    }
  }
  ~PtyMaster() {
    if (fd_ >= 0) close(fd_);
  }
  int fd() const { return fd_; }
  const std::string& slave() const { return slave_; }

 private:
  int fd_ = -1;
  std::string slave_;
};

std::vector<uint8_t> ReadAvailable(int fd, std::size_t want) {
  std::vector<uint8_t> got;
  for (int i = 0; i < 200 && got.size() < want; ++i) {  // up to 2 s
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 10) <= 0) continue;
    uint8_t buffer[256];
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n > 0) got.insert(got.end(), buffer, buffer + n);
  }
  return got;
}

// Bytes a cooked terminal would eat or change: CR, LF, XON/XOFF, ^C, ^D,
// DEL, 0xFF. A raw port passes them unchanged both ways, and echoes nothing.
TEST(SerialPortTest, IsRawOnAPty) {
  PtyMaster master;
  ASSERT_FALSE(master.slave().empty());
  SerialPortOptions options;
  options.path = master.slave();
  SerialPort port(options);
  const std::vector<uint8_t> bytes = {0x0D, 0x0A, 0x11, 0x13, 0x03, 0x04, 0x7F,
                                      0xFF, 0xFA, 0x00, 0x1A, 0x0D, 0x0D, 0x0A};
  ASSERT_EQ(write(master.fd(), bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  EXPECT_EQ(ReadAvailable(port.fd(), bytes.size()), bytes);

  ASSERT_TRUE(port.WriteAll(bytes, Duration::Seconds(1)));
  EXPECT_EQ(ReadAvailable(master.fd(), bytes.size()), bytes);
  // Nothing came back to the master as echo of what it wrote first.
  pollfd p{master.fd(), POLLIN, 0};
  EXPECT_EQ(poll(&p, 1, 50), 0);
}

TEST(SerialPortTest, NamesThePathAndTheSystemError) {
  SerialPortOptions options;
  options.path = "/dev/does-not-exist-imu";
  try {
    SerialPort port(options);
    FAIL() << "expected ImuDeviceError";
  } catch (const ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/does-not-exist-imu"), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  options.path = "/dev/null";  // opens, but is not a terminal
  try {
    SerialPort port(options);
    FAIL() << "expected ImuDeviceError";
  } catch (const ImuDeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/null"), std::string::npos) << what;
    EXPECT_NE(what.find("terminal"), std::string::npos) << what;
  }
}

TEST(SerialPortTest, RejectsUnknownBaudRates) {
  SerialPortOptions options;
  options.baud_rate = 12345;
  try {
    options.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("baud_rate"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("12345"), std::string::npos);
  }
}

}  // namespace
}  // namespace rover::drivers
