#ifndef ROVER_FIRMWARE_ROVERD_MAPD_LINK_H_
#define ROVER_FIRMWARE_ROVERD_MAPD_LINK_H_

// roverd's end of the roverd <-> mapd link (firmware/runtime/topics):
// publishes every estimate, frame switch and stereo pair, and hands mapd's
// frame-switch requests to the estimator loop.
//
// Real-time contract: OnState / OnFrameSwitch run on the IMU thread and
// PublishFrame on the camera thread; they write into transport buffers
// (iceoryx shared memory) and never block or allocate. A missing or dead
// mapd costs nothing: iceoryx publishes into the subscribers' queues, and
// with no subscriber the chunk is simply released. PollRequests runs on
// roverd's normal-priority link thread.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "core/calib/camera_model.h"
#include "core/ipc/transport.h"
#include "core/log/msgs/diagnostic_msgs.h"
#include "drivers/camera/stereo_frame.h"
#include "firmware/roverd/estimator_loop.h"
#include "firmware/runtime/topics/rover_topics.h"

namespace rover::roverd {

/// Counters of the link, readable from any thread.
struct MapdLinkStats {
  uint64_t poses_published = 0;
  uint64_t frames_published = 0;
  uint64_t frame_switches_published = 0;
  uint64_t publish_drops = 0;     ///< no transport buffer
  uint64_t requests = 0;          ///< frame-switch requests handed to the filter
  uint64_t requests_refused = 0;  ///< wrong topics version, or the loop's ring was full
  uint64_t oversized_frames = 0;  ///< larger than StereoFrameMsg carries: not published
};

class MapdLink final : public EstimatorListener {
 public:
  /// Creates the endpoints on `transport` (start-up: allocates) and, given
  /// the stereo head's calibration, publishes it once with history so that
  /// mapd receives it whenever it connects. Throws std::runtime_error naming
  /// the topic the transport refused.
  explicit MapdLink(ipc::Transport* transport,
                    const std::optional<runtime::topics::StereoCalibrationMsg>& calibration = {});

  // EstimatorListener, IMU thread.
  void OnState(const estimator::EskfOutput& output) override;
  void OnFrameSwitch(const estimator::FrameSwitchRecord& record) override;

  /// Camera thread: publishes one captured pair (copied once, into shared
  /// memory). A pair larger than the message carries is counted, not sent.
  void PublishFrame(const drivers::StereoFrame& frame);

  /// Link thread: takes every queued request and pushes it to `loop`,
  /// stamped with the newest estimate's time, so that it takes effect at the
  /// next IMU sample rather than counting as late. Returns how many.
  int PollRequests(EstimatorLoop* loop);

  /// Health thread: publishes the health report on /roverd/diagnostics.
  /// False if it does not fit a DiagnosticsMsg or no buffer is free.
  bool PublishDiagnostics(const log::diagnostic_msgs::DiagnosticArray& diagnostics);

  /// True if mapd (any subscriber) listens to the poses. Not real-time.
  bool MapdConnected() const;

  MapdLinkStats stats() const;

 private:
  std::unique_ptr<ipc::Publisher<runtime::topics::PoseMsg>> poses_;
  std::unique_ptr<ipc::Publisher<runtime::topics::StereoFrameMsg>> frames_;
  std::unique_ptr<ipc::Publisher<runtime::topics::FrameSwitchMsg>> switches_;
  std::unique_ptr<ipc::Publisher<runtime::topics::DiagnosticsMsg>> diagnostics_;
  std::unique_ptr<ipc::Publisher<runtime::topics::StereoCalibrationMsg>> calibration_;
  std::unique_ptr<ipc::Subscriber<runtime::topics::FrameSwitchRequestMsg>> requests_;
  std::atomic<int64_t> latest_stamp_ns_{0};
  std::atomic<uint64_t> requests_handed_{0};
  std::atomic<uint64_t> requests_refused_{0};
  std::atomic<uint64_t> oversized_frames_{0};
};

/// The calibration message of a stereo head.
runtime::topics::StereoCalibrationMsg ToCalibrationMsg(const calib::CameraModel& cam0,
                                                       const calib::CameraModel& cam1);

/// Forwards the estimator's outputs to two listeners (either may be null).
class ListenerPair final : public EstimatorListener {
 public:
  ListenerPair(EstimatorListener* first, EstimatorListener* second)
      : first_(first), second_(second) {}
  void OnState(const estimator::EskfOutput& output) override {
    if (first_ != nullptr) first_->OnState(output);
    if (second_ != nullptr) second_->OnState(output);
  }
  void OnFrameSwitch(const estimator::FrameSwitchRecord& record) override {
    if (first_ != nullptr) first_->OnFrameSwitch(record);
    if (second_ != nullptr) second_->OnFrameSwitch(record);
  }

 private:
  EstimatorListener* first_;
  EstimatorListener* second_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_MAPD_LINK_H_
