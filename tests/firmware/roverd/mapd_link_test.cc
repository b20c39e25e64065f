// roverd's end of the mapd link over the in-process transport: what the IMU
// and camera threads publish, without allocating, and how mapd's requests
// reach the estimator loop.

#include "firmware/roverd/mapd_link.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/ipc/in_process_transport.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/malloc_counter.h"

namespace rover::roverd {
namespace {

namespace topics = runtime::topics;

ipc::Topic T(std::string_view name) { return *ipc::Topic::Parse(name); }

estimator::EskfOutput Output(double t_s, uint32_t frame) {
  estimator::EskfOutput o;
  o.stamp = Time::FromSeconds(t_s);
  o.frame_id = frame;
  o.p_local_body = {1.0, 2.0, 3.0};
  o.v_local_m_s = {0.1, 0.2, 0.3};
  o.q_local_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  for (int i = 0; i < 15; ++i) o.covariance(i, i) = 0.001 * (i + 1);
  o.covariance(0, 6) = o.covariance(6, 0) = 1e-5;  // dp_x / dtheta_x
  o.covariance(1, 1) = 0.04;                       // sigma_y = 0.2 m: the largest
  return o;
}

class MapdLinkTest : public ::testing::Test {
 protected:
  MapdLinkTest()
      : transport_(ipc::InProcessTransport::Options{.max_queue_capacity = 4}),
        poses_(transport_.MakeSubscriber<topics::PoseMsg>(T(topics::kPoseTopic))),
        frames_(transport_.MakeSubscriber<topics::StereoFrameMsg>(T(topics::kStereoFrameTopic),
                                                                  {.queue_capacity = 2})),
        link_(&transport_),
        requests_(transport_.MakePublisher<topics::FrameSwitchRequestMsg>(
            T(topics::kFrameSwitchRequestTopic))) {}

  ipc::InProcessTransport transport_;
  std::unique_ptr<ipc::Subscriber<topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Subscriber<topics::StereoFrameMsg>> frames_;
  MapdLink link_;
  std::unique_ptr<ipc::Publisher<topics::FrameSwitchRequestMsg>> requests_;
};

TEST_F(MapdLinkTest, PublishesEachEstimateWithThePoseCovarianceAndPositionSigma) {
  link_.OnState(Output(2.5, 3));
  topics::PoseMsg m;
  ASSERT_TRUE(poses_->TryTake(&m));
  EXPECT_EQ(m.version, topics::kTopicsVersion);
  EXPECT_EQ(m.frame_id, 3u);
  EXPECT_EQ(m.stamp_ns, Time::FromSeconds(2.5).nanoseconds());
  EXPECT_EQ(m.p_local_body_m[1], 2.0);
  EXPECT_EQ(m.v_local_m_s[2], 0.3);
  EXPECT_NEAR(m.q_local_body_wxyz[0], std::cos(0.15), 1e-15);
  EXPECT_NEAR(m.q_local_body_wxyz[3], std::sin(0.15), 1e-15);
  // [dp, dtheta] = filter indices 0..2 and 6..8.
  EXPECT_EQ(m.pose_covariance[0 * 6 + 0], 0.001);
  EXPECT_EQ(m.pose_covariance[1 * 6 + 1], 0.04);
  EXPECT_EQ(m.pose_covariance[3 * 6 + 3], 0.007);
  EXPECT_EQ(m.pose_covariance[0 * 6 + 3], 1e-5);
  EXPECT_EQ(m.pose_covariance[3 * 6 + 0], 1e-5);
  EXPECT_NEAR(m.position_sigma_m, 0.2, 1e-12);
  EXPECT_EQ(link_.stats().poses_published, 1u);
}

TEST_F(MapdLinkTest, PublishesFramesWithPackedRowsAndRefusesOversizedOnes) {
  const int w = 6, h = 4;
  const std::size_t stride = 8;  // padded rows, as drivers deliver them
  std::vector<uint8_t> left(stride * h), right(stride * h);
  for (std::size_t i = 0; i < left.size(); ++i) {
    left[i] = static_cast<uint8_t>(i);
    right[i] = static_cast<uint8_t>(200 - i);
  }
  drivers::StereoFrame frame;
  frame.stamp = Time::FromSeconds(1.0);
  frame.sequence = 42;
  frame.cam0 = {w, h, stride, left.data()};
  frame.cam1 = {w, h, stride, right.data()};
  link_.PublishFrame(frame);
  auto msg = std::make_unique<topics::StereoFrameMsg>();
  ASSERT_TRUE(frames_->TryTake(msg.get()));
  EXPECT_EQ(msg->width_px, 6u);
  EXPECT_EQ(msg->height_px, 4u);
  EXPECT_EQ(msg->sequence, 42u);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const std::size_t packed = static_cast<std::size_t>(r * w + c);
      const std::size_t padded = static_cast<std::size_t>(r) * stride + static_cast<std::size_t>(c);
      ASSERT_EQ(msg->cam0[packed], left[padded]) << r << "," << c;
      ASSERT_EQ(msg->cam1[packed], right[padded]) << r << "," << c;
    }
  }
  frame.cam0.width_px = static_cast<int>(topics::kMaxFrameWidthPx) + 1;
  link_.PublishFrame(frame);
  EXPECT_FALSE(frames_->TryTake(msg.get()));
  EXPECT_EQ(link_.stats().oversized_frames, 1u);
  EXPECT_EQ(link_.stats().frames_published, 1u);
}

TEST_F(MapdLinkTest, TheRealTimeCallsDoNotAllocate) {
  std::vector<uint8_t> image(752 * 480, 7);
  drivers::StereoFrame frame;
  frame.cam0 = {752, 480, 752, image.data()};
  frame.cam1 = frame.cam0;
  const estimator::EskfOutput o = Output(1.0, 0);
  estimator::FrameSwitchRecord record;
  link_.OnState(o);  // first use of each path outside the check
  link_.PublishFrame(frame);
  link_.OnFrameSwitch(record);
  rover::testing::ScopedAllocationCheck news;
  rover::testing::ScopedMallocCheck mallocs;
  for (int i = 0; i < 100; ++i) {
    link_.OnState(o);
    if (i % 10 == 0) link_.PublishFrame(frame);
  }
  link_.OnFrameSwitch(record);
  EXPECT_EQ(news.allocations(), 0u);
  EXPECT_EQ(mallocs.mallocs(), 0u);
}

TEST_F(MapdLinkTest, HandsRequestsToTheLoopStampedAtTheNewestEstimate) {
  estimator::EskfOptions options;
  EstimatorLoop loop(options, EstimatorLogChannels{});
  link_.OnState(Output(5.0, 0));
  topics::FrameSwitchRequestMsg request;
  request.pose_stamp_ns = Time::FromSeconds(1.0).nanoseconds();  // mapd lags behind
  ASSERT_TRUE(requests_->Publish(request));
  request.version = topics::kTopicsVersion + 1;
  ASSERT_TRUE(requests_->Publish(request));
  EXPECT_EQ(link_.PollRequests(&loop), 1);
  EXPECT_EQ(link_.stats().requests, 1u);
  EXPECT_EQ(link_.stats().requests_refused, 1u);
  // The request is due at 5.0 s: an IMU sample at 5.0025 s takes it, in time.
  loop.Step({Time::FromSeconds(5.0025), Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)});
  EXPECT_EQ(loop.stats().inputs, 2u);
  EXPECT_EQ(loop.stats().late_inputs, 0u);
}

// The calibration message carries each camera's lens model and vignetting,
// so that mapd rectifies (and flat-fields) the pairs as roverd does.
TEST(CalibrationMsgTest, CarriesTheDistortionModelThePoseAndTheVignetting) {
  calib::CameraModel cam0;
  cam0.width_px = 752;
  cam0.height_px = 480;
  cam0.intrinsics = {458.0, 457.0, 367.0, 248.0};
  cam0.distortion = {-0.28, 0.07, 2e-4, 2e-5};
  cam0.T_body_cam.translation() = Eigen::Vector3d(0.1, -0.05, 0.02);
  calib::CameraModel cam1 = cam0;
  cam1.distortion_model = calib::DistortionModel::kEquidistant;
  cam1.distortion = {0.0034, 0.0007, -0.0021, 0.0002};
  cam1.vignetting_cos4_strength = 0.4;
  const topics::StereoCalibrationMsg m = ToCalibrationMsg(cam0, cam1);
  EXPECT_EQ(m.version, topics::kTopicsVersion);
  EXPECT_EQ(m.cam0.distortion_model, topics::kDistortionRadialTangential);
  EXPECT_EQ(m.cam1.distortion_model, topics::kDistortionEquidistant);
  EXPECT_EQ(m.cam1.distortion, cam1.distortion);
  EXPECT_EQ(m.cam0.width_px, 752);
  EXPECT_EQ(m.cam0.intrinsics, cam0.intrinsics);
  EXPECT_EQ(m.cam0.p_body_cam_m[0], 0.1);
  EXPECT_EQ(m.cam0.q_body_cam_wxyz[0], 1.0);
  EXPECT_EQ(m.cam0.vignetting_cos4_strength, 0.0);
  EXPECT_EQ(m.cam1.vignetting_cos4_strength, 0.4);
}

}  // namespace
}  // namespace rover::roverd
