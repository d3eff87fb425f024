// Tests of the streaming solver on structures given by matrices
// (MatrixMcreProblem as a StreamingCoupledProblem, docs/streaming.md section 5): one
// streaming application is the stored sweeps' to the bit; the streaming CG gives the
// stored-field CG's e^2, zone gradients, traces and maps under every support treatment;
// auto streams when the fields do not fit; the zone objective evaluates alike with
// either solver; the model's outputs need no stored field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/simulation.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::RelativeDifference;
using testing::SupportedLattice;
using testing::SupportedLatticeHistories;
using testing::Weights;

CoupledSolverOptions MatrixStreamingOptions(CoupledSolverType type) {
  CoupledSolverOptions options;
  options.type = type;
  options.tolerance = 1e-12;
  return options;
}

// The lattice under its trusted support, its problem at the moduli (1.8, 2.1) x 1e11 Pa.
struct TrustedLatticeProblem {
  TrustedLatticeProblem()
      : problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                ClampModel::kTrusted) {
    problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
  }
  MatrixModelData lattice = SupportedLattice();
  ChannelSet data = SupportedLatticeHistories(lattice);
  MatrixMcreProblem problem;
};

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

// Runs check(problem, whole) on the lattice's problem at the moduli (1.8, 2.1) x 1e11 Pa
// under every support treatment, from checkpoints (whole false) and from omega's whole
// history.
template <typename Check>
void ForEveryLatticeProblem(Check&& check) {
  const ChannelSet data = SupportedLatticeHistories(SupportedLattice());
  for (const MatrixStreamingCase& c : kMatrixStreamingCases) {
    for (const bool whole : {false, true}) {
      SCOPED_TRACE(std::string(c.name) + (whole ? ", whole history" : ", checkpoints"));
      const MatrixModelData lattice = MatrixStreamingLattice(c);
      MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5,
                                Factorization::kSparse, c.treatment);
      if (!whole) problem.SetHistoryBudget(0);
      problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
      check(problem, whole);
    }
  }
}

// StreamingMap at traces y = H U runs the retrograde sweep of U and the direct sweep of
// the W it gives, and gathers the cost, gradients and maps of those fields: from
// checkpoints (three sweeps) and from omega's whole history (two; the default at this
// size), the same bits.
TEST(MatrixStreamingTest, OneApplicationIsTheStoredSweeps) {
  ForEveryLatticeProblem([](MatrixMcreProblem& problem, bool whole) {
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
    EXPECT_EQ(problem.sweep_count() - sweeps, whole ? 2 : 3);
    EXPECT_EQ(problem.checkpoint_stride() == problem.num_steps(), whole);
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
    // No element blocks: no element map, no picture.
    EXPECT_EQ(totals.element_error_map.size(), 0);
    EXPECT_EQ(totals.gap_density.size(), 0);
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
  });
}

// At the data itself (y = d~, the start of every solve) the retrograde loads vanish:
// StreamingMap skips the backward sweep and gives the direct sweep of W = 0, the same
// bits as the stored fields of that sweep, in one sweep instead of two or three.
TEST(MatrixStreamingTest, AtTheDataItselfOneDirectSweepGivesTheMap) {
  ForEveryLatticeProblem([](MatrixMcreProblem& problem, bool whole) {
    Matrix u0;
    problem.DirectSweep(problem.ZeroField(), true, &u0);
    Matrix image;
    StreamingCoupledProblem::StreamingTotals totals;
    const long sweeps = problem.sweep_count();
    problem.StreamingMap(problem.DataTraces(), true, &image, &totals);
    EXPECT_EQ(problem.sweep_count() - sweeps, 1);
    EXPECT_EQ(image, problem.ObservedTraces(u0));
    // Measured 0 apart: the same sums in the same order, W's terms zero.
    const double cost = problem.Cost(u0, problem.ZeroField());
    EXPECT_NEAR(totals.cost, cost, 4e-16 * cost);
    EXPECT_EQ(totals.zone_error_map.norm(), 0.0);
    EXPECT_EQ(totals.error_map.norm(), 0.0);
    // Beside the data, the full map again.
    Matrix beside = problem.DataTraces();
    beside(0, 1) += 1e-3 * (std::abs(beside(0, 1)) + 1e-9);
    const long before = problem.sweep_count();
    problem.StreamingMap(beside, true, &image, &totals);
    EXPECT_EQ(problem.sweep_count() - before, whole ? 2 : 3);
    EXPECT_GT(totals.zone_error_map.norm(), 0.0);
  });
}

// A small bar of 20 elements in two zones (12 and 8), exported with its clamp as a
// support (element blocks, one per element), and its synthetic data.
struct ZonedBar {
  ZonedBar() {
    const testing::SmallCase c = testing::MakeSmallCase(20, 300, 20.0, 2);
    std::vector<int> zones(20);
    for (int e = 0; e < 20; ++e) zones[e] = e < 12 ? 0 : 1;
    data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
    model = BarMatrixModel(BarModel(c.bar, zones), c.bar.modulus, {}, BarClampExport::kSupport);
  }
  ChannelSet data;
  MatrixModelData model;
};

// With element blocks (the bar exported, 2 zones), one application sums the element
// map's shares and picture rows of the W it passes through, and the sensitivities of W
// and U: ComputeElementErrorMap's and ElementSensitivities' of the stored fields to the
// bit (the same fields from the checkpoints, the same sums in the same order), under a
// trusted and a measured support.
TEST(MatrixStreamingTest, OneApplicationGivesTheStoredFieldsElementMap) {
  const ZonedBar zoned;
  const ChannelSet& data = zoned.data;
  const MatrixModelData& model = zoned.model;
  for (const ClampModel treatment : {ClampModel::kTrusted, ClampModel::kMeasured}) {
    SCOPED_TRACE(ClampModelToString(treatment));
    MatrixMcreProblem problem(model, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kAutomatic,
                              treatment);
    problem.SetModuli((Vector(2) << 1.9e11, 1.7e11).finished());
    Matrix u0, w;
    problem.DirectSweep(problem.ZeroField(), true, &u0);
    problem.RetrogradeSweep(u0, true, &w);
    Matrix image;
    StreamingCoupledProblem::StreamingTotals totals;
    problem.StreamingMap(problem.ObservedTraces(u0), true, &image, &totals);
    const ErrorMap stored = ComputeElementErrorMap(model, problem.moduli(), w, problem.time_step());
    const ErrorMap streamed =
        AssembleElementErrorMap(model, totals.element_error_map, totals.gap_density,
                                problem.num_steps(), problem.time_step());
    ASSERT_EQ(streamed.share.size(), 20);
    EXPECT_TRUE(streamed.share == stored.share);
    EXPECT_TRUE(streamed.density == stored.density);
    EXPECT_TRUE(streamed.times == stored.times);
    EXPECT_TRUE(streamed.position == stored.position);
    EXPECT_TRUE(streamed.density_position == stored.density_position);
    EXPECT_GT(streamed.share.maxCoeff(), 0.0);
    // The sensitivities of that application's fields, W and U = Direct(W).
    Matrix u;
    problem.DirectSweep(w, true, &u);
    Vector sensitivity;
    problem.ElementSensitivities(u, w, &sensitivity);
    EXPECT_TRUE(totals.element_sensitivity == sensitivity);
    EXPECT_GT(sensitivity.cwiseAbs().maxCoeff(), 0.0);
  }
}

// With the element map left out (set_element_maps(false)), a streaming solve's totals
// hold none and the same cost and gradients; StreamingElementMaps then gives, from the
// solution's traces, the map a solve that gathered it holds, to the bit.
TEST(MatrixStreamingTest, TheElementMapLeftOutIsGatheredFromTheTraces) {
  const ZonedBar zoned;
  const ChannelSet& data = zoned.data;
  const MatrixModelData& model = zoned.model;
  CoupledSolverOptions streaming;
  streaming.type = CoupledSolverType::kStreamingConjugateGradient;
  const Vector moduli = (Vector(2) << 1.9e11, 1.7e11).finished();
  CoupledSolution with_maps, without_maps;
  for (const bool gather : {true, false}) {
    MatrixMcreProblem problem(model, data, Weights(0.01, 1.0), 2e11, 0.5);
    problem.set_element_maps(gather);
    problem.SetModuli(moduli);
    CoupledSolution& solution = gather ? with_maps : without_maps;
    ASSERT_TRUE(SolveCoupled(streaming, &problem, nullptr, &solution).IsSolutionUsable());
    if (!gather) {
      EXPECT_EQ(solution.element_error_map.size(), 0);
      EXPECT_EQ(solution.gap_density.size(), 0);
      problem.StreamingElementMaps(solution.traces, &solution);
    }
  }
  EXPECT_EQ(without_maps.cost, with_maps.cost);
  EXPECT_TRUE(without_maps.cost_gradients == with_maps.cost_gradients);
  ASSERT_EQ(with_maps.element_error_map.size(), 20);
  EXPECT_TRUE(without_maps.element_error_map == with_maps.element_error_map);
  EXPECT_TRUE(without_maps.gap_density == with_maps.gap_density);
  EXPECT_GT(with_maps.element_error_map.maxCoeff(), 0.0);
}

// The streaming CG against the stored-field CG, both to 1e-12, under every treatment.
TEST(MatrixStreamingTest, StreamingAndStoredFieldConjugateGradientsAgree) {
  for (const MatrixStreamingCase& c : kMatrixStreamingCases) {
    SCOPED_TRACE(c.name);
    const MatrixModelData lattice = MatrixStreamingLattice(c);
    const ChannelSet data = SupportedLatticeHistories(SupportedLattice());
    MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                              c.treatment);
    problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
    CoupledSolution stored, streamed;
    const CoupledSolverSummary stored_summary = SolveCoupled(
        MatrixStreamingOptions(CoupledSolverType::kConjugateGradient), &problem, nullptr, &stored);
    ASSERT_TRUE(stored_summary.IsSolutionUsable()) << stored_summary.FullReport();
    const CoupledSolverSummary streamed_summary =
        SolveCoupled(MatrixStreamingOptions(CoupledSolverType::kStreamingConjugateGradient),
                     &problem, nullptr, &streamed);
    ASSERT_TRUE(streamed_summary.IsSolutionUsable()) << streamed_summary.FullReport();
    EXPECT_EQ(streamed_summary.type, CoupledSolverType::kStreamingConjugateGradient);
    EXPECT_FALSE(streamed.has_fields());
    const double cost = std::abs(streamed.cost - stored.cost) / stored.cost;
    const double gradients =
        (streamed.cost_gradients - stored.cost_gradients).norm() / stored.cost_gradients.norm();
    const double traces =
        RelativeDifference(streamed.traces, problem.ObservedTraces(stored.displacement));
    const double zones =
        RelativeDifference(streamed.zone_error_map, problem.ZoneErrorMap(stored.retrograde));
    const double energies =
        RelativeDifference(streamed.zone_strain_energy, problem.ZoneErrorMap(stored.displacement));
    const double dofs =
        RelativeDifference(streamed.error_map, problem.DofErrorMap(stored.retrograde));
    // Measured at most (none, measured, trusted, pinned; the pinned support the stiffest,
    // 73 iterations streamed against 65 stored, 6 to 8 otherwise): e^2 3.0e-15 apart
    // (relative); the zone gradients 2.9e-9 of their norm (3.4e-11 but pinned), the
    // traces 2.3e-10, the zone maps of W 3.2e-10 and of U 6.8e-11, the dof map 9.8e-10.
    // The model's channels from the streamed traces and G^T W, against the stored fields':
    // every load, sensor and support channel, named as the data's.
    const ChannelSet stored_channels = problem.ModelChannels(stored);
    const ChannelSet streamed_channels = problem.ModelChannels(streamed);
    std::size_t expected_channels = lattice.loads.size() + lattice.sensors.size();
    for (const MatrixModelSupport& support : lattice.supports) {
      expected_channels += support.displacement_channel.empty() ? 1 : 2;
    }
    ASSERT_EQ(stored_channels.channels.size(), expected_channels);
    ASSERT_EQ(streamed_channels.channels.size(), expected_channels);
    double channels = 0.0;
    for (std::size_t i = 0; i < expected_channels; ++i) {
      EXPECT_EQ(streamed_channels.channels[i].name, stored_channels.channels[i].name);
      EXPECT_TRUE(data.Find(stored_channels.channels[i].name) >= 0);
      channels = std::max(channels, RelativeDifference(streamed_channels.channels[i].values,
                                                       stored_channels.channels[i].values));
    }
    // Measured at most 6.4e-13 (none, measured, trusted) and 9.9e-9 (pinned, whose support's
    // displacement, a datum 0, is the smallest channel).
    EXPECT_LT(channels, c.treatment == ClampModel::kPinned && c.supported ? 1e-7 : 6e-12);
    EXPECT_LT(cost, 3e-14);
    EXPECT_LT(gradients, 3e-8);
    EXPECT_LT(traces, 2e-9);
    EXPECT_LT(zones, 3e-9);
    EXPECT_LT(energies, 7e-10);
    EXPECT_LT(dofs, 1e-8);
  }
}

// Noise-free data of the model itself, solved at moduli 1e-12 off the truth's: the
// start's residual Phi(d~) - d~ is at the sweeps' round-off, so no decrease relative to
// it can be measured. The streaming CG accepts the traces once their residual is within
// the tolerance of their own norm, as the stored-field CG accepts its round-off floor;
// both leave e^2 at the round-off. (Before, the streaming CG restarted twice and failed.)
TEST(MatrixStreamingTest, DataTheModelMatchesAreAcceptedAtTheSweepsRoundOff) {
  const MatrixModelData lattice = SupportedLattice();
  const int steps = 120;
  const double time_step = 2e-3;
  const Matrix loads = testing::HalfSineLoadRow(steps, time_step, 0.05);
  ChannelSet at_rest = MatrixChannelSet(
      lattice, time_step, loads, Matrix::Zero(static_cast<int>(lattice.sensors.size()), steps + 1));
  at_rest.Add("R", ChannelKind::kForce, Vector::Zero(steps + 1));
  at_rest.Add("uR", ChannelKind::kDisplacement, Vector::Zero(steps + 1));
  const Vector truth_moduli = (Vector(2) << 2e11, 1.6e11).finished();
  MatrixMcreProblem truth(lattice, at_rest, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                          ClampModel::kTrusted);
  truth.SetModuli(truth_moduli);
  ChannelSet data = MatrixChannelSet(lattice, time_step, loads, truth.ModelOutputs());
  data.Add("R", ChannelKind::kForce, truth.ModelSupportForces().row(0).transpose());
  data.Add("uR", ChannelKind::kDisplacement, Vector::Zero(steps + 1));
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                            ClampModel::kTrusted);
  problem.SetModuli(truth_moduli * (1.0 + 1e-12));
  CoupledSolverOptions options;
  options.tolerance = 1e-8;
  options.type = CoupledSolverType::kStreamingConjugateGradient;
  CoupledSolution streamed, stored;
  const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &streamed);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_NE(summary.message.find("the data are matched within the tolerance"), std::string::npos)
      << summary.message;
  options.type = CoupledSolverType::kConjugateGradient;
  const CoupledSolverSummary stored_summary = SolveCoupled(options, &problem, nullptr, &stored);
  ASSERT_TRUE(stored_summary.IsSolutionUsable()) << stored_summary.FullReport();
  // The streamed traces (the data's own) against the stored-field CG's: measured 3.4e-14.
  EXPECT_LT(RelativeDifference(streamed.traces, problem.ObservedTraces(stored.displacement)),
            3e-13);
  // e^2 at the round-off: measured 4.5e-26 and 4.7e-26 J s, 1.0e-18 times the e^2 of the
  // same data at moduli 1e-3 off (4.5e-8 J s).
  problem.SetModuli(truth_moduli * (1.0 + 1e-3));
  CoupledSolution off;
  ASSERT_TRUE(SolveCoupled(options, &problem, nullptr, &off).IsSolutionUsable());
  EXPECT_LT(streamed.cost, 1e-17 * off.cost);
  EXPECT_LT(stored.cost, 1e-17 * off.cost);
}

// auto takes the stored-field CG while its fields fit inner.max_field_bytes and the
// streaming CG when they do not, on a matrix model as on the bar.
TEST(MatrixStreamingTest, AutoStreamsWhenTheFieldsDoNotFit) {
  const MatrixModelData lattice = SupportedLattice();
  const ChannelSet data = SupportedLatticeHistories(lattice);
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                            ClampModel::kTrusted);
  // 18 dofs, 120 steps: 10 fields of 18 x 121 doubles, 174240 bytes.
  ASSERT_EQ(IterativeSolverFieldBytes(problem.num_nodes(), problem.num_steps()), 174240.0);
  CoupledSolverOptions options = MatrixStreamingOptions(CoupledSolverType::kAuto);
  options.max_field_bytes = 174240;
  CoupledSolution stored, streamed;
  const CoupledSolverSummary fits = SolveCoupled(options, &problem, nullptr, &stored);
  EXPECT_EQ(fits.type, CoupledSolverType::kConjugateGradient);
  ASSERT_TRUE(fits.IsSolutionUsable()) << fits.FullReport();
  options.max_field_bytes = 174239;
  EXPECT_EQ(ResolveCoupledSolverType(options, problem.num_nodes(), problem.num_steps(), true),
            CoupledSolverType::kStreamingConjugateGradient);
  const CoupledSolverSummary streams = SolveCoupled(options, &problem, nullptr, &streamed);
  EXPECT_EQ(streams.type, CoupledSolverType::kStreamingConjugateGradient);
  ASSERT_TRUE(streams.IsSolutionUsable()) << streams.FullReport();
  EXPECT_EQ(CoupledSolverName(options.type, streams.type), "auto (streaming_conjugate_gradient)");
  // The trusted case of the test above: e^2 measured 2.9e-15 apart.
  EXPECT_NEAR(streamed.cost, stored.cost, 3e-14 * stored.cost);
}

// A streaming solve keeps omega's whole history when it fits inner.max_field_bytes
// (two sweeps an application) and takes it from checkpoints when it does not (three):
// the same steps, so the same solution to the bit, and a problem's layout follows the
// budget of each solve.
TEST(MatrixStreamingTest, TheSolveKeepsOmegasWholeHistoryWhenItFitsTheFieldBudget) {
  TrustedLatticeProblem trusted;
  MatrixMcreProblem& problem = trusted.problem;
  // 18 dofs, 120 steps: omega's history is 18 x 121 doubles, 17424 bytes.
  const long history_bytes = 8L * problem.num_nodes() * (problem.num_steps() + 1);
  ASSERT_EQ(history_bytes, 17424);
  CoupledSolverOptions options =
      MatrixStreamingOptions(CoupledSolverType::kStreamingConjugateGradient);
  CoupledSolution whole, checkpointed, whole_again;
  options.max_field_bytes = history_bytes;
  const CoupledSolverSummary fits = SolveCoupled(options, &problem, nullptr, &whole);
  ASSERT_TRUE(fits.IsSolutionUsable()) << fits.FullReport();
  EXPECT_EQ(problem.checkpoint_stride(), problem.num_steps());
  options.max_field_bytes = history_bytes - 1;
  const CoupledSolverSummary checkpoints = SolveCoupled(options, &problem, nullptr, &checkpointed);
  ASSERT_TRUE(checkpoints.IsSolutionUsable()) << checkpoints.FullReport();
  EXPECT_LT(problem.checkpoint_stride(), problem.num_steps());
  options.max_field_bytes = history_bytes;
  const CoupledSolverSummary fits_again = SolveCoupled(options, &problem, nullptr, &whole_again);
  EXPECT_EQ(problem.checkpoint_stride(), problem.num_steps());
  // From checkpoints, one sweep more per application of the map away from the data:
  // the directions p_0 .. p_k of k iterations and the final pass (measured: 8 iterations,
  // 23 sweeps against 33). The start at the data is one direct sweep either way.
  EXPECT_EQ(checkpoints.iterations, fits.iterations);
  EXPECT_EQ(checkpoints.sweeps - fits.sweeps, fits.iterations + 2);
  EXPECT_EQ(fits_again.sweeps, fits.sweeps);
  EXPECT_EQ(checkpointed.cost, whole.cost);
  EXPECT_TRUE(checkpointed.cost_gradients == whole.cost_gradients);
  EXPECT_TRUE(checkpointed.traces == whole.traces);
  EXPECT_EQ(whole_again.cost, whole.cost);
}

// ZoneMcreObjective on a matrix model evaluates e^2 / J_rest and its gradient in
// p = log(E / E_nom) alike with either solver, the streaming one warm-started from its
// traces.
TEST(MatrixStreamingTest, TheZoneObjectiveEvaluatesAlikeWithEitherSolver) {
  const MatrixModelData lattice = SupportedLattice();
  const ChannelSet data = SupportedLatticeHistories(lattice);
  McreOptions mcre;
  mcre.weights = Weights(0.01, 1.0);
  mcre.reference_modulus = 2e11;
  mcre.clamp = ClampModel::kTrusted;
  McreObjective stored_mcre = MatrixMcreObjective(
      lattice, data, mcre, 0.5, MatrixStreamingOptions(CoupledSolverType::kConjugateGradient),
      Factorization::kSparse);
  McreObjective streamed_mcre =
      MatrixMcreObjective(lattice, data, mcre, 0.5,
                          MatrixStreamingOptions(CoupledSolverType::kStreamingConjugateGradient),
                          Factorization::kSparse);
  ZoneMcreObjective stored(&stored_mcre, lattice.NominalModuli());
  ZoneMcreObjective streamed(&streamed_mcre, lattice.NominalModuli());
  for (const double scale : {-0.1, -0.08}) {
    const double p[2] = {scale, 0.5 * scale};
    double stored_cost = 0.0, streamed_cost = 0.0, stored_gradient[2], streamed_gradient[2];
    ASSERT_TRUE(stored.Evaluate(p, &stored_cost, stored_gradient)) << stored.error_message();
    ASSERT_TRUE(streamed.Evaluate(p, &streamed_cost, streamed_gradient))
        << streamed.error_message();
    // Measured: e^2 / J_rest 1.7e-15 apart, the gradient 4.7e-10 (relative).
    EXPECT_NEAR(streamed_cost, stored_cost, 2e-14 * stored_cost);
    for (int z = 0; z < 2; ++z) {
      EXPECT_NEAR(streamed_gradient[z], stored_gradient[z], 5e-9 * std::abs(stored_gradient[z]));
    }
  }
  EXPECT_FALSE(streamed_mcre.last_solution().has_fields());
  EXPECT_GT(streamed_mcre.last_solution().traces.size(), 0);
}

// The model's outputs and its supports' forces come from one direct sweep keeping its
// state (no field: a run that streams stores none): the stored sweep's numbers.
TEST(MatrixStreamingTest, ModelOutputsAreTheStoredSweepsWithoutItsField) {
  TrustedLatticeProblem trusted;
  MatrixMcreProblem& problem = trusted.problem;
  Matrix displacement;
  problem.DirectSweep(problem.ZeroField(), true, &displacement);
  // H's rows: the three sensors, then the support's reaction.
  const Matrix traces = problem.ObservedTraces(displacement);
  ASSERT_EQ(traces.rows(), 4);
  const long sweeps = problem.sweep_count();
  EXPECT_EQ(problem.ModelOutputs(), traces.topRows(3));
  EXPECT_EQ(problem.ModelSupportForces(), traces.bottomRows(1));
  EXPECT_EQ(problem.sweep_count() - sweeps, 2);
}

}  // namespace
}  // namespace mcrewave
