// Helper process for the IPC tests. Two modes:
//
//   core_ipc_test_peer echo <ping_topic> <pong_topic> <count> <timeout_ms>
//     Connects to the running RouDi, answers each Ping on <ping_topic> with a
//     Pong on <pong_topic> until <count> pings were answered. Exit 0 on
//     success, 1 on timeout or error. Started by the two-process test.
//
//   core_ipc_test_peer --expect-no-roudi
//     Checks that IceoryxTransport::Create fails cleanly, and quickly, when no
//     RouDi is running (instead of blocking in iceoryx's initRuntime). Exit 0
//     on success, 1 on failure, 77 (ctest SKIP_RETURN_CODE) if a RouDi is
//     running so the check is impossible.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <thread>

#include "core/ipc/iceoryx_transport.h"
#include "tests/core/ipc/test_messages.h"

namespace rover::ipc {
namespace {

using Clock = std::chrono::steady_clock;

int ExpectNoRouDi() {
  if (IceoryxTransport::IsRouDiRunning()) {
    std::fprintf(stderr, "SKIP: a RouDi is running, cannot test its absence\n");
    return 77;
  }
  IceoryxTransport::Options options;
  options.runtime_name = "core_ipc_no_roudi_" + std::to_string(::getpid());
  options.roudi_wait_timeout = Duration::Milliseconds(300);
  const Clock::time_point start = Clock::now();
  std::string error;
  const std::unique_ptr<IceoryxTransport> transport = IceoryxTransport::Create(options, &error);
  const auto elapsed = Clock::now() - start;
  if (transport != nullptr) {
    // A RouDi came up in the meantime; not what this check is about.
    std::fprintf(stderr, "SKIP: RouDi appeared during the check\n");
    return 77;
  }
  std::fprintf(stderr, "Create failed as expected: %s\n", error.c_str());
  if (error.find("RouDi is not running") == std::string::npos) {
    std::fprintf(stderr, "FAIL: unexpected error text\n");
    return 1;
  }
  if (elapsed < std::chrono::milliseconds(250) || elapsed > std::chrono::seconds(5)) {
    std::fprintf(stderr, "FAIL: took %lld ms, expected about 300 ms\n",
                 static_cast<long long>(
                     std::chrono::duration_cast<std::chrono::milliseconds>(elapsed).count()));
    return 1;
  }
  return 0;
}

int Echo(std::string_view ping_name, std::string_view pong_name, uint64_t count,
         std::chrono::milliseconds timeout) {
  std::string error;
  IceoryxTransport::Options options;
  options.runtime_name = "core_ipc_peer_" + std::to_string(::getpid());
  std::unique_ptr<IceoryxTransport> transport = IceoryxTransport::Create(options, &error);
  const std::optional<Topic> ping_topic = Topic::Parse(ping_name, &error);
  const std::optional<Topic> pong_topic = Topic::Parse(pong_name, &error);
  if (transport == nullptr || !ping_topic || !pong_topic) {
    std::fprintf(stderr, "peer: %s\n", error.c_str());
    return 1;
  }
  auto pings = transport->MakeSubscriber<test::Ping>(*ping_topic, {.queue_capacity = 64}, &error);
  auto pongs = transport->MakePublisher<test::Pong>(*pong_topic, {}, &error);
  if (pings == nullptr || pongs == nullptr) {
    std::fprintf(stderr, "peer: %s\n", error.c_str());
    return 1;
  }
  const Clock::time_point deadline = Clock::now() + timeout;
  uint64_t answered = 0;
  while (answered < count) {
    test::Ping ping;
    if (pings->TryTake(&ping)) {
      const test::Pong pong{ping.sequence, 2 * ping.value, static_cast<int32_t>(::getpid())};
      if (!pongs->Publish(pong)) {
        std::fprintf(stderr, "peer: publish failed\n");
        return 1;
      }
      ++answered;
    } else if (Clock::now() > deadline) {
      std::fprintf(stderr, "peer: timed out after %llu of %llu pings\n",
                   static_cast<unsigned long long>(answered),
                   static_cast<unsigned long long>(count));
      return 1;
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }
  // Let the last pong be taken before our ports disappear.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return 0;
}

}  // namespace
}  // namespace rover::ipc

int main(int argc, char** argv) {
  const std::string_view mode = argc > 1 ? argv[1] : "";
  if (mode == "--expect-no-roudi" && argc == 2) {
    return rover::ipc::ExpectNoRouDi();
  }
  if (mode == "echo" && argc == 6) {
    return rover::ipc::Echo(argv[2], argv[3], std::strtoull(argv[4], nullptr, 10),
                            std::chrono::milliseconds(std::strtoll(argv[5], nullptr, 10)));
  }
  std::fprintf(stderr,
               "usage: %s echo <ping_topic> <pong_topic> <count> <timeout_ms>\n"
               "       %s --expect-no-roudi\n",
               argv[0], argv[0]);
  return 2;
}
