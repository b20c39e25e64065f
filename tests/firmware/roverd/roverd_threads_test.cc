// roverd's threads in real-time mode (free-running, no lockstep gate) on
// scripted drivers: the IMU loop, camera, trigger-less clone requests, VO,
// CAN, the mapd link (in-process transport) and the health thread all run at
// once. Under TSan this is the race check of their hand-overs; in every
// build it checks that everything handed over arrives and is counted.
//
// The drivers are scripted (a stationary rover: gravity only, zero wheel
// speeds, a fixed random-texture scene) because the point is the threads,
// not the estimate; the simulator's drivers would need the renderer.

#include "firmware/roverd/roverd.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <random>
#include <thread>

#include "core/ipc/in_process_transport.h"
#include "drivers/can/canopen_wheel_protocol.h"

namespace rover::roverd {
namespace {

constexpr double kImuRateHz = 400.0;
constexpr int kImuSamples = 2400;  // 6 s of sensor time
const Time kStart = Time::FromSeconds(500.0);

Time ImuStamp(int i) { return kStart + Duration::FromSeconds(i / kImuRateHz); }

// Paces the scripted sensors loosely against each other: each driver waits
// until the IMU has reached its stamp, so every thread has work in flight at
// the same time (and the filter sees inputs about when they are due).
std::atomic<int64_t> g_imu_ns{0};
// And the IMU does not run more than a frame period ahead of the camera, so
// a slow camera thread (2 MB copies per frame under TSan) still delivers
// every frame before the IMU stream, and with it the run, ends.
std::atomic<int64_t> g_camera_ns{0};
bool WaitForImu(Time stamp, Duration timeout) {
  const Time until = Time::Now() + timeout;
  while (g_imu_ns.load() < stamp.nanoseconds()) {
    if (until < Time::Now()) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

class ScriptedImu final : public drivers::ImuDriver {
 public:
  drivers::ReadStatus Read(drivers::ImuSample* s, Duration) override {
    if (next_ >= kImuSamples) return drivers::ReadStatus::kEndOfStream;
    if (next_ % 4 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    while (g_camera_ns.load() < (ImuStamp(next_) - Duration::Milliseconds(150)).nanoseconds()) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    s->stamp = ImuStamp(next_);
    s->sequence = static_cast<uint64_t>(next_);
    s->angular_velocity_rad_s.setZero();
    s->linear_acceleration_m_s2 = Eigen::Vector3d(0.0, 0.0, 9.81);
    g_imu_ns.store(s->stamp.nanoseconds());
    ++next_;
    return drivers::ReadStatus::kOk;
  }

 private:
  int next_ = 0;
};

class ScriptedCamera final : public drivers::StereoCameraDriver {
 public:
  ScriptedCamera() : scene_(240, 376, CV_8UC1) {
    cv::RNG rng(7);
    rng.fill(scene_, cv::RNG::UNIFORM, 0, 255);
  }
  drivers::ReadStatus Next(drivers::StereoFrame* f, Duration timeout) override {
    if (next_ >= 60) return drivers::ReadStatus::kEndOfStream;  // 10 Hz
    const Time stamp = kStart + Duration::Milliseconds(100 * next_);
    if (!WaitForImu(stamp, timeout)) return drivers::ReadStatus::kTimeout;
    f->stamp = stamp;
    f->sequence = static_cast<uint64_t>(next_);
    const drivers::ImageView view{scene_.cols, scene_.rows, scene_.step[0], scene_.data};
    f->cam0 = view;
    f->cam1 = view;  // zero disparity: points at infinity, which the VO must survive
    ++next_;
    g_camera_ns.store(next_ >= 60 ? INT64_MAX : stamp.nanoseconds());
    return drivers::ReadStatus::kOk;
  }
  void Release(const drivers::StereoFrame&) override {}

 private:
  cv::Mat scene_;
  int next_ = 0;
};

class ScriptedCan final : public drivers::CanBus {
 public:
  drivers::ReadStatus Receive(drivers::CanFrame* frame, Duration timeout) override {
    if (period_ >= 600) return drivers::ReadStatus::kEndOfStream;  // 100 Hz
    const Time stamp = kStart + Duration::Milliseconds(10 * period_);
    if (in_period_ == 0 && !WaitForImu(stamp, timeout)) return drivers::ReadStatus::kTimeout;
    if (in_period_ == 0) {
      *frame = drivers::EncodeSync(stamp);
    } else {
      *frame =
          drivers::EncodeWheelTpdo1(stamp, {static_cast<uint8_t>(in_period_), 0, 1000 * period_});
    }
    if (++in_period_ > drivers::kWheelNodeCount) {
      in_period_ = 0;
      ++period_;
    }
    return drivers::ReadStatus::kOk;
  }
  bool Send(const drivers::CanFrame&) override { return true; }

 private:
  int period_ = 0;
  int in_period_ = 0;
};

calib::CameraModel Camera(double x_m) {
  calib::CameraModel c;
  c.width_px = 376;
  c.height_px = 240;
  c.intrinsics = {230.0, 230.0, 188.0, 120.0};
  c.T_body_cam.translation() = Eigen::Vector3d(x_m, 0.0, 0.0);
  return c;
}

TEST(RoverdThreadsTest, AllThreadsHandOverWithoutLossInRealTimeMode) {
  cv::setNumThreads(1);
  g_imu_ns.store(0);
  g_camera_ns.store((kStart - Duration::Milliseconds(100)).nanoseconds());
  RoverdOptions options;
  options.lockstep = false;
  options.camera = CameraSetup{Camera(0.0), Camera(0.11), {}};
  options.camera->vo.checks.nominal_rate_hz = 10.0;
  options.health.period_s = 0.2;
  // The scripted drivers run as fast as the machine lets them (slowly under
  // TSan), not at their nominal rates: judge staleness, not rates.
  options.health.rate_warn_fraction = 0.0;
  // Unprivileged and shared machines: normal scheduling for every thread.
  for (runtime::RtThreadOptions* t : {&options.camera_thread, &options.can_thread}) {
    t->priority = 0;
  }
  ipc::InProcessTransport transport(ipc::InProcessTransport::Options{.max_queue_capacity = 2});
  MapdLink link(&transport);
  auto poses = transport.MakeSubscriber<runtime::topics::PoseMsg>(
      *ipc::Topic::Parse(runtime::topics::kPoseTopic), {.queue_capacity = 2});
  ScriptedImu imu;
  ScriptedCamera camera;
  ScriptedCan can;
  Roverd roverd(options, {&imu, &camera, nullptr, &can}, EstimatorLogChannels{},
                {.mapd_link = &link});
  // A reader on another thread, as mapd would be, while roverd publishes.
  std::atomic<bool> done{false};
  uint64_t taken = 0;
  std::thread reader([&] {
    runtime::topics::PoseMsg m;
    while (!done.load()) {
      while (poses->TryTake(&m)) ++taken;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  const RoverdStats s = roverd.Run();
  done.store(true);
  reader.join();

  EXPECT_EQ(s.imu_samples, static_cast<uint64_t>(kImuSamples));
  EXPECT_EQ(s.imu_drops, 0u);
  EXPECT_EQ(s.frames, 60u);
  // The CAN script waits for the IMU to reach each SYNC's stamp; the last
  // periods lie beyond the last IMU sample.
  EXPECT_GE(s.wheel_readings, 590u);
  EXPECT_EQ(s.loop.ring_drops, 0u);
  // Every camera frame's clone trigger and every wheel reading reached the
  // filter: the inputs are the IMU samples plus those (plus VO results).
  EXPECT_GE(s.loop.inputs, static_cast<uint64_t>(kImuSamples) + 60u + s.wheel_readings);
  std::string reasons;
  for (int k = 0; k <= static_cast<int>(estimator::RejectReason::kNumerical); ++k) {
    const auto reason = static_cast<estimator::RejectReason>(k);
    reasons += std::string(estimator::ToString(reason)) + "=" +
               std::to_string(s.filter.Rejected(estimator::InputKind::kWheelSpeeds, reason)) + " ";
  }
  EXPECT_GT(s.filter.Accepted(estimator::InputKind::kWheelSpeeds), 300u)
      << "a stationary rover's wheel speeds are accepted once the filter runs; rejected: "
      << reasons;
  const MapdLinkStats m = link.stats();
  EXPECT_EQ(m.frames_published, 60u);
  EXPECT_EQ(m.poses_published, s.loop.states);
  EXPECT_GT(taken, 0u);
  EXPECT_GT(s.health_reports, 2u);
  EXPECT_NE(s.health.find("imu ok"), std::string::npos) << s.health;
}

}  // namespace
}  // namespace rover::roverd
