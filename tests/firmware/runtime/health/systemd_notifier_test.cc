// SystemdNotifier against a real AF_UNIX datagram socket standing in for
// systemd's notification socket: the test binds it, points NOTIFY_SOCKET at
// it and reads back exactly what libsystemd sent.

#include "firmware/runtime/health/systemd_notifier.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "tests/support/temp_dir.h"

namespace rover::runtime {
namespace {

class SystemdNotifierTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ClearEnvironment();
    socket_path_ = dir_.File("notify.sock").string();
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    ASSERT_LT(socket_path_.size(), sizeof(address.sun_path)) << socket_path_;
    std::memcpy(address.sun_path, socket_path_.c_str(), socket_path_.size() + 1);
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(fd_, 0) << std::strerror(errno);
    ASSERT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0)
        << std::strerror(errno);
  }

  void TearDown() override {
    ClearEnvironment();
    if (fd_ >= 0) ::close(fd_);
  }

  static void ClearEnvironment() {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
  }

  void PointNotifySocketAtTestSocket() const {
    ASSERT_EQ(::setenv("NOTIFY_SOCKET", socket_path_.c_str(), 1), 0);
  }

  // The next queued datagram, or nullopt if none is queued. sd_notify's
  // sendmsg() has queued its datagram by the time it returns, so there is
  // no need (and no reason) to wait.
  std::optional<std::string> Receive() const {
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (n < 0) return std::nullopt;
    return std::string(buffer, static_cast<std::size_t>(n));
  }

  testing::TempDir dir_{"notify"};
  std::string socket_path_;
  int fd_ = -1;
};

TEST_F(SystemdNotifierTest, SendsExactlyTheProtocolDatagrams) {
  PointNotifySocketAtTestSocket();
  const SystemdNotifier notifier = SystemdNotifier::FromEnvironment();
  ASSERT_TRUE(notifier.enabled());

  EXPECT_TRUE(notifier.Ready());
  EXPECT_EQ(Receive(), "READY=1");
  EXPECT_TRUE(notifier.Watchdog());
  EXPECT_EQ(Receive(), "WATCHDOG=1");
  EXPECT_TRUE(notifier.Status("imu ok 400.0 Hz, can STALE 1.2 s"));
  EXPECT_EQ(Receive(), "STATUS=imu ok 400.0 Hz, can STALE 1.2 s");
  EXPECT_TRUE(notifier.Stopping());
  EXPECT_EQ(Receive(), "STOPPING=1");
  EXPECT_EQ(Receive(), std::nullopt);  // Nothing else was sent.

  // The environment is left for child processes.
  const char* still_set = std::getenv("NOTIFY_SOCKET");
  ASSERT_NE(still_set, nullptr);
  EXPECT_EQ(std::string(still_set), socket_path_);
}

TEST_F(SystemdNotifierTest, StatusCannotSmuggleAnotherAssignment) {
  PointNotifySocketAtTestSocket();
  const SystemdNotifier notifier = SystemdNotifier::FromEnvironment();
  using std::string_literals::operator""s;
  EXPECT_TRUE(notifier.Status("imu WARN\nREADY=1\r\0x"s));
  EXPECT_EQ(Receive(), "STATUS=imu WARN READY=1  x");
  EXPECT_EQ(Receive(), std::nullopt);
}

TEST_F(SystemdNotifierTest, WatchdogIntervalComesFromWatchdogUsec) {
  PointNotifySocketAtTestSocket();
  ASSERT_EQ(::setenv("WATCHDOG_USEC", "3000000", 1), 0);
  ASSERT_EQ(::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1), 0);
  const SystemdNotifier notifier = SystemdNotifier::FromEnvironment();
  ASSERT_TRUE(notifier.watchdog_interval().has_value());
  EXPECT_EQ(*notifier.watchdog_interval(), Duration::Seconds(3));
  ASSERT_TRUE(notifier.watchdog_ping_period().has_value());
  EXPECT_EQ(*notifier.watchdog_ping_period(), Duration::Milliseconds(1500));
  // sd_watchdog_enabled() was asked to leave the variables in place.
  EXPECT_NE(std::getenv("WATCHDOG_USEC"), nullptr);
}

TEST_F(SystemdNotifierTest, WatchdogOfAnotherProcessIsNotOurs) {
  PointNotifySocketAtTestSocket();
  ASSERT_EQ(::setenv("WATCHDOG_USEC", "3000000", 1), 0);
  ASSERT_EQ(::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1), 0);
  const SystemdNotifier notifier = SystemdNotifier::FromEnvironment();
  EXPECT_TRUE(notifier.enabled());
  EXPECT_EQ(notifier.watchdog_interval(), std::nullopt);
  EXPECT_EQ(notifier.watchdog_ping_period(), std::nullopt);
}

TEST_F(SystemdNotifierTest, MalformedWatchdogUsecMeansNoWatchdog) {
  ASSERT_EQ(::setenv("WATCHDOG_USEC", "soon", 1), 0);
  EXPECT_EQ(SystemdNotifier::FromEnvironment().watchdog_interval(), std::nullopt);
}

TEST_F(SystemdNotifierTest, WithoutNotifySocketEverythingIsANoOp) {
  for (const SystemdNotifier& notifier : {SystemdNotifier::FromEnvironment(), SystemdNotifier()}) {
    EXPECT_FALSE(notifier.enabled());
    EXPECT_EQ(notifier.watchdog_interval(), std::nullopt);
    EXPECT_FALSE(notifier.Ready());
    EXPECT_FALSE(notifier.Watchdog());
    EXPECT_FALSE(notifier.Status("imu ok"));
    EXPECT_FALSE(notifier.Stopping());
  }
  EXPECT_EQ(Receive(), std::nullopt);
}

TEST_F(SystemdNotifierTest, NotifySocketSetLaterIsIgnoredUntilReadAgain) {
  // The environment is read once: a notifier made outside systemd stays off.
  const SystemdNotifier before = SystemdNotifier::FromEnvironment();
  PointNotifySocketAtTestSocket();
  EXPECT_FALSE(before.Ready());
  EXPECT_EQ(Receive(), std::nullopt);
  EXPECT_TRUE(SystemdNotifier::FromEnvironment().Ready());
  EXPECT_EQ(Receive(), "READY=1");
}

TEST_F(SystemdNotifierTest, UnreachableSocketReportsFailureWithoutThrowing) {
  const std::string missing = dir_.File("nobody_listens.sock").string();
  ASSERT_EQ(::setenv("NOTIFY_SOCKET", missing.c_str(), 1), 0);
  const SystemdNotifier notifier = SystemdNotifier::FromEnvironment();
  EXPECT_TRUE(notifier.enabled());
  EXPECT_FALSE(notifier.Ready());
  EXPECT_FALSE(notifier.Watchdog());
  EXPECT_FALSE(notifier.Status("imu ok"));
  EXPECT_EQ(Receive(), std::nullopt);
}

}  // namespace
}  // namespace rover::runtime
