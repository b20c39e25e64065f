#include "firmware/runtime/rt/rt_thread_options.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <thread>

namespace rover::runtime {

RtThreadOptions RtThreadOptions::Load(const ConfigNode& node, const std::string& default_name) {
  RtThreadOptions o;
  o.name = node.Get<std::string>("name", default_name);
  o.priority = node.GetInRange<int>("priority", 0, 99, o.priority);
  o.nice = node.GetInRange<int>("nice", -20, 19, o.nice);
  o.cpus = node.Get<std::vector<int>>("cpus", o.cpus);
  o.stack_prefault_bytes = node.GetInRange<std::size_t>(
      "stack_prefault_bytes", 0, kMaxStackPrefaultBytes, o.stack_prefault_bytes);
  if (const auto problem = o.Problem()) node.Fail(problem->first, problem->second);
  return o;
}

std::optional<std::pair<std::string, std::string>> RtThreadOptions::Problem() const {
  using Result = std::pair<std::string, std::string>;
  if (name.empty() || name.size() > kMaxNameLength) {
    return Result{"name", "expected 1 to " + std::to_string(kMaxNameLength) +
                              " characters, found \"" + name + "\" (" +
                              std::to_string(name.size()) + ")"};
  }
  if (priority < 0 || priority > 99) {
    return Result{"priority",
                  "expected a SCHED_FIFO priority in [0, 99] (0 = SCHED_OTHER), found " +
                      std::to_string(priority)};
  }
  if (nice < -20 || nice > 19) {
    return Result{"nice", "expected a nice value in [-20, 19], found " + std::to_string(nice)};
  }
  const int cpu_count = static_cast<int>(std::thread::hardware_concurrency());
  for (std::size_t i = 0; i < cpus.size(); ++i) {
    const int cpu = cpus[i];
    if (cpu < 0 || (cpu_count > 0 && cpu >= cpu_count)) {
      return Result{"cpus", "expected CPU ids in [0, " + std::to_string(cpu_count) +
                                ") (this machine's CPUs), found " + std::to_string(cpu)};
    }
    if (std::find(cpus.begin(), cpus.begin() + static_cast<std::ptrdiff_t>(i), cpu) !=
        cpus.begin() + static_cast<std::ptrdiff_t>(i)) {
      return Result{"cpus", "expected each CPU id once, found " + std::to_string(cpu) + " twice"};
    }
  }
  if (stack_prefault_bytes > kMaxStackPrefaultBytes) {
    return Result{"stack_prefault_bytes",
                  "expected at most " + std::to_string(kMaxStackPrefaultBytes) + " bytes, found " +
                      std::to_string(stack_prefault_bytes)};
  }
  return std::nullopt;
}

void RtThreadOptions::Validate() const {
  if (const auto problem = Problem()) {
    throw std::invalid_argument("RtThreadOptions." + problem->first + ": " + problem->second);
  }
}

}  // namespace rover::runtime
