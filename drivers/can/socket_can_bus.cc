#include "drivers/can/socket_can_bus.h"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rover::drivers {
namespace {

std::string SystemError(const std::string& what, const std::string& interface) {
  return "SocketCAN " + interface + ": " + what + ": " + std::strerror(errno);
}

}  // namespace

SocketCanBus::SocketCanBus(const std::string& interface) : interface_(interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    throw CanError("SocketCAN: interface name '" + interface + "' must have 1 to " +
                   std::to_string(IFNAMSIZ - 1) + " characters");
  }
  const unsigned index = if_nametoindex(interface.c_str());
  if (index == 0) throw CanError(SystemError("no such interface", interface));
  fd_ = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) throw CanError(SystemError("cannot open a raw CAN socket", interface));
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const std::string message = SystemError("cannot bind", interface);
    close(fd_);
    throw CanError(message);
  }
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) close(fd_);
}

ReadStatus SocketCanBus::Receive(CanFrame* frame, Duration timeout) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = poll(&p, 1, static_cast<int>(timeout.nanoseconds() / 1'000'000));
  if (ready == 0) return ReadStatus::kTimeout;
  if (ready < 0) return errno == EINTR ? ReadStatus::kTimeout : ReadStatus::kError;
  can_frame raw{};
  if (read(fd_, &raw, sizeof raw) != static_cast<ssize_t>(sizeof raw)) return ReadStatus::kError;
  frame->stamp = Time::Now();
  frame->id = raw.can_id & CAN_SFF_MASK;
  frame->dlc = raw.can_dlc;
  std::memcpy(frame->data.data(), raw.data, sizeof raw.data);
  return ReadStatus::kOk;
}

bool SocketCanBus::Send(const CanFrame& frame) {
  can_frame raw{};
  raw.can_id = frame.id & CAN_SFF_MASK;
  raw.can_dlc = frame.dlc > 8 ? 8 : frame.dlc;
  std::memcpy(raw.data, frame.data.data(), sizeof raw.data);
  if (write(fd_, &raw, sizeof raw) != static_cast<ssize_t>(sizeof raw)) {
    ++send_failures_;
    return false;
  }
  return true;
}

}  // namespace rover::drivers
