#include "firmware/mapd/team_worker.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "core/link/dds/dds_link.h"

namespace rover::mapd {
namespace {

using mapping::GraphKey;

// Cyclone DDS on loopback; a domain of this test process's own.
std::unique_ptr<link::LinkEndpoint> Endpoint(link::RobotId self) {
  link::DdsLinkOptions o;
  o.self = self;
  o.domain_id = 100 + static_cast<uint32_t>(getpid()) % 100;
  o.config_xml = link::MakeUnicastConfig("lo", {"127.0.0.1"});
  return std::make_unique<link::DdsLink>(o);
}

TeamWorkerOptions Options() {
  TeamWorkerOptions o;
  o.sync.summary_interval = Duration::Milliseconds(100);
  return o;
}

// Collects `worker`'s inbox until `done` holds or 20 s pass.
template <typename F>
TeamInbox Collect(TeamWorker* worker, F done) {
  TeamInbox all;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < end) {
    TeamInbox in = worker->Take();
    for (auto& r : in.records) all.records.push_back(std::move(r));
    for (auto& c : in.constraints) all.constraints.push_back(std::move(c));
    for (auto& c : in.claims) all.claims.push_back(c);
    for (auto& s : in.submaps) all.submaps.push_back(std::move(s));
    if (done(all)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return all;
}

mapping::GraphFactorRecord Switch(int robot, int64_t frame) {
  mapping::GraphFactorRecord f = mapping::FrameSwitchFactor(
      robot, frame, Eigen::Vector3d(7.0, 0.1, 0.0), 0.05, Eigen::Matrix4d::Identity() * 1e-4);
  f.id = static_cast<uint64_t>(frame + 1);
  return f;
}

TEST(TeamWorkerTest, RoversExchangeConstraintsClaimsSubmapsAndHeartbeats) {
  TeamWorker a(Endpoint(1), Options());
  TeamWorker b(Endpoint(2), Options());
  a.PublishConstraint(Switch(1, 0));
  a.PublishConstraint(Switch(1, 1));
  a.PublishClaim({GraphKey::Origin(1, 0), GraphKey::Origin(2, 3), 1});
  a.PublishSubmap(std::vector<uint8_t>(50000, 9));
  mapping::TeamHeartbeat beat;
  beat.submap = 2;
  beat.T_world_body.translation() = Eigen::Vector3d(3.0, 4.0, 0.5);
  a.SetHeartbeat(beat);
  const TeamInbox in = Collect(&b, [](const TeamInbox& i) {
    return i.constraints.size() == 2 && i.claims.size() == 1 && i.submaps.size() == 1;
  });
  ASSERT_EQ(in.constraints.size(), 2u);
  EXPECT_EQ(in.constraints[0].kind, mapping::FactorKind::kFrameSwitch);
  EXPECT_EQ(in.constraints[1].b, GraphKey::Origin(1, 2));
  ASSERT_EQ(in.claims.size(), 1u);
  EXPECT_EQ(in.claims[0].claimant, 1u);
  ASSERT_EQ(in.submaps.size(), 1u);
  EXPECT_EQ(in.submaps[0].bytes, std::vector<uint8_t>(50000, 9));
  EXPECT_EQ(in.records.size(), 4u);  // all of it, for mapd's log
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (b.Stats().heartbeats.count(1) == 0 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(b.Stats().heartbeats.count(1), 1u);
  EXPECT_EQ(b.Stats().heartbeats.at(1).submap, 2);
  EXPECT_TRUE(b.Stats().heartbeats.at(1).T_world_body.isApprox(beat.T_world_body));
  EXPECT_EQ(b.Stats().undecodable, 0u);
}

TEST(TeamWorkerTest, WhatDoesNotDecodeIsCountedWithTheReasonAndTheRestArrives) {
  TeamWorker b(Endpoint(2), Options());
  // A rover of the team that speaks the protocol but sends nonsense, and a
  // constraint of a robot other than its sender.
  std::unique_ptr<link::LinkEndpoint> raw_endpoint = Endpoint(3);
  link::TeamSync raw(raw_endpoint.get(), Options().sync);
  raw.Publish(0, {1, 1, 0, 0, 0});
  raw.Publish(0, mapping::EncodeConstraint(Switch(5, 0)));
  raw.Publish(0, mapping::EncodeConstraint(Switch(3, 0)));
  raw.Publish(6, {1});
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  TeamInbox in;
  while (std::chrono::steady_clock::now() < end && in.constraints.empty()) {
    raw.Tick();
    TeamInbox got = b.Take();
    for (auto& c : got.constraints) in.constraints.push_back(c);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (int i = 0; i < 50 && b.Stats().undecodable < 3; ++i) {
    raw.Tick();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(in.constraints.size(), 1u);
  EXPECT_EQ(in.constraints[0].a, GraphKey::Origin(3, 0));
  EXPECT_EQ(b.Stats().undecodable, 3u);
  EXPECT_NE(b.Stats().last_decode_error.find("message 3/"), std::string::npos)
      << b.Stats().last_decode_error;
}

TEST(TeamWorkerTest, ARestartedRoverGetsOnlyWhatItMissed) {
  TeamWorker a(Endpoint(1), Options());
  TeamBacklog backlog;
  {
    TeamWorker b(Endpoint(2), Options());
    a.PublishConstraint(Switch(1, 0));
    b.PublishConstraint(Switch(2, 0));
    const TeamInbox got = Collect(&b, [](const TeamInbox& i) { return !i.records.empty(); });
    ASSERT_EQ(got.records.size(), 1u);
    backlog.received = got.records;
    backlog.own.push_back(
        {2, mapping::TeamStream::kConstraints, 1, mapping::EncodeConstraint(Switch(2, 0))});
    Collect(&a, [](const TeamInbox& i) { return !i.records.empty(); });
  }
  a.PublishConstraint(Switch(1, 1));
  TeamWorker b(Endpoint(2), Options(), backlog);
  b.PublishConstraint(Switch(2, 1));
  const TeamInbox at_b = Collect(&b, [](const TeamInbox& i) { return !i.records.empty(); });
  const TeamInbox at_a = Collect(&a, [](const TeamInbox& i) { return !i.records.empty(); });
  // Each gets the one new constraint, and nothing twice.
  ASSERT_EQ(at_b.constraints.size(), 1u);
  EXPECT_EQ(at_b.constraints[0].b, GraphKey::Origin(1, 2));
  ASSERT_EQ(at_a.constraints.size(), 1u);
  EXPECT_EQ(at_a.constraints[0].b, GraphKey::Origin(2, 2));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_TRUE(a.Take().records.empty());
  EXPECT_TRUE(b.Take().records.empty());
}

TEST(TeamWorkerTest, BadOptionsAndBacklogsAreRefused) {
  TeamWorkerOptions o = Options();
  o.tick = Duration::Zero();
  EXPECT_THROW(TeamWorker(Endpoint(1), o), std::invalid_argument);
  EXPECT_THROW(TeamWorker(nullptr, Options()), std::invalid_argument);
  TeamBacklog wrong;
  wrong.own.push_back({7, mapping::TeamStream::kConstraints, 1, {1}});
  EXPECT_THROW(TeamWorker(Endpoint(1), Options(), wrong), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapd
