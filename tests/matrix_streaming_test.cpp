// Tests of the streaming solver on structures given by matrices
// (MatrixMcreProblem as a StreamingCoupledProblem, docs/streaming.md section 5): one
// streaming application is the stored sweeps' to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::RelativeDifference;
using testing::SupportedLattice;
using testing::SupportedLatticeHistories;
using testing::Weights;

// The support treatments the tests run through; "none" is the lattice without its
// support.
struct MatrixStreamingCase {
  const char* name;
  bool supported;
  ClampModel treatment;
};
constexpr MatrixStreamingCase kMatrixStreamingCases[] = {
    {"none", false, ClampModel::kMeasured},
    {"measured", true, ClampModel::kMeasured},
    {"trusted", true, ClampModel::kTrusted},
    {"pinned", true, ClampModel::kPinned},
};

MatrixModelData MatrixStreamingLattice(const MatrixStreamingCase& c) {
  MatrixModelData lattice = SupportedLattice();
  if (!c.supported) lattice.supports.clear();
  return lattice;
}

// StreamingMap at traces y = H U runs the retrograde sweep of U and the direct sweep of
// the W it gives, and gathers the cost, gradients and maps of those fields.
TEST(MatrixStreamingTest, OneApplicationIsTheStoredSweeps) {
  for (const MatrixStreamingCase& c : kMatrixStreamingCases) {
    SCOPED_TRACE(c.name);
    const MatrixModelData lattice = MatrixStreamingLattice(c);
    const ChannelSet data = SupportedLatticeHistories(SupportedLattice());
    MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                              c.treatment);
    problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
    Matrix u0, w, u;
    problem.DirectSweep(problem.ZeroField(), true, &u0);
    problem.RetrogradeSweep(u0, true, &w);
    problem.DirectSweep(w, true, &u);
    const Matrix traces = problem.ObservedTraces(u0);
    ASSERT_EQ(traces.rows(), problem.num_traces());
    Matrix image;
    StreamingCoupledProblem::StreamingTotals totals;
    const long sweeps = problem.sweep_count();
    problem.StreamingMap(traces, true, &image, &totals);
    EXPECT_EQ(problem.sweep_count() - sweeps, 3);
    // The same steps from the same loads: the same bits.
    EXPECT_EQ(image, problem.ObservedTraces(u));
    // The sums of the stored-field path, e^2 and the maps in the same order (measured
    // 0 apart), the gradients from K_z W and K_z U apart (measured at most 4.1e-16).
    const double cost = problem.Cost(u, w);
    EXPECT_NEAR(totals.cost, cost, 4e-16 * cost);
    Vector gradients;
    problem.CostGradients(u, w, &gradients);
    EXPECT_LT((totals.cost_gradients - gradients).norm(), 4e-15 * gradients.norm());
    EXPECT_LT(RelativeDifference(totals.zone_error_map, problem.ZoneErrorMap(w)), 4e-16);
    EXPECT_LT(RelativeDifference(totals.zone_strain_energy, problem.ZoneErrorMap(u)), 4e-16);
    EXPECT_LT(RelativeDifference(totals.error_map, problem.DofErrorMap(w)), 4e-16);
    // The linear part, and the retrograde energy of traces without data: the P-norm of
    // the retrograde sweep they drive (RetrogradeSweep of a U with H U = traces).
    Matrix linear_w;
    problem.RetrogradeSweep(u0, false, &linear_w);
    const double energy = problem.InnerProduct(linear_w, linear_w);
    // Measured at most 8.5e-16 apart.
    EXPECT_NEAR(problem.RetrogradeEnergy(traces), energy, 8e-15 * energy);
    Matrix linear_image, linear_u;
    problem.StreamingMap(traces, false, &linear_image);
    problem.DirectSweep(linear_w, false, &linear_u);
    EXPECT_EQ(linear_image, problem.ObservedTraces(linear_u));
  }
}

}  // namespace
}  // namespace mcrewave
