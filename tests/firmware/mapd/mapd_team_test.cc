// Two mapd processes' team exchange over Cyclone DDS on loopback: each rover's
// graph takes the other's factors, a constraint naming a robot outside the
// team is refused, and a restarted mapd carries on from its log without
// anything arriving twice.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <thread>

#include "core/ipc/in_process_transport.h"
#include "core/link/dds/dds_link.h"
#include "firmware/mapd/mapd.h"
#include "mapping/slam/graph_log.h"
#include "mapping/submap/submap_messages.h"

namespace rover::mapd {
namespace {

namespace fs = std::filesystem;
namespace topics = runtime::topics;

ipc::Topic T(std::string_view name) { return *ipc::Topic::Parse(name); }

// Cyclone DDS on loopback; a domain of this test process's own.
std::unique_ptr<link::LinkEndpoint> Endpoint(int self) {
  link::DdsLinkOptions o;
  o.self = static_cast<link::RobotId>(self);
  o.domain_id = 150 + static_cast<uint32_t>(getpid()) % 80;
  o.config_xml = link::MakeUnicastConfig("lo", {"127.0.0.1"});
  return std::make_unique<link::DdsLink>(o);
}

TeamWorkerOptions Team() {
  TeamWorkerOptions o;
  o.sync.summary_interval = Duration::Milliseconds(100);
  o.sync.team = {0, 1};
  return o;
}

// One rover's mapd on its own in-process transport (its own "RouDi").
struct Rover {
  explicit Rover(int id, const std::string& output_stem = {})
      : transport(ipc::InProcessTransport::Options{.max_queue_capacity = 8}),
        mapd(Options(id, output_stem), &transport, Endpoint(id)),
        poses(transport.MakePublisher<topics::PoseMsg>(T(topics::kPoseTopic))),
        switches(transport.MakePublisher<topics::FrameSwitchMsg>(T(topics::kFrameSwitchTopic))) {}

  static MapdOptions Options(int id, const std::string& output_stem) {
    MapdOptions o{.trigger = {.max_distance_m = 100.0, .max_position_sigma_m = 10.0},
                  .pose_queue = 8,
                  .global_pose_period = Duration::Zero()};
    o.mapping = !output_stem.empty();  // the log needs the mapping archive
    o.output_stem = output_stem;
    o.loop_closures = false;
    o.robot_id = id;
    o.robot_name = id == 0 ? "rover_a" : "rover_b";
    o.team = Team();
    return o;
  }

  void Pose(double t_s, uint32_t frame, double x_m) {
    topics::PoseMsg m;
    m.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    m.frame_id = frame;
    m.p_local_body_m = {x_m, 0.0, 0.0};
    m.position_sigma_m = 0.01;
    ASSERT_TRUE(poses->Publish(m));
  }

  void Switch(uint32_t old_frame, double t_s, double x_m) {
    topics::FrameSwitchMsg sw;
    sw.old_frame_id = old_frame;
    sw.new_frame_id = old_frame + 1;
    sw.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    sw.p_old_new_m = {x_m, 0.0, 0.0};
    for (int i = 0; i < 4; ++i) sw.covariance[static_cast<std::size_t>(5 * i)] = 1e-4;
    ASSERT_TRUE(switches->Publish(sw));
  }

  ipc::InProcessTransport transport;
  Mapd mapd;
  std::unique_ptr<ipc::Publisher<topics::PoseMsg>> poses;
  std::unique_ptr<ipc::Publisher<topics::FrameSwitchMsg>> switches;
};

// Polls every rover until `done` holds (true) or 20 s pass (false).
bool PollUntil(std::vector<Rover*> rovers, const std::function<bool()>& done,
               std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    for (Rover* r : rovers) r->mapd.Poll();
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

TEST(MapdTeamTest, EachRoversGraphTakesTheOthersFactorsButNotTheirPriors) {
  Rover a(0);
  Rover b(1);
  a.Pose(1.0, 0, 0.0);
  b.Pose(1.0, 0, 0.0);
  a.Switch(0, 1.5, 7.0);
  a.Switch(1, 2.5, 6.0);
  b.Switch(0, 1.5, 5.0);
  a.Pose(3.0, 2, 1.0);
  b.Pose(3.0, 1, 1.0);
  // Each graph: its prior, its switches and the other rover's switches.
  ASSERT_TRUE(PollUntil({&a, &b},
                        [&] {
                          return a.mapd.slam_stats().factors_added == 4 &&
                                 b.mapd.slam_stats().factors_added == 4;
                        }))
      << "a: " << a.mapd.slam_stats().factors_added
      << " factors, b: " << b.mapd.slam_stats().factors_added;
  const TeamExchangeStats ta = a.mapd.team_stats();
  const TeamExchangeStats tb = b.mapd.team_stats();
  EXPECT_EQ(ta.constraints_shared, 2u);
  EXPECT_EQ(ta.constraints_received, 1u);
  EXPECT_EQ(tb.constraints_shared, 1u);
  EXPECT_EQ(tb.constraints_received, 2u);
  EXPECT_EQ(ta.constraints_refused + tb.constraints_refused, 0u);
  // The other rover's map hangs off no prior here (nothing links the two
  // yet): its origins wait outside the solve, and this rover's are as alone.
  const SlamSnapshot snap = b.mapd.slam_snapshot();
  ASSERT_EQ(snap.origins.size(), 2u);
  EXPECT_NEAR(snap.origins.at(1).T_world_origin.translation().x(), 5.0, 1e-6);
  EXPECT_NE(a.mapd.Summary().find("team (robot 0): 2 constraints shared, 1 received"),
            std::string::npos)
      << a.mapd.Summary();
}

TEST(MapdTeamTest, AConstraintNamingARobotOutsideTheTeamIsRefusedAndCounted) {
  Rover a(0);
  TeamWorker b(Endpoint(1), Team());
  a.Pose(1.0, 0, 0.0);
  a.mapd.Poll();
  // A match between robot 1's submap and one of robot 7, which the team
  // does not have; then a good one.
  mapping::GraphFactorRecord bad = mapping::SubmapMatchFactor(
      mapping::GraphKey::Origin(1, 0), mapping::GraphKey::Origin(7, 0),
      Eigen::Isometry3d::Identity(), mapping::Matrix6d::Identity() * 1e-2);
  bad.id = 1;
  mapping::GraphFactorRecord good = mapping::FrameSwitchFactor(
      1, 0, Eigen::Vector3d(3.0, 0.0, 0.0), 0.0, Eigen::Matrix4d::Identity() * 1e-4);
  good.id = 2;
  b.PublishConstraint(bad);
  b.PublishConstraint(good);
  ASSERT_TRUE(PollUntil({&a}, [&] {
    const TeamExchangeStats t = a.mapd.team_stats();
    return t.constraints_refused + t.constraints_received == 2;
  }));
  const TeamExchangeStats t = a.mapd.team_stats();
  EXPECT_EQ(t.constraints_refused, 1u);
  EXPECT_EQ(t.constraints_received, 1u);
  EXPECT_NE(t.last_refusal.find("s7_0 of robot 7, which is not in the team"), std::string::npos)
      << t.last_refusal;
  ASSERT_TRUE(PollUntil({&a}, [&] { return a.mapd.slam_stats().factors_added == 2; }))
      << "the prior and robot 1's switch";
}

TEST(MapdTeamTest, ARestartedMapdCarriesOnFromItsLogAndNothingArrivesTwice) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("mapd_team_restart_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  Rover b(1);
  b.Pose(1.0, 0, 0.0);
  b.Switch(0, 1.5, 5.0);
  {
    Rover a(0, (dir / "mapd-1").string());
    a.Pose(1.0, 0, 0.0);
    a.Switch(0, 1.5, 7.0);
    ASSERT_TRUE(PollUntil({&a, &b}, [&] {
      return a.mapd.team_stats().constraints_received == 1 &&
             b.mapd.team_stats().constraints_received == 1;
    }));
    a.mapd.Shutdown();
  }
  const mapping::GraphLogContents first = mapping::ReadGraphLogs({(dir / "mapd-1.mcap").string()});
  EXPECT_EQ(first.team_sent.size(), 1u);
  EXPECT_EQ(first.team_received.size(), 1u);
  EXPECT_EQ(first.factors.size(), 3u) << "a's prior and switch, and b's switch";

  // The new mapd sees roverd's switch history again and resumes.
  Rover a(0, (dir / "mapd-2").string());
  a.Switch(0, 1.5, 7.0);
  a.Pose(2.0, 1, 0.5);
  a.Switch(1, 2.5, 6.0);
  b.Switch(1, 2.5, 4.0);
  ASSERT_TRUE(PollUntil({&a, &b},
                        [&] {
                          return a.mapd.slam_stats().factors_added == 5 &&
                                 b.mapd.team_stats().constraints_received == 2;
                        }))
      << "a: " << a.mapd.slam_stats().factors_added << " factors; b received "
      << b.mapd.team_stats().constraints_received;
  // Give a resend time to show up (several summary rounds) before counting.
  PollUntil(
      {&a, &b}, [] { return false; }, std::chrono::milliseconds(1500));
  const TeamExchangeStats ta = a.mapd.team_stats();
  EXPECT_EQ(ta.messages_resumed, 2u);
  EXPECT_EQ(ta.constraints_received, 1u) << "b's first switch came from the log, not again";
  EXPECT_EQ(ta.constraints_shared, 1u);
  EXPECT_EQ(b.mapd.team_stats().constraints_received, 2u) << "a's first switch arrived once";
  EXPECT_EQ(a.mapd.slam_stats().factors_added, 5u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rover::mapd

namespace rover::mapd {
namespace {

mapping::TeamSubmap SmallSubmap(uint32_t frame) {
  mapping::TeamSubmap s;
  s.info.frame_id = frame;
  s.info.index = frame;
  s.octomap.id = "OcTree";
  s.octomap.resolution = 0.1;
  s.octomap.data.assign(5000, 0);
  mapping::PointCloud cloud(250);
  for (std::size_t k = 0; k < cloud.size(); ++k) {
    cloud[k].p_submap_m = Eigen::Vector3f(0.05f * static_cast<float>(k), 1.0f, -0.35f);
  }
  s.cloud = mapping::ToPointCloud2(cloud, s.info.header);
  return s;
}

template <typename F>
bool Wait(F done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST(TeamExchangeTest, SubmapsAndClaimsArriveDecodedAndADamagedSubmapIsRefused) {
  TeamExchange a(0, Endpoint(0), Team(), nullptr, nullptr);
  TeamExchange b(1, Endpoint(1), Team(), nullptr, nullptr);
  TeamWorker raw(Endpoint(1), Team());  // another process claiming to be robot 1
  a.ShareSubmap(SmallSubmap(4), 0);
  a.ShareClaim({mapping::GraphKey::Origin(0, 4), mapping::GraphKey::Origin(1, 2), 0}, 0);
  TeamArrivals got;
  ASSERT_TRUE(Wait([&] {
    TeamArrivals in = b.Take(0);
    for (auto& s : in.submaps) got.submaps.push_back(std::move(s));
    for (auto& c : in.claims) got.claims.push_back(c);
    return got.submaps.size() == 1 && got.claims.size() == 1;
  }));
  EXPECT_EQ(got.submaps[0].robot, 0);
  EXPECT_EQ(got.submaps[0].messages.info.frame_id, 4u);
  EXPECT_EQ(got.submaps[0].messages.octomap.data.size(), 5000u);
  EXPECT_EQ(got.submaps[0].messages.cloud.width, 250u);
  EXPECT_EQ(got.claims[0].b, mapping::GraphKey::Origin(1, 2));

  // A submap whose cloud is not mapd's layout is not shared, and mapd goes on.
  mapping::TeamSubmap odd = SmallSubmap(6);
  odd.cloud.fields.clear();
  a.ShareSubmap(odd, 0);
  EXPECT_EQ(a.Stats().submaps_shared, 1u);
  EXPECT_EQ(a.Stats().submaps_not_shared, 1u);

  std::vector<uint8_t> damaged = mapping::EncodeSubmap(SmallSubmap(5));
  damaged[damaged.size() - 6] ^= 0x40;
  raw.PublishSubmap(damaged);
  ASSERT_TRUE(Wait([&] {
    a.Take(0);
    return a.Stats().submaps_refused == 1;
  }));
  EXPECT_NE(a.Stats().last_refusal.find("team submap"), std::string::npos)
      << a.Stats().last_refusal;
  EXPECT_EQ(a.Stats().submaps_received, 0u);
}

}  // namespace
}  // namespace rover::mapd
