#include "core/link/emulated_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace rover::link {
namespace {

std::vector<uint8_t> Bytes(std::size_t n, uint8_t fill = 7) {
  return std::vector<uint8_t>(n, fill);
}

Time At(double seconds) { return Time::FromSeconds(seconds); }

TEST(EmulatedNetworkTest, DelaysEachDatagramByTheOneWayDelay) {
  EmulatedNetwork net(1);
  auto a = net.Join(1);
  auto b = net.Join(2);
  LinkConditions c;
  c.delay = Duration::Milliseconds(2000);
  net.SetConditions(1, 2, c);
  ASSERT_TRUE(a->Send(2, Bytes(100)));
  net.AdvanceTo(At(1.999));
  EXPECT_FALSE(b->Receive().has_value());
  net.AdvanceTo(At(2.0));
  const auto d = b->Receive();
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->from, 1u);
  EXPECT_EQ(d->bytes.size(), 100u);
  EXPECT_EQ(d->received, At(2.0));
  // The other direction is untouched: immediate.
  ASSERT_TRUE(b->Send(1, Bytes(10)));
  net.AdvanceTo(At(2.0));
  EXPECT_TRUE(a->Receive().has_value());
}

TEST(EmulatedNetworkTest, LosesTheConfiguredShareReproduciblyBySeed) {
  const auto run = [](uint64_t seed) {
    EmulatedNetwork net(seed);
    auto a = net.Join(1);
    auto b = net.Join(2);
    LinkConditions c;
    c.loss = 0.2;
    net.SetConditions(1, 2, c);
    for (int i = 0; i < 5000; ++i) a->Send(2, Bytes(20));
    net.AdvanceTo(At(1.0));
    return net.stats(1, 2);
  };
  const DirectionStats s = run(3);
  EXPECT_EQ(s.sent, 5000u);
  EXPECT_EQ(s.lost + s.delivered, 5000u);
  // 5000 draws at p = 0.2: sigma 28, so within 4 sigma.
  EXPECT_NEAR(static_cast<double>(s.lost), 1000.0, 115.0);
  EXPECT_EQ(run(3).lost, s.lost);
  EXPECT_NE(run(4).lost, s.lost);
}

TEST(EmulatedNetworkTest, PacesDatagramsAtTheRateAndDropsBeyondTheQueue) {
  EmulatedNetwork net(1);
  auto a = net.Join(1);
  auto b = net.Join(2);
  LinkConditions c;
  c.rate_bytes_per_s = 10000.0;
  c.queue_bytes = 5000;
  net.SetConditions(1, 2, c);
  for (int i = 0; i < 10; ++i) a->Send(2, Bytes(1000));
  // 1000 bytes leave every 0.1 s; the sixth and later wait behind more than
  // 5000 bytes and are dropped.
  std::vector<Time> arrivals;
  for (double t = 0.0; t <= 2.0; t += 0.01) {
    net.AdvanceTo(At(t));
    while (auto d = b->Receive()) arrivals.push_back(d->received);
  }
  const DirectionStats s = net.stats(1, 2);
  EXPECT_EQ(s.delivered, arrivals.size());
  EXPECT_EQ(s.dropped_queue, 10u - arrivals.size());
  ASSERT_EQ(arrivals.size(), 6u);
  for (std::size_t i = 0; i < arrivals.size(); ++i) {
    EXPECT_NEAR(arrivals[i].ToSeconds(), 0.1 * static_cast<double>(i + 1), 1e-6);
  }
}

TEST(EmulatedNetworkTest, AnOutageCarriesNothingAndBroadcastsReachEveryOtherRover) {
  EmulatedNetwork net(1);
  auto a = net.Join(1);
  auto b = net.Join(2);
  auto c = net.Join(3);
  LinkConditions cut;
  cut.outages.push_back({At(10.0), At(70.0)});
  net.SetConditions(1, 2, cut);
  net.AdvanceTo(At(30.0));
  ASSERT_TRUE(a->Send(kAllRobots, Bytes(50)));
  net.AdvanceTo(At(30.0));
  EXPECT_FALSE(b->Receive().has_value());  // 1 -> 2 is out
  EXPECT_TRUE(c->Receive().has_value());   // 1 -> 3 is not
  EXPECT_FALSE(a->Receive().has_value());  // never to itself
  EXPECT_EQ(net.stats(1, 2).dropped_outage, 1u);
  net.AdvanceTo(At(70.0));
  ASSERT_TRUE(a->Send(2, Bytes(50)));
  net.AdvanceTo(At(70.0));
  EXPECT_TRUE(b->Receive().has_value());
}

TEST(EmulatedNetworkTest, RefusesWhatNoLinkCarriesWithoutTouchingTheRest) {
  EmulatedNetwork net(1);
  auto a = net.Join(1);
  auto b = net.Join(2);
  EXPECT_FALSE(a->Send(2, Bytes(kMaxDatagramBytes + 1)));
  EXPECT_FALSE(a->Send(1, Bytes(10)));  // to itself
  EXPECT_TRUE(a->Send(2, Bytes(kMaxDatagramBytes)));
  EXPECT_EQ(a->stats().refused, 2u);
  EXPECT_EQ(a->stats().sent, 1u);
  EXPECT_THROW(net.Join(1), std::invalid_argument);
  EXPECT_THROW(net.Join(kAllRobots), std::invalid_argument);
  LinkConditions bad;
  bad.loss = 1.5;
  EXPECT_THROW(net.SetConditions(1, 2, bad), std::invalid_argument);
  bad = LinkConditions{};
  bad.outages.push_back({At(5.0), At(4.0)});
  EXPECT_THROW(net.SetConditions(1, 2, bad), std::invalid_argument);
}

}  // namespace
}  // namespace rover::link
