#ifndef ROVER_FIRMWARE_ROVERD_ROVERD_H_
#define ROVER_FIRMWARE_ROVERD_ROVERD_H_

// roverd's threads around the estimator loop (DESIGN.md):
//   IMU thread (the caller of Run)  read IMU -> EstimatorLoop::Step
//   camera thread                   frame -> clone trigger; images -> VO slot
//   VO thread (low priority)        StereoOdometry -> relative pose
//   CAN thread                      wheel drives' frames -> wheel speeds
// The drivers are interfaces, so the same code runs on a board, on the HIL
// bench and on the simulator's drivers. In lockstep mode (simulation faster
// or slower than real time) the threads are coupled by a LockstepGate and no
// input is dropped; in real time they run free and a busy VO drops frames
// (counted), never the IMU loop.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/ring/spsc_ring.h"
#include "drivers/camera/camera_trigger.h"
#include "drivers/camera/stereo_camera_driver.h"
#include "drivers/can/can_bus.h"
#include "drivers/can/wheel_speed_decoder.h"
#include "drivers/imu/imu_driver.h"
#include "estimator/vo/stereo_odometry.h"
#include "firmware/roverd/estimator_loop.h"
#include "firmware/roverd/image_logger.h"
#include "firmware/roverd/lockstep_gate.h"
#include "firmware/roverd/mapd_link.h"
#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/loop_probe.h"
#include "firmware/runtime/rt/rt_thread.h"
#include "firmware/runtime/rt/rt_thread_options.h"

namespace rover::roverd {

/// The stereo head: calibration and VO options (absent: no VO).
struct CameraSetup {
  estimator::vo::CameraModel cam0;
  estimator::vo::CameraModel cam1;
  estimator::vo::StereoOdometryOptions vo;
};

struct RoverdOptions {
  estimator::EskfOptions estimator;
  std::optional<CameraSetup> camera;
  bool lockstep = false;
  /// Lockstep: a frame's VO result is delivered at capture + this (real time:
  /// when the VO finishes).
  Duration lockstep_vo_latency = Duration::Milliseconds(100);
  /// Lockstep: how far the camera and CAN threads may run ahead of the IMU
  /// (more than the CAN period, less than the rings hold).
  Duration lockstep_lead = Duration::Milliseconds(300);
  /// Image slots between the camera and the VO thread.
  int frame_slots = 3;
  /// Driver read timeouts; a silent sensor is noticed this often.
  Duration read_timeout = Duration::Milliseconds(200);
  /// Scheduling of the worker threads (DESIGN.md). In lockstep every thread
  /// runs at normal priority, since they wait on each other. The IMU loop
  /// runs on the thread that calls Run(); its caller sets that up.
  runtime::RtThreadOptions camera_thread{"camera", 70, 0, {}, 64 * 1024};
  runtime::RtThreadOptions can_thread{"can", 60, 0, {}, 64 * 1024};
  runtime::RtThreadOptions vo_thread{"vo", 0, 10, {}, 64 * 1024};
  /// The thread taking mapd's requests (with a MapdLink).
  runtime::RtThreadOptions link_thread{"mapd-link", 0, 0, {}, 64 * 1024};
  /// How often the link thread looks for mapd's requests.
  Duration link_poll_period = Duration::Milliseconds(5);
};

/// The sensors. `camera`, `trigger` and `can` may be null (absent). With a
/// trigger, clone requests go out at each trigger edge (real time); without
/// one, or in lockstep, at each frame's arrival.
struct RoverdDrivers {
  drivers::ImuDriver* imu = nullptr;
  drivers::StereoCameraDriver* camera = nullptr;
  drivers::CameraTrigger* trigger = nullptr;
  drivers::CanBus* can = nullptr;
};

/// What a run did, for the summary and the health report.
struct RoverdStats {
  uint64_t imu_samples = 0;
  uint64_t imu_drops = 0;  ///< samples missing from the IMU's sequence numbers
  uint64_t imu_errors = 0;
  uint64_t frames = 0;
  uint64_t frame_drops = 0;  ///< frames the camera lost (sequence gaps) or the VO had no slot for
  uint64_t vo_measurements = 0;
  uint64_t images_logged = 0;
  uint64_t image_log_drops = 0;
  estimator::vo::VoHealth vo;
  uint64_t wheel_readings = 0;
  drivers::WheelSpeedDecoderStats can;
  uint64_t can_errors = 0;
  EstimatorLoopStats loop;
  estimator::EskfHealth filter;
  runtime::LatencySummary step_latency;  ///< wall time of EstimatorLoop::Step
  /// Real time only (sensor stamps on CLOCK_MONOTONIC): from the IMU sample's
  /// time to the estimate it produced, and to the read returning it.
  runtime::LatencySummary sample_to_estimate;
  runtime::LatencySummary sample_to_read;
  /// How each worker thread was scheduled (empty entries: not started).
  std::vector<std::string> thread_reports;
};

class Roverd {
 public:
  /// Sets everything up (threads start in Run()). Throws std::invalid_argument
  /// when the camera calibration is unusable or the IMU driver is missing.
  /// With a `mapd_link` (which must outlive this), every estimate, frame
  /// switch and stereo pair goes to mapd and mapd's frame-switch requests
  /// reach the filter. With an `image_logger`, the camera thread logs images.
  Roverd(const RoverdOptions& options, const RoverdDrivers& drivers,
         const EstimatorLogChannels& channels, EstimatorListener* listener = nullptr,
         MapdLink* mapd_link = nullptr, ImageLogger* image_logger = nullptr);
  ~Roverd();
  Roverd(const Roverd&) = delete;
  Roverd& operator=(const Roverd&) = delete;

  /// Runs the IMU loop on the calling thread until the IMU stream ends or
  /// Stop() is called, then stops the other threads and returns the totals.
  RoverdStats Run();
  /// Asks Run() to return (any thread, e.g. a signal handler's relay).
  void Stop();

  const EstimatorLoop& loop() const { return loop_; }

 private:
  struct FrameSlot {
    Time capture;
    cv::Mat cam0;
    cv::Mat cam1;
  };

  void ImuLoop(RoverdStats* stats);
  void CameraThread();
  void TriggerThread();
  /// The trigger thread, not the camera thread, requests the clones.
  bool TriggerClones() const { return drivers_.trigger != nullptr && !options_.lockstep; }
  void VoThread();
  void CanThread();
  void LinkThread();
  int AcquireSlot();

  RoverdOptions options_;
  RoverdDrivers drivers_;
  MapdLink* mapd_link_;
  ImageLogger* image_logger_;  // camera thread only
  ListenerPair listeners_;     // the caller's listener, then the mapd link
  EstimatorLoop loop_;
  std::optional<estimator::vo::StereoOdometry> vo_;
  LockstepGate gate_;
  runtime::LatencyHistogram step_latency_;
  runtime::LoopProbe probe_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> filter_init_ns_{0};  ///< IMU stamp when the filter started; 0: not yet

  std::vector<FrameSlot> slots_;
  SpscRing<int, 16> to_vo_;       // camera -> VO: filled slot indices
  SpscRing<int, 16> free_slots_;  // VO -> camera: slots to reuse
  std::atomic<uint64_t> frames_{0};
  std::atomic<uint64_t> frame_drops_{0};
  std::atomic<uint64_t> vo_measurements_{0};
  std::atomic<uint64_t> wheel_readings_{0};
  std::atomic<uint64_t> can_errors_{0};
  drivers::WheelSpeedDecoder decoder_;  // CAN thread only; read after join
  std::vector<std::unique_ptr<runtime::RtThread>> threads_;
  std::vector<std::string> thread_reports_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_ROVERD_H_
