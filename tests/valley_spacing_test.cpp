// Tests of PredictedValleySpacing (optim/valley_spacing.h) against closed forms:
// one sinusoid of frequency f over a window T gives Rice's 2 pi sqrt(lambda_2 /
// lambda_4) -> 2 sqrt(5/3) / (f T) as f T grows; the spacing scales as 1 / f; the
// weights pick the channels; degenerate outputs give 0.
#include "mcrewave/optim/valley_spacing.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mcrewave {
namespace {

// One row sin(2 pi f t_j), t_j = j h, j = 0..m.
Matrix Sinusoid(double frequency, double time_step, int steps) {
  Matrix traces(1, steps + 1);
  for (int j = 0; j <= steps; ++j) traces(0, j) = std::sin(2.0 * M_PI * frequency * j * time_step);
  return traces;
}

TEST(ValleySpacingTest, OneSinusoidGivesTwoSqrtFiveThirdsOverFT) {
  // y = sin(w t): lambda_2 = sum (t/2)^2 w^2 cos^2, lambda_4 = sum (t/2)^4 w^4 sin^2, so
  // over many periods 2 pi sqrt(lambda_2 / lambda_4) -> 2 pi sqrt((20/3) / (w T)^2) =
  // 2 sqrt(5/3) / (f T). f = 20 kHz, T = 1 ms, 20 000 samples: measured 1.3e-3 off
  // (the finite sums over 20 periods).
  const double f = 20e3, T = 1e-3;
  const int steps = 20000;
  const double predicted =
      PredictedValleySpacing(Sinusoid(f, T / steps, steps), Vector::Ones(1), T / steps);
  EXPECT_NEAR(predicted / (2.0 * std::sqrt(5.0 / 3.0) / (f * T)), 1.0, 1e-2);
}

TEST(ValleySpacingTest, ScalesAsOneOverTheFrequency) {
  const double T = 1e-3;
  const int steps = 40000;
  const double low =
      PredictedValleySpacing(Sinusoid(20e3, T / steps, steps), Vector::Ones(1), T / steps);
  const double high =
      PredictedValleySpacing(Sinusoid(80e3, T / steps, steps), Vector::Ones(1), T / steps);
  // Measured ratio 4.005.
  EXPECT_NEAR(low / high, 4.0, 0.04);
}

TEST(ValleySpacingTest, WeightsPickTheChannels) {
  const double T = 1e-3;
  const int steps = 20000;
  Matrix traces(2, steps + 1);
  traces.row(0) = Sinusoid(20e3, T / steps, steps);
  traces.row(1) = Sinusoid(80e3, T / steps, steps);
  Vector only_first(2), only_second(2);
  only_first << 1.0, 0.0;
  only_second << 0.0, 1.0;
  EXPECT_DOUBLE_EQ(PredictedValleySpacing(traces, only_first, T / steps),
                   PredictedValleySpacing(traces.topRows(1), Vector::Ones(1), T / steps));
  EXPECT_DOUBLE_EQ(PredictedValleySpacing(traces, only_second, T / steps),
                   PredictedValleySpacing(traces.bottomRows(1), Vector::Ones(1), T / steps));
}

TEST(ValleySpacingTest, OutputsWithoutCurvatureGiveZero) {
  EXPECT_EQ(PredictedValleySpacing(Matrix::Zero(2, 100), Vector::Ones(2), 1e-6), 0.0);
  // A straight line has no curvature.
  Matrix line(1, 100);
  for (int j = 0; j < 100; ++j) line(0, j) = j;
  EXPECT_EQ(PredictedValleySpacing(line, Vector::Ones(1), 1e-6), 0.0);
  EXPECT_EQ(PredictedValleySpacing(Matrix::Ones(1, 2), Vector::Ones(1), 1e-6), 0.0);
}

}  // namespace
}  // namespace mcrewave
