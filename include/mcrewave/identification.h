// The outer loop: minimises a ModulusObjective (objective.h) over E within
// bounds with NLopt or Ceres.
//
//   nlopt  derivative-free BOBYQA (default), COBYLA or Sbplx on x = E / E_scale
//          within the bounds; or gradient-based MMA / L-BFGS with the adjoint
//          gradient. Guarded against NLopt's traps: the objective's exceptions
//          and failures are caught in the callback, their message kept and the
//          run force-stopped (the C++ wrapper would turn them into a bare
//          "nlopt failure"); the best point seen is reported, not NLopt's last;
//          roundoff_limited is a usable stop; the evaluation and time limits are
//          enforced in the callback as well.
//   ceres  ceres::GradientProblemSolver (line search, L-BFGS by default) with the
//          adjoint gradient, no numeric differentiation. Ceres has no bounds for
//          a GradientProblem: it works on z with the smooth bounded map
//            x(z) = x_lo + (x_hi - x_lo) / (1 + exp(-z)),
//          so every trial E lies strictly inside (lower_bound, upper_bound).
//
// Both see the same objective: x = E / E_scale of order 1 (E_scale =
// objective->modulus_scale()) and the cost scaled by the objective.
#pragma once

#include <string>

#include "mcrewave/coupled_solver.h"
#include "mcrewave/objective.h"

namespace mcrewave {

enum class OptimizerType {
  kNlopt,
  kCeres,
};
const char* OptimizerTypeToString(OptimizerType type);
bool StringToOptimizerType(const std::string& name, OptimizerType* type);

// The algorithm of the outer optimiser; not every one exists in both.
enum class OuterAlgorithm {
  kDefault,  // bobyqa for nlopt, lbfgs for ceres
  kBobyqa,   // nlopt: Powell's BOBYQA, quadratic models, derivative-free, bounded
  kCobyla,   // nlopt: Powell's COBYLA, linear models, derivative-free, bounded
  kSbplx,    // nlopt: Subplex (Nelder-Mead on subspaces), derivative-free, bounded
  kMma,      // nlopt: method of moving asymptotes, adjoint gradient, bounded
  kLbfgs,    // nlopt or ceres: limited-memory BFGS, adjoint gradient
  kBfgs,     // ceres: dense BFGS, adjoint gradient
};
const char* OuterAlgorithmToString(OuterAlgorithm algorithm);
bool StringToOuterAlgorithm(const std::string& name, OuterAlgorithm* algorithm);
// True when the optimiser offers the algorithm (kDefault: always).
bool IsAlgorithmAvailable(OptimizerType optimizer, OuterAlgorithm algorithm);
// kDefault resolved for the optimiser; other values unchanged.
OuterAlgorithm ResolveAlgorithm(OptimizerType optimizer, OuterAlgorithm algorithm);
// Whether the algorithm uses the gradient (kDefault resolved first).
bool UsesGradient(OptimizerType optimizer, OuterAlgorithm algorithm);

// The `outer:` section of the config.
struct IdentificationOptions {
  OptimizerType optimizer = OptimizerType::kNlopt;
  OuterAlgorithm algorithm = OuterAlgorithm::kDefault;
  double lower_bound = 100e9;  // [Pa]
  double upper_bound = 400e9;  // [Pa]
  double initial = 160e9;      // start E [Pa], strictly inside the bounds; also E_scale
  // Stop when a step changes E by less than this fraction of E (NLopt xtol_rel;
  // Ceres parameter_tolerance on x).
  double relative_tolerance = 1e-7;
  // e^2 evaluations allowed; reaching the limit is not convergence.
  int max_evaluations = 100;
  // Wall time allowed to the outer loop [s]; reaching it is not convergence.
  double max_time = 600.0;

  // Valid when 0 < lower_bound < initial < upper_bound (finite),
  // relative_tolerance in (0, 0.1), max_evaluations >= 2, max_time > 0, and the
  // algorithm exists for the optimiser. Messages name the outer.* keys.
  bool IsValid(std::string* error) const;
};

struct IdentificationSummary {
  OptimizerType optimizer = OptimizerType::kNlopt;
  OuterAlgorithm algorithm = OuterAlgorithm::kDefault;  // as resolved
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  double initial_modulus = -1.0;  // [Pa]
  double modulus = -1.0;          // best E seen [Pa] (-1: no usable evaluation)
  double cost = -1.0;             // the objective's (scaled) cost at modulus
  double gradient = 0.0;          // d cost / dx at modulus, when known (else 0)
  int evaluations = 0;            // objective evaluations (failed ones included)
  int gradient_evaluations = 0;   // of which with the gradient
  int iterations = -1;            // Ceres iterations; -1 for NLopt (it does not say)
  std::string optimizer_message;  // the optimiser's own word on why it stopped
  double wall_time_s = -1.0;

  // Convergence: a tolerance was met (NLopt xtol/ftol or roundoff-limited;
  // Ceres convergence). Limits reached, a failed evaluation or an exception in
  // the objective are not usable.
  bool IsSolutionUsable() const { return termination == TerminationType::kConvergence; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Minimises the objective from x0 = options.initial / objective->modulus_scale()
// within the bounds. Never throws for what the objective does: an exception
// thrown by the objective ends the run with termination kFailure and its what()
// in the message. Precondition: options.IsValid().
IdentificationSummary Identify(const IdentificationOptions& options, ModulusObjective* objective);

}  // namespace mcrewave
