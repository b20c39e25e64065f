#include "firmware/runtime/rt/rt_thread.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "firmware/runtime/rt/rt_setup.h"

namespace rover::runtime {
namespace {

int RefuseEverything(pthread_t, int, const sched_param*) { return EPERM; }

RtThreadOptions Options(const std::string& name, int priority) {
  RtThreadOptions o;
  o.name = name;
  o.priority = priority;
  o.stack_prefault_bytes = 32 * 1024;
  return o;
}

TEST(RtThreadTest, RunsTheBodyWithItsNameAndReportsThePolicyObtained) {
  std::atomic<bool> ran{false};
  std::string name_seen;
  {
    RtThread thread(Options("rt_test", 0), [&](std::stop_token) {
      char name[16] = {};
      pthread_getname_np(pthread_self(), name, sizeof name);
      name_seen = name;
      ran = true;
    });
    const RtThreadReport& r = thread.report();
    EXPECT_EQ(r.policy, SchedPolicy::kOther);
    EXPECT_EQ(r.priority, 0);
    EXPECT_TRUE(r.name_set);
    EXPECT_EQ(r.stack_prefaulted_bytes, 32u * 1024u);
    EXPECT_FALSE(r.degraded());
    EXPECT_EQ(r.Describe(), "rt_test: SCHED_OTHER nice 0, any CPU, 32 KiB stack prefaulted");
    thread.Join();
  }
  EXPECT_TRUE(ran);
  EXPECT_EQ(name_seen, "rt_test");
}

TEST(RtThreadTest, FifoIsGrantedOrReportedAsRefused) {
  const bool permitted = RtSetup::ProbeFifo(10) == 0;
  RtThreadOptions o = Options("rt_fifo", 10);
  o.cpus = {0};
  RtThread thread(o, [](std::stop_token stop) {
    while (!stop.stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  const RtThreadReport& r = thread.report();
  if (permitted) {
    EXPECT_EQ(r.policy, SchedPolicy::kFifo);
    EXPECT_EQ(r.priority, 10);
    EXPECT_EQ(r.sched_errno, 0);
  } else {
    EXPECT_EQ(r.policy, SchedPolicy::kOther);
    EXPECT_NE(r.sched_errno, 0);
    EXPECT_TRUE(r.degraded());
  }
  EXPECT_TRUE(r.affinity_set);
  thread.RequestStop();
  thread.Join();
}

TEST(RtThreadTest, RefusedFifoDegradesToSchedOtherWithoutThrowing) {
  std::atomic<int> policy_seen{-1};
  RtThread thread(
      Options("rt_refused", 80),
      [&](std::stop_token) {
        int policy = -1;
        sched_param param{};
        pthread_getschedparam(pthread_self(), &policy, &param);
        policy_seen = policy;
      },
      &RefuseEverything);
  const RtThreadReport& r = thread.report();
  EXPECT_EQ(r.policy, SchedPolicy::kOther);
  EXPECT_EQ(r.sched_errno, EPERM);
  EXPECT_TRUE(r.degraded());
  EXPECT_EQ(r.Describe(),
            "rt_refused: SCHED_OTHER nice 0 (SCHED_FIFO 80 refused: EPERM), any CPU, 32 KiB "
            "stack prefaulted");
  thread.Join();
  EXPECT_EQ(policy_seen.load(), SCHED_OTHER);
}

TEST(RtThreadTest, WithoutRtprioLimitOrPrivilegesTheKernelRefusesAndTheThreadStillRuns) {
  // A forked child drops its real-time rights the way an unprivileged
  // service has none: RLIMIT_RTPRIO 0 and, if it runs as root, a switch to
  // an unprivileged user (which also drops CAP_SYS_NICE).
  const pid_t child = fork();
  ASSERT_GE(child, 0) << "fork failed: errno " << errno;
  if (child == 0) {
    const rlimit zero{0, 0};
    if (setrlimit(RLIMIT_RTPRIO, &zero) != 0) _exit(10);
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(11);
    int code = 0;
    try {
      std::atomic<bool> ran{false};
      RtThread thread(Options("rt_unpriv", 80), [&](std::stop_token) { ran = true; });
      thread.Join();
      const RtThreadReport& r = thread.report();
      if (r.policy != SchedPolicy::kOther)
        code = 20;
      else if (r.sched_errno != EPERM)
        code = 21;
      else if (!r.degraded())
        code = 22;
      else if (!ran)
        code = 23;
    } catch (...) {
      code = 30;
    }
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "child did not exit normally";
  EXPECT_EQ(WEXITSTATUS(status), 0)
      << "10/11: could not drop rights, 20: not SCHED_OTHER, 21: not EPERM, 22: not degraded, "
         "23: body did not run, 30: threw";
}

TEST(RtThreadTest, InvalidOptionsThrowBeforeAnyThreadStarts) {
  RtThreadOptions o = Options("rt_bad", 100);
  EXPECT_THROW(RtThread(o, [](std::stop_token) {}), std::invalid_argument);
}

TEST(RtThreadTest, DestructorStopsAndJoins) {
  std::atomic<int> iterations{0};
  {
    RtThread thread(Options("rt_stop", 0), [&](std::stop_token stop) {
      while (!stop.stop_requested()) {
        ++iterations;
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    });
  }
  EXPECT_GE(iterations.load(), 0);  // reached only if the destructor joined
}

}  // namespace
}  // namespace rover::runtime
