#ifndef ROVER_FIRMWARE_ROVERD_ROVERD_PROCESS_H_
#define ROVER_FIRMWARE_ROVERD_ROVERD_PROCESS_H_

// Everything around Roverd that makes it the roverd process, whatever its
// drivers (the simulator's, a replayed dataset, the hardware): the flight
// log with the estimator's channels, images and health; the iceoryx link to
// mapd; the board's HTTP log service; real-time set-up and the IMU thread.
// roverd (firmware/roverd/roverd_main.cc) and roverd-sim (hil/sim/mission)
// both run through it, so the simulator exercises exactly the board's
// wiring.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "core/ipc/iceoryx_transport.h"
#include "core/log/flight/flight_log.h"
#include "firmware/roverd/roverd.h"
#include "firmware/runtime/log_service/log_service_options.h"

namespace rover::runtime {
class LogService;
}

namespace rover::roverd {

struct RoverdProcessOptions {
  /// The flight log to write (an existing file is replaced).
  std::string log_path;
  /// Metadata records written first: name -> key/value pairs.
  std::map<std::string, std::map<std::string, std::string>> metadata;
  /// iceoryx runtime name for the mapd link; empty: no link.
  std::string ipc_runtime_name;
  Duration roudi_wait = Duration::Seconds(5);
  ImageLogOptions images;
  /// The HTTP log service; absent: none.
  std::optional<runtime::LogServiceOptions> log_service;
  /// Real time (not lockstep): lock memory first (if asked) and run the IMU
  /// loop on an RtThread with these options.
  bool lock_memory = true;
  runtime::RtThreadOptions imu_thread{"imu", 80, 0, {}, 256 * 1024};
  /// Program name for the real-time set-up's messages.
  std::string program_name = "roverd";
};

/// What the process did besides RoverdStats.
struct RoverdProcessResult {
  RoverdStats stats;
  std::optional<MapdLinkStats> mapd_link;
  log::FlightLogStats log;
  int log_service_port = 0;  ///< 0: no service
};

class RoverdProcess {
 public:
  /// Opens the log, connects to RouDi and starts the log service. Throws
  /// with the reason (log path, RouDi, bind address) if any of it fails.
  /// `listener` (may be null) sees every estimate on the IMU thread.
  RoverdProcess(const RoverdOptions& roverd_options, const RoverdDrivers& drivers,
                const RoverdProcessOptions& options, EstimatorListener* listener = nullptr);
  ~RoverdProcess();
  RoverdProcess(const RoverdProcess&) = delete;
  RoverdProcess& operator=(const RoverdProcess&) = delete;

  /// Runs until the IMU stream ends or Stop(); closes the log. Throws if the
  /// log could not be written.
  RoverdProcessResult Run();
  /// Any thread (e.g. a signal relay).
  void Stop() { roverd_->Stop(); }

  const Roverd& roverd() const { return *roverd_; }
  /// Null without a link.
  const MapdLink* mapd_link() const { return mapd_link_ ? &*mapd_link_ : nullptr; }

 private:
  static log::FlightLogOptions LogOptions(bool lockstep, const RoverdProcess* self);

  RoverdProcessOptions options_;
  bool lockstep_;
  log::FlightLog flight_log_;
  std::unique_ptr<ImageLogger> images_;
  std::unique_ptr<ipc::IceoryxTransport> transport_;
  std::optional<MapdLink> mapd_link_;
  std::unique_ptr<runtime::LogService> log_service_;
  std::unique_ptr<Roverd> roverd_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_ROVERD_PROCESS_H_
