// mapd's data flow over the in-process transport (same semantics as
// iceoryx): estimates in, frame-switch requests out, switches open submaps.

#include "firmware/mapd/mapd.h"

#include <gtest/gtest.h>

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
                          .pose_queue = 8},
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

}  // namespace
}  // namespace rover::mapd
