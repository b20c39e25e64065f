#ifndef ROVER_TESTS_SUPPORT_ROUDI_PROCESS_H_
#define ROVER_TESTS_SUPPORT_ROUDI_PROCESS_H_

// A private iox-roudi for tests that exercise iceoryx.
//
// Policy on an already running RouDi: the tests never share it. Its mempool
// configuration and its other clients are unknown, and our tests must not
// register with (or disturb) a rover that is actually running. iceoryx 2.0
// allows only one RouDi per machine, so in that case the iceoryx tests are
// skipped with a loud message, or fail if ROVER_REQUIRE_OWN_ROUDI=1 is set
// in the environment (set it in CI, where a skip would hide a regression).
// Within one ctest run the iceoryx tests hold the RESOURCE_LOCK "roudi", so
// they never race each other for the daemon.
//
// Clean-up: the destructor stops RouDi with SIGTERM (RouDi then unlinks its
// shared memory and socket), escalating to SIGKILL. If the test process dies
// without running destructors, PR_SET_PDEATHSIG delivers the SIGTERM. Files
// left by a RouDi killed with SIGKILL (/dev/shm/iceoryx_mgmt, /tmp/roudi,
// lock files) do not block the next start: iox-roudi 2.0.3 takes its lock
// with flock (released by the kernel) and unlinks the stale channel and
// shared memory itself (checked with kill -9 while writing this).

#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "core/time/time.h"

namespace rover::testing {

class RouDiProcess {
 public:
  struct Options {
    /// iox-roudi binary, looked up in PATH if it has no '/'.
    std::string executable = "iox-roudi";
    /// RouDi TOML config; empty for RouDi's built-in config (which reserves
    /// about 215 MB of shared memory and takes ~0.7 s to start).
    std::filesystem::path config_file;
    /// RouDi's -l argument.
    std::string log_level = "warning";
    /// How long Start() waits for RouDi to accept connections.
    Duration ready_timeout = Duration::Seconds(10);
    /// How long the destructor waits after SIGTERM before SIGKILL.
    Duration stop_timeout = Duration::Seconds(5);
  };

  /// Starts RouDi as a child process and waits until it accepts connections.
  /// Returns nullptr with the reason in `*error` if a RouDi is already
  /// running, the binary cannot be started, or it is not ready within
  /// ready_timeout (the reason then includes RouDi's output).
  static std::unique_ptr<RouDiProcess> Start(const Options& options, std::string* error);

  /// Stops RouDi (SIGTERM, then SIGKILL after stop_timeout) and reaps it.
  ~RouDiProcess();
  RouDiProcess(const RouDiProcess&) = delete;
  RouDiProcess& operator=(const RouDiProcess&) = delete;

  /// Process id of the RouDi child.
  pid_t pid() const { return pid_; }
  /// Everything RouDi has written to stdout/stderr so far.
  std::string ReadLog() const;

 private:
  RouDiProcess(pid_t pid, std::filesystem::path log_dir, Duration stop_timeout);

  pid_t pid_;
  std::filesystem::path log_dir_;
  Duration stop_timeout_;
};

/// The RouDi shared by all iceoryx tests of this test process, started with
/// `config_file` on the first call (later calls ignore the argument).
/// Returns nullptr and the reason in `*unavailable_reason` if it could not
/// be started (the reason is remembered, later calls fail the same way).
///
/// It is stopped at process exit, after the iceoryx runtime has deregistered:
/// both are function-local statics and this one is constructed first, so it
/// is destroyed last. The order matters: a RouDi shutting down sends SIGTERM
/// to every process still registered with it. Call this before the first
/// IceoryxTransport::Create of the process.
RouDiProcess* SharedTestRouDi(const std::filesystem::path& config_file,
                              std::string* unavailable_reason);

/// True if ROVER_REQUIRE_OWN_ROUDI is set to a non-empty value other than
/// "0": tests must then fail, not skip, when SharedTestRouDi() is null.
bool OwnRouDiRequired();

/// "<prefix>_<pid>": a runtime name no other live process uses.
std::string UniqueRuntimeName(std::string_view prefix);

}  // namespace rover::testing

#endif  // ROVER_TESTS_SUPPORT_ROUDI_PROCESS_H_
