#include "tests/core/ipc/ipc_test_util.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "core/ipc/iceoryx_transport.h"
#include "tests/support/roudi_process.h"

namespace rover::ipc::test {

Topic TopicForCurrentTest(const std::string& event) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string instance = info == nullptr
                             ? std::string("no_test")
                             : std::string(info->test_suite_name()) + "__" + info->name();
  for (char& c : instance) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) {
      c = '_';
    }
  }
  if (instance.size() > Topic::kMaxPartChars) {
    instance.resize(Topic::kMaxPartChars);
  }
  return *Topic::Parse("/ipc_test/" + instance + "/" + event);
}

std::unique_ptr<Transport> MakeTestIceoryxTransport(bool* skip, std::string* why) {
  *skip = false;
  std::string roudi_problem;
  if (testing::SharedTestRouDi(ROVER_IPC_TEST_ROUDI_CONFIG, &roudi_problem) == nullptr) {
    *skip = !testing::OwnRouDiRequired();
    *why = "no private RouDi for the iceoryx tests: " + roudi_problem;
    return nullptr;
  }
  IceoryxTransport::Options options;
  options.runtime_name = testing::UniqueRuntimeName("core_ipc_test");
  return IceoryxTransport::Create(options, why);
}

std::string SkipBanner(const std::string& why) {
  const std::string banner =
      "\n********************************************************************\n"
      "*** ICEORYX TEST SKIPPED. Set ROVER_REQUIRE_OWN_ROUDI=1 to fail instead.\n*** " +
      why + "\n********************************************************************\n";
  std::fputs(banner.c_str(), stderr);
  return banner;
}

}  // namespace rover::ipc::test
