#include "firmware/runtime/rt/rt_thread.h"

#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <latch>
#include <utility>

namespace rover::runtime {
namespace {

SchedPolicy PolicyFromKernel(int policy) {
  switch (policy) {
    case SCHED_OTHER:
      return SchedPolicy::kOther;
    case SCHED_FIFO:
      return SchedPolicy::kFifo;
    case SCHED_RR:
      return SchedPolicy::kRoundRobin;
    default:
      return SchedPolicy::kUnknown;
  }
}

std::string CpuList(const std::vector<int>& cpus) {
  std::string text;
  for (const int cpu : cpus) {
    if (!text.empty()) text += ",";
    text += std::to_string(cpu);
  }
  return text;
}

}  // namespace

const char* SchedPolicyName(SchedPolicy policy) {
  switch (policy) {
    case SchedPolicy::kOther:
      return "SCHED_OTHER";
    case SchedPolicy::kFifo:
      return "SCHED_FIFO";
    case SchedPolicy::kRoundRobin:
      return "SCHED_RR";
    case SchedPolicy::kUnknown:
      break;
  }
  return "unknown policy";
}

bool RtThreadReport::degraded() const {
  return (requested_priority > 0 && policy != SchedPolicy::kFifo) || affinity_errno != 0 ||
         nice_errno != 0;
}

std::string RtThreadReport::Describe() const {
  std::string text = name + ": " + SchedPolicyName(policy);
  if (policy == SchedPolicy::kFifo || policy == SchedPolicy::kRoundRobin) {
    text += " " + std::to_string(priority);
  } else {
    text += " nice " + std::to_string(nice);
  }
  if (sched_errno != 0) {
    text += " (SCHED_FIFO " + std::to_string(requested_priority) +
            " refused: " + RtSetup::ErrnoName(sched_errno) + ")";
  }
  if (nice_errno != 0) text += " (nice refused: " + RtSetup::ErrnoName(nice_errno) + ")";
  text += cpus.empty() ? ", any CPU" : ", cpus " + CpuList(cpus);
  if (affinity_errno != 0) {
    text += " (affinity refused: " + RtSetup::ErrnoName(affinity_errno) + ")";
  }
  text += ", " + std::to_string(stack_prefaulted_bytes / 1024) + " KiB stack prefaulted";
  return text;
}

RtThread::RtThread(const RtThreadOptions& options, Body body, SetSchedParamFn set_sched_param) {
  options.Validate();
  std::latch configured(1);
  // `options` and `configured` outlive their use: the thread reads them only
  // before count_down(), and this constructor waits for that.
  thread_ = std::jthread(
      [this, &options, &configured, set_sched_param, body = std::move(body)](std::stop_token stop) {
        Configure(options, set_sched_param);
        configured.count_down();
        body(std::move(stop));
      });
  configured.wait();
}

RtThread::~RtThread() {
  RequestStop();
  Join();
}

void RtThread::Join() {
  if (thread_.joinable()) thread_.join();
}

void RtThread::Configure(const RtThreadOptions& options, SetSchedParamFn set_sched_param) {
  RtThreadReport& r = report_;
  r.name = options.name;
  r.requested_priority = options.priority;
  r.cpus = options.cpus;
  const pthread_t self = pthread_self();
  const auto tid = static_cast<id_t>(gettid());

  r.name_set = pthread_setname_np(self, options.name.c_str()) == 0;

  if (!options.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (const int cpu : options.cpus) CPU_SET(static_cast<std::size_t>(cpu), &set);
    r.affinity_errno = pthread_setaffinity_np(self, sizeof(set), &set);
    r.affinity_set = r.affinity_errno == 0;
  }

  bool fifo = false;
  if (options.priority > 0) {
    sched_param param{};
    param.sched_priority = options.priority;
    r.sched_errno = set_sched_param(self, SCHED_FIFO, &param);
    fifo = r.sched_errno == 0;
  }
  if (!fifo) {
    // A thread inherits its creator's policy: drop to SCHED_OTHER explicitly
    // (always permitted), then apply the nice value.
    sched_param param{};
    param.sched_priority = 0;
    pthread_setschedparam(self, SCHED_OTHER, &param);
    errno = 0;
    const int current_nice = getpriority(PRIO_PROCESS, tid);
    if (errno == 0 && current_nice != options.nice &&
        setpriority(PRIO_PROCESS, tid, options.nice) != 0) {
      r.nice_errno = errno;
    }
  }

  int policy = 0;
  sched_param obtained{};
  if (pthread_getschedparam(self, &policy, &obtained) == 0) {
    r.policy = PolicyFromKernel(policy);
    r.priority = obtained.sched_priority;
  }
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, tid);
  r.nice = errno == 0 ? nice : 0;

  r.stack_prefaulted_bytes = RtSetup::PrefaultStack(options.stack_prefault_bytes);
}

}  // namespace rover::runtime
