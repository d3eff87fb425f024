// No heap allocation in the time loops: once initialised, ThetaIntegrator's steps
// and sweeps and BarMcreProblem's sweeps (outputs preallocated) neither allocate nor
// free memory; the least-squares zone objective's time loop neither (its heap calls
// do not grow with the number of steps); the Matrix Market reader allocates for the
// entries a file holds, not for what its size line declares.
//
// Allocations are counted by replacing the C allocator of this test binary (malloc,
// calloc, realloc, free: glibc's documented way of replacing malloc) with
// pass-throughs to glibc's own functions (__libc_malloc, ...) that count, on the
// calling thread, while its flag is set. The C allocator rather than operator new:
// Eigen's dense matrices and vectors allocate with std::malloc directly, and
// libstdc++'s operator new calls malloc, so both are seen (the aligned allocation
// functions stay glibc's: neither Eigen nor the sweeps use them). The replacement
// applies to the whole test binary and only forwards. Under AddressSanitizer, which
// brings its own allocator, nothing is replaced and these tests are skipped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "mcrewave/data/matrix_market.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"
#include "reference/bar_mcre_problem.h"
#include "test_problems.h"

#if defined(__GLIBC__) && !defined(MCREWAVE_ADDRESS_SANITIZER)
#define MCREWAVE_COUNTS_ALLOCATIONS 1
#else
#define MCREWAVE_COUNTS_ALLOCATIONS 0
#endif

namespace {

// Heap calls of this thread while counting_heap_calls is set. Constant-initialised
// thread_local of the executable: reading them from malloc allocates nothing.
thread_local bool counting_heap_calls = false;
thread_local long allocation_count = 0;           // malloc, calloc, realloc
thread_local long deallocation_count = 0;         // free of a non-null pointer
thread_local std::size_t allocated_bytes = 0;     // their sizes, summed
thread_local std::size_t largest_allocation = 0;  // and the largest

#if MCREWAVE_COUNTS_ALLOCATIONS
void CountAllocation(std::size_t size) {
  ++allocation_count;
  allocated_bytes += size;
  largest_allocation = std::max(largest_allocation, size);
}
#endif

}  // namespace

#if MCREWAVE_COUNTS_ALLOCATIONS
extern "C" {
void* __libc_malloc(std::size_t size) noexcept;
void* __libc_calloc(std::size_t count, std::size_t size) noexcept;
void* __libc_realloc(void* pointer, std::size_t size) noexcept;
void __libc_free(void* pointer) noexcept;

void* malloc(std::size_t size) noexcept {
  if (counting_heap_calls) CountAllocation(size);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  if (counting_heap_calls) CountAllocation(count * size);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  if (counting_heap_calls) CountAllocation(size);
  return __libc_realloc(pointer, size);
}
void free(void* pointer) noexcept {
  if (counting_heap_calls && pointer != nullptr) ++deallocation_count;
  __libc_free(pointer);
}
}  // extern "C"
#endif

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::ProblemBundle;
using testing::Weights;

struct HeapCalls {
  long allocations = 0;
  long deallocations = 0;
  std::size_t bytes = 0;    // allocated, summed (a realloc counts its new size)
  std::size_t largest = 0;  // the largest allocation
};

// The heap calls `work` makes on this thread.
template <typename Work>
HeapCalls CountHeapCalls(Work&& work) {
  allocation_count = 0;
  deallocation_count = 0;
  allocated_bytes = 0;
  largest_allocation = 0;
  counting_heap_calls = true;
  work();
  counting_heap_calls = false;
  return {allocation_count, deallocation_count, allocated_bytes, largest_allocation};
}

// Keeps a pointer observable so that the compiler cannot elide its allocation.
void* volatile pointer_sink = nullptr;

#define SKIP_WITHOUT_ALLOCATION_COUNTING()                                                  \
  if (!MCREWAVE_COUNTS_ALLOCATIONS) {                                                       \
    GTEST_SKIP() << "allocation counting needs glibc's allocator (not AddressSanitizer's)"; \
  }

// The counter itself: deliberate allocations are seen, and nothing outside the
// counted region is.
TEST(AllocationCounterTest, CountsDeliberateAllocations) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const HeapCalls standard_vector = CountHeapCalls([] {
    std::vector<double> values(100, 1.0);
    pointer_sink = values.data();
  });
  EXPECT_EQ(standard_vector.allocations, 1);
  EXPECT_EQ(standard_vector.deallocations, 1);
  // Eigen's dense storage goes through std::malloc, not operator new.
  const HeapCalls eigen_vector = CountHeapCalls([] {
    Vector values = Vector::Constant(100, 1.0);
    pointer_sink = values.data();
  });
  EXPECT_EQ(eigen_vector.allocations, 1);
  EXPECT_EQ(eigen_vector.deallocations, 1);
  EXPECT_EQ(eigen_vector.bytes, 100 * sizeof(double));
  EXPECT_EQ(eigen_vector.largest, 100 * sizeof(double));
  const HeapCalls nothing = CountHeapCalls([] { pointer_sink = nullptr; });
  EXPECT_EQ(nothing.allocations, 0);
  EXPECT_EQ(nothing.deallocations, 0);
}

// A 20-element bar at the paper's Courant number, 200 steps.
constexpr int kElements = 20;
constexpr int kSteps = 200;
constexpr double kTimeStep = 0.36e-6 * 100.0 / kElements;  // h [s]
constexpr double kModulus = 200e9;                         // E [Pa]

// The bar's K, or with `banded` a K of half bandwidth 2 (every node also coupled to
// its second neighbour), so that the integrator leaves its tridiagonal fast path.
SparseMatrix TestStiffness(const BarModel& model, bool banded) {
  SparseMatrix stiffness = model.Stiffness(kModulus);
  if (!banded) return stiffness;
  const int n = model.num_nodes();
  const double k = 0.1 * kModulus * model.unit_stiffness().coeff(0, 0);  // [N/m]
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i + 2 < n; ++i) {
    entries.emplace_back(i, i, k);
    entries.emplace_back(i + 2, i + 2, k);
    entries.emplace_back(i, i + 2, -k);
    entries.emplace_back(i + 2, i, -k);
  }
  SparseMatrix second_neighbours(n, n);
  second_neighbours.setFromTriplets(entries.begin(), entries.end());
  return stiffness + second_neighbours;
}

class IntegratorAllocationTest : public ::testing::TestWithParam<bool> {};

TEST_P(IntegratorAllocationTest, StepsAndSweepsAllocateNothingAfterInit) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  BarProperties bar;
  bar.elements = kElements;
  const BarModel model(bar);
  ThetaIntegratorOptions options;
  options.time_step = kTimeStep;
  ThetaIntegrator integrator;
  integrator.Init(model.mass(), TestStiffness(model, GetParam()), options);
  const int n = integrator.size(), last = n - 1;

  // States [m/s, m] and a unit end force [N], all preallocated.
  Matrix velocity = Matrix::Zero(n, kSteps + 1), displacement = Matrix::Zero(n, kSteps + 1);
  Vector force = Vector::Zero(n);
  force[last] = 1.0;
  const Vector shift = Vector::Constant(n, 1e-9);  // z [m]
  const HeapCalls steps = CountHeapCalls([&] {
    for (int k = 0; k < kSteps; ++k) {
      integrator.Step(velocity.col(k), displacement.col(k), force, velocity.col(k + 1),
                      displacement.col(k + 1));
    }
  });
  EXPECT_EQ(steps.allocations, 0);
  EXPECT_EQ(steps.deallocations, 0);
  EXPECT_GT(displacement.col(kSteps).norm(), 0.0);  // the steps ran

  const HeapCalls end_load_steps = CountHeapCalls([&] {
    for (int k = 0; k < kSteps; ++k) {
      integrator.StepWithEndLoads(velocity.col(k), displacement.col(k), shift, 1.0, -1.0,
                                  velocity.col(k + 1), displacement.col(k + 1));
      integrator.StepWithEndLoads(velocity.col(k), displacement.col(k), 1.0, -1.0,
                                  velocity.col(k + 1), displacement.col(k + 1));
    }
  });
  EXPECT_EQ(end_load_steps.allocations, 0);
  EXPECT_EQ(end_load_steps.deallocations, 0);

  // Three independent steps at once, from three columns into three others.
  const HeapCalls batched_steps = CountHeapCalls([&] {
    for (int k = 0; k + 6 <= kSteps; k += 6) {
      const double* v_k[3] = {velocity.col(k).data(), velocity.col(k + 1).data(),
                              velocity.col(k + 2).data()};
      const double* u_k[3] = {displacement.col(k).data(), displacement.col(k + 1).data(),
                              displacement.col(k + 2).data()};
      const double* z[3] = {shift.data(), nullptr, shift.data()};
      const double f0[3] = {1.0, 0.0, -1.0}, fL[3] = {0.0, 1.0, 2.0};
      double* v_next[3] = {velocity.col(k + 3).data(), velocity.col(k + 4).data(),
                           velocity.col(k + 5).data()};
      double* u_next[3] = {displacement.col(k + 3).data(), displacement.col(k + 4).data(),
                           displacement.col(k + 5).data()};
      integrator.StepsWithEndLoads<3>(v_k, u_k, z, f0, fL, v_next, u_next);
    }
  });
  EXPECT_EQ(batched_steps.allocations, 0);
  EXPECT_EQ(batched_steps.deallocations, 0);

  const Vector zero = Vector::Zero(n);
  auto end_force = [last](int k, Eigen::Ref<Vector> f) {
    f.setZero();
    f[last] = 1.0 + 0.01 * k;  // [N]
  };
  int observed = 0;
  auto record = [&](int k, const Vector& v, const Vector& u) {
    velocity.col(k) = v;
    displacement.col(k) = u;
    ++observed;
  };
  const HeapCalls forward_sweep =
      CountHeapCalls([&] { integrator.SweepForward(kSteps, zero, zero, end_force, record); });
  EXPECT_EQ(forward_sweep.allocations, 0);
  EXPECT_EQ(forward_sweep.deallocations, 0);
  EXPECT_EQ(observed, kSteps + 1);
  EXPECT_GT(displacement.col(kSteps).norm(), 0.0);

  const Vector final_velocity = velocity.col(kSteps), final_displacement = displacement.col(kSteps);
  observed = 0;
  const HeapCalls backward_sweep = CountHeapCalls([&] {
    integrator.SweepBackward(kSteps, final_velocity, final_displacement, end_force, record);
  });
  EXPECT_EQ(backward_sweep.allocations, 0);
  EXPECT_EQ(backward_sweep.deallocations, 0);
  EXPECT_EQ(observed, kSteps + 1);
}

INSTANTIATE_TEST_SUITE_P(TridiagonalAndBanded, IntegratorAllocationTest,
                         ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "Banded" : "Tridiagonal";
                         });

// The sparse path (linalg/sparse_theta_step.h) on a 2-D lattice: its steps, shifted
// steps, batched steps and sweeps neither allocate nor free after Init.
TEST(SparseIntegratorAllocationTest, StepsAndSweepsAllocateNothingAfterInit) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  constexpr int kSide = 12, n = kSide * kSide;
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const int a = j * kSide + i;
      entries.emplace_back(a, a, i == 0 ? 1.0 : 0.0);  // springs to the ground at i = 0
      for (const int b : {i + 1 < kSide ? a + 1 : -1, j + 1 < kSide ? a + kSide : -1}) {
        if (b < 0) continue;
        entries.emplace_back(a, a, 1.0);
        entries.emplace_back(b, b, 1.0);
        entries.emplace_back(a, b, -1.0);
        entries.emplace_back(b, a, -1.0);
      }
    }
  }
  SparseMatrix stiffness(n, n), mass(n, n);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  mass.setIdentity();
  ThetaIntegratorOptions options;
  options.time_step = 0.1;
  options.factorization = Factorization::kSparse;
  ThetaIntegrator integrator;
  integrator.Init(mass, stiffness, options);
  ASSERT_EQ(integrator.factorization(), Factorization::kSparse);
  Matrix velocity = Matrix::Zero(n, kSteps + 1), displacement = Matrix::Zero(n, kSteps + 1);
  Vector force = Vector::Zero(n);
  force[n - 1] = 1.0;
  const Vector shift = Vector::Constant(n, 1e-3);
  const int nodes[2] = {3, 70};
  const double values[2] = {1.0, -2.0};
  const PointLoads point_loads{2, nodes, values};
  const HeapCalls steps = CountHeapCalls([&] {
    for (int k = 0; k < kSteps; ++k) {
      integrator.Step(velocity.col(k), displacement.col(k), force, velocity.col(k + 1),
                      displacement.col(k + 1));
      integrator.StepShifted(velocity.col(k), displacement.col(k), shift, force,
                             velocity.col(k + 1), displacement.col(k + 1));
      integrator.StepWithEndLoads(velocity.col(k), displacement.col(k), shift, 1.0, -1.0,
                                  velocity.col(k + 1), displacement.col(k + 1), &point_loads);
      integrator.StepWithEndLoads(velocity.col(k), displacement.col(k), 1.0, -1.0,
                                  velocity.col(k + 1), displacement.col(k + 1), &point_loads);
    }
  });
  EXPECT_EQ(steps.allocations, 0);
  EXPECT_EQ(steps.deallocations, 0);
  EXPECT_GT(displacement.col(kSteps).norm(), 0.0);
  const HeapCalls batched_steps = CountHeapCalls([&] {
    for (int k = 0; k + 4 <= kSteps; k += 4) {
      const double* v_k[2] = {velocity.col(k).data(), velocity.col(k + 1).data()};
      const double* u_k[2] = {displacement.col(k).data(), displacement.col(k + 1).data()};
      const double* z[2] = {shift.data(), nullptr};
      const double f0[2] = {1.0, 0.0}, fL[2] = {0.0, 1.0};
      double* v_next[2] = {velocity.col(k + 2).data(), velocity.col(k + 3).data()};
      double* u_next[2] = {displacement.col(k + 2).data(), displacement.col(k + 3).data()};
      integrator.StepsWithEndLoads<2>(v_k, u_k, z, f0, fL, v_next, u_next);
    }
  });
  EXPECT_EQ(batched_steps.allocations, 0);
  EXPECT_EQ(batched_steps.deallocations, 0);
  const Vector zero = Vector::Zero(n);
  auto end_force = [](int k, Eigen::Ref<Vector> f) {
    f.setZero();
    f[n - 1] = 1.0 + 0.01 * k;
  };
  auto record = [&](int k, const Vector& v, const Vector& u) {
    velocity.col(k) = v;
    displacement.col(k) = u;
  };
  const HeapCalls sweeps = CountHeapCalls([&] {
    integrator.SweepForward(kSteps, zero, zero, end_force, record);
    integrator.SweepBackward(kSteps, zero, zero, end_force, record);
  });
  EXPECT_EQ(sweeps.allocations, 0);
  EXPECT_EQ(sweeps.deallocations, 0);
}

TEST(McreProblemAllocationTest, SweepsIntoPreallocatedFieldsAllocateNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  ProblemBundle bundle(MakeSmallCase(kElements, kSteps, 5.0, 2), Weights(0.01, 1.0));
  testing::BarMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * testing::kReferenceModulus);
  // Preallocated fields, n x (m + 1); the solvers' workspace (its zero field) too.
  Matrix displacement = problem.ZeroField(), retrograde = problem.ZeroField();
  Matrix displacement_2 = problem.ZeroField(), retrograde_2 = problem.ZeroField();
  Matrix displacement_3 = problem.ZeroField(), retrograde_3 = problem.ZeroField();
  Matrix image = problem.ZeroField();
  problem.workspace();
  // A non-zero retrograde field to drive the direct sweeps: W_u = Retrograde(0).
  problem.RetrogradeSweep(problem.ZeroField(), true, &retrograde);
  ASSERT_GT(retrograde.norm(), 0.0);
  const long sweeps_before = problem.sweep_count();

  const HeapCalls direct = CountHeapCalls([&] {
    problem.DirectSweep(retrograde, true, &displacement);
    problem.DirectSweep(retrograde, false, &displacement_2);
  });
  EXPECT_EQ(direct.allocations, 0);
  EXPECT_EQ(direct.deallocations, 0);
  EXPECT_GT(displacement.norm(), 0.0);
  EXPECT_GT(displacement_2.norm(), 0.0);

  const HeapCalls retrograde_sweeps = CountHeapCalls([&] {
    problem.RetrogradeSweep(displacement, true, &retrograde_2);
    problem.RetrogradeSweep(displacement, false, &retrograde_3);
  });
  EXPECT_EQ(retrograde_sweeps.allocations, 0);
  EXPECT_EQ(retrograde_sweeps.deallocations, 0);
  EXPECT_GT(retrograde_2.norm(), 0.0);
  EXPECT_GT(retrograde_3.norm(), 0.0);

  // The batched sweeps, with their argument lists built beforehand.
  const std::vector<const Matrix*> retrograde_inputs{&retrograde, nullptr, &retrograde_2};
  const std::vector<Matrix*> displacement_outputs{&displacement, &displacement_2, &displacement_3};
  const std::vector<const Matrix*> displacement_inputs{&displacement, nullptr, &displacement_2};
  const std::vector<Matrix*> retrograde_outputs{&retrograde_3, &image, &retrograde_2};
  const std::vector<const Matrix*> one_retrograde{nullptr}, one_displacement{&displacement};
  const std::vector<Matrix*> one_displacement_output{&displacement_3},
      one_retrograde_output{&image};
  const HeapCalls batched = CountHeapCalls([&] {
    problem.DirectSweepsWithData(retrograde_inputs, displacement_outputs);
    problem.RetrogradeSweepsWithData(displacement_inputs, retrograde_outputs);
    problem.DirectSweepsWithData(one_retrograde, one_displacement_output);
    problem.RetrogradeSweepsWithData(one_displacement, one_retrograde_output);
  });
  EXPECT_EQ(batched.allocations, 0);
  EXPECT_EQ(batched.deallocations, 0);

  // The compositions the solvers iterate on.
  const HeapCalls maps = CountHeapCalls([&] {
    problem.FixedPointMap(retrograde, &displacement, &image);
    problem.ApplyIterationMap(retrograde, &displacement_2, &image);
  });
  EXPECT_EQ(maps.allocations, 0);
  EXPECT_EQ(maps.deallocations, 0);
  // 2 direct, 2 retrograde, 3 + 3 + 1 + 1 batched, 2 + 2 in the maps.
  EXPECT_EQ(problem.sweep_count() - sweeps_before, 16);
}

TEST(McreProblemAllocationTest, RetrogradeSweepsWithInteriorSensorsAllocateNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  ProblemBundle bundle(MakeSmallCase(kElements, kSteps, 5.0, 2), Weights(0.01, 1.0));
  // A displacement and a strain sensor inside the bar, read off the data's own model.
  ChannelSet data = bundle.data;
  data.Add("u@0.4", ChannelKind::kDisplacement, 1e-6 * data.Values("uL"));
  data.Add("e@0.7", ChannelKind::kStrain, 1e-3 * data.Values("uL"));
  testing::BarMcreProblem problem(bundle.model, data, Weights(0.01, 1.0),
                                  testing::kReferenceModulus, 0.5);
  problem.SetModulus(0.9 * testing::kReferenceModulus);
  Matrix displacement = problem.ZeroField(), retrograde = problem.ZeroField();
  Matrix retrograde_2 = problem.ZeroField(), retrograde_3 = problem.ZeroField();
  problem.workspace();
  problem.DirectSweep(problem.ZeroField(), true, &displacement);
  const std::vector<const Matrix*> inputs{&displacement, nullptr};
  const std::vector<Matrix*> outputs{&retrograde_2, &retrograde_3};
  const HeapCalls calls = CountHeapCalls([&] {
    problem.RetrogradeSweep(displacement, true, &retrograde);
    problem.RetrogradeSweep(displacement, false, &retrograde_2);
    problem.RetrogradeSweepsWithData(inputs, outputs);
  });
  EXPECT_EQ(calls.allocations, 0);
  EXPECT_EQ(calls.deallocations, 0);
  EXPECT_GT(retrograde.norm(), 0.0);
}

// The problem of a structure given by matrices (the coarse plate, sparse path): its
// sweeps, the solvers' maps and the sums over the fields allocate nothing.
TEST(MatrixMcreProblemAllocationTest, SweepsAndSumsAllocateNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const MatrixModelData plate =
      ReadMatrixModel(std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/coarse/model.yaml");
  Matrix loads = Matrix::Zero(1, 21);
  loads(0, 3) = 1e3;
  const ChannelSet data = MatrixChannelSet(
      plate, 1e-6, loads, Matrix::Constant(static_cast<int>(plate.sensors.size()), 21, 1e-7));
  MatrixMcreProblem problem(plate, data, Weights(0.01, 1.0), 2e11, 0.5);
  ASSERT_EQ(problem.integrator().factorization(), Factorization::kSparse);
  Matrix displacement = problem.ZeroField(), retrograde = problem.ZeroField();
  Matrix image = problem.ZeroField();
  Vector gradient = Vector::Zero(2);
  problem.workspace();
  problem.RetrogradeSweep(problem.ZeroField(), true, &retrograde);
  const std::vector<const Matrix*> inputs{&retrograde, nullptr};
  const std::vector<Matrix*> outputs{&displacement, &image};
  double sums = 0.0;
  const HeapCalls calls = CountHeapCalls([&] {
    problem.DirectSweep(retrograde, true, &displacement);
    problem.RetrogradeSweep(displacement, false, &image);
    problem.FixedPointMap(retrograde, &displacement, &image);
    problem.DirectSweepsWithData(inputs, outputs);
    sums = problem.InnerProduct(retrograde, image) + problem.Cost(displacement, retrograde);
    problem.CostGradients(displacement, retrograde, &gradient);
  });
  EXPECT_EQ(calls.allocations, 0);
  EXPECT_EQ(calls.deallocations, 0);
  EXPECT_TRUE(std::isfinite(sums));
  EXPECT_GT(displacement.norm(), 0.0);
  EXPECT_NE(gradient[0], 0.0);
}

TEST(McreProblemAllocationTest, StreamingMapAllocatesNothingAfterItsFirstCall) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  ProblemBundle bundle(MakeSmallCase(kElements, kSteps, 5.0, 2), Weights(0.01, 1.0));
  ChannelSet data = bundle.data;
  data.Add("e@0.7", ChannelKind::kStrain, 1e-3 * data.Values("uL"));
  testing::BarMcreProblem problem(bundle.model, data, Weights(0.01, 1.0),
                                  testing::kReferenceModulus, 0.5);
  problem.SetModulus(0.9 * testing::kReferenceModulus);
  const Matrix traces = Matrix::Constant(problem.num_traces(), problem.num_steps() + 1, 1e-7);
  Matrix image;
  testing::BarMcreProblem::StreamingTotals totals;
  // The first calls size the image and the totals.
  problem.StreamingMap(traces, true, &image, &totals);
  const HeapCalls calls = CountHeapCalls([&] {
    problem.StreamingMap(traces, true, &image);
    problem.StreamingMap(traces, false, &image);
    problem.StreamingMap(traces, true, &image, &totals);
  });
  EXPECT_EQ(calls.allocations, 0);
  EXPECT_EQ(calls.deallocations, 0);
  EXPECT_GT(totals.cost, 0.0);
}

// The streaming map of a structure given by matrices (the coarse plate, sparse path,
// its checkpoints allocated by the first call) and the retrograde energy allocate
// nothing.
TEST(MatrixMcreProblemAllocationTest, StreamingMapAllocatesNothingAfterItsFirstCall) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const MatrixModelData plate =
      ReadMatrixModel(std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/coarse/model.yaml");
  Matrix loads = Matrix::Zero(1, 21);
  loads(0, 3) = 1e3;
  const ChannelSet data = MatrixChannelSet(
      plate, 1e-6, loads, Matrix::Constant(static_cast<int>(plate.sensors.size()), 21, 1e-7));
  MatrixMcreProblem problem(plate, data, Weights(0.01, 1.0), 2e11, 0.5);
  const Matrix traces = Matrix::Constant(problem.num_traces(), problem.num_steps() + 1, 1e-7);
  Matrix image;
  StreamingCoupledProblem::StreamingTotals totals;
  // The first call sizes the checkpoints, the image and the totals.
  problem.StreamingMap(traces, true, &image, &totals);
  double energy = 0.0;
  const HeapCalls calls = CountHeapCalls([&] {
    problem.StreamingMap(traces, true, &image);
    problem.StreamingMap(traces, false, &image);
    problem.StreamingMap(traces, true, &image, &totals);
    energy = problem.RetrogradeEnergy(traces) + problem.TraceInnerProduct(traces, image);
  });
  EXPECT_EQ(calls.allocations, 0);
  EXPECT_EQ(calls.deallocations, 0);
  EXPECT_GT(totals.cost, 0.0);
  EXPECT_TRUE(std::isfinite(energy));
}

// MatrixOutputErrorObjective::Cost on the zoned bar of the run (BarRunModel, the band
// path, its clamp held) re-initialises the integrator for the new moduli (allocations
// before the loop); the loop over the steps, with a sensitivity per zone, the clamp's
// reaction and interior sensors, allocates nothing, nor does the adjoint's backward
// sweep: the same heap calls for 100 and 200 steps.
TEST(MatrixOutputErrorAllocationTest, OnTheZonedBarTheTimeLoopAllocatesNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  HeapCalls calls[2], adjoint_calls[2];
  for (int i = 0; i < 2; ++i) {
    testing::SmallCase small = MakeSmallCase(kElements, 100 * (i + 1), INFINITY, 1);
    ZoneLayout layout;
    layout.zone_count = 4;
    const BarModel model(small.bar, layout.ElementZones(small.bar));
    const ChannelSet data =
        SimulateClampedBar(small.bar, small.load, small.time, {}, {"u@0.3", "e@0.6"});
    NoiseLevels noise;
    noise.displacement_std = 1e-7;
    noise.force_std = 1.0;
    noise.strain_std = 1e-7;
    const MatrixModelData matrices = BarRunModel(model, data, {});
    MatrixOutputErrorObjective objective(matrices, data, noise, 0.5);
    const Vector moduli = Vector::Constant(4, 0.9 * kModulus);
    Vector gradient(4);
    objective.Cost(moduli, &gradient);
    calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
    // The adjoint's gradient: its backward sweep allocates nothing either.
    objective.SetGradientMethod(LeastSquaresGradient::kAdjoint);
    objective.Cost(moduli, &gradient);
    adjoint_calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
  }
  EXPECT_EQ(calls[0].allocations, calls[1].allocations);
  EXPECT_EQ(calls[0].deallocations, calls[1].deallocations);
  EXPECT_EQ(adjoint_calls[0].allocations, adjoint_calls[1].allocations);
  EXPECT_EQ(adjoint_calls[0].deallocations, adjoint_calls[1].deallocations);
}

// MatrixOutputErrorObjective::Cost likewise (the coarse plate, sparse path, 2 zones, 5
// sensors), by forward sensitivities and by the adjoint: the same heap calls for 20 and
// 80 steps.
TEST(MatrixOutputErrorAllocationTest, TheTimeLoopAllocatesNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const MatrixModelData plate =
      ReadMatrixModel(std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/coarse/model.yaml");
  HeapCalls calls[2], adjoint_calls[2];
  for (int i = 0; i < 2; ++i) {
    const int samples = 1 + 20 * (1 + 3 * i);
    Matrix loads = Matrix::Zero(1, samples);
    loads(0, 3) = 1e3;
    const ChannelSet data =
        MatrixChannelSet(plate, 1e-6, loads,
                         Matrix::Constant(static_cast<int>(plate.sensors.size()), samples, 1e-7));
    NoiseLevels levels;
    levels.displacement_std = 1e-7;
    levels.strain_std = 1e-7;
    MatrixOutputErrorObjective objective(plate, data, levels, 0.5);
    const Vector moduli = (Vector(2) << 1.9e11, 1.5e11).finished();
    Vector gradient(2);
    objective.Cost(moduli, &gradient);
    ASSERT_EQ(objective.integrator().factorization(), Factorization::kSparse);
    calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
    objective.SetGradientMethod(LeastSquaresGradient::kAdjoint);
    objective.Cost(moduli, &gradient);
    adjoint_calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
  }
  EXPECT_EQ(calls[0].allocations, calls[1].allocations);
  EXPECT_EQ(calls[0].deallocations, calls[1].deallocations);
  EXPECT_EQ(adjoint_calls[0].allocations, adjoint_calls[1].allocations);
  EXPECT_EQ(adjoint_calls[0].deallocations, adjoint_calls[1].deallocations);
}

// The same with a support (the supported lattice: its reaction an output, the held
// dofs decoupled), with and without the Fisher information and each sensor's, and with
// the adjoint's gradient: the same heap calls for 20 and 80 steps.
TEST(MatrixOutputErrorAllocationTest, WithASupportTheTimeLoopAllocatesNothing) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const MatrixModelData lattice = testing::SupportedLattice();
  HeapCalls calls[2], fisher_calls[2], sensor_calls[2], adjoint_calls[2];
  for (int i = 0; i < 2; ++i) {
    const int samples = 1 + 20 * (1 + 3 * i);
    Matrix loads = Matrix::Zero(1, samples);
    loads(0, 3) = 1e3;
    ChannelSet data =
        MatrixChannelSet(lattice, 2e-3, loads,
                         Matrix::Constant(static_cast<int>(lattice.sensors.size()), samples, 1e-7));
    data.Add("R", ChannelKind::kForce, Vector::Constant(samples, 1.0));
    NoiseLevels levels;
    levels.displacement_std = 1e-7;
    levels.strain_std = 1e-7;
    levels.force_std = 1.0;
    MatrixOutputErrorObjective objective(lattice, data, levels, 0.5);
    const Vector moduli = (Vector(2) << 1.9e11, 1.5e11).finished();
    Vector gradient(2);
    objective.Cost(moduli, &gradient);
    calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
    // With the Fisher information as well.
    Matrix information;
    objective.Cost(moduli, &gradient, &information);
    fisher_calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient, &information); });
    // And each sensor's: its matrices are sized before the time loop.
    std::vector<Matrix> sensors;
    objective.Cost(moduli, &gradient, &information, &sensors);
    sensor_calls[i] =
        CountHeapCalls([&] { objective.Cost(moduli, &gradient, &information, &sensors); });
    // The adjoint's gradient, the supports' reactions in its loads.
    objective.SetGradientMethod(LeastSquaresGradient::kAdjoint);
    objective.Cost(moduli, &gradient);
    adjoint_calls[i] = CountHeapCalls([&] { objective.Cost(moduli, &gradient); });
  }
  EXPECT_EQ(adjoint_calls[0].allocations, adjoint_calls[1].allocations);
  EXPECT_EQ(adjoint_calls[0].deallocations, adjoint_calls[1].deallocations);
  EXPECT_EQ(sensor_calls[0].allocations, sensor_calls[1].allocations);
  EXPECT_EQ(sensor_calls[0].deallocations, sensor_calls[1].deallocations);
  EXPECT_EQ(calls[0].allocations, calls[1].allocations);
  EXPECT_EQ(calls[0].deallocations, calls[1].deallocations);
  EXPECT_EQ(fisher_calls[0].allocations, fisher_calls[1].allocations);
  EXPECT_EQ(fisher_calls[0].deallocations, fisher_calls[1].deallocations);
}

// The heap calls of parsing `text` as a Matrix Market matrix (InputError or not).
HeapCalls MatrixMarketHeapCalls(const std::string& text) {
  std::istringstream stream(text);
  return CountHeapCalls([&] {
    try {
      pointer_sink = ParseMatrixMarketMatrix(stream, "k.mtx").outerIndexPtr();
    } catch (const InputError&) {
    }
  });
}

// What a size line declares is not allocated ahead: 1e7 entries declared and one given
// reserved 240 MB (24 bytes an entry, up to 2^26 entries: 1.6 GB for the 1e8 declared
// of a 40-byte file), now at most 2^14 entries. A matrix of 1e7 columns allocates its
// column starts once, 40 MB (4 bytes a column): Eigen's triplet path, which built it,
// allocated 160 MB in all for 1 x 1e7 as for 1e7 x 1e7 (1.6 GB for 1e8 x 1e8, which
// the size line then allowed).
TEST(MatrixMarketAllocationTest, ASizeLineAloneAllocatesLittle) {
  SKIP_WITHOUT_ALLOCATION_COUNTING();
  const std::string banner = "%%MatrixMarket matrix coordinate real general\n";
  const HeapCalls declared = MatrixMarketHeapCalls(banner + "10000000 1 10000000\n1 1 1\n");
  EXPECT_LT(declared.largest, std::size_t{1} << 20);
  EXPECT_LT(declared.bytes, std::size_t{2} << 20);
  const std::size_t column_starts = (10000000 + 1) * sizeof(int);
  for (const char* size_line : {"1 10000000 1\n1 10000000 2\n", "10000000 10000000 0\n"}) {
    const HeapCalls wide = MatrixMarketHeapCalls(banner + size_line);
    EXPECT_EQ(wide.largest, column_starts) << size_line;
    EXPECT_LT(wide.bytes, column_starts + (std::size_t{1} << 20)) << size_line;
  }
}

}  // namespace
}  // namespace mcrewave
