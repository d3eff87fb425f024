// The objective of the outer loop: the MCRE cost e^2 as a function of the
// trial modulus E. McreObjective implements the optimisers' interface
// (ModulusObjective, optim/modulus_objective.h) with a coupled problem of any structure
// (StreamingCoupledProblem: MatrixMcreProblem, whose model may be the built-in bar
// exported as matrices) and the coupled solver of coupled_solver.h: each evaluation sets E,
// solves the coupled problem warm-started from the previous usable solutions and
// records what it did.
//
// Warm start: with the last two usable solutions W(E1) (last) and W(E0) at
// E0 != E1, the next solve at E starts from the linear extrapolation
//   W^(0) = W(E1) + t (W(E1) - W(E0)),  t = (E - E1) / (E1 - E0),
// when |t| <= kMaxExtrapolation (W depends smoothly on E between resonances); otherwise
// from W(E1) alone. The streaming solver's unknown is the traces H U instead of W
// (CoupledSolution::WarmStart()), extrapolated the same way.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/data/measurement.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/mcre_weights.h"
#include "mcrewave/optim/identification.h"
#include "mcrewave/optim/log_moduli_objective.h"
#include "mcrewave/optim/modulus_objective.h"

namespace mcrewave {

// The config's default weights with the clamp trusted: w_u = w_e = 1e-7, w_r = 1e-6
// (w_f: McreWeights' 1). Why these: docs/trusted_clamp.md section 7.
inline McreWeights TrustedClampWeights() {
  McreWeights weights;
  weights.displacement_weight = 1e-7;
  weights.strain_weight = 1e-7;
  weights.reaction_weight = 1e-6;
  return weights;
}

// The `mcre:` section of the config: the weights of the data terms and the
// modulus E0 they are built with (mcre_weights.h):
//   beta = w_u k*,  alpha = w_f / k*,  k* = E0 a* (the bar: a* = S / L).
// E0 is a fixed nominal modulus, not the unknown: the same functional is then
// minimised whatever the start or the bounds of the outer loop.
struct McreOptions {
  McreWeights weights = TrustedClampWeights();
  double reference_modulus = 200e9;  // E0 [Pa]
  // The clamp at x = 0: trusted (u(0) = 0, f0 a measured output), measured (the
  // paper's free-free model) or pinned (free-free, u0's datum the known 0 with w_u0,
  // f0 a load with w_r); matrix_mcre_problem.h, docs/trusted_clamp.md.
  ClampModel clamp = ClampModel::kTrusted;
  // What a run does when the clamp is trusted and its data contradict a support
  // (support_check.h, docs/boundaries.md): switch to the paper's treatment, warn, or
  // not test; and the threshold of its t above which they contradict it.
  SupportCheckAction support_check = SupportCheckAction::kSwitch;
  double support_check_threshold = 2.5;
  // With support_check switch, a run whose t lies between this and the threshold
  // identifies E both ways and weighs the paper's E by SupportSwitchWeight
  // (support_check.h, docs/boundaries.md section 10). Equal to the threshold: a hard
  // switch.
  double support_check_ramp_start = 1.28;
  // The model's load channels whose histories were not measured (docs/unmeasured_loads.md):
  // each is found with the admissible fields, weighted by weights.unmeasured_force_weight
  // against the datum 0; the data need not hold them.
  std::vector<std::string> unmeasured_loads;
  // Two times [s] per unmeasured load, in its order, start then end: the interval
  // outside which the load is known to vanish (a striker that has left the bar). Empty:
  // every unmeasured load may act over the whole window.
  std::vector<double> unmeasured_load_interval;

  // Also: the names not repeated, the intervals 0 or 2 per load, finite, start <= end.
  bool IsValid(std::string* error) const;
};

// The unmeasured loads of mcre (MatrixMcreProblem's form), their intervals paired.
// Precondition: mcre.IsValid().
std::vector<UnmeasuredLoad> UnmeasuredLoads(const McreOptions& mcre);

// The `search:` section: the functional the global search of a bar's identification
// scans (docs/trusted_clamp.md section 10). The trusted clamp's e^2 has several valleys
// over the bounds, the pinned clamp's e^2 at heavier data weights one, near the trusted
// one's minimiser. With functional pinned, the pinned e^2 is scanned and refined
// (scan_points samples at least, its inner solves to inner_tolerance), then mcre:'s e^2
// is scanned and refined within E_search (1 -+ refine_window) (IdentifyInTwoStages,
// identification.h).
struct SearchOptions {
  SearchFunctional functional = SearchFunctional::kPinned;
  // The search functional's weights w_u, w_e, w_u0 and w_r; w_f and E0 are mcre:'s.
  // The defaults are configs/paper_bar_pinned.yaml's (docs/trusted_clamp.md section 9).
  double displacement_weight = 0.01;       // search.w_u
  double strain_weight = 0.01;             // search.w_e
  double clamp_displacement_weight = 0.1;  // search.w_u0
  double reaction_weight = 0.1;            // search.w_r
  // Relative residual of the search's inner solves (docs/trusted_clamp.md section 9,
  // "The inner tolerance"; docs/performance.md, issue 41's section: its refinement
  // only places e^2's window).
  double inner_tolerance = 1e-4;
  // Fewest moduli of its scan (outer.scan_points for the functional `same`).
  int scan_points = 6;
  // Its scan's samples per predicted valley spacing (0: outer.scan_samples_per_valley).
  // The search functional has one valley by design, so its scan may sample it more
  // sparsely than e^2's, whose valleys it must not miss.
  double samples_per_valley = 2.0;
  // Moduli of e^2's scan within E_search (1 -+ refine_window), the window's edges
  // included: at least 3 (an interior one and the edges).
  int window_points = 3;
  // Half width of the refinement of mcre:'s e^2 around the search's E*, relative
  // (its choice: docs/trusted_clamp.md section 10).
  double refine_window = 0.03;
  // The refinement of its valley, which only places that window: NLopt BOBYQA or
  // kSecant, to relative_tolerance on E (0: outer.relative_tolerance).
  OuterAlgorithm algorithm = OuterAlgorithm::kSecant;
  double relative_tolerance = 1e-3;
  // The largest time step of the search functional, in steps of the data's grid: its
  // scan and refinement run on the data resampled to k times the step, k at most this
  // and as small as the forces' band asks (SearchTimeStepFactor,
  // app/identification_run.h), as its minimiser only places e^2's window; 1: the
  // data's own grid.
  int time_step_factor = 4;

  // Valid when the weights and inner_tolerance are finite and positive,
  // inner_tolerance < 1, scan_points in [3, 100000], samples_per_valley 0 or in
  // [1, 100], window_points in [3, 100], refine_window in (0, 0.5], algorithm bobyqa
  // or secant, relative_tolerance 0 or in (0, 0.1] and time_step_factor in [1, 64].
  // Messages name the search.* keys.
  bool IsValid(std::string* error) const;
};

// The McreOptions of the search functional: mcre's w_f and E0, the clamp pinned (or
// measured, with functional measured) and the search's weights.
McreOptions SearchMcreOptions(const McreOptions& mcre, const SearchOptions& search);

// How IdentifyInTwoStages samples and refines the search, and scans e^2's window, as
// `search` says.
SearchRefinement SearchRefinementOf(const SearchOptions& search);

// Whether SearchMcreOptions(mcre, search) poses mcre's own problem on a model with or
// without supports: the same w_u and w_e, and either no supports (the clamp's treatment,
// w_u0 and w_r then act on nothing), or mcre's clamp pinned at the search's w_u0 and w_r
// (functional pinned), or mcre's clamp measured (functional measured).
// The search's scan is then e^2's own, and its second stage would refine e^2 again.
bool SearchIsTheObjective(const McreOptions& mcre, const SearchOptions& search,
                          bool model_has_supports);

// One evaluation of e^2(E) by McreObjective.
struct ObjectiveEvaluation {
  double modulus = -1.0;            // E [Pa] when every zone has it; -1 when they differ
  Vector moduli;                    // E_z [Pa], one per zone
  double cost = -1.0;               // e^2(E) [J s]; meaningful only when usable
  double cost_gradient = 0.0;       // de^2/dE [J s / Pa], the adjoint gradient (sum over zones)
  Vector cost_gradients;            // de^2/dE_z [J s / Pa], one per zone
  bool gradient_requested = false;  // whether the caller asked for the gradient
  bool usable = false;              // inner.IsSolutionUsable()
  CoupledSolverSummary inner;       // the coupled solve
};

class McreObjective : public ModulusObjective {
 public:
  // Makes the coupled problem the objective solves: a new one per call (the objective's
  // and each CloneForScan's own).
  using ProblemFactory = std::function<std::unique_ptr<StreamingCoupledProblem>()>;

  // The objective over the problems make_problem makes, whatever the structure.
  // modulus_scale [Pa] is E per unit of x. Preconditions: make_problem gives a problem,
  // inner.IsValid(), modulus_scale > 0.
  McreObjective(ProblemFactory make_problem, const CoupledSolverOptions& inner,
                double modulus_scale);

  double modulus_scale() const override { return modulus_scale_; }

  // cost = e^2(E) / cost_scale() and gradient = (de^2/dE) modulus_scale / cost_scale()
  // at E = x modulus_scale. False when x is not a positive finite number or the
  // coupled solve is not usable (the solver's message is kept).
  bool Evaluate(const double* parameters, double* cost, double* gradient) override;
  std::string error_message() const override { return error_message_; }
  // A new McreObjective on a problem of the same factory with
  // inner.tolerance = inner_tolerance (its evaluations are its own).
  std::unique_ptr<ModulusObjective> CloneForScan(double inner_tolerance) const override;
  // Drops the warm starts, the round-off floor's tolerance and the problem's trace
  // preconditioner; the evaluations so far stay recorded.
  void StartAfresh() override;

  // Evaluates e^2 and de^2/dE at modulus E [Pa] (> 0) and records it; returns the
  // record. Evaluate calls this.
  const ObjectiveEvaluation& EvaluateModulus(double modulus, bool gradient_requested = true);
  // Evaluates e^2 and every de^2/dE_z at the zone moduli E_z [Pa] (> 0, one per zone
  // of the model) and records it. Equal moduli: EvaluateModulus. Unequal: the solve
  // starts from the last usable solution.
  const ObjectiveEvaluation& EvaluateModuli(const Vector& zone_moduli,
                                            bool gradient_requested = true);

  // J_rest [J s], the problem's RestCost() at construction: the functional of the
  // structure left at rest (U = W = 0, zero loads), which satisfies the state equation
  // for every E, so 0 <= e^2(E) <= J_rest.
  double rest_cost() const { return rest_cost_; }
  // The cost scale [J s]: J_rest, or 1 when the data are all zero (J_rest = 0).
  double cost_scale() const { return rest_cost_ > 0.0 ? rest_cost_ : 1.0; }

  // Every evaluation, in order.
  const std::vector<ObjectiveEvaluation>& evaluations() const { return evaluations_; }
  // Index in evaluations() of the usable evaluation of least cost (the first
  // one on ties), or -1 when none was usable.
  int best_index() const { return best_index_; }
  // The coupled solution of evaluations()[best_index()] (empty when none).
  const CoupledSolution& best_solution() const { return best_solution_; }
  // The coupled solution of the last evaluation (valid when it was usable).
  const CoupledSolution& last_solution() const { return solution_; }
  // Sweeps (direct + retrograde) of every evaluation.
  long sweeps() const override { return problem_->sweep_count(); }
  // From the traces of the model driven by the measured forces at the problem's
  // current moduli (StreamingCoupledProblem::DataResponseTraces), weighted by beta_k: one sweep.
  double ValleySpacing() override;

  // The next evaluation starts its inner iteration from `start` (a solution's
  // WarmStart(): a retrograde field of problem().ZeroField()'s shape, or the traces of
  // problem().ZeroTraces()'s for the streaming solver) instead of the last usable
  // solutions; later evaluations extrapolate from it once they have a second solution.
  // reference_residual_norm > 0: the summary's reference_residual_norm of the solve that
  // gave `start` (SolveCoupled's), taken by the next solve from it.
  void SetWarmStart(const Matrix& start, double reference_residual_norm = 0.0);

  // Largest |t| of the extrapolated warm start (above: the last solution alone).
  static constexpr double kMaxExtrapolation = 2.0;
  // Once a solve is accepted at a round-off floor f above inner.tolerance
  // (CoupledSolverSummary::at_round_off_floor: the streaming CG's sweeps lose digits at
  // a high Courant number), later solves take the tolerance kFloorMargin times the
  // largest such f: a warm start or a first true residual within it is accepted
  // instead of being confirmed at the floor by two restarts (docs/boundaries.md
  // section 7). Solves that meet inner.tolerance never change it, and it stays within
  // kMaxFloorTolerance times inner.tolerance (the streaming CG's own bound on a floor).
  static constexpr double kFloorMargin = 2.0;
  static constexpr double kMaxFloorTolerance = 100.0;
  // inner.tolerance, or the floor's tolerance above once one was met [-].
  double inner_tolerance() const { return inner_.tolerance; }

  StreamingCoupledProblem& problem() { return *problem_; }

 private:
  // Solves at the problem's moduli from `initial` (nullable) and records the evaluation;
  // modulus is the common modulus, or -1 when the zones differ.
  const ObjectiveEvaluation& Solve(double modulus, bool gradient_requested, const Matrix* initial);

  ProblemFactory make_problem_;
  std::unique_ptr<StreamingCoupledProblem> problem_;
  CoupledSolverOptions inner_;
  double given_tolerance_;  // inner.tolerance as given, before any floor
  double modulus_scale_;
  double rest_cost_ = 0.0;
  std::vector<ObjectiveEvaluation> evaluations_;
  int best_index_ = -1;
  CoupledSolution best_solution_;
  CoupledSolution solution_;             // of the last evaluation
  Matrix warm_start_;                    // W(E1) (or its traces), the last usable solution; empty: none
  double warm_start_modulus_ = 0.0;      // E1 [Pa]; 0 when W(E1) was set by SetWarmStart
  double warm_start_reference_norm_ = 0.0;  // SetWarmStart's, until a solve is usable
  Matrix previous_start_;                // W(E0), the one before; empty: none
  double previous_start_modulus_ = 0.0;  // E0 [Pa]
  Matrix initial_;                       // the extrapolated W^(0)
  std::string error_message_;
};

// The objective of a structure given by matrices: a MatrixMcreProblem on model and data
// with mcre's weights and E0, its supports treated as mcre.clamp says, E per unit of x
// modulus_scale [Pa] (0: mcre.reference_modulus; the bar's run takes outer.initial);
// element_maps false: its streaming solves leave the element map out
// (MatrixMcreProblem::set_element_maps). Keeps references to model and data: both must
// outlive it. Preconditions: those of MatrixMcreProblem and McreObjective,
// modulus_scale >= 0.
McreObjective MatrixMcreObjective(const MatrixModelData& model, const ChannelSet& data,
                                  const McreOptions& mcre, double theta,
                                  const CoupledSolverOptions& inner,
                                  Factorization factorization = Factorization::kAutomatic,
                                  double modulus_scale = 0.0, bool element_maps = true);

// McreObjective::EvaluateModuli seen as a function of p_z = log(E_z / E_z,ref)
// (optim/log_moduli_objective.h), J_scale = McreObjective::cost_scale(), whatever the
// structure: the bar's zones from the homogeneous E* (E_z,ref = E*), a structure given
// by matrices from its nominal moduli. Logs one line per usable evaluation.
class ZoneMcreObjective : public LogModuliObjective {
 public:
  // objective must outlive this adapter; its problem has the identification's zones,
  // one reference modulus E_z,ref [Pa] each (positive).
  ZoneMcreObjective(McreObjective* objective, const Vector& reference_moduli);
  // Every zone from the same E_ref = modulus_scale [Pa].
  ZoneMcreObjective(McreObjective* objective, double modulus_scale);

  double cost_scale() const override;

 protected:
  bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient, std::string* why) override;
  void OnEvaluated(const Vector& moduli, double cost, double gradient_norm) override;

 private:
  McreObjective* objective_;
  std::string inner_report_;  // the last usable solve's BriefReport()
};

}  // namespace mcrewave
