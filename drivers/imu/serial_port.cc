#include "drivers/imu/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "drivers/imu/imu_device_error.h"

namespace rover::drivers {
namespace {

// termios speed constants for the rates a UART or USB adapter may run at.
bool BaudConstant(int baud_rate, speed_t* speed) {
  switch (baud_rate) {
    case 9600:
      *speed = B9600;
      return true;
    case 19200:
      *speed = B19200;
      return true;
    case 38400:
      *speed = B38400;
      return true;
    case 57600:
      *speed = B57600;
      return true;
    case 115200:
      *speed = B115200;
      return true;
    case 230400:
      *speed = B230400;
      return true;
    case 460800:
      *speed = B460800;
      return true;
    case 921600:
      *speed = B921600;
      return true;
    case 1000000:
      *speed = B1000000;
      return true;
    case 2000000:
      *speed = B2000000;
      return true;
    case 4000000:
      *speed = B4000000;
      return true;
    default:
      return false;
  }
}

std::string SystemError(const std::string& path, const std::string& step) {
  return "serial port " + path + ": " + step + ": " + std::strerror(errno);
}

}  // namespace

void SerialPortOptions::Validate() const {
  if (path.empty()) throw std::invalid_argument("SerialPortOptions: path must not be empty");
  speed_t speed{};
  if (!BaudConstant(baud_rate, &speed)) {
    throw std::invalid_argument(
        "SerialPortOptions: baud_rate must be one of 9600, 19200, 38400, 57600, 115200, 230400, "
        "460800, 921600, 1000000, 2000000, 4000000; found " +
        std::to_string(baud_rate));
  }
}

SerialPort::SerialPort(const SerialPortOptions& options)
    : path_(options.path), baud_rate_(options.baud_rate) {
  options.Validate();
  fd_ = open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw ImuDeviceError(SystemError(path_, "cannot open"));
  try {
    termios tio{};
    if (tcgetattr(fd_, &tio) != 0) {
      throw ImuDeviceError(SystemError(path_, "tcgetattr failed (expected a terminal device)"));
    }
    cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB);
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    speed_t speed{};
    BaudConstant(baud_rate_, &speed);
    if (cfsetispeed(&tio, speed) != 0 || cfsetospeed(&tio, speed) != 0) {
      throw ImuDeviceError(
          SystemError(path_, "cannot set baud rate " + std::to_string(baud_rate_)));
    }
    if (tcsetattr(fd_, TCSANOW, &tio) != 0) {
      throw ImuDeviceError(SystemError(path_, "tcsetattr (raw mode) failed"));
    }
    // Exclusive use is a safeguard, not a requirement: ignore a refusal.
    (void)ioctl(fd_, TIOCEXCL);
    tcflush(fd_, TCIOFLUSH);
  } catch (...) {
    close(fd_);
    fd_ = -1;
    throw;
  }
}

SerialPort::~SerialPort() {
  if (fd_ >= 0) close(fd_);
}

bool SerialPort::WriteAll(std::span<const uint8_t> bytes, Duration timeout) {
  const Time deadline = Time::Now() + timeout;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
    const Duration left = deadline - Time::Now();
    if (left <= Duration::Zero()) {
      errno = ETIMEDOUT;
      return false;
    }
    pollfd p{fd_, POLLOUT, 0};
    const int64_t ms = left.nanoseconds() / 1'000'000 + 1;
    if (poll(&p, 1, static_cast<int>(ms)) < 0 && errno != EINTR) return false;
  }
  return true;
}

void SerialPort::DiscardInput() { tcflush(fd_, TCIFLUSH); }

}  // namespace rover::drivers
