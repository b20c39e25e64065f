// iceoryx-only behaviour: a real second process, and type mismatches that
// only show up at run time when the two ends live in different binaries.

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "core/ipc/iceoryx_transport.h"
#include "tests/core/ipc/ipc_test_util.h"
#include "tests/core/ipc/test_messages.h"

extern char** environ;

namespace rover::ipc {
namespace {

class IceoryxProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    bool skip = false;
    std::string why;
    transport_ = test::MakeTestIceoryxTransport(&skip, &why);
    if (transport_ == nullptr) {
      if (skip) {
        GTEST_SKIP() << test::SkipBanner(why);
      }
      FAIL() << why;
    }
  }

  std::unique_ptr<Transport> transport_;
};

// Kills and reaps the child if the test bails out early.
class ChildProcess {
 public:
  explicit ChildProcess(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (std::string& arg : args) {
      argv.push_back(arg.data());
    }
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) {
      pid_ = -1;
    }
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }

  /// Waits for the child to exit; returns its exit code, or -1 if it was
  /// killed by a signal.
  int Wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
};

TEST_F(IceoryxProcessTest, RoundTripWithASecondProcess) {
  constexpr uint64_t kPings = 50;
  const Topic ping_topic = test::TopicForCurrentTest("ping");
  const Topic pong_topic = test::TopicForCurrentTest("pong");
  std::string error;
  auto pings = transport_->MakePublisher<test::Ping>(ping_topic, {}, &error);
  auto pongs = transport_->MakeSubscriber<test::Pong>(pong_topic, {.queue_capacity = 64}, &error);
  ASSERT_TRUE(pings && pongs) << error;

  ChildProcess peer({ROVER_IPC_TEST_PEER, "echo", ping_topic.name(), pong_topic.name(),
                     std::to_string(kPings), "20000"});
  ASSERT_GT(peer.pid(), 0) << "cannot start " << ROVER_IPC_TEST_PEER;
  ASSERT_TRUE(
      test::WaitUntil([&] { return pings->HasSubscribers(); }, std::chrono::milliseconds(10'000)))
      << "the peer never subscribed";
  ASSERT_TRUE(
      test::WaitUntil([&] { return pongs->HasPublishers(); }, std::chrono::milliseconds(10'000)));

  for (uint64_t i = 0; i < kPings; ++i) {
    ASSERT_TRUE(pings->Publish(test::Ping{i, 0.25 * static_cast<double>(i)}));
    test::Pong pong;
    ASSERT_TRUE(test::WaitUntil([&] { return pongs->TryTake(&pong); })) << "no pong " << i;
    EXPECT_EQ(pong.sequence, i);
    EXPECT_EQ(pong.doubled_value, 0.5 * static_cast<double>(i));
    EXPECT_EQ(pong.peer_pid, peer.pid()) << "answered by the other process";
  }
  EXPECT_EQ(peer.Wait(), 0);
  EXPECT_FALSE(pongs->HasMissedData());
}

TEST_F(IceoryxProcessTest, WrongSizedMessagesAreDiscardedAndReported) {
  // In-process this is refused when the subscriber is created; across
  // processes it can only be detected per message.
  const Topic topic = test::TopicForCurrentTest("mismatch");
  auto publisher = transport_->MakePublisher<test::TestPose>(topic);
  auto subscriber = transport_->MakeSubscriber<test::Small>(topic);
  ASSERT_TRUE(publisher && subscriber);
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));
  ASSERT_TRUE(publisher->Publish(test::TestPose{}));
  test::Small small;
  EXPECT_FALSE(subscriber->TryTake(&small));
  EXPECT_TRUE(subscriber->HasMissedData());
  EXPECT_EQ(subscriber->taken(), 0u);
}

TEST_F(IceoryxProcessTest, SecondCreateSharesTheRuntimeButRefusesANewName) {
  IceoryxTransport::Options options;
  options.runtime_name = "some_other_name";
  std::string error;
  EXPECT_EQ(IceoryxTransport::Create(options, &error), nullptr);
  EXPECT_NE(error.find("one runtime per process"), std::string::npos) << error;

  options.runtime_name = "bad name/with slash";
  EXPECT_EQ(IceoryxTransport::Create(options, &error), nullptr);
  EXPECT_NE(error.find("invalid iceoryx runtime name"), std::string::npos) << error;
}

}  // namespace
}  // namespace rover::ipc
