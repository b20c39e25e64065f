#ifndef ROVER_TESTS_CORE_IPC_IPC_TEST_UTIL_H_
#define ROVER_TESTS_CORE_IPC_IPC_TEST_UTIL_H_

// Helpers shared by the IPC tests.

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "core/ipc/topic.h"
#include "core/ipc/transport.h"

namespace rover::ipc::test {

/// Polls `condition` every millisecond until it is true or `timeout` has
/// passed. iceoryx connects publishers and subscribers asynchronously
/// (through RouDi's discovery loop), so tests wait for connections instead
/// of assuming them.
template <typename Condition>
bool WaitUntil(Condition&& condition,
               std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= deadline) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

/// "/ipc_test/<suite>__<test>/<event>" for the running gtest test, so no two
/// tests of one process share a topic (iceoryx endpoints of earlier tests
/// may still be disconnecting).
Topic TopicForCurrentTest(const std::string& event);

/// An IceoryxTransport connected to this test process's private RouDi
/// (started on first use with roudi_test.toml). On failure returns nullptr
/// with the reason in `*why`, and `*skip` true if the test should be skipped
/// rather than failed (a foreign RouDi is running and ROVER_REQUIRE_OWN_ROUDI
/// is not set).
std::unique_ptr<Transport> MakeTestIceoryxTransport(bool* skip, std::string* why);

/// The loud message printed when iceoryx tests are skipped.
std::string SkipBanner(const std::string& why);

}  // namespace rover::ipc::test

#endif  // ROVER_TESTS_CORE_IPC_IPC_TEST_UTIL_H_
