// The outer loop: minimises a ModulusObjective (modulus_objective.h) over E within
// bounds with NLopt or Ceres. Both see x = E / E_scale of order 1 (E_scale =
// objective->modulus_scale()) and the objective's scaled cost.
//
//   nlopt  derivative-free BOBYQA (default), COBYLA or Sbplx, or MMA / L-BFGS with the
//          adjoint gradient, within the bounds. The objective's exceptions and failures
//          are caught in the callback, their message kept and the run force-stopped; the
//          best point seen is reported, not NLopt's last; roundoff_limited is a usable
//          stop; the evaluation and time limits are enforced in the callback.
//   ceres  ceres::GradientProblemSolver (line search, L-BFGS by default) with the
//          adjoint gradient, on z with the bounded map
//            x(z) = x_lo + (x_hi - x_lo) / (1 + exp(-z)),
//          so every trial E lies strictly inside (lower_bound, upper_bound).
//
// Global search (scan_points > 0, the default; docs/global_search.md sections 2 to 4):
// e^2(E) of noisy data has several valleys, so Identify first samples the cost and its
// gradient evenly in log E over the bounds, scan_samples_per_valley samples per
// predicted valley spacing (ModulusObjective::ValleySpacing), at least scan_points and
// at most scan_max_points, at the inner tolerance scan_tolerance, on copies of the
// objective in 8 fixed contiguous chunks spread over scan_threads threads: every sample
// is the same bits whatever the thread count. Between neighbouring samples the cubic
// Hermite interpolant p of the costs and gradients locates a valley when it has a local
// minimum inside; a gradient pointing out of the bounds at a bound is a valley there.
// Every valley whose estimate p(x*) lies within refine_margin (relative) of the lowest
// is refined (at most refine_candidates, lowest first) by the local optimiser inside its
// bracket, started at x* with the curvature p''(x*); a refinement that ends on an inner
// edge of its bracket is run again over the two neighbouring intervals. The refined
// valley of least cost is the result; every valley is reported. scan_points = 0 keeps
// the local search from `initial` alone.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/optim/algorithms.h"
#include "mcrewave/optim/modulus_objective.h"

namespace mcrewave {

// The `outer:` section of the config.
struct IdentificationOptions {
  // Read by the caller that builds the objective, not by Identify.
  OuterFunctional functional = OuterFunctional::kMcre;
  OptimizerType optimizer = OptimizerType::kNlopt;
  OuterAlgorithm algorithm = OuterAlgorithm::kDefault;
  double lower_bound = 100e9;  // [Pa]
  double upper_bound = 400e9;  // [Pa]
  double initial = 160e9;      // start E [Pa], strictly inside the bounds; also E_scale
  // Stop when a step changes E by less than this fraction of E (NLopt xtol_rel;
  // Ceres parameter_tolerance on x).
  double relative_tolerance = 1e-7;
  // Evaluations allowed to the whole identification, the scans' included (and, in
  // two stages, the search functional's); reaching the limit is not convergence.
  int max_evaluations = 1000;
  // Wall time allowed to the whole identification (scan and refinements) [s];
  // reaching it is not convergence.
  double max_time = 600.0;
  // Fewest moduli of the global scan, evenly spaced in log E over the bounds
  // (ends included); 0: no scan, local search from `initial` only.
  int scan_points = 41;
  // Samples per predicted valley spacing (ModulusObjective::ValleySpacing); the
  // scan takes max(scan_points, this many per spacing over the bounds). With the
  // gradient at every sample, a valley is missed only when a maximum and a minimum
  // fall between two samples (docs/global_search.md section 3). 0: scan_points alone.
  double scan_samples_per_valley = 4.0;
  // Most samples of the scan; a scan that would need more is cut to this and
  // reported (summary.scan_resolution_limited, a warning).
  int scan_max_points = 2000;
  // Relative residual asked of the inner solves of the scan (the refinement uses
  // the objective's own, inner.tolerance): the scan only ranks and brackets
  // valleys. Its gradients, on whose signs the valleys are found, err in proportion
  // to it: looser scans see valleys that are not there (docs/performance.md, issue
  // 41's section).
  double scan_tolerance = 1e-4;
  // Threads of the scan (each its own copy of the objective).
  int scan_threads = 2;
  // Every valley whose estimated scaled cost is within refine_margin x the lowest
  // estimate (relative) is refined: valleys whose costs differ by less than the noise
  // energy's spread between draws, sqrt(2 / N) for N independent samples, cannot be
  // told apart by their cost (docs/global_search.md section 4).
  double refine_margin = 0.05;
  // Most valleys refined.
  int refine_candidates = 10;

  // Valid when 0 < lower_bound < initial < upper_bound (finite),
  // relative_tolerance in (0, 0.1), max_evaluations >= 2 (and >= scan_points + 2
  // with a scan), max_time > 0, the algorithm exists for the optimiser,
  // scan_points is 0 or in [3, 100000], scan_samples_per_valley 0 or in [1, 100],
  // scan_max_points in [scan_points, 100000], scan_tolerance in (0, 1),
  // scan_threads in [1, 64], refine_margin in [0, 10] and refine_candidates in
  // [1, 100]. Messages name the outer.* keys.
  bool IsValid(std::string* error) const;
};

// A valley of the cost seen by the global scan.
struct ScanValley {
  double lower_modulus = -1.0;      // [Pa] its bracket, two neighbouring samples
  double upper_modulus = -1.0;      // [Pa]
  double estimated_modulus = -1.0;  // [Pa] minimum of the Hermite interpolant
  double estimated_cost = 0.0;      // scaled cost there (the interpolant's)
  bool refined = false;
  TerminationType termination = TerminationType::kFailure;  // of its refinement
  double modulus = -1.0;  // [Pa] refined minimiser (-1: not refined)
  double cost = 0.0;      // scaled cost there
  int evaluations = 0;    // of its refinement
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
  std::vector<double> scan_moduli;     // [Pa], ascending
  std::vector<double> scan_costs;      // scaled cost at scan_moduli (NaN: not usable)
  std::vector<double> scan_gradients;  // d cost / dx there (NaN: not usable)
  int scan_evaluations = 0;            // scan evaluations, not counted in `evaluations`
  long scan_sweeps = 0;                // inner sweeps of the scan (its copies' or the objective's)
  int scan_failures = 0;               // scan samples without a usable cost (NaN in scan_costs)
  // Predicted mean spacing of the valleys in ln E (0: the objective cannot tell).
  double predicted_valley_spacing = 0.0;
  // The scan wanted more than outer.scan_max_points samples: valleys may be missed.
  bool scan_resolution_limited = false;
  // Every valley the scan saw, lowest estimated cost first.
  std::vector<ScanValley> valleys;
  int local_minima = 0;  // valleys.size()
  // Scaled cost of the second-lowest valley minus the lowest, both refined when
  // refined (NaN with fewer than two valleys): a small gap says a second valley
  // nearly as deep, i.e. a fragile identification.
  double cost_gap = std::numeric_limits<double>::quiet_NaN();
  double second_modulus = -1.0;  // [Pa] the second-lowest valley (-1: none)
  int refinements = 0;           // local refinements run
  double scan_wall_time_s = 0.0;

  // Two stages (IdentifyInTwoStages): the search functional's minimiser [Pa] (-1: one
  // stage, Identify).
  double search_modulus = -1.0;
  // The scan fields above (samples, valleys, gap, refinements) are the search
  // functional's, their costs scaled by its own cost scale: true in two stages unless
  // the refinement reached an inner edge of its window and the objective's own scan
  // replaced the search.
  bool scan_of_search = false;

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
// Never throws for what the objective does: an exception thrown by the objective
// ends the run (or, in the scan, makes that sample unusable) with termination
// kFailure and its what() in the message. Precondition: options.IsValid().
IdentificationSummary Identify(const IdentificationOptions& options, ModulusObjective* objective);

// Whether `modulus` [Pa], found within `window`'s bounds, lies on an edge of the window
// that is not a bound of `bounds` (within 4 bounds.relative_tolerance |modulus|): the
// minimum lies beyond the window. IdentifyInTwoStages' test of its stage 2, and the bar's
// ladder of meshes' (app/identification_run.h).
bool EndsOnAnInnerEdge(const IdentificationOptions& window, const IdentificationOptions& bounds,
                       double modulus);

// The local search of Identify without a scan, from options.initial within options'
// bounds, given an estimate `curvature` of d^2 cost / dx^2 near the start (0: unknown):
// the secant's first step is Newton's with it, and it sets the step scale of Ceres and
// of NLopt's gradient methods, as a scanned valley's curvature does. Used where a
// cheaper problem already located the minimum (the bar's coarse mesh,
// app/identification_run.h). options.scan_points is not read. Never throws for what the
// objective does. Precondition: options.IsValid().
IdentificationSummary RefineFrom(const IdentificationOptions& options, ModulusObjective* objective,
                                 double curvature);

// Two stages: a global search on another functional, a local refinement of the objective.
//   1. Identify(options with scan_points = search_scan_points and
//      refinement.samples_per_valley, search): the scan and its valleys' refinements on
//      `search`, a cost of one valley over the bounds whose minimiser E_s lies near
//      the objective's. The refinements are `refinement`'s whatever options'
//      optimiser, so that every optimiser then refines the objective around the same
//      E_s: by default the secant on the search's gradient to 1e-3 in E. E_s only
//      places stage 2's window, so a loose refinement moves the result within that
//      window only.
//   2. Identify(options with scan_points = refinement.window_points, objective) within
//      E_s (1 -+ refine_window), cut to the bounds: a scan of the window (cost and
//      gradient) that brackets the objective's valleys there and gives the local
//      optimiser its curvature, then their refinements.
//   3. When stage 2 ends on an edge of its window inside the bounds (the objective's
//      minimum lies farther from E_s), Identify(options, objective): the objective's own
//      scan and refinements, as in one stage.
// max_evaluations and max_time hold for the whole. The result is stage 2's (or 3's)
// with search_modulus = E_s, scan_evaluations = the search's evaluations (scan and
// refinements) plus the scans of stages 2 and 3, evaluations = the objective's own,
// scan_sweeps = those scans' (on copies; the search objective's own sweeps are its
// sweeps()), and, unless stage 3 ran, the search's scan fields (scan_of_search). A
// search that does not converge ends the identification with its termination and
// message. Preconditions: options.IsValid(), options.scan_points > 0,
// search_scan_points in [3, 100000], refine_window in (0, 0.5].
// How stage 1 samples and refines the search's valleys, and how densely stage 2 scans
// its window. Defaults: SearchOptions' (objective.h).
struct SearchRefinement {
  // The search's refinement: NLopt BOBYQA or kSecant (on the search's gradient), to
  // relative_tolerance (0: options.relative_tolerance).
  OuterAlgorithm algorithm = OuterAlgorithm::kSecant;
  double relative_tolerance = 1e-3;
  // The search's scan samples per predicted valley spacing (0: the options').
  double samples_per_valley = 2.0;
  // Stage 2's scan: moduli over the window, its edges included (at least 3).
  int window_points = 3;
};
IdentificationSummary IdentifyInTwoStages(const IdentificationOptions& options,
                                          ModulusObjective* search, int search_scan_points,
                                          double refine_window, ModulusObjective* objective,
                                          const SearchRefinement& refinement = {});

}  // namespace mcrewave
