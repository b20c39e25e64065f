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

#include "core/calib/camera_model.h"
#include "core/log/msgs/diagnostic_msgs.h"
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
#include "firmware/runtime/board/board_config.h"
#include "firmware/runtime/health/health_options.h"
#include "firmware/runtime/health/health_report.h"
#include "firmware/runtime/health/sensor_monitor.h"
#include "firmware/runtime/health/systemd_notifier.h"
#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/loop_probe.h"
#include "firmware/runtime/rt/rt_thread.h"
#include "firmware/runtime/rt/rt_thread_options.h"

namespace rover::roverd {

/// The stereo head: calibration and VO options (absent: no VO).
struct CameraSetup {
  calib::CameraModel cam0;
  calib::CameraModel cam1;
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
  /// The health thread: sensor rates, gaps, drops and latency, filter and
  /// loop status, once per period to the log, mapd's link and systemd.
  runtime::HealthOptions health;
  runtime::RtThreadOptions health_thread{"health", 0, 0, {}, 64 * 1024};
  /// Nominal rate of the CAN wheel readings (one per SYNC).
  double wheel_rate_hz = 100.0;
};

/// Takes the board profile's scheduling of the worker threads and its health
/// settings (the IMU thread is its caller's, see RoverdProcessOptions).
void ApplyBoard(const runtime::BoardConfig& board, RoverdOptions* options);

/// The flight-log channel of the health reports.
using DiagnosticsChannel = log::LogChannel<log::diagnostic_msgs::DiagnosticArray, 16384, 64>;

/// Where roverd's outputs go besides the estimator's log channels; each may
/// be null. They must outlive the Roverd.
struct RoverdOutputs {
  EstimatorListener* listener = nullptr;      ///< IMU thread, after each estimate
  MapdLink* mapd_link = nullptr;              ///< estimates, frames, health out; requests in
  ImageLogger* images = nullptr;              ///< camera thread
  DiagnosticsChannel* diagnostics = nullptr;  ///< health thread
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
  /// Health reports made, and the last one as one line.
  uint64_t health_reports = 0;
  std::string health;
  uint64_t watchdog_pings = 0;
};

class Roverd {
 public:
  /// Sets everything up (threads start in Run()). Throws std::invalid_argument
  /// when the camera calibration is unusable, the IMU driver is missing or
  /// the health options are invalid.
  Roverd(const RoverdOptions& options, const RoverdDrivers& drivers,
         const EstimatorLogChannels& channels, const RoverdOutputs& outputs = {});
  ~Roverd();
  Roverd(const Roverd&) = delete;
  Roverd& operator=(const Roverd&) = delete;

  /// Starts the streams of the devices that must not run ahead of their
  /// reader (ImuDriver::Start, CanBus::Start): call once, last thing before
  /// Run(), on a thread that may block and throw (the drivers' start-up
  /// errors). Without it the devices stream from their construction on.
  void StartDevices();
  /// Runs the IMU loop on the calling thread until the IMU stream ends or
  /// Stop() is called, then stops the other threads and returns the totals.
  RoverdStats Run();
  /// Asks Run() to return (any thread, e.g. a signal handler's relay).
  void Stop();

  const EstimatorLoop& loop() const { return loop_; }
  /// Counters while running, for status lines. Any thread.
  struct LiveCounters {
    uint64_t imu_samples = 0;
    uint64_t frames = 0;
    uint64_t frame_drops = 0;
    uint64_t wheel_readings = 0;
    uint64_t vo_measurements = 0;
  };
  LiveCounters live() const {
    return {imu_steps_.load(std::memory_order_relaxed), frames_.load(std::memory_order_relaxed),
            frame_drops_.load(std::memory_order_relaxed),
            wheel_readings_.load(std::memory_order_relaxed),
            vo_measurements_.load(std::memory_order_relaxed)};
  }
  /// Stamp of the newest IMU sample the loop has processed (zero before the
  /// first). Any thread.
  Time latest_imu_stamp() const {
    return Time::FromNanoseconds(latest_imu_ns_.load(std::memory_order_relaxed));
  }

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
  void HealthThread();
  void SleepFor(Duration d) const;
  void PublishFilterHealth(Time imu_stamp);
  /// The clock the sensor monitors run on: CLOCK_MONOTONIC in real time,
  /// the sensors' own (simulated) stamps in lockstep.
  Time MonitorClock(Time sensor_stamp) const;
  /// One health cycle: report to the log, mapd's link and systemd. Health
  /// thread, or the caller of Run() once it has stopped.
  void Report(Time wall_now);
  runtime::HealthReport BuildHealthReport(Time wall_now);
  int AcquireSlot();

  RoverdOptions options_;
  RoverdDrivers drivers_;
  RoverdOutputs outputs_;
  ListenerPair listeners_;  // the caller's listener, then the mapd link
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
  // Health: one monitor per sensor (producer: its thread; reader: health).
  runtime::SensorMonitor imu_monitor_;
  runtime::SensorMonitor camera_monitor_;
  runtime::SensorMonitor wheel_monitor_;
  runtime::SystemdNotifier notifier_;
  // The filter's state as the IMU thread last saw it, for the health thread.
  std::atomic<uint32_t> filter_status_{0};
  std::atomic<uint64_t> relative_poses_accepted_{0};
  std::atomic<uint64_t> relative_poses_rejected_{0};
  std::atomic<uint64_t> wheel_speeds_accepted_{0};
  std::atomic<uint64_t> imu_steps_{0};
  std::atomic<int64_t> latest_imu_ns_{0};
  // Written by the health thread, read after it is joined.
  uint64_t health_reports_ = 0;
  uint64_t watchdog_pings_ = 0;
  std::string last_health_;
  std::vector<std::unique_ptr<runtime::RtThread>> threads_;
  std::vector<std::string> thread_reports_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_ROVERD_H_
