// One test suite run against both transports: whatever the in-process
// transport is used for in tests and replay must behave like iceoryx.
//
// The iceoryx instantiation needs a private RouDi (tests/support/
// roudi_process.h); ctest serialises it through RESOURCE_LOCK "roudi".

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/ipc/iceoryx_transport.h"
#include "core/ipc/in_process_transport.h"
#include "core/ipc/transport.h"
#include "tests/core/ipc/ipc_test_util.h"
#include "tests/core/ipc/test_messages.h"
#include "tests/support/allocation_counter.h"

namespace rover::ipc {
namespace {

using test::Ping;
using test::Small;
using test::TestPose;

enum class Backend { kInProcess, kIceoryx };

std::string BackendName(const ::testing::TestParamInfo<Backend>& info) {
  return info.param == Backend::kIceoryx ? "Iceoryx" : "InProcess";
}

TestPose MakePose(uint32_t sequence) {
  TestPose pose;
  pose.stamp_ns = 1'000'000'000LL + sequence;
  pose.position_m[0] = 1.5 * sequence;
  pose.position_m[1] = -2.25;
  pose.position_m[2] = 1e-3;
  pose.orientation_xyzw[0] = 0.5;
  pose.orientation_xyzw[3] = 0.5;
  pose.sequence = sequence;
  std::strncpy(pose.frame_id, "base_link", sizeof(pose.frame_id) - 1);
  return pose;
}

bool SamePose(const TestPose& a, const TestPose& b) {
  return a.stamp_ns == b.stamp_ns && a.sequence == b.sequence &&
         std::memcmp(a.position_m, b.position_m, sizeof(a.position_m)) == 0 &&
         std::memcmp(a.orientation_xyzw, b.orientation_xyzw, sizeof(a.orientation_xyzw)) == 0 &&
         std::strncmp(a.frame_id, b.frame_id, sizeof(a.frame_id)) == 0;
}

class TransportTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::kInProcess) {
      transport_ = std::make_unique<InProcessTransport>();
      return;
    }
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

  // iceoryx's Publish loans a chunk too, so it fails while all loans are
  // taken; the in-process Publish copies straight into the topic ring.
  bool PublishNeedsAFreeLoan() const { return GetParam() == Backend::kIceoryx; }

  // A topic no other test of this process uses.
  Topic UniqueTopic(const std::string& event = "pose") const {
    return test::TopicForCurrentTest(event);
  }

  template <typename T>
  std::unique_ptr<Publisher<T>> Pub(const Topic& topic, PublisherOptions options = {}) {
    std::string error;
    auto publisher = transport_->MakePublisher<T>(topic, options, &error);
    EXPECT_NE(publisher, nullptr) << error;
    return publisher;
  }

  template <typename T>
  std::unique_ptr<Subscriber<T>> Sub(const Topic& topic, SubscriberOptions options = {}) {
    std::string error;
    auto subscriber = transport_->MakeSubscriber<T>(topic, options, &error);
    EXPECT_NE(subscriber, nullptr) << error;
    return subscriber;
  }

  std::unique_ptr<Transport> transport_;
};

INSTANTIATE_TEST_SUITE_P(Backends, TransportTest,
                         ::testing::Values(Backend::kInProcess, Backend::kIceoryx), BackendName);

TEST_P(TransportTest, RoundTripsAStruct) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic);
  auto subscriber = Sub<TestPose>(topic);
  ASSERT_TRUE(publisher && subscriber);
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->HasPublishers(); }));

  const TestPose sent = MakePose(7);
  ASSERT_TRUE(publisher->Publish(sent));
  TestPose received;
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->TryTake(&received); }));
  EXPECT_TRUE(SamePose(sent, received));
  EXPECT_FALSE(subscriber->TryTake(&received));
  EXPECT_FALSE(subscriber->HasMissedData());
  EXPECT_EQ(publisher->published(), 1u);
  EXPECT_EQ(publisher->dropped(), 0u);
  EXPECT_EQ(subscriber->taken(), 1u);
}

TEST_P(TransportTest, PublishInPlaceBuildsTheMessageInTheTransportBuffer) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic);
  auto subscriber = Sub<TestPose>(topic);
  ASSERT_TRUE(publisher && subscriber);
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));

  ASSERT_TRUE(publisher->PublishInPlace([](TestPose& pose) { pose = MakePose(3); }));
  TestPose received;
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->TryTake(&received); }));
  EXPECT_TRUE(SamePose(received, MakePose(3)));
  EXPECT_EQ(publisher->published(), 1u);
}

TEST_P(TransportTest, EverySubscriberGetsEveryMessageInOrder) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic);
  std::vector<std::unique_ptr<Subscriber<TestPose>>> subscribers;
  for (int i = 0; i < 3; ++i) {
    subscribers.push_back(Sub<TestPose>(topic));
    ASSERT_NE(subscribers.back(), nullptr);
  }
  ASSERT_NE(publisher, nullptr);
  for (auto& subscriber : subscribers) {
    ASSERT_TRUE(test::WaitUntil([&] { return subscriber->HasPublishers(); }));
  }
  for (uint32_t i = 0; i < 10; ++i) {
    ASSERT_TRUE(publisher->Publish(MakePose(i)));
  }
  for (auto& subscriber : subscribers) {
    for (uint32_t i = 0; i < 10; ++i) {
      TestPose received;
      ASSERT_TRUE(test::WaitUntil([&] { return subscriber->TryTake(&received); }));
      EXPECT_EQ(received.sequence, i);
    }
    EXPECT_FALSE(subscriber->HasMissedData());
  }
}

TEST_P(TransportTest, FullQueueDiscardsTheOldestAndReportsIt) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic);
  auto slow = Sub<TestPose>(topic, {.queue_capacity = 4});
  auto fast = Sub<TestPose>(topic, {.queue_capacity = 16});
  ASSERT_TRUE(publisher && slow && fast);
  ASSERT_TRUE(test::WaitUntil([&] { return slow->HasPublishers() && fast->HasPublishers(); }));

  for (uint32_t i = 0; i < 10; ++i) {
    ASSERT_TRUE(publisher->Publish(MakePose(i))) << "a slow subscriber never blocks publishing";
  }
  EXPECT_EQ(publisher->dropped(), 0u);
  EXPECT_TRUE(slow->HasMissedData());
  EXPECT_FALSE(slow->HasMissedData()) << "reported once";
  TestPose received;
  for (uint32_t expected = 6; expected < 10; ++expected) {
    ASSERT_TRUE(slow->TryTake(&received));
    EXPECT_EQ(received.sequence, expected);
  }
  EXPECT_FALSE(slow->TryTake(&received));

  // The other subscriber's queue is independent.
  EXPECT_FALSE(fast->HasMissedData());
  for (uint32_t expected = 0; expected < 10; ++expected) {
    ASSERT_TRUE(fast->TryTake(&received));
    EXPECT_EQ(received.sequence, expected);
  }
}

TEST_P(TransportTest, LateSubscriberReceivesRequestedHistory) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic, {.history_capacity = 3});
  ASSERT_NE(publisher, nullptr);
  for (uint32_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(publisher->Publish(MakePose(i)));
  }
  auto with_history = Sub<TestPose>(topic, {.history_request = 2});
  auto without_history = Sub<TestPose>(topic);
  ASSERT_TRUE(with_history && without_history);
  ASSERT_TRUE(test::WaitUntil(
      [&] { return with_history->HasPublishers() && without_history->HasPublishers(); }));

  TestPose received;
  ASSERT_TRUE(test::WaitUntil([&] { return with_history->TryTake(&received); }));
  EXPECT_EQ(received.sequence, 3u);
  ASSERT_TRUE(test::WaitUntil([&] { return with_history->TryTake(&received); }));
  EXPECT_EQ(received.sequence, 4u);
  EXPECT_FALSE(without_history->TryTake(&received));

  ASSERT_TRUE(publisher->Publish(MakePose(5)));
  ASSERT_TRUE(test::WaitUntil([&] { return without_history->TryTake(&received); }));
  EXPECT_EQ(received.sequence, 5u);
  ASSERT_TRUE(test::WaitUntil([&] { return with_history->TryTake(&received); }));
  EXPECT_EQ(received.sequence, 5u);
}

TEST_P(TransportTest, SubscriberCreatedBeforePublisherConnects) {
  const Topic topic = UniqueTopic();
  auto subscriber = Sub<TestPose>(topic);
  ASSERT_NE(subscriber, nullptr);
  EXPECT_FALSE(subscriber->HasPublishers());
  auto publisher = Pub<TestPose>(topic);
  ASSERT_NE(publisher, nullptr);
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->HasPublishers(); }));
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));
  ASSERT_TRUE(publisher->Publish(MakePose(1)));
  TestPose received;
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->TryTake(&received); }));
  EXPECT_EQ(received.sequence, 1u);

  publisher.reset();
  EXPECT_TRUE(test::WaitUntil([&] { return !subscriber->HasPublishers(); }));
}

TEST_P(TransportTest, LoanFailsAndCountsWhenNoBufferIsLeft) {
  const Topic topic = UniqueTopic();
  std::string error;
  std::unique_ptr<RawPublisher> publisher = transport_->MakeRawPublisher(
      topic, MessageLayout::Of<TestPose>(), PublisherOptions{}, &error);
  ASSERT_NE(publisher, nullptr) << error;

  // Both transports bound the loans a publisher may hold (iceoryx: 8,
  // in-process: 1); the first loan past the bound fails and is counted.
  std::vector<void*> loans;
  for (int i = 0; i < 64; ++i) {
    void* loan = publisher->Loan();
    if (loan == nullptr) {
      break;
    }
    loans.push_back(loan);
  }
  ASSERT_FALSE(loans.empty());
  ASSERT_LT(loans.size(), 64u) << "loans are not bounded";
  EXPECT_EQ(publisher->dropped(), 1u);
  const TestPose pose = MakePose(1);
  uint64_t expected_dropped = 1;
  uint64_t expected_published = 0;
  if (PublishNeedsAFreeLoan()) {
    EXPECT_FALSE(publisher->Publish(&pose)) << "no chunk for Publish either";
    ++expected_dropped;
  } else {
    EXPECT_TRUE(publisher->Publish(&pose));
    ++expected_published;
  }
  EXPECT_EQ(publisher->dropped(), expected_dropped);

  for (void* loan : loans) {
    publisher->ReleaseLoan(loan);
  }
  void* loan = publisher->Loan();
  ASSERT_NE(loan, nullptr) << "loans are available again";
  std::memcpy(loan, &pose, sizeof(pose));
  publisher->PublishLoaned(loan);
  EXPECT_EQ(publisher->dropped(), expected_dropped);
  EXPECT_EQ(publisher->published(), expected_published + 1);
}

TEST_P(TransportTest, RejectsInvalidSubscriberOptions) {
  std::string error;
  EXPECT_EQ(transport_->MakeSubscriber<TestPose>(UniqueTopic(), {.queue_capacity = 0}, &error),
            nullptr);
  EXPECT_NE(error.find("queue_capacity"), std::string::npos) << error;
}

TEST_P(TransportTest, PublishAndTakeDoNotAllocateAfterWarmUp) {
  const Topic topic = UniqueTopic();
  auto publisher = Pub<TestPose>(topic);
  auto subscriber = Sub<TestPose>(topic, {.queue_capacity = 8});
  ASSERT_TRUE(publisher && subscriber);
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));
  ASSERT_TRUE(test::WaitUntil([&] { return subscriber->HasPublishers(); }));

  TestPose pose = MakePose(0);
  TestPose received;
  for (uint32_t i = 0; i < 10; ++i) {  // Warm-up: first-use paths may allocate.
    publisher->Publish(pose);
    subscriber->TryTake(&received);
  }
  testing::ScopedAllocationCheck check;
  uint64_t taken = 0;
  for (uint32_t i = 0; i < 1000; ++i) {
    pose.sequence = i;
    ASSERT_TRUE(publisher->Publish(pose));
    ASSERT_TRUE(publisher->PublishInPlace([i](TestPose& p) { p.sequence = i; }));
    while (subscriber->TryTake(&received)) {
      ++taken;
    }
    subscriber->HasMissedData();
  }
  EXPECT_EQ(check.allocations(), 0u);
  EXPECT_EQ(check.deallocations(), 0u);
  EXPECT_EQ(taken, 2000u);
}

TEST_P(TransportTest, CrossThreadStreamKeepsOrder) {
  constexpr uint32_t kMessages = 20'000;
  const Topic topic = UniqueTopic();
  auto publisher = Pub<Ping>(topic);
  auto subscriber = Sub<Ping>(topic, {.queue_capacity = 256});
  ASSERT_TRUE(publisher && subscriber);
  ASSERT_TRUE(test::WaitUntil([&] { return publisher->HasSubscribers(); }));

  std::atomic<bool> done{false};
  uint64_t received = 0;
  uint64_t out_of_order = 0;
  bool missed = false;
  std::thread consumer([&] {
    int64_t last = -1;
    Ping ping;
    auto drain = [&] {
      while (subscriber->TryTake(&ping)) {
        ++received;
        out_of_order += static_cast<int64_t>(ping.sequence) <= last ? 1 : 0;
        last = static_cast<int64_t>(ping.sequence);
      }
      missed = subscriber->HasMissedData() || missed;
    };
    while (!done.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::yield();
    }
    drain();
  });
  for (uint32_t i = 0; i < kMessages; ++i) {
    if (!publisher->Publish(Ping{i, 0.5 * i})) {
      ADD_FAILURE() << "publish " << i << " failed";
      break;
    }
    if (i % 128 == 127) {
      std::this_thread::yield();
    }
  }
  done.store(true, std::memory_order_release);
  consumer.join();
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_GT(received, 0u);
  EXPECT_LE(received, kMessages);
  // Whatever was not received was reported missed.
  EXPECT_TRUE(received == kMessages || missed);
  EXPECT_EQ(publisher->published(), kMessages);
}

// ----------------------------------------------- transport-specific behaviour

TEST(InProcessTransportTest, RejectsASecondPublisherAndMismatchedTypes) {
  InProcessTransport transport;
  const Topic topic = *Topic::Parse("/test/one_publisher");
  auto first = transport.MakePublisher<TestPose>(topic);
  ASSERT_NE(first, nullptr);
  std::string error;
  EXPECT_EQ(transport.MakePublisher<TestPose>(topic, {}, &error), nullptr);
  EXPECT_NE(error.find("already has a publisher"), std::string::npos) << error;
  EXPECT_EQ(transport.MakeSubscriber<Small>(topic, {}, &error), nullptr);
  EXPECT_NE(error.find("bytes"), std::string::npos) << error;

  first.reset();
  EXPECT_NE(transport.MakePublisher<TestPose>(topic), nullptr) << "free again";
}

TEST(InProcessTransportTest, EndpointsMayOutliveTheTransport) {
  auto transport = std::make_unique<InProcessTransport>();
  const Topic topic = *Topic::Parse("/test/outlive");
  auto publisher = transport->MakePublisher<Small>(topic);
  auto subscriber = transport->MakeSubscriber<Small>(topic);
  transport.reset();
  ASSERT_TRUE(publisher->Publish(Small{5}));
  Small received;
  ASSERT_TRUE(subscriber->TryTake(&received));
  EXPECT_EQ(received.value, 5u);
}

TEST(InProcessTransportTest, QueueCapacityIsClampedToTheTransportMaximum) {
  InProcessTransport transport(InProcessTransport::Options{.max_queue_capacity = 8});
  const Topic topic = *Topic::Parse("/test/clamp");
  auto publisher = transport.MakePublisher<Small>(topic);
  auto subscriber = transport.MakeSubscriber<Small>(topic, {.queue_capacity = 1000});
  for (uint32_t i = 0; i < 20; ++i) {
    publisher->Publish(Small{i});
  }
  Small received;
  ASSERT_TRUE(subscriber->TryTake(&received));
  EXPECT_EQ(received.value, 12u);
}

}  // namespace
}  // namespace rover::ipc
