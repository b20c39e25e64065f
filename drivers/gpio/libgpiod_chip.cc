#include "drivers/gpio/libgpiod_chip.h"

#include <gpiod.h>
#include <poll.h>
#include <sys/utsname.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <utility>

#include "core/time/posix_time.h"

namespace rover::drivers {

struct LibgpiodChip::Impl {
  gpiod_chip* chip = nullptr;
  std::string name;
  uint32_t num_lines = 0;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (chip != nullptr) gpiod_chip_close(chip);
  }
};

namespace {

std::string SystemError(int error) { return std::strerror(error); }

std::string LineName(const std::string& chip, uint32_t line) {
  return "GPIO " + chip + " line " + std::to_string(line);
}

// Looks up the line and checks the offset before anything is requested, so
// an out-of-range offset gets its own message rather than a bare EINVAL.
gpiod_line* GetLine(const LibgpiodChip::Impl& impl, const GpioLineRequest& request) {
  if (request.line >= impl.num_lines) {
    throw GpioError(LineName(impl.name, request.line) + ": expected a line offset below " +
                    std::to_string(impl.num_lines) + " (the chip's line count), found " +
                    std::to_string(request.line));
  }
  gpiod_line* line = gpiod_chip_get_line(impl.chip, request.line);
  if (line == nullptr) {
    throw GpioError(LineName(impl.name, request.line) +
                    ": cannot read the line's info: " + SystemError(errno));
  }
  return line;
}

[[noreturn]] void ThrowRequestFailed(const LibgpiodChip::Impl& impl, const GpioLineRequest& request,
                                     gpiod_line* line, const char* what, int error) {
  std::string message = LineName(impl.name, request.line) + ": cannot request " + what +
                        " for consumer '" + request.consumer + "'";
  if (error == EBUSY && gpiod_line_update(line) == 0 && gpiod_line_is_used(line)) {
    const char* holder = gpiod_line_consumer(line);
    message += " (expected a free line; it is held by '" +
               std::string(holder != nullptr ? holder : "the kernel") + "')";
  }
  throw GpioError(message + ": " + SystemError(error));
}

int RequestFlags(const GpioLineRequest& request) {
  return request.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
}

void CheckConsumer(const std::string& chip, const GpioLineRequest& request) {
  // The kernel truncates labels silently; a truncated name in gpioinfo is
  // confusing, so refuse it here where the caller can still fix it.
  if (request.consumer.empty() || request.consumer.size() > 31) {
    throw GpioError(LineName(chip, request.line) +
                    ": consumer: expected 1 to 31 characters, found '" + request.consumer + "'");
  }
}

class LibgpiodOutputLine final : public GpioOutputLine {
 public:
  LibgpiodOutputLine(std::shared_ptr<LibgpiodChip::Impl> chip, gpiod_line* line, uint32_t offset)
      : chip_(std::move(chip)), line_(line), offset_(offset) {}
  ~LibgpiodOutputLine() override { gpiod_line_release(line_); }
  LibgpiodOutputLine(const LibgpiodOutputLine&) = delete;
  LibgpiodOutputLine& operator=(const LibgpiodOutputLine&) = delete;

  // One GPIOHANDLE_SET_LINE_VALUES ioctl; libgpiod builds its request on
  // the stack.
  bool Set(bool active) override { return gpiod_line_set_value(line_, active ? 1 : 0) == 0; }
  uint32_t line() const override { return offset_; }

 private:
  std::shared_ptr<LibgpiodChip::Impl> chip_;  // keeps the chip open
  gpiod_line* line_;
  uint32_t offset_;
};

class LibgpiodEventLine final : public GpioEventLine {
 public:
  LibgpiodEventLine(std::shared_ptr<LibgpiodChip::Impl> chip, gpiod_line* line, uint32_t offset,
                    int fd)
      : chip_(std::move(chip)), line_(line), offset_(offset), fd_(fd) {}
  ~LibgpiodEventLine() override { gpiod_line_release(line_); }
  LibgpiodEventLine(const LibgpiodEventLine&) = delete;
  LibgpiodEventLine& operator=(const LibgpiodEventLine&) = delete;

  ReadStatus Read(GpioEdge* edge, Duration timeout) override {
    // ppoll rather than gpiod_line_event_wait: same syscall, but the fd is
    // cached, so nothing is looked up on the real-time path.
    const timespec wait = ToTimespec(timeout);
    pollfd p{fd_, POLLIN | POLLPRI, 0};
    const int ready = ppoll(&p, 1, &wait, nullptr);
    if (ready == 0) return ReadStatus::kTimeout;
    if (ready < 0) return errno == EINTR ? ReadStatus::kTimeout : ReadStatus::kError;
    if ((p.revents & (POLLIN | POLLPRI)) == 0) return ReadStatus::kError;
    // Reads one struct gpioevent_data into a stack buffer and converts it.
    gpiod_line_event event{};
    if (gpiod_line_event_read_fd(fd_, &event) != 0) return ReadStatus::kError;
    edge->stamp = Time::FromNanoseconds(static_cast<int64_t>(event.ts.tv_sec) * 1'000'000'000 +
                                        static_cast<int64_t>(event.ts.tv_nsec));
    edge->line = offset_;
    edge->rising = event.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
    return ReadStatus::kOk;
  }
  uint32_t line() const override { return offset_; }

 private:
  std::shared_ptr<LibgpiodChip::Impl> chip_;  // keeps the chip open
  gpiod_line* line_;
  uint32_t offset_;
  int fd_;
};

// Parses the leading "major.minor" of a release string; false if absent.
bool ParseRelease(const std::string& release, int* major, int* minor) {
  const char* begin = release.data();
  const char* end = begin + release.size();
  auto [p, ec] = std::from_chars(begin, end, *major);
  if (ec != std::errc() || p == end || *p != '.') return false;
  auto [q, ec2] = std::from_chars(p + 1, end, *minor);
  (void)q;
  return ec2 == std::errc();
}

std::string KernelRelease() {
  utsname u{};
  if (uname(&u) != 0) return "";
  return u.release;
}

bool IsDeviceName(const std::string& chip) {
  if (chip.rfind("gpiochip", 0) != 0 || chip.size() == 8) return false;
  for (std::size_t i = 8; i < chip.size(); ++i) {
    if (chip[i] < '0' || chip[i] > '9') return false;
  }
  return true;
}

}  // namespace

bool LibgpiodChip::KernelStampsAreMonotonic(const std::string& release) {
  int major = 0;
  int minor = 0;
  if (!ParseRelease(release, &major, &minor)) return false;
  return major > 5 || (major == 5 && minor >= 7);
}

LibgpiodChip::LibgpiodChip(const std::string& chip) : impl_(std::make_shared<Impl>()) {
  const char* how = "label";
  if (!chip.empty() && chip.front() == '/') {
    how = "path";
    impl_->chip = gpiod_chip_open(chip.c_str());
  } else if (IsDeviceName(chip)) {
    how = "device name";
    impl_->chip = gpiod_chip_open_by_name(chip.c_str());
  } else if (!chip.empty()) {
    impl_->chip = gpiod_chip_open_by_label(chip.c_str());
  } else {
    errno = EINVAL;
  }
  if (impl_->chip == nullptr) {
    const int error = errno;
    throw GpioError("GPIO chip '" + chip + "' (by " + how +
                    "): cannot open it; expected a GPIO character device given as a path "
                    "(/dev/gpiochip0), a name (gpiochip0) or a label listed by gpiodetect: " +
                    SystemError(error));
  }
  const char* name = gpiod_chip_name(impl_->chip);
  const char* label = gpiod_chip_label(impl_->chip);
  impl_->name =
      std::string(name != nullptr ? name : chip) + " [" + (label != nullptr ? label : "") + "]";
  impl_->num_lines = gpiod_chip_num_lines(impl_->chip);
}

LibgpiodChip::~LibgpiodChip() = default;

std::unique_ptr<GpioOutputLine> LibgpiodChip::RequestOutput(const GpioLineRequest& request,
                                                            bool initial_active) {
  CheckConsumer(impl_->name, request);
  gpiod_line* line = GetLine(*impl_, request);
  if (gpiod_line_request_output_flags(line, request.consumer.c_str(), RequestFlags(request),
                                      initial_active ? 1 : 0) != 0) {
    ThrowRequestFailed(*impl_, request, line, "it as an output", errno);
  }
  return std::make_unique<LibgpiodOutputLine>(impl_, line, request.line);
}

std::unique_ptr<GpioEventLine> LibgpiodChip::RequestEdges(const GpioLineRequest& request,
                                                          GpioEdges edges) {
  CheckConsumer(impl_->name, request);
  const std::string release = KernelRelease();
  if (!KernelStampsAreMonotonic(release)) {
    throw GpioError(LineName(impl_->name, request.line) +
                    ": expected Linux >= 5.7, whose GPIO event stamps are CLOCK_MONOTONIC; "
                    "found kernel '" +
                    release + "', which stamps them on CLOCK_REALTIME");
  }
  gpiod_line* line = GetLine(*impl_, request);
  const int flags = RequestFlags(request);
  int result = 0;
  switch (edges) {
    case GpioEdges::kRising:
      result = gpiod_line_request_rising_edge_events_flags(line, request.consumer.c_str(), flags);
      break;
    case GpioEdges::kFalling:
      result = gpiod_line_request_falling_edge_events_flags(line, request.consumer.c_str(), flags);
      break;
    case GpioEdges::kBoth:
      result = gpiod_line_request_both_edges_events_flags(line, request.consumer.c_str(), flags);
      break;
  }
  if (result != 0) {
    ThrowRequestFailed(*impl_, request, line, "edge events (is the line interrupt-capable?)",
                       errno);
  }
  const int fd = gpiod_line_event_get_fd(line);
  if (fd < 0) {
    const int error = errno;
    gpiod_line_release(line);
    throw GpioError(LineName(impl_->name, request.line) +
                    ": expected an event file descriptor after the request: " + SystemError(error));
  }
  return std::make_unique<LibgpiodEventLine>(impl_, line, request.line, fd);
}

const std::string& LibgpiodChip::name() const { return impl_->name; }

uint32_t LibgpiodChip::num_lines() const { return impl_->num_lines; }

}  // namespace rover::drivers
