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
//
// Global search (scan_points > 0, the default): e^2(E) of noisy data is rugged
// (the noise shifts the model's resonances in and out of phase with it as E
// changes, docs/robustness.md), so a local optimiser started anywhere stops in
// the nearest valley. Identify first evaluates the cost on scan_points moduli
// evenly spaced in log E over [lower_bound, upper_bound] (copies of the objective at the
// loose inner tolerance scan_tolerance, in 8 fixed contiguous chunks, each a
// fresh copy warm-started point to point, spread over scan_threads threads: every
// cost is the same bits whatever the thread count or timing), counts the local minima of those
// samples, and then refines the refine_candidates lowest of them with the local optimiser, each
// bracketed by its two neighbouring scan points (a sampled minimum c_i < c_{i-1},
// c_{i+1} of a continuous cost holds a local minimum strictly between them). The
// refined minimum of least cost is the result. scan_points = 0 keeps the local
// search from `initial` alone.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/objective.h"

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
  kBrent,    // under nlopt: Brent's bounded 1-D minimiser (mcrewave's own), derivative-free
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
  // e^2 evaluations allowed to the whole identification, the scan's included;
  // reaching the limit is not convergence.
  int max_evaluations = 150;
  // Wall time allowed to the whole identification (scan and refinements) [s];
  // reaching it is not convergence.
  double max_time = 600.0;
  // Moduli of the global scan, evenly spaced in log E over the bounds (ends
  // included); 0: no scan, local search from `initial` only. 41 over the default
  // bounds is a step of 3.5 % in E, under a third of the spacing of the valleys
  // measured at SNR 2.5 (docs/robustness.md).
  int scan_points = 41;
  // Relative residual asked of the inner solves of the scan (the refinement uses
  // the objective's own, inner.tolerance): the scan only ranks valleys. 1e-4 picks
  // the same brackets as 1e-5 on paper_bar.yaml over seeds 1..10 (identical refined
  // E) for 14 % fewer scan sweeps (docs/performance.md).
  double scan_tolerance = 1e-4;
  // Threads of the scan (each its own copy of the objective).
  int scan_threads = 2;
  // Lowest sampled minima refined by the local optimiser.
  int refine_candidates = 2;

  // Valid when 0 < lower_bound < initial < upper_bound (finite),
  // relative_tolerance in (0, 0.1), max_evaluations >= 2 (and >= scan_points + 2
  // with a scan), max_time > 0, the
  // algorithm exists for the optimiser, scan_points is 0 or in [3, 100000],
  // scan_tolerance in (0, 1), scan_threads in [1, 64] and refine_candidates in
  // [1, 100]. Messages name the outer.* keys.
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

  // The global scan (empty / zero when scan_points = 0).
  std::vector<double> scan_moduli;  // [Pa], ascending
  std::vector<double> scan_costs;   // scaled cost at scan_moduli (NaN: not usable)
  int scan_evaluations = 0;         // scan evaluations, not counted in `evaluations`
  long scan_sweeps = 0;             // inner sweeps of the scan (its copies' or the objective's)
  int scan_failures = 0;            // scan samples without a usable cost (NaN in scan_costs)
  int local_minima = 0;             // sampled local minima of scan_costs (ends included)
  // Scaled cost of the second-lowest minimum minus the lowest, both refined
  // when refined (NaN with fewer than two minima): a small gap says a second
  // valley nearly as deep, i.e. a fragile identification.
  double cost_gap = std::numeric_limits<double>::quiet_NaN();
  double second_modulus = -1.0;  // [Pa] the second-lowest minimum (-1: none)
  int refinements = 0;           // local refinements run
  double scan_wall_time_s = 0.0;

  // Convergence: a tolerance was met (NLopt xtol/ftol or roundoff-limited;
  // Ceres convergence). Limits reached, a failed evaluation or an exception in
  // the objective are not usable.
  bool IsSolutionUsable() const { return termination == TerminationType::kConvergence; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Minimises the objective within the bounds: with scan_points > 0 the scan and
// refinements described above (the scan on objective->CloneForScan copies when
// the objective offers them, else on the objective itself in one thread), else
// from x0 = options.initial / objective->modulus_scale(). max_evaluations and
// max_time hold for the whole identification: each refinement gets what the
// scan and the earlier refinements left, and a limit reached anywhere makes the
// result kNoConvergence (samples the scan could not reach in time stay NaN).
// Never throws for what the objective
// does: an exception thrown by the objective ends the run (or, in the scan,
// makes that sample unusable) with termination kFailure and its what() in the
// message. Precondition: options.IsValid().
IdentificationSummary Identify(const IdentificationOptions& options, ModulusObjective* objective);

}  // namespace mcrewave
