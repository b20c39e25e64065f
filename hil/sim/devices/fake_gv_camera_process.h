#ifndef ROVER_HIL_SIM_DEVICES_FAKE_GV_CAMERA_PROCESS_H_
#define ROVER_HIL_SIM_DEVICES_FAKE_GV_CAMERA_PROCESS_H_

// arv-fake-gv-camera-0.8 (Debian package aravis-tools) as a child process:
// a GigE Vision camera on 127.0.0.1 that speaks real GVCP/GVSP over UDP, for
// the tests and benches of drivers::AravisCamera. Each instance has its own
// serial, so several runs on one machine do not pick each other's camera.

#include <sys/types.h>

#include <string>

#include "core/time/time.h"

namespace rover::sim {

struct FakeGvCameraOptions {
  /// The camera's serial; its Aravis device id is "Aravis-Fake-<serial>".
  std::string serial;
  /// Packets the camera drops on purpose, per thousand (its -r option).
  int lost_packets_per_thousand = 0;
  /// How long Start() waits for Aravis discovery to list the camera.
  Duration discovery_timeout = Duration::Seconds(20);
};

class FakeGvCameraProcess {
 public:
  explicit FakeGvCameraProcess(FakeGvCameraOptions options);
  /// Kills the process if it runs.
  ~FakeGvCameraProcess();
  FakeGvCameraProcess(const FakeGvCameraProcess&) = delete;
  FakeGvCameraProcess& operator=(const FakeGvCameraProcess&) = delete;

  /// Starts the process (its output goes to /dev/null: its warnings about
  /// unknown GVCP commands and heartbeats are expected) and waits until
  /// Aravis discovery lists its serial. Throws std::runtime_error naming the
  /// program and what failed: not installed (not in PATH), not started, or
  /// not discovered in time (the process is then killed).
  void Start();
  /// SIGKILL and reap; nothing if not running. Start() may follow.
  void Kill();

  /// The running process, or -1.
  pid_t pid() const { return pid_; }
  const std::string& serial() const { return options_.serial; }
  /// The id Aravis lists it under.
  std::string device_id() const { return "Aravis-Fake-" + options_.serial; }

  /// The program's name.
  static constexpr const char* kProgram = "arv-fake-gv-camera-0.8";
  /// Its path in PATH, or "" when aravis-tools is not installed.
  static std::string FindProgram();

 private:
  FakeGvCameraOptions options_;
  pid_t pid_ = -1;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_DEVICES_FAKE_GV_CAMERA_PROCESS_H_
