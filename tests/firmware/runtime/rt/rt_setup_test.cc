#include "firmware/runtime/rt/rt_setup.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <string>

namespace rover::runtime {
namespace {

int RefuseEverything(pthread_t, int, const sched_param*) { return EPERM; }

TEST(RtSetupTest, WithoutPrivilegesItDegradesWithOneWarningLine) {
  RtSetupOptions options;
  options.lock_memory = false;  // mlockall is covered by the no-sanitizer test
  options.set_sched_param = &RefuseEverything;
  const RtSetupReport r = RtSetup::Apply(options);
  EXPECT_FALSE(r.rt_scheduling_allowed);
  EXPECT_EQ(r.sched_errno, EPERM);
  EXPECT_TRUE(r.degraded());
  EXPECT_EQ(r.warning.find('\n'), std::string::npos);
  EXPECT_EQ(r.warning.rfind("roverd: no real-time privileges (SCHED_FIFO refused: EPERM, "
                            "RLIMIT_RTPRIO ",
                            0),
            0u)
      << r.warning;
  EXPECT_NE(r.warning.find("); running degraded with normal scheduling"), std::string::npos)
      << r.warning;
}

TEST(RtSetupTest, ProbeReportsTheHookResult) {
  EXPECT_EQ(RtSetup::ProbeFifo(1, &RefuseEverything), EPERM);
}

TEST(RtSetupTest, ReportMatchesTheProbeOnThisMachine) {
  RtSetupOptions options;
  options.lock_memory = false;
  options.program_name = "test";
  const RtSetupReport r = RtSetup::Apply(options);
  EXPECT_EQ(r.rt_scheduling_allowed, r.sched_errno == 0);
  EXPECT_EQ(r.warning.empty(), !r.degraded());
  if (!r.warning.empty()) {
    EXPECT_EQ(r.warning.rfind("test: ", 0), 0u);
  }
}

TEST(RtSetupTest, PrefaultTouchesWhatWasAskedAndClampsToTheStack) {
  EXPECT_EQ(RtSetup::PrefaultStack(128 * 1024), 128u * 1024u);
  EXPECT_EQ(RtSetup::PrefaultStack(0), 0u);
  const std::size_t huge = std::size_t{1} << 40;  // far beyond any stack
  const std::size_t touched = RtSetup::PrefaultStack(huge);
  EXPECT_LT(touched, huge);
}

TEST(RtSetupTest, ErrnoNames) {
  EXPECT_EQ(RtSetup::ErrnoName(EPERM), "EPERM");
  EXPECT_EQ(RtSetup::ErrnoName(ENOMEM), "ENOMEM");
}

}  // namespace
}  // namespace rover::runtime
