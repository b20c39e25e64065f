#include "hil/sim/devices/fake_gv_camera_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>
#include <vector>

#include "drivers/camera/aravis_camera.h"

extern char** environ;

namespace rover::sim {

FakeGvCameraProcess::FakeGvCameraProcess(FakeGvCameraOptions options)
    : options_(std::move(options)) {}

FakeGvCameraProcess::~FakeGvCameraProcess() { Kill(); }

std::string FakeGvCameraProcess::FindProgram() {
  const char* path = std::getenv("PATH");
  const std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path candidate =
        std::filesystem::path(dirs.substr(start, end - start)) / kProgram;
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return {};
}

void FakeGvCameraProcess::Start() {
  Kill();
  const std::string binary = FindProgram();
  if (binary.empty()) {
    throw std::runtime_error(std::string(kProgram) +
                             ": not found in PATH (install the package aravis-tools)");
  }
  std::vector<std::string> args = {binary, "-i", "127.0.0.1", "-s", options_.serial};
  if (options_.lost_packets_per_thousand > 0) {
    args.push_back("-r");
    args.push_back(std::to_string(options_.lost_packets_per_thousand));
  }
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  const int rc = posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    pid_ = -1;
    throw std::runtime_error("cannot start " + binary + ": " + std::strerror(rc));
  }
  const Time deadline = Time::Now() + options_.discovery_timeout;
  while (Time::Now() < deadline) {
    for (const drivers::AravisDeviceInfo& d : drivers::AravisCamera::ListDevices()) {
      if (d.serial == options_.serial) return;
    }
  }
  Kill();
  throw std::runtime_error(std::string(kProgram) + " with serial " + options_.serial +
                           " was not discovered within " + options_.discovery_timeout.ToString());
}

void FakeGvCameraProcess::Kill() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
}

}  // namespace rover::sim
