// Real-time loop latency, measured by the firmware's own primitives: a
// SCHED_FIFO RtThread paced by a PeriodicTimer, with a LoopProbe recording
// per tick
//   - wake-up latency (wake - deadline) of every wake-up from a sleep, the
//     figure cyclictest reports (a slot served late straight after an
//     overrun has no wake-up; it is counted as a late tick), and
//   - sample-to-estimate latency: the tick's deadline stands for the IMU
//     sample time; a fixed synthetic work item (arithmetic calibrated once to
//     about --work-us) stands for the estimator step, and the estimate is
//     "published" when it ends.
// Printed as figures (never a timed test). scripts/rt_latency.sh runs it
// beside cyclictest with the same priority, period and loop count.
//
// Like cyclictest (unless --default-system), it locks memory and holds
// /dev/cpu_dma_latency at 0 us while it runs, so both see the same power
// management.
//
// usage: bench_rt_loop [--priority 80] [--period-us 1000] [--duration-s 10 | --loops N]
//                      [--work-us 10] [--cpu -1] [--histfile PATH] [--hist-max-us 10000]

#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stop_token>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/loop_probe.h"
#include "firmware/runtime/rt/periodic_timer.h"
#include "firmware/runtime/rt/rt_setup.h"
#include "firmware/runtime/rt/rt_thread.h"

namespace {

using rover::Duration;
using rover::Time;
using rover::runtime::LatencyHistogram;
using rover::runtime::LatencySummary;
using rover::runtime::LoopProbe;
using rover::runtime::PeriodicTimer;
using rover::runtime::RtSetup;
using rover::runtime::RtSetupOptions;
using rover::runtime::RtThread;
using rover::runtime::RtThreadOptions;

struct Args {
  int priority = 80;
  int64_t period_us = 1000;
  double duration_s = 10.0;
  int64_t loops = 0;
  double work_us = 10.0;
  int cpu = -1;
  std::string histfile;
  int hist_max_us = 10000;
};

// The synthetic estimator step: a dependent chain of floating-point
// operations whose length is fixed after calibration.
[[gnu::noinline]] double Work(int64_t iterations, double seed) {
  double x = seed;
  double y = 0.0;
  for (int64_t i = 0; i < iterations; ++i) {
    x = x * 1.000000119 + 1e-7;
    y += x * 0.5;
  }
  return x + y;
}

volatile double g_sink = 0.0;

// Iterations of Work() that take about `work_us`, from the fastest of several
// timed trials (the least disturbed one).
int64_t CalibrateWork(double work_us) {
  constexpr int64_t kTrialIterations = 20'000;
  double best_ns_per_iteration = 1e9;
  for (int trial = 0; trial < 20; ++trial) {
    const Time start = Time::Now();
    g_sink = Work(kTrialIterations, g_sink + 1.0);
    const double ns = static_cast<double>((Time::Now() - start).nanoseconds());
    best_ns_per_iteration = std::min(best_ns_per_iteration, ns / kTrialIterations);
  }
  return std::max<int64_t>(1, std::llround(work_us * 1e3 / best_ns_per_iteration));
}

// Whole microseconds, truncated as cyclictest truncates.
int64_t Us(int64_t ns) { return ns / 1000; }

void PrintRow(const char* label, const LatencySummary& s) {
  std::printf("  %-20s %10" PRIu64 " %9" PRId64 " %9" PRId64 " %9" PRId64 " %9" PRId64 " %9.1f\n",
              label, s.count, Us(s.p50_ns), Us(s.p99_ns), Us(s.p999_ns), Us(s.max_ns),
              s.mean_ns * 1e-3);
}

// Counts per whole microsecond in [0, max_us), as cyclictest's histogram has
// them; above 1024 us each coarse bucket is attributed to its lower edge.
std::vector<uint64_t> PerMicrosecond(const LatencyHistogram& h, int max_us, uint64_t* overflow) {
  std::vector<uint64_t> out(static_cast<std::size_t>(max_us), 0);
  *overflow = 0;
  for (int b = 0; b < LatencyHistogram::kBucketCount; ++b) {
    const uint64_t n = h.bucket_count(b);
    if (n == 0) continue;
    const int64_t us = LatencyHistogram::BucketLowerNs(b) / 1000;
    if (us < max_us) {
      out[static_cast<std::size_t>(us)] += n;
    } else {
      *overflow += n;
    }
  }
  return out;
}

// Writes the wake-up (column 2) and sample-to-estimate (column 3) histograms
// in cyclictest's --histfile layout, so one parser reads both tools.
bool WriteHistfile(const std::string& path, const LoopProbe& probe, int max_us) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  uint64_t wake_over = 0;
  uint64_t est_over = 0;
  const std::vector<uint64_t> wake = PerMicrosecond(probe.wakeup_latency(), max_us, &wake_over);
  const std::vector<uint64_t> est = PerMicrosecond(probe.sample_to_estimate(), max_us, &est_over);
  const LatencySummary ws = probe.wakeup_latency().Summarize();
  const LatencySummary es = probe.sample_to_estimate().Summarize();
  std::fprintf(f, "# Histogram (bench_rt_loop: wake-up latency, sample-to-estimate latency)\n");
  for (std::size_t us = 0; us < wake.size(); ++us) {
    std::fprintf(f, "%06zu %06" PRIu64 " %06" PRIu64 "\n", us, wake[us], est[us]);
  }
  std::fprintf(f, "# Total: %09" PRIu64 " %09" PRIu64 "\n", ws.count - wake_over,
               es.count - est_over);
  std::fprintf(f, "# Min Latencies: %05" PRId64 " %05" PRId64 "\n", ws.min_ns / 1000,
               es.min_ns / 1000);
  std::fprintf(f, "# Avg Latencies: %05.0f %05.0f\n", ws.mean_ns * 1e-3, es.mean_ns * 1e-3);
  std::fprintf(f, "# Max Latencies: %05" PRId64 " %05" PRId64 "\n", ws.max_ns / 1000,
               es.max_ns / 1000);
  std::fprintf(f, "# Histogram Overflows: %05" PRIu64 " %05" PRIu64 "\n", wake_over, est_over);
  return std::fclose(f) == 0;
}

// Holds /dev/cpu_dma_latency at 0 us while alive (as cyclictest does).
class PmQosGuard {
 public:
  PmQosGuard() {
    fd_ = ::open("/dev/cpu_dma_latency", O_RDWR | O_CLOEXEC);
    if (fd_ < 0) return;
    const int32_t zero = 0;
    if (::write(fd_, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~PmQosGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  PmQosGuard(const PmQosGuard&) = delete;
  PmQosGuard& operator=(const PmQosGuard&) = delete;
  bool active() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{"Real-time loop latency with PeriodicTimer + LoopProbe (compare with cyclictest)"};
  app.add_option("--priority", args.priority, "SCHED_FIFO priority of the loop (0: SCHED_OTHER)")
      ->check(CLI::Range(0, 99));
  app.add_option("--period-us", args.period_us, "loop period in microseconds")
      ->check(CLI::Range(int64_t{50}, int64_t{1'000'000}));
  app.add_option("--duration-s", args.duration_s, "run time in seconds (ignored with --loops)")
      ->check(CLI::Range(0.01, 86400.0));
  app.add_option("--loops", args.loops, "number of loop iterations (as cyclictest -l)")
      ->check(CLI::Range(int64_t{1}, int64_t{1'000'000'000}));
  app.add_option("--work-us", args.work_us, "synthetic estimator work per tick in microseconds")
      ->check(CLI::Range(0.0, 500.0));
  app.add_option("--cpu", args.cpu, "pin the loop to this CPU (-1: any CPU)");
  app.add_option("--histfile", args.histfile,
                 "write wake-up and estimate histograms here, in cyclictest's layout");
  app.add_option("--hist-max-us", args.hist_max_us, "histogram range for --histfile (us)")
      ->check(CLI::Range(10, 1'000'000));
  CLI11_PARSE(app, argc, argv);
  const int64_t loops =
      args.loops > 0 ? args.loops
                     : std::llround(args.duration_s * 1e6 / static_cast<double>(args.period_us));

  RtSetupOptions setup_options;
  setup_options.program_name = "bench_rt_loop";
  const rover::runtime::RtSetupReport setup = RtSetup::Apply(setup_options);
  if (!setup.warning.empty()) std::fprintf(stderr, "%s\n", setup.warning.c_str());
  const PmQosGuard pm_qos;

  const int64_t work_iterations = args.work_us > 0 ? CalibrateWork(args.work_us) : 0;
  const Duration period = Duration::Microseconds(args.period_us);
  auto probe = std::make_unique<LoopProbe>(period);
  auto work_time = std::make_unique<LatencyHistogram>();

  RtThreadOptions thread_options;
  thread_options.name = "rt_loop";
  thread_options.priority = args.priority;
  if (args.cpu >= 0) thread_options.cpus = {args.cpu};
  thread_options.stack_prefault_bytes = 64 * 1024;
  try {
    thread_options.Validate();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_rt_loop: %s\n", e.what());
    return 2;
  }

  RtThread loop(thread_options, [&](std::stop_token stop) {
    PeriodicTimer timer(period);
    double state = 1.0;
    for (int64_t i = 0; i < loops && !stop.stop_requested(); ++i) {
      const PeriodicTimer::Tick tick = timer.WaitNext();
      probe->OnWake(tick);
      const Time work_start = Time::Now();
      state = Work(work_iterations, state);
      const Time published = Time::Now();
      probe->OnEstimatePublished(tick.deadline, published);
      work_time->Record((published - work_start).nanoseconds());
    }
    g_sink = state;
  });
  std::printf("bench_rt_loop: %s; %" PRId64 " loops of %" PRId64 " us, work %.1f us (%" PRId64
              " iterations); memory %s; pm_qos %s\n",
              loop.report().Describe().c_str(), loops, args.period_us, args.work_us,
              work_iterations, setup.memory_locked ? "locked" : "NOT locked",
              pm_qos.active() ? "0 us" : "unavailable");
  loop.Join();

  const rover::runtime::LoopProbeSnapshot s = probe->Snapshot();
  const LatencySummary work = work_time->Summarize();
  std::printf("  %-20s %10s %9s %9s %9s %9s %9s\n", "us", "count", "p50", "p99", "p99.9", "max",
              "mean");
  PrintRow("wake-up latency", s.wakeup_latency);
  PrintRow("period jitter", s.period_jitter);
  PrintRow("sample-to-estimate", s.sample_to_estimate);
  PrintRow("work item", work);
  std::printf("  ticks %" PRIu64 ", missed periods %" PRIu64
              ", late ticks (served after an overrun without sleeping, not in wake-up "
              "latency) %" PRIu64 "\n",
              s.ticks, s.missed_periods, s.late_ticks);
  if (!args.histfile.empty() && !WriteHistfile(args.histfile, *probe, args.hist_max_us)) {
    std::fprintf(stderr, "bench_rt_loop: cannot write histogram file %s\n", args.histfile.c_str());
    return 1;
  }
  const bool fifo = loop.report().policy == rover::runtime::SchedPolicy::kFifo;
  std::printf("RESULT period_us=%" PRId64 " priority=%d policy=%s loops=%" PRIu64 " missed=%" PRIu64
              " late=%" PRIu64 " wake_us_p50=%" PRId64 " wake_us_p99=%" PRId64
              " wake_us_p999=%" PRId64 " wake_us_max=%" PRId64 " est_us_p50=%" PRId64
              " est_us_p99=%" PRId64 " est_us_p999=%" PRId64 " est_us_max=%" PRId64
              " work_us_p50=%" PRId64 "\n",
              args.period_us, fifo ? loop.report().priority : 0,
              rover::runtime::SchedPolicyName(loop.report().policy), s.ticks, s.missed_periods,
              s.late_ticks, Us(s.wakeup_latency.p50_ns), Us(s.wakeup_latency.p99_ns),
              Us(s.wakeup_latency.p999_ns), Us(s.wakeup_latency.max_ns),
              Us(s.sample_to_estimate.p50_ns), Us(s.sample_to_estimate.p99_ns),
              Us(s.sample_to_estimate.p999_ns), Us(s.sample_to_estimate.max_ns), Us(work.p50_ns));
  return 0;
}
