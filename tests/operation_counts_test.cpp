// Tests of the multiply-accumulate counts: the kernel formulas against their
// closed forms, and the Riccati solver's count against its loop structure
// (exactly affine in the number of steps, about 6.3 n^3 per step).
#include "mcrewave/core/operation_counts.h"

#include <gtest/gtest.h>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

namespace counts = operation_counts;

TEST(OperationCountsTest, BandKernelsCountEveryStoredEntry) {
  // Tridiagonal: 3n - 2 entries; L has n - 1 entries below the diagonal.
  EXPECT_EQ(counts::BandProduct(10, 1), 28.0);
  EXPECT_EQ(counts::BandSolve(10, 1), 2.0 * 9.0 + 10.0);
  EXPECT_EQ(counts::BandProductAdd(10, 1), 38.0);
  // Pentadiagonal: n + 2 (n - 1) + 2 (n - 2).
  EXPECT_EQ(counts::BandProduct(10, 2), 10.0 + 18.0 + 16.0);
}

TEST(OperationCountsTest, DenseKernelsMatchTheirClosedForms) {
  EXPECT_EQ(counts::LuFactorization(3), 8.0);  // (27 - 3) / 3
  EXPECT_EQ(counts::LuSolve(4, 2), 32.0);
  EXPECT_EQ(counts::DenseProduct(2, 3, 4), 24.0);
  EXPECT_EQ(counts::TriangularSolve(4, 1), 10.0);
  // Householder QR of a square N x N: 2 N^3 / 3 + O(N^2).
  const double n = 300;
  EXPECT_NEAR(counts::HouseholderQr(n, n) / (n * n * n), 2.0 / 3.0, 0.01);
  EXPECT_NEAR(counts::ApplyHouseholderReflectors(n, n, 1) / (n * n), 1.0, 0.01);
}

TEST(OperationCountsTest, RiccatiCountIsAffineInTheStepsWithSixAndAThirdNCubedPerStep) {
  const int elements = 40, n = elements + 1;
  auto riccati_macs = [&](int steps) {
    testing::ProblemBundle bundle(testing::MakeSmallCase(elements, steps, 5.0, 1), McreWeights());
    CoupledSolverOptions options;
    options.type = CoupledSolverType::kRiccati;
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(options, &bundle.problem, nullptr, &solution);
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    return summary.multiply_accumulates;
  };
  const double m10 = riccati_macs(10), m20 = riccati_macs(20), m30 = riccati_macs(30);
  EXPECT_NEAR(m30 - m20, m20 - m10, 1e-9 * m30);
  const double per_step = (m20 - m10) / 10.0;
  const double cube = static_cast<double>(n) * n * n;
  // 6.33 n^3 of dense work and O(n^2) band work on the columns (about 112 n^2).
  EXPECT_GT(per_step, 6.33 * cube);
  EXPECT_LT(per_step, 6.34 * cube + 130.0 * n * n);
}

}  // namespace
}  // namespace mcrewave
