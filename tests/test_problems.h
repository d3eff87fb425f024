// Small MCRE problems shared by the tests of the coupled solvers.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/bounded_minimizer.h"
#include "reference/bar_mcre_problem.h"

// MCREWAVE_ADDRESS_SANITIZER: defined when this build runs under AddressSanitizer
// (gcc's macro or clang's feature test), whose allocator and memory overhead some
// tests must allow for.
#if defined(__SANITIZE_ADDRESS__)
#define MCREWAVE_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MCREWAVE_ADDRESS_SANITIZER 1
#endif
#endif

namespace mcrewave::testing {

#ifdef MCREWAVE_ADDRESS_SANITIZER
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif

// A bar with `elements` elements and a time grid of `steps` steps of the
// paper's Courant number c h / h_e = 0.57, the window scaled accordingly.
struct SmallCase {
  BarProperties bar;
  LoadOptions load;
  TimeOptions time;
  DataOptions data;
};

inline SmallCase MakeSmallCase(int elements, int steps, double snr, int truth_refinement) {
  SmallCase c;
  c.bar.elements = elements;
  c.time.step = 0.36e-6 * 100.0 / elements;
  c.time.window = c.time.step * steps;
  c.load.duration = 0.1e-3 * c.time.window / 0.63e-3;
  c.data.snr = snr;
  c.data.seed = 7;
  c.data.truth_refinement = truth_refinement;
  return c;
}

// The synthetic measurements of a small case at theta.
inline ChannelSet SmallCaseData(const SmallCase& c, double theta) {
  TimeOptions time = c.time;
  time.theta = theta;
  return MakeSyntheticMeasurements(c.bar, c.load, time, c.data);
}

// Owns the model, the data and the built-in bar's own problem built on them.
struct ProblemBundle {
  ProblemBundle(const SmallCase& c, const McreWeights& weights, double theta = 0.5)
      : model(c.bar),
        data(SmallCaseData(c, theta)),
        problem(model, data, weights, c.bar.modulus, theta) {}
  BarModel model;
  ChannelSet data;
  testing::BarMcreProblem problem;
};

// The same bar and data as every run solves them: the bar exported as matrices
// (BarRunModel; its clamp a support, measured by default as ProblemBundle's BarMcreProblem
// has it: the paper's free-free formulation) and its MatrixMcreProblem at the bar's
// modulus.
struct BarRunProblem {
  BarRunProblem(const SmallCase& c, const McreWeights& weights, double theta = 0.5)
      : model(c.bar),
        data(SmallCaseData(c, theta)),
        matrices(BarRunModel(model, data, {})),
        problem(matrices, data, weights, c.bar.modulus, theta) {}
  BarModel model;
  ChannelSet data;
  MatrixModelData matrices;
  MatrixMcreProblem problem;
};

// The MCRE objective of the bar exported as matrices (MatrixMcreObjective); matrices
// and data must outlive it.
inline McreObjective BarObjective(const MatrixModelData& matrices, const ChannelSet& data,
                                  const McreOptions& mcre, const CoupledSolverOptions& inner,
                                  double modulus_scale, double theta = 0.5) {
  return MatrixMcreObjective(matrices, data, mcre, theta, inner, Factorization::kAutomatic,
                             modulus_scale);
}

// Minimises a zone objective in p_z = log(E_z / E_z,ref) from p = 0 within
// [log 1/2, log 2] for every zone, at the step tolerance 1e-10 and no cost tolerance
// (the inverse crimes' setting).
inline BoundedMinimizerSummary MinimizeWithinHalfAndTwice(FirstOrderObjective* objective) {
  BoundedMinimizerOptions options;
  options.step_tolerance = 1e-10;
  options.function_tolerance = 0.0;
  const auto zones = static_cast<std::size_t>(objective->num_parameters());
  return MinimizeWithinBounds(options, objective, std::vector<double>(zones, std::log(0.5)),
                              std::vector<double>(zones, std::log(2.0)),
                              std::vector<double>(zones, 0.0));
}

inline McreWeights Weights(double w_u, double w_f) {
  McreWeights weights;
  weights.displacement_weight = w_u;
  weights.force_weight = w_f;
  return weights;
}

// The paper's free-free formulation (mcre.clamp: measured) at w_u, w_f = 1, in which
// the figures of many tests were measured (the config's defaults trust the clamp).
inline McreOptions FreeFreeMcre(double w_u = 0.01) {
  McreOptions mcre;
  mcre.weights = Weights(w_u, 1.0);
  mcre.clamp = ClampModel::kMeasured;
  return mcre;
}

// The noise-free truth of `bar` on its own mesh and step (data.truth_refinement 1), held
// at x = 0 by a spring of `stiffness_factor` E S / L (data.support_stiffness), with the
// default load and time grid.
inline ChannelSet SpringSupportedBarData(const BarProperties& bar, double stiffness_factor,
                                         DataOptions* data) {
  data->truth_refinement = 1;
  data->support_stiffness = stiffness_factor * bar.modulus * bar.section / bar.length;
  return SimulateTruth(bar, LoadOptions(), TimeOptions(), *data);
}

// ||a - b|| / ||b|| (Frobenius).
inline double RelativeDifference(const Matrix& a, const Matrix& b) {
  return (a - b).norm() / b.norm();
}

constexpr double kReferenceModulus = 200e9;  // E_ref of the small cases [Pa]

inline CoupledSolverOptions Options(CoupledSolverType type, double tolerance) {
  CoupledSolverOptions options;
  options.type = type;
  options.tolerance = tolerance;
  options.max_iterations = 20000;
  return options;
}

struct Solved {
  CoupledSolverSummary summary;
  CoupledSolution solution;
};

inline Solved Solve(const CoupledSolverOptions& options, CoupledProblem* problem,
                    const Matrix* initial = nullptr, double reference_residual_norm = 0.0) {
  Solved solved;
  solved.summary =
      SolveCoupled(options, problem, initial, &solved.solution, reference_residual_norm);
  return solved;
}

// Relative differences of a solution from a reference in U, W and e^2.
struct Agreement {
  double displacement, retrograde, cost;
};

inline Agreement Compare(const Solved& solved, const Solved& reference) {
  return {RelativeDifference(solved.solution.displacement, reference.solution.displacement),
          RelativeDifference(solved.solution.retrograde, reference.solution.retrograde),
          std::abs(solved.solution.cost - reference.solution.cost) / reference.solution.cost};
}

// Riccati, single and multiple shooting at `tolerance` on `problem` against the
// all-at-once solver (1e-12) and against conjugate gradients at 1e-13, each printed
// under `label`; expects every solve usable and, for every solver, the relative
// differences in U, W and e^2 below lu_bound (to all_at_once) and cg_bound (to CG; CG
// itself stops at its round-off floor, so its figures are CG's error more than theirs).
inline constexpr CoupledSolverType kDenseSolvers[] = {CoupledSolverType::kRiccati,
                                                      CoupledSolverType::kSingleShooting,
                                                      CoupledSolverType::kMultipleShooting};
inline void ExpectDenseSolversAgree(const std::string& label, CoupledProblem* problem,
                                    double tolerance, double lu_bound, double cg_bound) {
  const Solved lu = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-12), problem);
  ASSERT_TRUE(lu.summary.IsSolutionUsable()) << lu.summary.FullReport();
  const Solved krylov = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-13), problem);
  ASSERT_TRUE(krylov.summary.IsSolutionUsable()) << krylov.summary.FullReport();
  for (CoupledSolverType type : kDenseSolvers) {
    const Solved solved = Solve(Options(type, tolerance), problem);
    EXPECT_TRUE(solved.summary.IsSolutionUsable()) << label << ": " << solved.summary.FullReport();
    if (!solved.summary.IsSolutionUsable()) continue;
    const Agreement to_lu = Compare(solved, lu), to_krylov = Compare(solved, krylov);
    const char* name = CoupledSolverTypeToString(type);
    std::cout << label << ", " << name << " vs all_at_once / conjugate_gradient: U "
              << to_lu.displacement << " / " << to_krylov.displacement << ", W " << to_lu.retrograde
              << " / " << to_krylov.retrograde << ", e^2 " << to_lu.cost << " / " << to_krylov.cost
              << ", residual " << solved.summary.relative_residual << "\n";
    EXPECT_LT(std::max({to_lu.displacement, to_lu.retrograde, to_lu.cost}), lu_bound)
        << label << ", " << name;
    EXPECT_LT(std::max({to_krylov.displacement, to_krylov.retrograde, to_krylov.cost}), cg_bound)
        << label << ", " << name;
  }
}

// A small structure given by matrices with a support (matrix_supports_test.cpp,
// matrix_streaming_test.cpp).
// The 1 x dofs row e_dof^T.
inline SparseMatrix SupportsTestDofRow(int dof, int dofs) {
  SparseMatrix row(1, dofs);
  row.insert(0, dof) = 1.0;
  return row;
}

// The model of a spring lattice's triplets: M, and zones zone0 and zone1 at the nominal
// 2e11 Pa, with a* = 1e-8 m (k* = E0 a* = 2e3 N/m at E0 = 2e11 Pa) and l* = 0.1 m.
inline MatrixModelData TwoZoneLatticeModel(
    int dofs, const std::vector<Eigen::Triplet<double>>& mass,
    const std::vector<Eigen::Triplet<double>> (&stiffness)[2]) {
  MatrixModelData model;
  model.stiffness_length = 1e-8;
  model.length = 0.1;
  model.mass.resize(dofs, dofs);
  model.mass.setFromTriplets(mass.begin(), mass.end());
  for (int z = 0; z < 2; ++z) {
    MatrixModelZone zone;
    zone.name = "zone" + std::to_string(z);
    zone.nominal_modulus = 2e11;
    zone.stiffness.resize(dofs, dofs);
    zone.stiffness.setFromTriplets(stiffness[z].begin(), stiffness[z].end());
    model.zones.push_back(zone);
  }
  return model;
}

// A 2-D-like lattice of 6 columns x 3 rows of unit dofs (mass 2 on the diagonal, 0.25
// coupling), springs along rows, columns and diagonals, zone 0 the first three
// columns, zone 1 the rest; held by the support "left" on the first column's dofs with
// g = (1, 2, 1) (force channel R, displacement channel uR), loaded on the last column
// (channel F), observed at two dofs and by a difference row.
inline MatrixModelData SupportedLattice() {
  constexpr int kColumns = 6, kRows = 3, kDofs = kColumns * kRows;
  auto dof = [](int column, int row) { return column * kRows + row; };
  std::vector<Eigen::Triplet<double>> mass, stiffness[2];
  for (int i = 0; i < kDofs; ++i) mass.emplace_back(i, i, 2.0);
  auto spring = [&](int a, int b, int zone, double k) {
    stiffness[zone].emplace_back(a, a, k);
    stiffness[zone].emplace_back(b, b, k);
    stiffness[zone].emplace_back(a, b, -k);
    stiffness[zone].emplace_back(b, a, -k);
    mass.emplace_back(a, b, 0.25);
    mass.emplace_back(b, a, 0.25);
  };
  for (int c = 0; c < kColumns; ++c) {
    const int zone = c < 3 ? 0 : 1;
    for (int r = 0; r < kRows; ++r) {
      if (c + 1 < kColumns) spring(dof(c, r), dof(c + 1, r), zone, 3e3);
      if (r + 1 < kRows) spring(dof(c, r), dof(c, r + 1), zone, 1e3);
      if (c + 1 < kColumns && r + 1 < kRows) spring(dof(c, r), dof(c + 1, r + 1), zone, 5e2);
    }
  }
  MatrixModelData model = TwoZoneLatticeModel(kDofs, mass, stiffness);
  Vector load = Vector::Zero(kDofs);
  for (int r = 0; r < kRows; ++r) load[dof(kColumns - 1, r)] = 1.0 / kRows;
  model.loads.push_back({"F", load});
  model.sensors.push_back({"u_tip", SupportsTestDofRow(dof(kColumns - 1, 1), kDofs)});
  model.sensors.push_back({"u_mid", SupportsTestDofRow(dof(2, 0), kDofs)});
  SparseMatrix gauge(1, kDofs);
  gauge.insert(0, dof(1, 2)) = -10.0;  // a strain-like difference that touches column 1
  gauge.insert(0, dof(2, 2)) = 10.0;
  model.sensors.push_back({"e_top", gauge, SensorKind::kStrain});
  MatrixModelSupport left;
  left.name = "left";
  left.dofs = {dof(0, 0), dof(0, 1), dof(0, 2)};
  left.reaction = Vector::Zero(kDofs);
  left.reaction[dof(0, 0)] = 1.0;
  left.reaction[dof(0, 1)] = 2.0;
  left.reaction[dof(0, 2)] = 1.0;
  left.force_channel = "R";
  left.displacement_channel = "uR";
  model.supports.push_back(left);
  return model;
}

// One load channel's row, 1 x (steps + 1): a half sine of 1 kN over `duration` [s],
// sampled at t_j = j time_step, then zero.
inline Matrix HalfSineLoadRow(int steps, double time_step, double duration) {
  Matrix loads = Matrix::Zero(1, steps + 1);
  for (int j = 0; j <= steps; ++j) {
    const double t = j * time_step;
    if (t < duration) loads(0, j) = 1e3 * std::sin(M_PI * t / duration);
  }
  return loads;
}

// The lattice's histories: a half sine on F; the sensors and the support force of the
// held lattice (trusted) at truth moduli, with a deterministic wiggle of 5 % so that the
// data are not the model's; a support displacement of a few % of the tip's.
inline ChannelSet SupportedLatticeHistories(const MatrixModelData& model) {
  const int steps = 120;
  const double time_step = 2e-3, duration = 0.05;
  const Matrix loads = HalfSineLoadRow(steps, time_step, duration);
  ChannelSet at_rest = MatrixChannelSet(
      model, time_step, loads, Matrix::Zero(static_cast<int>(model.sensors.size()), steps + 1));
  at_rest.Add("R", ChannelKind::kForce, Vector::Zero(steps + 1));
  at_rest.Add("uR", ChannelKind::kDisplacement, Vector::Zero(steps + 1));
  MatrixMcreProblem truth(model, at_rest, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                          ClampModel::kTrusted);
  truth.SetModuli((Vector(2) << 2e11, 1.6e11).finished());
  Matrix outputs = truth.ModelOutputs();
  Matrix forces = truth.ModelSupportForces();
  auto spoil = [](Matrix* rows, int seed) {
    for (int k = 0; k < rows->rows(); ++k) {
      const double scale = rows->row(k).cwiseAbs().maxCoeff();
      for (int j = 0; j < rows->cols(); ++j) {
        (*rows)(k, j) += 0.05 * scale * std::sin(0.37 * j + k + seed);
      }
    }
  };
  spoil(&outputs, 0);
  spoil(&forces, 5);
  ChannelSet data = MatrixChannelSet(model, time_step, loads, outputs);
  data.Add("R", ChannelKind::kForce, forces.row(0).transpose());
  data.Add("uR", ChannelKind::kDisplacement, (0.03 * outputs.row(0)).transpose());
  return data;
}

// The theta method (ThetaIntegratorOptions' defaults, this time step) on the band and on
// the sparse factorisation of (mass, stiffness) side by side, from rest, under the force
// `load` [-] times a half sine of 1000 N over the first `pulse_steps` of `steps` steps:
// the largest |u_band - u_sparse| over all steps, and the largest |u_band| [m].
// `observe`, if given, sees the band path's u after every step.
struct SparseAndBandRun {
  double worst_difference = 0.0;  // [m]
  double max_displacement = 0.0;  // [m]
};
inline SparseAndBandRun RunSparseAndBandPaths(
    const SparseMatrix& mass, const SparseMatrix& stiffness, const Vector& load, double time_step,
    int steps, int pulse_steps, const std::function<void(const Vector&)>& observe = nullptr) {
  ThetaIntegratorOptions options;
  options.time_step = time_step;
  ThetaIntegrator band, sparse;
  options.factorization = Factorization::kBand;
  band.Init(mass, stiffness, options);
  options.factorization = Factorization::kSparse;
  sparse.Init(mass, stiffness, options);
  const auto n = mass.rows();
  Vector v1 = Vector::Zero(n), u1 = v1, v2 = v1, u2 = v1, v(n), u(n);
  SparseAndBandRun run;
  for (int step = 0; step < steps; ++step) {
    const double force =
        step < pulse_steps ? 1000.0 * std::sin(M_PI * step / pulse_steps) : 0.0;  // [N]
    band.Step(v1, u1, force * load, v, u);
    v1 = v;
    u1 = u;
    sparse.Step(v2, u2, force * load, v, u);
    v2 = v;
    u2 = u;
    run.worst_difference = std::max(run.worst_difference, (u1 - u2).cwiseAbs().maxCoeff());
    run.max_displacement = std::max(run.max_displacement, u1.cwiseAbs().maxCoeff());
    if (observe) observe(u1);
  }
  return run;
}

}  // namespace mcrewave::testing
