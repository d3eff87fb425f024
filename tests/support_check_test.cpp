// The test of the data against a trusted support (mcre/support_check.h): its statistic
// is standard normal on a rigid support, finds a spring from its force, and the
// supports tested are those whose displacement the data hold.
#include "mcrewave/mcre/support_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mcrewave/core/random.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

// A smooth force history: a half sine over the first fifth of m + 1 samples, then its
// echoes of alternating sign every fifth [N].
Vector SmoothForce(int samples) {
  Vector force(samples);
  const int period = samples / 5;
  for (int j = 0; j < samples; ++j) {
    const int pulse = j / period;
    force[j] = (pulse % 2 == 0 ? 1.0 : -1.0) * 1000.0 * std::sin(M_PI * (j % period) / period);
  }
  return force;
}

TEST(SupportCheckTest, OnARigidSupportTheStatisticIsStandardNormal) {
  // u~ white noise of std 1e-6 m, z a noisy smooth force: over 2000 draws the mean of t
  // is 0 and its std 1, the noise level estimated from u~'s second differences.
  constexpr int kSamples = 1751;
  constexpr int kDraws = 2000;
  StandardNormal normal(7);
  const Vector clean = SmoothForce(kSamples);
  double sum = 0.0, squares = 0.0;
  int alarms = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    Vector displacement(kSamples), force = clean;
    for (int j = 0; j < kSamples; ++j) displacement[j] = 1e-6 * normal();
    for (int j = 0; j < kSamples; ++j) force[j] += 200.0 * normal();
    const SupportCheck check = CheckSupport(displacement, force, 1.645);
    sum += check.statistic;
    squares += check.statistic * check.statistic;
    alarms += check.contradicted ? 1 : 0;
  }
  const double mean = sum / kDraws;
  const double std_dev = std::sqrt(squares / kDraws - mean * mean);
  RecordProperty("mean", std::to_string(mean));
  RecordProperty("std", std::to_string(std_dev));
  RecordProperty("alarms", std::to_string(alarms));
  // Measured: mean -0.0033, std 0.988 (sampling errors 0.022 and 0.016), 94 false
  // alarms at 1.645 (1 - Phi = 5 %: 100 expected, std 9.7).
  EXPECT_LT(std::abs(mean), 0.07);
  EXPECT_LT(std::abs(std_dev - 1.0), 0.05);
  EXPECT_GT(alarms, 70);
  EXPECT_LT(alarms, 130);
}

TEST(SupportCheckTest, ASpringIsFoundFromTheForceItApplies) {
  // A spring to the wall: u = -f / k_s. Without noise the compliance is 1 / k_s to
  // round-off; with noise on u it is within 3 of its standard deviations.
  constexpr int kSamples = 1751;
  constexpr double kSpring = 2e8;  // k_s [N/m]
  const Vector force = SmoothForce(kSamples);
  const Vector motion = -force / kSpring;
  StandardNormal normal(3);
  Vector noisy = motion;
  for (int j = 0; j < kSamples; ++j) noisy[j] += 1e-7 * normal();

  const SupportCheck exact = CheckSupport(motion, force, 3.0);
  EXPECT_NEAR(exact.compliance * kSpring, 1.0, 1e-12);
  EXPECT_NEAR(exact.SupportStiffness() / kSpring, 1.0, 1e-12);
  EXPECT_TRUE(exact.contradicted);

  const SupportCheck check = CheckSupport(noisy, force, 3.0);
  EXPECT_NEAR(check.displacement_std, 1e-7, 1e-8);  // MAD estimate over 1750 samples
  EXPECT_LT(std::abs(check.compliance - 1.0 / kSpring), 3.0 * check.compliance_std);
  EXPECT_GT(check.statistic, 3.0);
  EXPECT_TRUE(check.contradicted);
  EXPECT_NE(check.BriefReport().find("the data contradict the trusted support"), std::string::npos)
      << check.BriefReport();

  // The support moving with its force is not a passive support: the one-sided test
  // leaves it.
  const SupportCheck pulled = CheckSupport(-noisy, force, 3.0);
  EXPECT_LT(pulled.statistic, -3.0);
  EXPECT_FALSE(pulled.contradicted);
  EXPECT_EQ(pulled.SupportStiffness(), std::numeric_limits<double>::infinity());
}

// a = (t - t1) / (t2 - t1) clipped to [0, 1], the largest over the supports;
// t1 = t2: the hard switch at t2 (docs/boundaries.md section 10).
TEST(SupportCheckTest, TheSwitchWeightRampsFromTheStartToTheThreshold) {
  auto checks = [](std::vector<double> statistics) {
    std::vector<SupportCheck> result;
    for (const double t : statistics) {
      SupportCheck check;
      check.statistic = t;
      result.push_back(check);
    }
    return result;
  };
  EXPECT_EQ(SupportSwitchWeight({}, 1.0, 3.0), 0.0);
  EXPECT_EQ(SupportSwitchWeight(checks({-4.0}), 1.0, 3.0), 0.0);
  EXPECT_EQ(SupportSwitchWeight(checks({1.0}), 1.0, 3.0), 0.0);
  EXPECT_EQ(SupportSwitchWeight(checks({1.5}), 1.0, 3.0), 0.25);
  EXPECT_EQ(SupportSwitchWeight(checks({3.0}), 1.0, 3.0), 1.0);
  EXPECT_EQ(SupportSwitchWeight(checks({30.0}), 1.0, 3.0), 1.0);
  EXPECT_EQ(SupportSwitchWeight(checks({1.5, 2.0, -1.0}), 1.0, 3.0), 0.5);
  // The hard switch: contradicted (t > t2) or not.
  EXPECT_EQ(SupportSwitchWeight(checks({2.5}), 2.5, 2.5), 0.0);
  EXPECT_EQ(SupportSwitchWeight(checks({2.5000001}), 2.5, 2.5), 1.0);
}

TEST(SupportCheckTest, NothingToTestWithoutAForce) {
  const Vector zero = Vector::Zero(100);
  const Vector displacement = Vector::Constant(100, 1e-6);
  const SupportCheck check = CheckSupport(displacement, zero, 3.0);
  EXPECT_EQ(check.statistic, 0.0);
  EXPECT_FALSE(check.contradicted);
}

TEST(SupportCheckTest, TheBarsClampIsTestedWhenItsDisplacementIsMeasured) {
  // The bar's clamp as a support (BarRunModel): spring-supported data of the bar
  // contradict it; without u0 among the data there is nothing to test.
  BarProperties bar;
  bar.elements = 20;
  DataOptions data;
  const ChannelSet measured = testing::SpringSupportedBarData(bar, 10.0, &data);
  const MatrixModelData model = BarRunModel(BarModel(bar), measured, EndDisplacementChannels());
  const std::vector<SupportCheck> checks = CheckSupports(model, measured, measured, 3.0);
  ASSERT_EQ(checks.size(), 1u);
  EXPECT_EQ(checks[0].support, "clamp");
  EXPECT_EQ(checks[0].displacement_channel, "u0");
  EXPECT_EQ(checks[0].force_channel, "f0");
  // f0 = -k_s u0 exactly.
  EXPECT_NEAR(checks[0].SupportStiffness() / data.support_stiffness, 1.0, 1e-12);
  EXPECT_TRUE(AnySupportContradicted(checks));

  EndDisplacementChannels without_u0;
  without_u0.u0 = false;
  const MatrixModelData unmeasured = BarRunModel(BarModel(bar), measured, without_u0);
  EXPECT_TRUE(CheckSupports(unmeasured, measured, measured, 3.0).empty());
}

}  // namespace
}  // namespace mcrewave
