// mapd's data flow over the in-process transport (same semantics as
// iceoryx): estimates in, frame-switch requests out, switches open submaps.

#include "firmware/mapd/mapd.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/geometry/yaw.h"
#include "core/ipc/in_process_transport.h"
#include "estimator/eskf/eskf_output.h"

namespace rover::mapd {
namespace {

namespace topics = runtime::topics;

ipc::Topic T(std::string_view name) { return *ipc::Topic::Parse(name); }

class MapdTest : public ::testing::Test {
 protected:
  MapdTest()
      // Small queues: the in-process transport preallocates them for every
      // topic, and a stereo pair is 2 MB.
      : transport_(ipc::InProcessTransport::Options{.max_queue_capacity = 8}),
        mapd_(MapdOptions{.trigger = {.max_distance_m = 7.0, .max_position_sigma_m = 0.1},
                          .pose_queue = 8,
                          .global_pose_period = Duration::Zero()},
              &transport_),
        poses_(transport_.MakePublisher<topics::PoseMsg>(T(topics::kPoseTopic))),
        switches_(transport_.MakePublisher<topics::FrameSwitchMsg>(T(topics::kFrameSwitchTopic))),
        requests_(transport_.MakeSubscriber<topics::FrameSwitchRequestMsg>(
            T(topics::kFrameSwitchRequestTopic), {.queue_capacity = 16})) {}

  void Pose(double t_s, uint32_t frame, double x_m, uint32_t status = 0) {
    topics::PoseMsg m;
    m.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    m.frame_id = frame;
    m.status = status;
    m.p_local_body_m = {x_m, 0.0, 0.0};
    m.position_sigma_m = 0.01;
    ASSERT_TRUE(poses_->Publish(m));
  }

  void Switch(uint32_t old_frame, double t_s, const Eigen::Vector3d& p, double yaw,
              double variance = 1e-4) {
    topics::FrameSwitchMsg sw;
    sw.old_frame_id = old_frame;
    sw.new_frame_id = old_frame + 1;
    sw.stamp_ns = Time::FromSeconds(t_s).nanoseconds();
    sw.p_old_new_m = {p.x(), p.y(), p.z()};
    sw.yaw_old_new_rad = yaw;
    for (int i = 0; i < 4; ++i) sw.covariance[static_cast<std::size_t>(5 * i)] = variance;
    ASSERT_TRUE(switches_->Publish(sw));
  }

  // Polls until the graph thread has taken `factors` factors (or 10 s).
  SlamStats WaitForFactors(uint64_t factors) {
    for (int i = 0; i < 1000; ++i) {
      mapd_.Poll();
      const SlamStats s = mapd_.slam_stats();
      if (s.factors_added + s.factors_refused >= factors) return s;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return mapd_.slam_stats();
  }

  // Polls until the graph has `origins` origins and a global pose (or 10 s).
  SlamSnapshot WaitForGraph(std::size_t origins) {
    for (int i = 0; i < 1000; ++i) {
      mapd_.Poll();
      const SlamSnapshot s = mapd_.slam_snapshot();
      if (s.origins.size() >= origins && s.T_world_body) return s;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return mapd_.slam_snapshot();
  }

  std::vector<topics::FrameSwitchRequestMsg> Requests() {
    std::vector<topics::FrameSwitchRequestMsg> out;
    topics::FrameSwitchRequestMsg m;
    while (requests_->TryTake(&m)) out.push_back(m);
    return out;
  }

  ipc::InProcessTransport transport_;
  Mapd mapd_;
  std::unique_ptr<ipc::Publisher<topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Publisher<topics::FrameSwitchMsg>> switches_;
  std::unique_ptr<ipc::Subscriber<topics::FrameSwitchRequestMsg>> requests_;
};

TEST_F(MapdTest, StartsWithASwitchRequestOnceTheFilterRuns) {
  Pose(1.0, 0, 0.0, estimator::kStatusNotInitialised);
  mapd_.Poll();
  EXPECT_TRUE(Requests().empty()) << "the filter would refuse a switch before initialising";
  Pose(1.1, 0, 0.0);
  mapd_.Poll();
  const auto requests = Requests();
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].reason, topics::SwitchReason::kRestart);
  EXPECT_EQ(requests[0].request_id, 1u);
  EXPECT_EQ(requests[0].pose_stamp_ns, Time::FromSeconds(1.1).nanoseconds());
}

TEST_F(MapdTest, ASwitchOpensASubmapWithItsOriginAndDistanceTriggersTheNext) {
  Pose(1.0, 0, 0.0);
  mapd_.Poll();
  ASSERT_EQ(Requests().size(), 1u);
  topics::FrameSwitchMsg sw;
  sw.old_frame_id = 0;
  sw.new_frame_id = 1;
  sw.stamp_ns = Time::FromSeconds(1.0).nanoseconds();
  sw.p_old_new_m = {0.5, 0.0, 0.0};
  ASSERT_TRUE(switches_->Publish(sw));
  // 8 m in frame 1 at 0.1 m per estimate.
  for (int i = 0; i <= 80; ++i) {
    Pose(1.1 + 0.1 * i, 1, 0.1 * i);
    mapd_.Poll();
  }
  const auto requests = Requests();
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].reason, topics::SwitchReason::kDistance);
  EXPECT_EQ(requests[0].pose_frame_id, 1u);
  EXPECT_EQ(requests[0].request_id, 2u);

  ASSERT_EQ(mapd_.submaps().size(), 2u);
  const SubmapRecord& s = mapd_.submaps()[1];
  EXPECT_EQ(s.frame_id, 1u);
  ASSERT_TRUE(s.origin.has_value());
  EXPECT_DOUBLE_EQ(s.origin->p_old_new_m[0], 0.5);
  ASSERT_TRUE(s.reason.has_value());
  EXPECT_EQ(*s.reason, topics::SwitchReason::kRestart);
  EXPECT_EQ(s.poses, 81u);
  EXPECT_NEAR(s.distance_m, 8.0, 1e-9);
  EXPECT_EQ(mapd_.stats().poses, 82u);
}

TEST_F(MapdTest, ARestartedMapdRecordsOnlyTheSubmapItAskedForWhateverArrivesFirst) {
  // Joined in frame 4 (a restart): asks for a switch, keeps no record of 4.
  Pose(1.0, 4, 0.0);
  mapd_.Poll();
  ASSERT_EQ(Requests().size(), 1u);
  Pose(1.1, 4, 0.1);
  mapd_.Poll();
  EXPECT_TRUE(mapd_.submaps().empty()) << "frame 4 was joined half-way";
  // The new frame's estimates arrive before its switch record.
  Pose(1.2, 5, 0.0);
  mapd_.Poll();
  ASSERT_EQ(mapd_.submaps().size(), 1u);
  EXPECT_EQ(mapd_.submaps()[0].frame_id, 5u);
  ASSERT_TRUE(mapd_.submaps()[0].reason.has_value());
  EXPECT_EQ(*mapd_.submaps()[0].reason, topics::SwitchReason::kRestart);
  EXPECT_FALSE(mapd_.submaps()[0].origin.has_value());
  topics::FrameSwitchMsg sw;
  sw.old_frame_id = 4;
  sw.new_frame_id = 5;
  sw.p_old_new_m = {0.25, 0.0, 0.0};
  ASSERT_TRUE(switches_->Publish(sw));
  mapd_.Poll();
  ASSERT_TRUE(mapd_.submaps()[0].origin.has_value()) << "attached when it arrives";
  EXPECT_DOUBLE_EQ(mapd_.submaps()[0].origin->p_old_new_m[0], 0.25);
}

TEST_F(MapdTest, IgnoresMessagesOfAnotherTopicsVersion) {
  topics::PoseMsg m;
  m.version = topics::kTopicsVersion + 1;
  ASSERT_TRUE(poses_->Publish(m));
  mapd_.Poll();
  EXPECT_EQ(mapd_.stats().version_mismatches, 1u);
  EXPECT_EQ(mapd_.stats().poses, 0u);
  EXPECT_TRUE(Requests().empty());
}

// The frame switches chain the origins in the pose graph (its own thread),
// and the global pose is the current origin composed with the estimate.
TEST_F(MapdTest, TheGraphChainsTheSwitchesAndComposesTheGlobalPose) {
  Pose(1.0, 0, 0.0);
  mapd_.Poll();
  Switch(0, 1.5, {7.0, 0.5, 0.1}, 0.3);
  Pose(2.0, 1, 0.0);
  mapd_.Poll();
  Switch(1, 2.5, {6.0, -1.0, 0.0}, -0.2);
  Pose(3.0, 2, 1.0);
  const SlamSnapshot snap = WaitForGraph(3);
  ASSERT_EQ(snap.origins.size(), 3u);
  const Eigen::Isometry3d s1 = GravityAlignedTransform(Eigen::Vector3d(7.0, 0.5, 0.1), 0.3);
  const Eigen::Isometry3d s2 = s1 * GravityAlignedTransform(Eigen::Vector3d(6.0, -1.0, 0.0), -0.2);
  EXPECT_LT((snap.origins.at(0).T_world_origin.matrix() - Eigen::Matrix4d::Identity()).norm(),
            1e-9);
  EXPECT_LT((snap.origins.at(1).T_world_origin.matrix() - s1.matrix()).norm(), 1e-6);
  EXPECT_LT((snap.origins.at(2).T_world_origin.matrix() - s2.matrix()).norm(), 1e-6);
  // Uncertainty grows along the chain.
  EXPECT_GT(snap.origins.at(2).covariance.trace(), snap.origins.at(1).covariance.trace());
  ASSERT_TRUE(snap.T_world_body.has_value());
  EXPECT_LT((snap.T_world_body->translation() - s2 * Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 1e-6);
  const SlamStats stats = mapd_.slam_stats();
  EXPECT_EQ(stats.factors_added, 3u);  // the prior and two switches
  EXPECT_EQ(stats.factors_refused, 0u);

  // A late subscriber gets the latest global pose and origins from history.
  auto pose_sub = transport_.MakeSubscriber<topics::GlobalPoseMsg>(
      T(topics::kGlobalPoseTopic), {.queue_capacity = 1, .history_request = 1});
  auto origins_sub = transport_.MakeSubscriber<topics::SubmapOriginsMsg>(
      T(topics::kSubmapOriginsTopic), {.queue_capacity = 8, .history_request = 8});
  topics::GlobalPoseMsg pose;
  ASSERT_TRUE(pose_sub->TryTake(&pose));
  EXPECT_EQ(pose.version, topics::kTopicsVersion);
  EXPECT_EQ(pose.frame_id, 2u);
  EXPECT_EQ(pose.stamp_ns, Time::FromSeconds(3.0).nanoseconds());
  const Eigen::Vector3d p_expected = *snap.T_world_body * Eigen::Vector3d::Zero();
  EXPECT_NEAR(pose.p_world_body_m[0], p_expected.x(), 1e-6);
  EXPECT_NEAR(pose.p_world_body_m[1], p_expected.y(), 1e-6);
  EXPECT_GT(pose.covariance[0], 0.0);
  topics::SubmapOriginsMsg origins;
  topics::SubmapOriginsMsg latest;
  bool any = false;
  while (origins_sub->TryTake(&origins)) {
    latest = origins;
    any = true;
  }
  ASSERT_TRUE(any);
  EXPECT_EQ(latest.update, pose.update);
  ASSERT_EQ(latest.total, 3u);
  EXPECT_EQ(latest.count, 3u);
  EXPECT_EQ(latest.pages, 1u);
  EXPECT_EQ(latest.origins[1].frame_id, 1u);
  EXPECT_NEAR(latest.origins[1].p_world_origin_m[0], 7.0, 1e-6);
  EXPECT_NEAR(latest.origins[2].p_world_origin_m[0], s2.translation().x(), 1e-6);
  EXPECT_GT(latest.origins[2].covariance[0], latest.origins[1].covariance[0]);
}

// A switch record with a NaN covariance is left out with a message; the
// frames after it wait outside the graph and the part before carries on.
TEST_F(MapdTest, ASwitchWithANanCovarianceIsLeftOutAndTheGraphCarriesOn) {
  Pose(1.0, 0, 0.0);
  mapd_.Poll();
  Switch(0, 1.5, {7.0, 0.0, 0.0}, 0.0, std::nan(""));
  Pose(2.0, 1, 0.0);
  mapd_.Poll();
  Switch(1, 2.5, {7.0, 0.0, 0.0}, 0.0);
  mapd_.Poll();
  const SlamStats stats = WaitForFactors(2);  // the prior and the second switch
  const SlamSnapshot snap = mapd_.slam_snapshot();
  EXPECT_EQ(snap.origins.size(), 1u) << "s0_1 and s0_2 hang off a refused switch";
  EXPECT_EQ(mapd_.stats().graph_factors_refused, 1u);
  EXPECT_EQ(stats.factors_added, 2u);
  EXPECT_EQ(stats.update_errors, 0u);
}

}  // namespace
}  // namespace rover::mapd
