#ifndef ROVER_FIRMWARE_RUNTIME_PROCESS_CHILD_PROCESS_H_
#define ROVER_FIRMWARE_RUNTIME_PROCESS_CHILD_PROCESS_H_

// A child process started by a launcher (rover-launch, tests): spawn, signal,
// wait with a timeout, and a readable account of how it ended. On a board
// systemd does this job; the launcher does it on a development machine and
// in the simulated mission.
//
// The child gets PR_SET_PDEATHSIG(SIGTERM), so a launcher that dies without
// cleaning up does not leave a RouDi or a mapd behind.

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

#include "core/time/time.h"

namespace rover::runtime {

/// How a child process ended.
struct ExitStatus {
  bool exited = false;    ///< exit() or return from main
  int exit_code = 0;      ///< when `exited`
  bool signaled = false;  ///< killed by a signal
  int signal = 0;         ///< when `signaled`

  /// True if it exited with status 0.
  bool ok() const { return exited && exit_code == 0; }
  /// "exited with status 3", "killed by signal 9 (Killed)".
  std::string Describe() const;
};

class ChildProcess {
 public:
  struct Options {
    /// argv[0] is looked up in PATH if it has no '/'.
    std::vector<std::string> argv{};
    /// Extra environment entries "NAME=value" on top of the parent's.
    std::vector<std::string> environment{};
    /// If non-empty, stdout and stderr go to this file (appended), else they
    /// are the parent's.
    std::string output_file{};
  };

  /// Starts the child. Throws std::runtime_error naming the program if
  /// fork() fails or the program cannot be executed (exec failure is
  /// reported by the child through a close-on-exec pipe, so "not found" is an
  /// error here rather than a mysterious exit status 127 later).
  static ChildProcess Spawn(const Options& options);

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  /// Stops a child still running: Terminate() with a 5 s grace.
  ~ChildProcess();

  pid_t pid() const { return pid_; }
  /// The program name, for messages.
  const std::string& name() const { return name_; }

  /// Sends `signal` if the child has not been reaped yet; false otherwise.
  bool Signal(int signal) const;

  /// Reaps the child if it has ended; never blocks.
  std::optional<ExitStatus> TryWait();

  /// Waits up to `timeout` for the child to end (nullopt if it is still
  /// running). Polls every few milliseconds.
  std::optional<ExitStatus> WaitFor(Duration timeout);

  /// SIGTERM, then SIGKILL if it has not ended within `grace`; reaps it.
  ExitStatus Terminate(Duration grace);

  /// The exit status once reaped.
  const std::optional<ExitStatus>& status() const { return status_; }

 private:
  ChildProcess(pid_t pid, std::string name) : pid_(pid), name_(std::move(name)) {}

  pid_t pid_ = -1;
  std::string name_;
  std::optional<ExitStatus> status_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_PROCESS_CHILD_PROCESS_H_
