// The incremental solver against full Ceres solves after every update of a
// 1000-submap synthetic rover sequence with loop closures (slow: one full
// Ceres solve per loop closure).

#include <gtest/gtest.h>

#include "tests/mapping/graph/incremental_agreement.h"

namespace rover::mapping {
namespace {

TEST(IncrementalGraph1000Test, EveryUpdateAgreesWithTheFullSolve) {
  const AgreementResult r = RunAgainstFullSolves(1000, 1);
  EXPECT_GT(r.loop_updates, 100);
  EXPECT_EQ(r.incremental_solves, r.loop_updates);
  RecordProperty("max_translation_gap_mm", std::to_string(1e3 * r.max_translation_m));
  std::printf("max gap %.4f mm, %.5f deg over %d loop closures\n", 1e3 * r.max_translation_m,
              r.max_rotation_rad * 180.0 / 3.14159265358979, r.loop_updates);
}

}  // namespace
}  // namespace rover::mapping
