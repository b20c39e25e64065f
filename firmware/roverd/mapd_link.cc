#include "firmware/roverd/mapd_link.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/log/msgs/message_traits.h"

namespace rover::roverd {
namespace {

namespace topics = runtime::topics;

template <typename T>
std::unique_ptr<ipc::Publisher<T>> MakePublisher(ipc::Transport* transport, std::string_view name,
                                                 const ipc::PublisherOptions& options = {}) {
  std::string error;
  const std::optional<ipc::Topic> topic = ipc::Topic::Parse(name, &error);
  std::unique_ptr<ipc::Publisher<T>> p;
  if (topic) p = transport->MakePublisher<T>(*topic, options, &error);
  if (p == nullptr)
    throw std::runtime_error("mapd link: cannot publish " + std::string(name) + ": " + error);
  return p;
}

// Copies `view` into `dst` with rows packed.
void CopyPacked(const drivers::ImageView& view, uint8_t* dst) {
  const auto width = static_cast<std::size_t>(view.width_px);
  for (int r = 0; r < view.height_px; ++r) {
    std::memcpy(dst + static_cast<std::size_t>(r) * width,
                view.data + static_cast<std::size_t>(r) * view.stride_bytes, width);
  }
}

topics::CameraCalibrationMsg ToCameraMsg(const calib::CameraModel& cam) {
  topics::CameraCalibrationMsg m;
  m.width_px = cam.width_px;
  m.height_px = cam.height_px;
  m.distortion_model = cam.distortion_model == calib::DistortionModel::kEquidistant
                           ? topics::kDistortionEquidistant
                           : topics::kDistortionRadialTangential;
  m.intrinsics = cam.intrinsics;
  m.distortion = cam.distortion;
  const Eigen::Vector3d p = cam.T_body_cam.translation();
  const Eigen::Quaterniond q(cam.T_body_cam.linear());
  m.p_body_cam_m = {p.x(), p.y(), p.z()};
  m.q_body_cam_wxyz = {q.w(), q.x(), q.y(), q.z()};
  m.vignetting_cos4_strength = cam.vignetting_cos4_strength;
  return m;
}

}  // namespace

topics::StereoCalibrationMsg ToCalibrationMsg(const calib::CameraModel& cam0,
                                              const calib::CameraModel& cam1) {
  topics::StereoCalibrationMsg m;
  m.cam0 = ToCameraMsg(cam0);
  m.cam1 = ToCameraMsg(cam1);
  return m;
}

MapdLink::MapdLink(ipc::Transport* transport,
                   const std::optional<topics::StereoCalibrationMsg>& calibration)
    : poses_(MakePublisher<topics::PoseMsg>(transport, topics::kPoseTopic)),
      frames_(MakePublisher<topics::StereoFrameMsg>(transport, topics::kStereoFrameTopic)),
      // History: a restarted mapd receives the switches it missed (its pose
      // graph needs every one) and recognises its mission by them.
      switches_(MakePublisher<topics::FrameSwitchMsg>(
          transport, topics::kFrameSwitchTopic, {.history_capacity = topics::kSwitchHistory})),
      diagnostics_(MakePublisher<topics::DiagnosticsMsg>(transport, topics::kDiagnosticsTopic)) {
  std::string error;
  const std::optional<ipc::Topic> topic =
      ipc::Topic::Parse(topics::kFrameSwitchRequestTopic, &error);
  if (topic) {
    requests_ = transport->MakeSubscriber<topics::FrameSwitchRequestMsg>(
        *topic, {.queue_capacity = 16, .history_request = 0}, &error);
  }
  if (requests_ == nullptr) {
    throw std::runtime_error("mapd link: cannot subscribe to " +
                             std::string(topics::kFrameSwitchRequestTopic) + ": " + error);
  }
  if (calibration) {
    calibration_ = MakePublisher<topics::StereoCalibrationMsg>(
        transport, topics::kStereoCalibrationTopic, {.history_capacity = 1});
    if (!calibration_->Publish(*calibration)) {
      throw std::runtime_error("mapd link: cannot publish the stereo calibration on " +
                               std::string(topics::kStereoCalibrationTopic));
    }
  }
}

static_assert(topics::kPoseStatusNotInitialised == estimator::kStatusNotInitialised,
              "PoseMsg::status carries the filter's status bits unchanged");

void MapdLink::OnState(const estimator::EskfOutput& o) {
  latest_stamp_ns_.store(o.stamp.nanoseconds(), std::memory_order_relaxed);
  poses_->PublishInPlace([&o](topics::PoseMsg& m) {
    m.frame_id = o.frame_id;
    m.stamp_ns = o.stamp.nanoseconds();
    m.status = o.status;
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      m.p_local_body_m[k] = o.p_local_body[i];
      m.v_local_m_s[k] = o.v_local_m_s[i];
    }
    m.q_local_body_wxyz = {o.q_local_body.w(), o.q_local_body.x(), o.q_local_body.y(),
                           o.q_local_body.z()};
    // [dp, dtheta] out of the filter's [dp, dv, dtheta, dba, dbg].
    constexpr int kIndex[6] = {0, 1, 2, 6, 7, 8};
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        m.pose_covariance[static_cast<std::size_t>(r * 6 + c)] = o.covariance(kIndex[r], kIndex[c]);
      }
    }
    // Fixed-size 3x3: the closed-form solver does not allocate.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(o.covariance.topLeftCorner<3, 3>(), Eigen::EigenvaluesOnly);
    m.position_sigma_m = std::sqrt(std::max(0.0, solver.eigenvalues().maxCoeff()));
  });
}

void MapdLink::OnFrameSwitch(const estimator::FrameSwitchRecord& record) {
  switches_->PublishInPlace([&record](topics::FrameSwitchMsg& m) {
    m.old_frame_id = record.old_frame_id;
    m.new_frame_id = record.new_frame_id;
    m.stamp_ns = record.stamp.nanoseconds();
    m.p_old_new_m = {record.p_old_new.x(), record.p_old_new.y(), record.p_old_new.z()};
    m.yaw_old_new_rad = record.yaw_old_new_rad;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        m.covariance[static_cast<std::size_t>(r * 4 + c)] = record.covariance(r, c);
      }
    }
  });
}

void MapdLink::PublishFrame(const drivers::StereoFrame& frame) {
  const auto fits = [](const drivers::ImageView& v) {
    return v.data != nullptr && v.width_px > 0 && v.height_px > 0 &&
           static_cast<uint32_t>(v.width_px) <= topics::kMaxFrameWidthPx &&
           static_cast<uint32_t>(v.height_px) <= topics::kMaxFrameHeightPx;
  };
  const bool right = fits(frame.cam1) && frame.cam1.width_px == frame.cam0.width_px &&
                     frame.cam1.height_px == frame.cam0.height_px;
  if (!fits(frame.cam0)) {
    oversized_frames_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  frames_->PublishInPlace([&](topics::StereoFrameMsg& m) {
    m.width_px = static_cast<uint32_t>(frame.cam0.width_px);
    m.height_px = static_cast<uint32_t>(frame.cam0.height_px);
    m.capture_stamp_ns = frame.stamp.nanoseconds();
    m.sequence = frame.sequence;
    CopyPacked(frame.cam0, m.cam0.data());
    if (right) {
      CopyPacked(frame.cam1, m.cam1.data());
    } else {
      // No usable right image: zeros say so (mapd skips the depth).
      std::memset(m.cam1.data(), 0, static_cast<std::size_t>(m.width_px) * m.height_px);
    }
  });
}

int MapdLink::PollRequests(EstimatorLoop* loop) {
  int handed = 0;
  topics::FrameSwitchRequestMsg msg;
  while (requests_->TryTake(&msg)) {
    const int64_t stamp = latest_stamp_ns_.load(std::memory_order_relaxed);
    if (msg.version != topics::kTopicsVersion ||
        !loop->PushFrameSwitchRequest({Time::FromNanoseconds(stamp)})) {
      requests_refused_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    requests_handed_.fetch_add(1, std::memory_order_relaxed);
    ++handed;
  }
  return handed;
}

bool MapdLink::PublishDiagnostics(const log::diagnostic_msgs::DiagnosticArray& diagnostics) {
  if (log::SerializedSize(diagnostics) > topics::DiagnosticsMsg::kMaxCdrBytes) return false;
  return diagnostics_->PublishInPlace([&diagnostics](topics::DiagnosticsMsg& m) {
    m.cdr_size = static_cast<uint32_t>(log::SerializeMessage(diagnostics, m.cdr));
  });
}

bool MapdLink::MapdConnected() const { return poses_->HasSubscribers(); }

MapdLinkStats MapdLink::stats() const {
  MapdLinkStats s;
  s.poses_published = poses_->published();
  s.frames_published = frames_->published();
  s.frame_switches_published = switches_->published();
  s.publish_drops = poses_->dropped() + frames_->dropped() + switches_->dropped();
  s.requests = requests_handed_.load(std::memory_order_relaxed);
  s.requests_refused = requests_refused_.load(std::memory_order_relaxed);
  s.oversized_frames = oversized_frames_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace rover::roverd
