#include "drivers/camera/stereo_pairer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#ifdef ROVER_TEST_MALLOC_COUNTER
#include "tests/support/malloc_counter.h"
#endif

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

const Time kT0 = Time::FromNanoseconds(10'000'000'000);
const Duration kPeriod = Duration::Milliseconds(100);
constexpr uint64_t kSeq0 = 1000;  // cam0's counter at trigger 0
constexpr uint64_t kSeq1 = 7;     // cam1's counter at trigger 0

// A MonoCamera playing a script of frames, timeouts and errors; an exhausted
// script times out. Each frame carries the trigger it belongs to in
// image.width_px and a unique buffer_index. Storage is reserved up front so
// Next() and Release() never allocate.
class ScriptedCamera final : public MonoCamera {
 public:
  ScriptedCamera() {
    steps_.reserve(8192);
    released_.reserve(8192);
  }

  void Frame(int trigger, Time stamp, uint64_t sequence, uint32_t dropped_before = 0) {
    Step step;
    step.frame.stamp = stamp;
    step.frame.sequence = sequence;
    step.frame.dropped_before = dropped_before;
    step.frame.image.width_px = trigger;
    step.frame.image.height_px = 1;
    step.frame.buffer_index = static_cast<int>(steps_.size());
    steps_.push_back(step);
  }
  void Timeout() { steps_.push_back(Step{ReadStatus::kTimeout, {}}); }
  void Error() { steps_.push_back(Step{ReadStatus::kError, {}}); }

  ReadStatus Next(CameraFrame* frame, Duration /*timeout*/) override {
    if (next_ == steps_.size()) return ReadStatus::kTimeout;
    const Step& step = steps_[next_++];
    if (step.status == ReadStatus::kOk) {
      *frame = step.frame;
      ++delivered_;
    }
    return step.status;
  }
  void Release(const CameraFrame& frame) override { released_.push_back(frame.buffer_index); }

  std::size_t outstanding() const { return delivered_ - released_.size(); }
  const std::vector<int>& released() const { return released_; }
  std::size_t delivered() const { return delivered_; }

 private:
  struct Step {
    ReadStatus status = ReadStatus::kOk;
    CameraFrame frame;
  };
  std::vector<Step> steps_;
  std::size_t next_ = 0;
  std::size_t delivered_ = 0;
  std::vector<int> released_;
};

// Two cameras on one trigger at 10 Hz, with independent frame counters.
struct Rig {
  ScriptedCamera cam0;
  ScriptedCamera cam1;

  static Time Stamp(int trigger) { return kT0 + kPeriod * trigger; }
  void Both(int trigger, Duration skew1 = Duration::Zero()) {
    cam0.Frame(trigger, Stamp(trigger), kSeq0 + static_cast<uint64_t>(trigger));
    cam1.Frame(trigger, Stamp(trigger) + skew1, kSeq1 + static_cast<uint64_t>(trigger));
  }
};

#ifndef ROVER_TEST_MALLOC_COUNTER

// Pairs until the scripts run dry; releases each pair after checking it.
std::vector<StereoFrame> PairAll(StereoPairer* pairer, bool release = true) {
  std::vector<StereoFrame> pairs;
  StereoFrame frame;
  while (pairer->Next(&frame, Duration::Milliseconds(10)) == ReadStatus::kOk) {
    pairs.push_back(frame);
    if (release) pairer->Release(frame);
  }
  return pairs;
}

std::vector<int> Triggers(const std::vector<StereoFrame>& pairs) {
  std::vector<int> triggers;
  for (const StereoFrame& p : pairs) {
    EXPECT_EQ(p.cam0.width_px, p.cam1.width_px) << "pair across triggers";
    triggers.push_back(p.cam0.width_px);
  }
  return triggers;
}

TEST(StereoPairerTest, PairsEveryTriggerOfTwoHealthyCameras) {
  Rig rig;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int64_t> skew_us(-500, 500);
  for (int k = 0; k < 10; ++k) rig.Both(k, Duration::Microseconds(skew_us(rng)));
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  const std::vector<StereoFrame> pairs = PairAll(&pairer);
  ASSERT_EQ(pairs.size(), 10U);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(pairs[k].sequence, k);
    EXPECT_EQ(pairs[k].stamp, Rig::Stamp(static_cast<int>(k)));  // cam0's stamp
    EXPECT_EQ(pairs[k].cam0.width_px, static_cast<int>(k));
    EXPECT_EQ(pairs[k].cam1.width_px, static_cast<int>(k));
  }
  EXPECT_EQ(rig.cam0.outstanding(), 0U);
  EXPECT_EQ(rig.cam1.outstanding(), 0U);
  const StereoPairerStats& s = pairer.stats();
  EXPECT_EQ(s.pairs, 10U);
  EXPECT_EQ(s.camera[0].unpaired + s.camera[1].unpaired, 0U);
  EXPECT_EQ(s.offset_changes, 0U);
  EXPECT_EQ(s.camera[0].paired, 10U);
}

TEST(StereoPairerTest, AFrameLostOnOneSideReleasesItsPartner) {
  Rig rig;
  for (int k = 0; k < 10; ++k) {
    if (k != 3) rig.cam1.Frame(k, Rig::Stamp(k), kSeq1 + static_cast<uint64_t>(k));
    // cam0 lost trigger 6 and says so on the next frame.
    if (k != 6) {
      rig.cam0.Frame(k, Rig::Stamp(k), kSeq0 + static_cast<uint64_t>(k), k == 7 ? 1U : 0U);
    }
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  const std::vector<StereoFrame> pairs = PairAll(&pairer);
  EXPECT_THAT(Triggers(pairs), ::testing::ElementsAre(0, 1, 2, 4, 5, 7, 8, 9));
  std::vector<uint64_t> sequences;
  for (const StereoFrame& p : pairs) sequences.push_back(p.sequence);
  // The trigger count keeps the gaps: 3 and 6 are missing.
  EXPECT_THAT(sequences, ::testing::ElementsAre(0U, 1U, 2U, 4U, 5U, 7U, 8U, 9U));
  const StereoPairerStats& s = pairer.stats();
  EXPECT_EQ(s.camera[0].unpaired, 1U);  // trigger 3
  EXPECT_EQ(s.camera[1].unpaired, 1U);  // trigger 6
  EXPECT_EQ(s.camera[0].device_dropped, 1U);
  EXPECT_EQ(rig.cam0.outstanding(), 0U);
  EXPECT_EQ(rig.cam1.outstanding(), 0U);
}

TEST(StereoPairerTest, StampsBeyondTheToleranceAreNotPaired) {
  Rig rig;
  for (int k = 0; k < 10; ++k) {
    rig.Both(k, k == 4 ? Duration::Milliseconds(5) : Duration::Microseconds(1900));
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);  // 2 ms tolerance
  const std::vector<StereoFrame> pairs = PairAll(&pairer);
  EXPECT_THAT(Triggers(pairs), ::testing::ElementsAre(0, 1, 2, 3, 5, 6, 7, 8, 9));
  const StereoPairerStats& s = pairer.stats();
  EXPECT_EQ(s.stamp_mismatches, 1U);  // the counters said "pair", the stamps did not
  EXPECT_EQ(s.camera[0].unpaired, 1U);
  EXPECT_EQ(s.camera[1].unpaired, 1U);
  EXPECT_EQ(s.offset_changes, 0U);
  EXPECT_EQ(rig.cam0.outstanding() + rig.cam1.outstanding(), 0U);
}

TEST(StereoPairerTest, ALargerToleranceAcceptsTheSameSkew) {
  Rig rig;
  for (int k = 0; k < 5; ++k) rig.Both(k, Duration::Milliseconds(5));
  StereoPairerOptions options;
  options.stamp_tolerance = Duration::Milliseconds(6);
  StereoPairer pairer(&rig.cam0, &rig.cam1, options);
  EXPECT_EQ(PairAll(&pairer).size(), 5U);
}

TEST(StereoPairerTest, TheCounterOffsetIsLearnedAndRelearned) {
  Rig rig;
  for (int k = 0; k < 10; ++k) {
    rig.cam0.Frame(k, Rig::Stamp(k), kSeq0 + static_cast<uint64_t>(k));
    // cam1's counter jumps by 5 at trigger 5 (it lost frames it never reported).
    rig.cam1.Frame(k, Rig::Stamp(k), kSeq1 + static_cast<uint64_t>(k) + (k >= 5 ? 5U : 0U));
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  EXPECT_EQ(PairAll(&pairer).size(), 10U);
  EXPECT_EQ(pairer.stats().offset_changes, 1U);
  EXPECT_EQ(pairer.stats().camera[1].unpaired, 0U);
}

TEST(StereoPairerTest, ACounterResetKeepsPairingAndTheTriggerCountRising) {
  Rig rig;
  for (int k = 0; k < 10; ++k) {
    const uint64_t seq0 = k < 5 ? kSeq0 + static_cast<uint64_t>(k) : static_cast<uint64_t>(k - 5);
    rig.cam0.Frame(k, Rig::Stamp(k), seq0);  // cam0's driver restarted at trigger 5
    rig.cam1.Frame(k, Rig::Stamp(k), kSeq1 + static_cast<uint64_t>(k));
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  const std::vector<StereoFrame> pairs = PairAll(&pairer);
  ASSERT_EQ(pairs.size(), 10U);
  for (std::size_t k = 0; k < pairs.size(); ++k) EXPECT_EQ(pairs[k].sequence, k);
  EXPECT_EQ(pairer.stats().camera[0].sequence_resets, 1U);
}

TEST(StereoPairerTest, AFrameOutOfOrderIsReleasedAtOnce) {
  Rig rig;
  for (int k = 0; k < 5; ++k) {
    rig.cam0.Frame(k, Rig::Stamp(k), kSeq0 + static_cast<uint64_t>(k));
    if (k == 2) rig.cam0.Frame(1, Rig::Stamp(1), kSeq0 + 1);  // a stale duplicate
    rig.cam1.Frame(k, Rig::Stamp(k), kSeq1 + static_cast<uint64_t>(k));
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  EXPECT_THAT(Triggers(PairAll(&pairer)), ::testing::ElementsAre(0, 1, 2, 3, 4));
  EXPECT_EQ(pairer.stats().camera[0].out_of_order, 1U);
  EXPECT_EQ(pairer.stats().camera[0].unpaired, 0U);
  EXPECT_EQ(rig.cam0.outstanding(), 0U);
}

TEST(StereoPairerTest, ALaggingStreamDropsItsOlderFrames) {
  Rig rig;
  // cam1 started three triggers before cam0 (or cam0 lost them all).
  for (int k = -3; k < 0; ++k)
    rig.cam1.Frame(k, Rig::Stamp(k), kSeq1 + 10 + static_cast<uint64_t>(k));
  for (int k = 0; k < 5; ++k) rig.Both(k);
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  EXPECT_THAT(Triggers(PairAll(&pairer)), ::testing::ElementsAre(0, 1, 2, 3, 4));
  EXPECT_EQ(pairer.stats().camera[1].unpaired, 3U);
  EXPECT_EQ(rig.cam1.outstanding(), 0U);
}

TEST(StereoPairerTest, ATimeoutKeepsTheHeldFrameForTheNextCall) {
  Rig rig;
  rig.cam0.Frame(0, Rig::Stamp(0), kSeq0);
  rig.cam1.Timeout();
  rig.cam1.Frame(0, Rig::Stamp(0), kSeq1);
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  StereoFrame frame;
  EXPECT_EQ(pairer.Next(&frame, Duration::Milliseconds(5)), ReadStatus::kTimeout);
  EXPECT_EQ(rig.cam0.outstanding(), 1U);  // held, not dropped
  EXPECT_EQ(pairer.stats().camera[1].timeouts, 1U);
  ASSERT_EQ(pairer.Next(&frame, Duration::Milliseconds(5)), ReadStatus::kOk);
  EXPECT_EQ(frame.stamp, Rig::Stamp(0));
  pairer.Release(frame);
  EXPECT_EQ(rig.cam0.outstanding() + rig.cam1.outstanding(), 0U);
  // Both scripts are exhausted: a plain timeout.
  EXPECT_EQ(pairer.Next(&frame, Duration::Zero()), ReadStatus::kTimeout);
}

TEST(StereoPairerTest, ACameraErrorIsReturnedAndCounted) {
  Rig rig;
  rig.cam0.Frame(0, Rig::Stamp(0), kSeq0);
  rig.cam1.Error();
  rig.cam1.Frame(0, Rig::Stamp(0), kSeq1);
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  StereoFrame frame;
  EXPECT_EQ(pairer.Next(&frame, Duration::Milliseconds(5)), ReadStatus::kError);
  EXPECT_EQ(pairer.stats().camera[1].errors, 1U);
  EXPECT_EQ(pairer.Next(&frame, Duration::Milliseconds(5)), ReadStatus::kOk);
}

TEST(StereoPairerTest, PairsInFlightAreBounded) {
  Rig rig;
  for (int k = 0; k < 4; ++k) rig.Both(k);
  StereoPairerOptions options;
  options.max_pairs_in_flight = 2;
  StereoPairer pairer(&rig.cam0, &rig.cam1, options);
  StereoFrame a;
  StereoFrame b;
  StereoFrame c;
  ASSERT_EQ(pairer.Next(&a, Duration::Zero()), ReadStatus::kOk);
  ASSERT_EQ(pairer.Next(&b, Duration::Zero()), ReadStatus::kOk);
  EXPECT_EQ(pairer.pairs_in_flight(), 2);
  EXPECT_EQ(pairer.Next(&c, Duration::Zero()), ReadStatus::kError);
  EXPECT_EQ(pairer.stats().in_flight_overflows, 1U);
  pairer.Release(a);
  ASSERT_EQ(pairer.Next(&c, Duration::Zero()), ReadStatus::kOk);
  EXPECT_EQ(c.sequence, 2U);
  EXPECT_EQ(rig.cam0.outstanding(), 2U);  // b and c
  pairer.Release(b);
  pairer.Release(c);
  pairer.Release(c);  // twice: ignored and counted
  EXPECT_EQ(pairer.stats().unknown_releases, 1U);
  EXPECT_EQ(rig.cam0.outstanding() + rig.cam1.outstanding(), 0U);
}

TEST(StereoPairerTest, DestructionReleasesHeldAndInFlightFrames) {
  Rig rig;
  for (int k = 0; k < 3; ++k) rig.Both(k);
  rig.cam0.Frame(3, Rig::Stamp(3), kSeq0 + 3);  // cam1 never delivers trigger 3
  {
    StereoPairer pairer(&rig.cam0, &rig.cam1);
    PairAll(&pairer, /*release=*/false);
    EXPECT_EQ(rig.cam0.outstanding(), 4U);
  }
  EXPECT_EQ(rig.cam0.outstanding(), 0U);
  EXPECT_EQ(rig.cam1.outstanding(), 0U);
}

// A long seeded run with losses on both sides and occasional skew beyond the
// tolerance: exactly the triggers with both frames within the tolerance are
// paired, never across triggers, and every frame is released exactly once.
TEST(StereoPairerTest, RandomLossesAndSkewsPairExactlyTheMatchingTriggers) {
  std::mt19937 rng(1234);
  std::bernoulli_distribution lose(0.1);
  std::bernoulli_distribution skewed(0.05);
  std::uniform_int_distribution<int64_t> small_us(-1500, 1500);
  std::uniform_int_distribution<int64_t> large_us(2500, 20'000);
  Rig rig;
  std::vector<int> expected;
  for (int k = 0; k < 1000; ++k) {
    const bool has0 = !lose(rng);
    const bool has1 = !lose(rng);
    const bool bad = skewed(rng);
    const Duration skew = Duration::Microseconds(bad ? large_us(rng) : small_us(rng));
    if (has0) rig.cam0.Frame(k, Rig::Stamp(k), kSeq0 + static_cast<uint64_t>(k));
    if (has1) rig.cam1.Frame(k, Rig::Stamp(k) + skew, kSeq1 + static_cast<uint64_t>(k));
    if (has0 && has1 && !bad) expected.push_back(k);
  }
  std::vector<StereoFrame> pairs;
  {
    StereoPairer pairer(&rig.cam0, &rig.cam1);
    pairs = PairAll(&pairer);
    EXPECT_EQ(pairer.stats().pairs, expected.size());
    EXPECT_EQ(pairer.stats().camera[0].paired + pairer.stats().camera[0].unpaired +
                  (rig.cam0.outstanding() > 0 ? 1U : 0U),
              rig.cam0.delivered());
  }
  EXPECT_EQ(Triggers(pairs), expected);
  for (const StereoFrame& p : pairs) {
    EXPECT_EQ(p.stamp, Rig::Stamp(p.cam0.width_px));
    EXPECT_EQ(p.sequence, static_cast<uint64_t>(p.cam0.width_px - expected.front()));
  }
  for (const ScriptedCamera* cam : {&rig.cam0, &rig.cam1}) {
    std::vector<int> released = cam->released();
    std::sort(released.begin(), released.end());
    EXPECT_EQ(std::adjacent_find(released.begin(), released.end()), released.end());
    EXPECT_EQ(released.size(), cam->delivered());
  }
}

TEST(StereoPairerTest, OptionsAndCamerasAreValidated) {
  ScriptedCamera a;
  ScriptedCamera b;
  StereoPairerOptions options;
  options.stamp_tolerance = Duration::Zero();
  try {
    StereoPairer pairer(&a, &b, options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("StereoPairerOptions.stamp_tolerance: expected > 0"));
  }
  options = StereoPairerOptions{};
  options.max_pairs_in_flight = 0;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
  options.max_pairs_in_flight = 65;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
  EXPECT_THROW(StereoPairer(&a, &a), std::invalid_argument);
  EXPECT_THROW(StereoPairer(nullptr, &b), std::invalid_argument);
}

#else  // ROVER_TEST_MALLOC_COUNTER

TEST(StereoPairerAllocationTest, NextAndReleaseDoNotAllocate) {
  std::mt19937 rng(99);
  std::bernoulli_distribution lose(0.1);
  Rig rig;
  for (int k = 0; k < 2000; ++k) {
    const bool has0 = !lose(rng);
    const bool has1 = !lose(rng);
    const Duration skew = Duration::Microseconds(k % 50 == 0 ? 5000 : 300);
    if (has0) rig.cam0.Frame(k, Rig::Stamp(k), kSeq0 + static_cast<uint64_t>(k));
    if (has1) rig.cam1.Frame(k, Rig::Stamp(k) + skew, kSeq1 + static_cast<uint64_t>(k));
    if (k % 100 == 0) rig.cam1.Timeout();
  }
  StereoPairer pairer(&rig.cam0, &rig.cam1);
  StereoFrame frame;
  uint64_t pairs = 0;
  int timeouts = 0;
  uint64_t mallocs = 0;
  {
    rover::testing::ScopedMallocCheck check;
    while (timeouts < 30) {
      if (pairer.Next(&frame, Duration::Zero()) == ReadStatus::kOk) {
        ++pairs;
        pairer.Release(frame);
      } else {
        ++timeouts;
      }
    }
    mallocs = check.mallocs();
  }
  EXPECT_EQ(mallocs, 0U);
  EXPECT_GT(pairs, 1500U);
  EXPECT_GT(pairer.stats().stamp_mismatches, 0U);
}

#endif  // ROVER_TEST_MALLOC_COUNTER

}  // namespace
}  // namespace rover::drivers
