// The library's asserts (programmer errors: violated preconditions) run in the
// sanitizer pass of scripts/test.sh, which builds without NDEBUG: a violated
// precondition must stop the process there. The Release pass compiles them out and
// skips this test.
#include <gtest/gtest.h>

#include "mcrewave/data/resample.h"

namespace mcrewave {
namespace {

TEST(AssertsTest, AViolatedPreconditionStopsTheSanitizerBuild) {
#if defined(MCREWAVE_EXPECT_ASSERTS)
  ChannelSet table;
  table.time_step = 1.0;
  table.Add("x", ChannelKind::kDisplacement, Vector::Zero(2));
  // ResampleMeasurements's precondition: a positive step.
  EXPECT_DEATH(ResampleMeasurements(table, -1.0, 2, "table.csv"), "step > 0");
#else
  GTEST_SKIP() << "NDEBUG build: the asserts are compiled out (the sanitizer pass runs them)";
#endif
}

}  // namespace
}  // namespace mcrewave
