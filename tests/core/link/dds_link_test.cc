#include "core/link/dds/dds_link.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/link/team_sync.h"

namespace rover::link {
namespace {

// A domain of this test process's own, so parallel test runs do not meet;
// fixed at the first call, so a forked child keeps its parent's.
uint32_t TestDomain() {
  static const uint32_t domain = 100 + static_cast<uint32_t>(getpid()) % 100;
  return domain;
}

DdsLinkOptions Loopback(RobotId self) {
  DdsLinkOptions o;
  o.self = self;
  o.domain_id = TestDomain();
  o.config_xml = MakeUnicastConfig("lo", {"127.0.0.1"});
  return o;
}

// Waits up to `timeout` for `done`, sleeping 10 ms between tries.
template <typename F>
bool WaitFor(F done, std::chrono::seconds timeout = std::chrono::seconds(20)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

std::vector<uint8_t> Payload(uint8_t tag, std::size_t n) {
  std::vector<uint8_t> b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<uint8_t>(tag + i * 7);
  return b;
}

TEST(DdsLinkTest, DatagramsReachTheAddressedRoverOnly) {
  DdsLink a(Loopback(1));
  DdsLink b(Loopback(2));
  DdsLink c(Loopback(3));
  ASSERT_TRUE(WaitFor([&] { return a.matched_readers() >= 2; }));
  ASSERT_TRUE(a.Send(2, Payload(5, 300)));
  ASSERT_TRUE(a.Send(kAllRobots, Payload(9, 40)));
  std::vector<Datagram> at_b, at_c;
  ASSERT_TRUE(WaitFor([&] {
    while (auto d = b.Receive()) at_b.push_back(*d);
    while (auto d = c.Receive()) at_c.push_back(*d);
    return at_b.size() >= 2 && !at_c.empty();
  }));
  EXPECT_EQ(at_b[0].from, 1u);
  EXPECT_EQ(at_b[0].bytes, Payload(5, 300));
  EXPECT_EQ(at_b[1].bytes, Payload(9, 40));
  ASSERT_EQ(at_c.size(), 1u);  // the broadcast, not the datagram for 2
  EXPECT_EQ(at_c[0].to, kAllRobots);
  EXPECT_FALSE(a.Receive().has_value());  // never its own
  EXPECT_FALSE(a.Send(1, Payload(1, 10)));
  EXPECT_FALSE(a.Send(2, Payload(1, kMaxDatagramBytes + 1)));
  EXPECT_EQ(a.stats().refused, 2u);
}

TEST(DdsLinkTest, BadOptionsAndConfigurationsSayWhatIsWrong) {
  DdsLinkOptions o = Loopback(1);
  o.domain_id = 300;
  EXPECT_THROW(DdsLink{o}, std::invalid_argument);
  o = Loopback(kAllRobots);
  EXPECT_THROW(DdsLink{o}, std::invalid_argument);
  o = Loopback(1);
  o.domain_id = 231 - 1;  // a domain no other test uses
  o.config_xml = "<CycloneDDS><Domain><General><NoSuchKey/></General></Domain></CycloneDDS>";
  try {
    DdsLink link(o);
    FAIL() << "a bad configuration was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dds_create_domain"), std::string::npos) << e.what();
  }
}

// Two processes, as on two boards: the team protocol over DDS on loopback.
// Each publishes 20 constraints and 3 submaps of 30 kB and must receive the
// other's. The child reports through its exit status.
int RunRover(RobotId self, RobotId other) {
  DdsLink link(Loopback(self));
  TeamSync sync(&link, TeamSyncOptions{});
  for (uint32_t i = 0; i < 20; ++i) sync.Publish(0, Payload(static_cast<uint8_t>(self + i), 200));
  for (uint32_t i = 0; i < 3; ++i) {
    sync.Publish(1, Payload(static_cast<uint8_t>(self * 3 + i), 30000));
  }
  const bool got = WaitFor(
      [&] {
        sync.Tick();
        return sync.ContiguousCount(other, 0) == 20 && sync.ContiguousCount(other, 1) == 3;
      },
      std::chrono::seconds(40));
  // Keep answering a while, so the other side gets what it still lacks.
  const auto linger = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (std::chrono::steady_clock::now() < linger) {
    sync.Tick();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!got) return 1;
  for (const TeamMessage& m : sync.TakeDelivered()) {
    const std::vector<uint8_t> expected =
        m.stream == 0 ? Payload(static_cast<uint8_t>(other + m.seq - 1), 200)
                      : Payload(static_cast<uint8_t>(other * 3 + m.seq - 1), 30000);
    if (m.bytes != expected) return 2;
  }
  return sync.stats().refused_datagrams == 0 ? 0 : 3;
}

TEST(DdsLinkTest, TwoProcessesExchangeEverythingThroughTheTeamProtocol) {
  TestDomain();
  const pid_t child = fork();  // before any DDS entity exists in this process
  ASSERT_GE(child, 0);
  if (child == 0) _exit(RunRover(2, 1));
  const int parent_result = RunRover(1, 2);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_EQ(parent_result, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
}  // namespace rover::link
