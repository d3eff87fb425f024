// Small MCRE problems shared by the tests of the coupled solvers.
#pragma once

#include <cmath>
#include <memory>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/bounded_minimizer.h"

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

// Owns the model, the data and the problem built on them.
struct ProblemBundle {
  ProblemBundle(const SmallCase& c, const McreWeights& weights, double theta = 0.5)
      : model(c.bar),
        data(MakeSyntheticMeasurements(
            c.bar, c.load,
            [&] {
              TimeOptions t = c.time;
              t.theta = theta;
              return t;
            }(),
            c.data)),
        problem(model, data, weights, c.bar.modulus, theta) {}
  BarModel model;
  ChannelSet data;
  McreProblem problem;
};

// Minimises a zone objective in p_z = log(E_z / E_z,ref) from p = 0 within
// [log 1/2, log 2] for every zone, at the step tolerance 1e-10 and no cost tolerance
// (the inverse crimes' setting).
inline BoundedMinimizerSummary MinimizeWithinHalfAndTwice(MultiParameterObjective* objective) {
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

inline Solved Solve(const CoupledSolverOptions& options, McreProblem* problem,
                    const Matrix* initial = nullptr) {
  Solved solved;
  solved.summary = SolveCoupled(options, problem, initial, &solved.solution);
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

}  // namespace mcrewave::testing
