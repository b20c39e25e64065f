#include "drivers/can/socket_can_bus.h"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/time/posix_time.h"

namespace rover::drivers {
namespace {

void Add(std::atomic<uint64_t>& counter, uint64_t n = 1) {
  counter.fetch_add(n, std::memory_order_relaxed);
}

bool InterfaceGone(int error) { return error == ENETDOWN || error == ENODEV || error == ENXIO; }

}  // namespace

std::vector<CanFilter> SocketCanOptions::WheelDriveFilters() {
  // 0x080 exactly; 0x180..0x187 and 0x700..0x707 with the node bits masked
  // out (nodes 5..7 pass the kernel and are ignored by the decoder).
  return {CanFilter{0x080, 0x7FF, false}, CanFilter{0x180, 0x7F8, false},
          CanFilter{0x700, 0x7F8, false}};
}

void SocketCanOptions::Validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("SocketCanOptions: " + what);
  };
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    fail("interface: expected a name of 1 to " + std::to_string(IFNAMSIZ - 1) +
         " characters, found '" + interface + "'");
  }
  for (std::size_t i = 0; i < filters.size(); ++i) {
    if (filters[i].id > CAN_SFF_MASK || filters[i].mask > CAN_SFF_MASK) {
      fail("filters[" + std::to_string(i) + "]: expected an 11-bit id and mask, found id 0x" +
           std::to_string(filters[i].id) + " mask 0x" + std::to_string(filters[i].mask));
    }
  }
  if (receive_buffer_bytes < 0) {
    fail("receive_buffer_bytes: expected >= 0, found " + std::to_string(receive_buffer_bytes));
  }
  if (reopen_backoff_initial <= Duration::Zero() || reopen_backoff_max < reopen_backoff_initial) {
    fail("reopen backoff: expected 0 < initial <= max, found initial " +
         reopen_backoff_initial.ToString() + ", max " + reopen_backoff_max.ToString());
  }
}

const char* ToString(CanBusHealth health) {
  switch (health) {
    case CanBusHealth::kActive:
      return "active";
    case CanBusHealth::kErrorWarning:
      return "error-warning";
    case CanBusHealth::kErrorPassive:
      return "error-passive";
    case CanBusHealth::kBusOff:
      return "bus-off";
    case CanBusHealth::kDown:
      return "down";
  }
  return "unknown";
}

SocketCanBus::SocketCanBus(const std::string& interface)
    : SocketCanBus([&] {
        SocketCanOptions o;
        o.interface = interface;
        return o;
      }()) {}

SocketCanBus::SocketCanBus(const SocketCanOptions& options)
    : options_(options), backoff_(options.reopen_backoff_initial) {
  options_.Validate();
  kernel_filters_.resize(options_.filters.size() * sizeof(can_filter));
  for (std::size_t i = 0; i < options_.filters.size(); ++i) {
    const CanFilter& f = options_.filters[i];
    can_filter k{};
    // CAN_EFF_FLAG | CAN_RTR_FLAG in the mask: only 11-bit data frames match.
    k.can_id = f.id | (f.inverted ? CAN_INV_FILTER : 0u);
    k.can_mask = f.mask | CAN_EFF_FLAG | CAN_RTR_FLAG;
    std::memcpy(kernel_filters_.data() + i * sizeof k, &k, sizeof k);
  }
  // Checked first: "no such interface" is the error a user meets most, and
  // it holds even where the kernel has no CAN support at all.
  if (if_nametoindex(options_.interface.c_str()) == 0) {
    throw CanError("SocketCAN " + options_.interface + ": no such interface (" +
                   std::strerror(errno) + "); `ip link` lists the interfaces");
  }
  const char* step = "";
  fd_ = OpenSocket(&step);
  if (fd_ < 0) {
    const std::string reason = errno == ENODEV ? "no such interface" : std::strerror(errno);
    throw CanError("SocketCAN " + options_.interface + ": " + step + ": " + reason);
  }
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) close(fd_);
}

int SocketCanBus::OpenSocket(const char** step) const {
  const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC | SOCK_NONBLOCK, CAN_RAW);
  if (fd < 0) {
    *step = "cannot open a raw CAN socket (is the can-raw module loaded?)";
    return -1;
  }
  auto fail = [fd, step](const char* what) {
    const int error = errno;
    close(fd);
    errno = error;
    *step = what;
    return -1;
  };
  ifreq request{};
  std::memcpy(request.ifr_name, options_.interface.c_str(), options_.interface.size() + 1);
  if (ioctl(fd, SIOCGIFINDEX, &request) != 0) return fail("cannot find the interface");
  const int on = 1;
  // A filter list of length zero makes the kernel deliver no data frames,
  // so "no filters" must leave the default (everything) in place.
  if (!kernel_filters_.empty() &&
      setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters_.data(),
                 static_cast<socklen_t>(kernel_filters_.size())) != 0) {
    return fail("cannot set the receive filters (CAN_RAW_FILTER)");
  }
  const can_err_mask_t error_mask = options_.error_frames ? CAN_ERR_MASK : 0u;
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask) != 0) {
    return fail("cannot set the error-frame mask (CAN_RAW_ERR_FILTER)");
  }
  if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) {
    return fail("cannot enable kernel receive timestamps (SO_TIMESTAMPNS)");
  }
  if (setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) {
    return fail("cannot enable the drop counter (SO_RXQ_OVFL)");
  }
  // SO_RCVBUF alone is capped at rmem_max without a word; FORCE is not,
  // but needs CAP_NET_ADMIN, which a board's roverd usually has.
  if (options_.receive_buffer_bytes > 0 &&
      setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &options_.receive_buffer_bytes,
                 sizeof options_.receive_buffer_bytes) != 0 &&
      setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &options_.receive_buffer_bytes,
                 sizeof options_.receive_buffer_bytes) != 0) {
    return fail("cannot set the receive buffer size (SO_RCVBUF)");
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    return fail("cannot bind");
  }
  return fd;
}

void SocketCanBus::Start() {
  if (fd_ >= 0) close(fd_);
  const char* step = "";
  fd_ = OpenSocket(&step);
  last_drop_count_ = 0;
  if (fd_ < 0) MarkDown();
}

int SocketCanBus::receive_buffer_bytes() const {
  if (fd_ < 0) return 0;
  int bytes = 0;
  socklen_t length = sizeof bytes;
  if (getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, &length) != 0) return 0;
  return bytes;
}

void SocketCanBus::MarkDown() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  health_.store(CanBusHealth::kDown, std::memory_order_relaxed);
  backoff_ = options_.reopen_backoff_initial;
  next_reopen_ = Time::Now() + backoff_;
}

bool SocketCanBus::WaitAndReopen(Time deadline) {
  SleepUntil(std::min(deadline, next_reopen_));
  if (Time::Now() < next_reopen_) return false;
  const char* step = "";
  const int fd = OpenSocket(&step);
  if (fd < 0) {
    backoff_ = std::min(backoff_ * 2, options_.reopen_backoff_max);
    next_reopen_ = Time::Now() + backoff_;
    return false;
  }
  // An interface that is present but down accepts the bind; it is only up
  // when flagged so (otherwise reads would fail with ENETDOWN again).
  ifreq request{};
  std::memcpy(request.ifr_name, options_.interface.c_str(), options_.interface.size() + 1);
  if (ioctl(fd, SIOCGIFFLAGS, &request) != 0 || (request.ifr_flags & IFF_UP) == 0) {
    close(fd);
    backoff_ = std::min(backoff_ * 2, options_.reopen_backoff_max);
    next_reopen_ = Time::Now() + backoff_;
    return false;
  }
  fd_ = fd;
  last_drop_count_ = 0;
  Add(reopens_);
  health_.store(CanBusHealth::kActive, std::memory_order_relaxed);
  return true;
}

ReadStatus SocketCanBus::Receive(CanFrame* frame, Duration timeout) {
  const Time deadline = Time::Now() + timeout;
  for (;;) {
    if (fd_ < 0 && !WaitAndReopen(deadline)) {
      if (Time::Now() >= deadline) {
        Add(read_errors_);
        return ReadStatus::kError;
      }
      continue;
    }
    bool data_frame = false;
    const ReadStatus status = ReceiveOne(frame, &data_frame);
    if (status == ReadStatus::kOk && data_frame) return ReadStatus::kOk;
    if (status == ReadStatus::kError) {
      Add(read_errors_);
      return ReadStatus::kError;
    }
    if (status == ReadStatus::kOk) continue;  // an error frame or ignored frame: keep reading
    const Duration left = deadline - Time::Now();
    if (left <= Duration::Zero()) {
      Add(timeouts_);
      return ReadStatus::kTimeout;
    }
    pollfd p{fd_, POLLIN, 0};
    const timespec ts = ToTimespec(left);
    const int ready = ppoll(&p, 1, &ts, nullptr);
    if (ready < 0 && errno != EINTR) {
      Add(read_errors_);
      return ReadStatus::kError;
    }
    // POLLERR (interface down) is read out by the next recvmsg.
  }
}

ReadStatus SocketCanBus::ReceiveOne(CanFrame* frame, bool* data_frame) {
  can_frame raw{};
  iovec io{&raw, sizeof raw};
  msghdr message{};
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control_;
  message.msg_controllen = sizeof control_;
  const ssize_t n = recvmsg(fd_, &message, MSG_DONTWAIT);
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return ReadStatus::kTimeout;  // EWOULDBLOCK == EAGAIN
    if (InterfaceGone(errno)) {
      MarkDown();
      return ReadStatus::kError;
    }
    return ReadStatus::kError;
  }
  // The kernel stamps frames on CLOCK_REALTIME (SO_TIMESTAMPNS).
  int64_t stamp_ns = Time::Now().nanoseconds();
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      stamp_ns =
          to_monotonic_.ToMonotonic(int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec).nanoseconds();
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      uint32_t drops = 0;
      std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      // The count is cumulative per socket (uint32, wrapping).
      Add(kernel_drops_, static_cast<uint32_t>(drops - last_drop_count_));
      last_drop_count_ = drops;
    }
  }
  if (n != static_cast<ssize_t>(sizeof raw)) return ReadStatus::kError;
  if ((raw.can_id & CAN_ERR_FLAG) != 0) {
    HandleErrorFrame(raw.can_id, raw.data);
    return ReadStatus::kOk;
  }
  if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0) {
    Add(ignored_);
    return ReadStatus::kOk;
  }
  // A controller that delivers data is on the bus again, even if its
  // restart notice was lost.
  CanBusHealth expected = CanBusHealth::kBusOff;
  if (health_.compare_exchange_strong(expected, CanBusHealth::kActive, std::memory_order_relaxed)) {
    Add(restarts_);
  }
  // Frames of one socket are stamped in queue order; a refreshed offset
  // must not make a stamp go back.
  stamp_ns = std::max(stamp_ns, last_stamp_ns_);
  last_stamp_ns_ = stamp_ns;
  frame->stamp = Time::FromNanoseconds(stamp_ns);
  frame->id = raw.can_id & CAN_SFF_MASK;
  frame->dlc = std::min<uint8_t>(raw.len, 8);
  std::memcpy(frame->data.data(), raw.data, sizeof raw.data);
  Add(frames_);
  *data_frame = true;
  return ReadStatus::kOk;
}

void SocketCanBus::HandleErrorFrame(uint32_t can_id, const uint8_t* data) {
  Add(error_frames_);
  const uint32_t error_class = can_id & CAN_ERR_MASK;
  if ((error_class & (CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_BUSERROR | CAN_ERR_TX_TIMEOUT |
                      CAN_ERR_LOSTARB | CAN_ERR_TRX)) != 0) {
    Add(protocol_errors_);
  }
  if ((error_class & CAN_ERR_CRTL) != 0) {
    Add(controller_problems_);
    const uint8_t status = data[1];
    if (health() != CanBusHealth::kBusOff) {
      if ((status & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
        health_.store(CanBusHealth::kErrorPassive, std::memory_order_relaxed);
      } else if ((status & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
        health_.store(CanBusHealth::kErrorWarning, std::memory_order_relaxed);
      } else if ((status & CAN_ERR_CRTL_ACTIVE) != 0) {
        health_.store(CanBusHealth::kActive, std::memory_order_relaxed);
      }
    }
  }
  if ((error_class & CAN_ERR_BUSOFF) != 0) {
    Add(bus_off_);
    health_.store(CanBusHealth::kBusOff, std::memory_order_relaxed);
  }
  if ((error_class & CAN_ERR_RESTARTED) != 0) {
    Add(restarts_);
    health_.store(CanBusHealth::kActive, std::memory_order_relaxed);
  }
}

bool SocketCanBus::Send(const CanFrame& frame) {
  if (fd_ < 0) {
    Add(send_failures_);
    return false;
  }
  can_frame raw{};
  raw.can_id = frame.id & CAN_SFF_MASK;
  raw.len = std::min<uint8_t>(frame.dlc, 8);
  std::memcpy(raw.data, frame.data.data(), sizeof raw.data);
  if (write(fd_, &raw, sizeof raw) != static_cast<ssize_t>(sizeof raw)) {
    // Not marked down here: Receive(), on the CAN thread, owns the socket's
    // life; Send() may come from another thread.
    Add(send_failures_);
    return false;
  }
  return true;
}

SocketCanStats SocketCanBus::stats() const {
  auto get = [](const std::atomic<uint64_t>& c) { return c.load(std::memory_order_relaxed); };
  SocketCanStats s;
  s.frames = get(frames_);
  s.error_frames = get(error_frames_);
  s.bus_off = get(bus_off_);
  s.restarts = get(restarts_);
  s.controller_problems = get(controller_problems_);
  s.protocol_errors = get(protocol_errors_);
  s.kernel_drops = get(kernel_drops_);
  s.ignored = get(ignored_);
  s.timeouts = get(timeouts_);
  s.read_errors = get(read_errors_);
  s.send_failures = get(send_failures_);
  s.reopens = get(reopens_);
  return s;
}

}  // namespace rover::drivers
