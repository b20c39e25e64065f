#ifndef ROVER_DRIVERS_IMU_SERIAL_PORT_H_
#define ROVER_DRIVERS_IMU_SERIAL_PORT_H_

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/time/time.h"

namespace rover::drivers {

struct SerialPortOptions {
  std::string path = "/dev/ttyUSB0";  ///< a TTY: UART, USB serial adapter, or pty slave
  int baud_rate = 921600;             ///< one of the POSIX/Linux rates, 9600 to 4000000

  /// Throws std::invalid_argument naming the field if the path is empty or
  /// the baud rate is not one termios knows.
  void Validate() const;
};

/// A serial port in raw mode: opened O_RDWR | O_NOCTTY | O_NONBLOCK, termios
/// set by cfmakeraw (8N1, no echo, no line editing, no CR/LF translation, no
/// software flow control), no hardware flow control, the receiver enabled,
/// modem lines ignored (CLOCAL), and VMIN = VTIME = 0 so reads never block:
/// callers wait with poll(). TIOCEXCL keeps other processes from opening it
/// as well. Works on a pseudo-terminal slave, where the baud rate is
/// accepted and ignored.
class SerialPort {
 public:
  /// Opens and configures the port; discards anything already received.
  /// Throws ImuDeviceError naming the path, the step (open, tcgetattr: "not
  /// a terminal", cfsetspeed, tcsetattr) and strerror(errno); and
  /// std::invalid_argument for invalid options.
  explicit SerialPort(const SerialPortOptions& options);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Writes all of `bytes`, waiting (poll) while the output queue is full,
  /// for at most `timeout` in total. Returns false on timeout or a write
  /// error (errno set). Start-up use: it may block for up to `timeout`.
  bool WriteAll(std::span<const uint8_t> bytes, Duration timeout);
  /// Discards received bytes not read yet (tcflush TCIFLUSH).
  void DiscardInput();

  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  int baud_rate() const { return baud_rate_; }

 private:
  std::string path_;
  int baud_rate_;
  int fd_ = -1;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_SERIAL_PORT_H_
