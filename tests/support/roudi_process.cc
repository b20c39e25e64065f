#include "tests/support/roudi_process.h"

#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "core/ipc/iceoryx_transport.h"

namespace rover::testing {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration ToChrono(Duration d) { return std::chrono::nanoseconds(d.nanoseconds()); }

std::filesystem::path MakeLogDir() {
  std::string templ = (std::filesystem::temp_directory_path() / "rover_roudi_XXXXXX").string();
  std::vector<char> buffer(templ.begin(), templ.end());
  buffer.push_back('\0');
  if (mkdtemp(buffer.data()) == nullptr) {
    return {};
  }
  return buffer.data();
}

// Non-blocking reap. Returns true if the child has exited (and was reaped).
bool Reaped(pid_t pid) {
  int status = 0;
  const pid_t rc = ::waitpid(pid, &status, WNOHANG);
  return rc == pid || (rc < 0 && errno == ECHILD);
}

// Pids of running iox-roudi processes that were started with `config_file`
// and whose parent is gone (re-parented to init). Those are private RouDis of
// test processes that crashed: PR_SET_PDEATHSIG has sent them SIGTERM and
// they are shutting down, which takes a few seconds.
std::vector<pid_t> OrphanedTestRouDis(const std::filesystem::path& config_file) {
  std::vector<pid_t> orphans;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    std::ifstream cmdline_file(entry.path() / "cmdline");
    std::stringstream cmdline_text;
    cmdline_text << cmdline_file.rdbuf();
    const std::string cmdline = cmdline_text.str();
    if (cmdline.find("iox-roudi") == std::string::npos || config_file.empty() ||
        cmdline.find(config_file.string()) == std::string::npos) {
      continue;
    }
    std::ifstream status_file(entry.path() / "status");
    std::string line;
    while (std::getline(status_file, line)) {
      if (line.rfind("PPid:", 0) == 0 && std::stol(line.substr(5)) == 1) {
        orphans.push_back(static_cast<pid_t>(std::stol(name)));
      }
    }
  }
  return orphans;
}

// Waits until `pids` have exited or `timeout` passed; true if all exited.
bool WaitForExit(const std::vector<pid_t>& pids, Clock::duration timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  for (const pid_t pid : pids) {
    while (::kill(pid, 0) == 0) {
      if (Clock::now() >= deadline) {
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  return true;
}

}  // namespace

std::unique_ptr<RouDiProcess> RouDiProcess::Start(const Options& options, std::string* error) {
  auto fail = [error](std::string reason) -> std::unique_ptr<RouDiProcess> {
    if (error != nullptr) {
      *error = std::move(reason);
    }
    return nullptr;
  };
  if (ipc::IceoryxTransport::IsRouDiRunning()) {
    // A RouDi left by a crashed test process is on its way out; wait for it
    // rather than skipping every test that follows a crash.
    const std::vector<pid_t> orphans = OrphanedTestRouDis(options.config_file);
    if (!orphans.empty()) {
      WaitForExit(orphans, std::chrono::seconds(15));
    }
  }
  if (ipc::IceoryxTransport::IsRouDiRunning()) {
    return fail("another RouDi is already running (it answers on " +
                std::string(ipc::IceoryxTransport::RouDiSocketPath()) +
                "); iceoryx allows one per machine and the tests will not share it. Stop it "
                "(scripts/roudi.sh stop, or systemctl stop rover-roudi) to run these tests.");
  }
  const std::filesystem::path log_dir = MakeLogDir();
  if (log_dir.empty()) {
    return fail(std::string("cannot create a log directory: ") + std::strerror(errno));
  }
  const std::string log_path = (log_dir / "roudi.log").string();
  const int log_fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    return fail("cannot create " + log_path + ": " + std::strerror(errno));
  }

  // Everything the child needs is prepared before fork(): between fork and
  // exec only async-signal-safe calls are allowed.
  std::vector<std::string> args = {options.executable, "-l", options.log_level};
  if (!options.config_file.empty()) {
    args.push_back("-c");
    args.push_back(options.config_file.string());
  }
  std::vector<char*> argv;
  for (std::string& arg : args) {
    argv.push_back(arg.data());
  }
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    return fail(std::string("fork failed: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // Child. If the test process dies, RouDi gets SIGTERM and cleans up.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) {
      ::_exit(126);  // The parent died before prctl took effect.
    }
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(log_fd);

  std::unique_ptr<RouDiProcess> roudi(new RouDiProcess(pid, log_dir, options.stop_timeout));
  const Clock::time_point deadline = Clock::now() + ToChrono(options.ready_timeout);
  while (Clock::now() < deadline) {
    if (Reaped(pid)) {
      roudi->pid_ = -1;  // Nothing left to stop.
      return fail(options.executable + " exited during start-up. Its output:\n" + roudi->ReadLog());
    }
    if (ipc::IceoryxTransport::IsRouDiRunning()) {
      return roudi;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return fail(options.executable + " did not accept connections within " +
              options.ready_timeout.ToString() + ". Its output:\n" + roudi->ReadLog());
}

RouDiProcess::RouDiProcess(pid_t pid, std::filesystem::path log_dir, Duration stop_timeout)
    : pid_(pid), log_dir_(std::move(log_dir)), stop_timeout_(stop_timeout) {}

RouDiProcess::~RouDiProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    const Clock::time_point deadline = Clock::now() + ToChrono(stop_timeout_);
    bool reaped = Reaped(pid_);
    while (!reaped && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      reaped = Reaped(pid_);
    }
    if (!reaped) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  std::error_code ec;
  std::filesystem::remove_all(log_dir_, ec);
}

std::string RouDiProcess::ReadLog() const {
  std::ifstream in(log_dir_ / "roudi.log");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

RouDiProcess* SharedTestRouDi(const std::filesystem::path& config_file,
                              std::string* unavailable_reason) {
  static std::string failure;
  static const std::unique_ptr<RouDiProcess> instance = [&config_file] {
    RouDiProcess::Options options;
    options.config_file = config_file;
    return RouDiProcess::Start(options, &failure);
  }();
  if (instance == nullptr && unavailable_reason != nullptr) {
    *unavailable_reason = failure;
  }
  return instance.get();
}

bool OwnRouDiRequired() {
  const char* value = std::getenv("ROVER_REQUIRE_OWN_ROUDI");
  return value != nullptr && value[0] != '\0' && std::string_view(value) != "0";
}

std::string UniqueRuntimeName(std::string_view prefix) {
  return std::string(prefix) + "_" + std::to_string(::getpid());
}

}  // namespace rover::testing
