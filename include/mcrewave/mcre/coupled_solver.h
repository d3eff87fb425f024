// Solvers of the coupled direct / retrograde MCRE system for one trial modulus
// (docs/discrete_mcre.md). All return the same (U, W) for the same discrete
// problem, to their tolerance:
//
//   all_at_once          the whole space-time system (D1, D2, R1, R2, R3) assembled
//                        sparse and solved by sparse LU; independent of the sweeps;
//                        the reference on small cases; refuses problems above
//                        max_all_at_once_unknowns or whose estimated memory would
//                        exceed max_all_at_once_bytes.
//   relaxation           the paper's waveform relaxation (eq. 17-19) with a fixed
//                        coefficient omega: one retrograde and one direct sweep per
//                        iteration, the direct one driven by omega W_new + (1-omega) W.
//   adaptive_relaxation  the same, omega = 2 / (a_min + a_max) from a Lanczos
//                        estimate of the extreme eigenvalues a of A = I - G, with a
//                        safeguard that re-estimates a_max from observed growth.
//   conjugate_gradient   CG on A W = c in the inner product <.,.>_P where A is
//                        self-adjoint positive definite: one retrograde and one
//                        direct sweep per iteration, no coefficient to tune.
//   riccati              the discrete Riccati sweep Z_k = P_k Y_k + q_k (dense 2n x 2n
//                        P_k) backward from the final condition, then the state
//                        forward (docs/riccati_shooting.md); refuses when its storage
//                        would exceed max_dense_solver_bytes.
//   single_shooting      the initial retrograde state Z_0 from the fundamental matrix
//                        of the coupled recursion; fails (never returns garbage) when
//                        the shooting matrix is too ill-conditioned, refuses like
//                        riccati above max_dense_solver_bytes.
//   multiple_shooting    the same on segments whose length follows the measured growth
//                        rate of the recursion, joined by continuity (robust variant).
//   streaming_conjugate_gradient
//                        CG on the sensor traces, storing no n x (m + 1) field
//                        (docs/streaming.md); any StreamingCoupledProblem: the bar and
//                        a structure given by matrices.
//   auto (the default)   conjugate_gradient when its fields fit max_field_bytes,
//                        streaming_conjugate_gradient when they do not
//                        (ResolveCoupledSolverType).
//
// all_at_once and the last three are direct: they report the same relative
// residual, computed afterwards from 5 sweeps, and converge when it meets the
// tolerance (or the round-off floor below); otherwise they fail.
//
// The iterative solvers stop on the relative residual ||c - A W||_P / ||c||_P
// (the same measure for all; c = T(0)), or when ||c - A W||_P falls to the
// round-off floor 1e-11 ||W_u||_P, W_u the retrograde response to the displacement
// data alone (c is a difference of two such responses, which cancel for data
// consistent with the model). Non-convergence and divergence are
// reported in the summary, never returned as numbers: the solution is usable only
// when summary.IsSolutionUsable().
#pragma once

#include <string>
#include <vector>

#include "mcrewave/mcre/streaming_coupled_problem.h"

namespace mcrewave {

// Fields of n x (m + 1) doubles an iterative solve holds at once: its iterates U
// and W, residual, search direction, image and scratch, the start's right-hand
// side and data response, and the caller's warm start and zero field.
constexpr int kIterativeSolverFields = 10;

// Bytes of the kIterativeSolverFields fields of an iterative solve on `num_nodes`
// nodes and `num_steps` steps; a double, so that no product overflows. Compared with
// CoupledSolverOptions::max_field_bytes by SolveCoupled and, for the bar, at load.
double IterativeSolverFieldBytes(double num_nodes, double num_steps);

// True for the methods whose memory is the fields above (relaxation,
// adaptive_relaxation, conjugate_gradient).
bool HoldsIterativeSolverFields(CoupledSolverType type);

struct CoupledSolverOptions {
  // inner.method; auto: conjugate_gradient or, when its fields do not fit
  // max_field_bytes, streaming_conjugate_gradient (ResolveCoupledSolverType).
  CoupledSolverType type = CoupledSolverType::kAuto;
  // Stopping test on ||c - A W||_P / ||c||_P (the paper used 1e-4).
  double tolerance = 1e-8;
  // conjugate_gradient: a solve whose tolerance is at least this ends on CG's recursive
  // residual, with U = Direct(W) updated along W (one more update a step), instead of
  // checking the true residual T(W) - W at the end (2 sweeps). The recursive residual
  // departs from the true one by round-off only (about 1e-12 of ||c||_P on the paper's
  // case), which a loose tolerance cannot see. 1: every solve checked. In (0, 1].
  double unchecked_tolerance = 1e-6;
  // Iterations (sweep pairs) allowed to the iterative solvers.
  int max_iterations = 5000;
  // omega of the fixed-coefficient relaxation, in (0, 2).
  double relaxation_coefficient = 0.5;
  // Lanczos steps of the adaptive relaxation's spectrum estimate (2 sweeps each).
  int spectrum_estimation_steps = 12;
  // The Lanczos estimate of a_max is multiplied by this factor before omega is chosen.
  double spectrum_safety_factor = 1.05;
  // A relative residual this many times above the smallest seen means divergence.
  double divergence_factor = 1e3;
  // The all-at-once solver refuses systems with more unknowns than this, and when
  // its estimated peak memory (the matrix and its sparse LU factors; see
  // src/mcre/all_at_once_solver.cpp) would exceed max_all_at_once_bytes.
  long max_all_at_once_unknowns = 1'500'000;
  long max_all_at_once_bytes = 2L << 30;
  // The Riccati and shooting solvers refuse when their dense storage
  // (docs/riccati_shooting.md) would exceed this many bytes.
  long max_dense_solver_bytes = 2L << 30;
  // The iterative solvers (relaxation, adaptive_relaxation, conjugate_gradient)
  // refuse when the fields they hold at once (kIterativeSolverFields fields of
  // n x (m + 1) doubles) would exceed this many bytes; auto then streams. The
  // streaming solver keeps the retrograde field's whole history (one such field) when
  // it fits this budget, and recomputes it from checkpoints when it does not
  // (StreamingCoupledProblem::SetHistoryBudget).
  long max_field_bytes = 2L << 30;
  // streaming_conjugate_gradient on a problem that rebuilds the retrograde field by the
  // reversed recursion at theta = 1/2 (the tests' band-model bar; MatrixMcreProblem
  // takes it from checkpoints, rebuild error 0): when the rebuilt state drifts by more
  // than this (||omega_0 rebuilt to omega_m|| /
  // max_j ||omega_j||, 0 in exact arithmetic, growing with the Courant number:
  // docs/streaming.md gives the measured values), the solver switches
  // the problem to checkpoints (StreamingCoupledProblem::UseCheckpoints) and goes on from its
  // traces. Library option, no config key.
  double max_rebuild_error = 1e-7;
  // streaming_conjugate_gradient's preconditioner (docs/streaming.md section 6): with
  // kDenseTraces, on a problem that offers it (MatrixMcreProblem, any structure given
  // by matrices), M = I - L built at moduli within preconditioner_rebuild_change
  // (relative) of the solve's, as a dense factor of num_traces (m + 1) rows when they
  // are at most max_preconditioner_traces (else CG runs without, and says so).
  TracePreconditioner preconditioner = TracePreconditioner::kNone;
  double preconditioner_rebuild_change = 0.02;
  long max_preconditioner_traces = 2048;
  // Shooting fails when the 2-norm condition number of its (equilibrated) shooting
  // matrix exceeds this, or is not finite.
  double shooting_condition_limit = 1e14;
  // Multiple shooting ends a segment when the largest of its fundamental solutions
  // (started from unit states in energy coordinates) has grown by this factor.
  double shooting_segment_growth = 100.0;

  bool IsValid(std::string* error) const;
};

// The solver that runs for `options` on a problem of `num_nodes` nodes and `num_steps`
// steps: options.type itself, unless it is kAuto, which takes conjugate_gradient when
// its fields (IterativeSolverFieldBytes) fit options.max_field_bytes, and
// streaming_conjugate_gradient when they do not and `streaming_available` (a
// StreamingCoupledProblem: MatrixMcreProblem, any structure); without
// it conjugate_gradient, which SolveCoupled then refuses. The one place where auto is
// resolved: SolveCoupled, the configs' load-time checks and the reports call it.
CoupledSolverType ResolveCoupledSolverType(const CoupledSolverOptions& options, double num_nodes,
                                           double num_steps, bool streaming_available);

// How the logs and messages name the solver `used` for inner.method `requested`:
// "auto (conjugate_gradient)" when auto was resolved, the solver's own name otherwise.
std::string CoupledSolverName(CoupledSolverType requested, CoupledSolverType used);

struct CoupledSolverSummary {
  // The solver that ran: options.type, or what auto resolved to.
  CoupledSolverType type = CoupledSolverType::kConjugateGradient;
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  int iterations = -1;                   // sweep pairs of the main iteration
  long sweeps = -1;                      // every direct or retrograde sweep, estimation included
  double relative_residual = -1.0;       // final ||c - A W||_P / ||c||_P
  // ||c||_P, the residual at W = 0 that the relative residuals are measured against
  // (the iterative solvers; -1 otherwise): the reference_residual_norm a warm start
  // on a nearby problem may take (SolveCoupled).
  double reference_residual_norm = -1.0;
  // The solve was accepted above the tolerance, at a round-off floor its restarts could
  // not lower (the streaming CG; relative_residual is that floor).
  bool at_round_off_floor = false;
  std::vector<double> residual_history;  // relative residual per iteration
  double relaxation_coefficient = -1.0;  // omega used by the relaxation solvers
  // Estimates of the extreme eigenvalues a_min, a_max of A = I - G: adaptive relaxation,
  // the Lanczos estimate its omega comes from; conjugate_gradient and
  // streaming_conjugate_gradient, the extreme Ritz values of their own Lanczos process
  // (from their coefficients, no extra sweep; a_max from below, a_min from above), once
  // they took a step; -1 otherwise. With inner.preconditioner, those of M^-1 (I - L).
  double spectrum_min = -1.0;
  double spectrum_max = -1.0;
  int safeguard_restarts = 0;            // adaptive only: omega re-chosen after growth
  double wall_time_s = -1.0;
  // Riccati and shooting only: multiply-accumulates of the method itself (the
  // residual check excluded), counted as include/mcrewave/core/operation_counts.h says.
  double multiply_accumulates = -1.0;
  // Single shooting: 2-norm condition number of the equilibrated shooting matrix.
  // Multiple shooting: max |r_ii| / min |r_ii| of the QR factor of the global
  // system, a lower bound of its condition number.
  double shooting_condition_number = -1.0;
  int shooting_segments = -1;  // shooting only: number of segments

  bool IsSolutionUsable() const { return termination == TerminationType::kConvergence; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct CoupledSolution {
  // U and W, n x (m + 1) [m]; empty (0 x 0) after a streaming solve, which stores
  // neither: its fields are summed as they pass (cost, gradients, error map) and
  // its traces (and, on a matrix model, G^T W) are kept.
  Matrix displacement;    // U, n x (m + 1) [m]
  Matrix retrograde;      // W, n x (m + 1) [m]
  // H U (streaming only), StreamingCoupledProblem::num_traces() x (m + 1).
  Matrix traces;
  // Streaming on a matrix model: G^T W, one row per load channel, C x (m + 1) [m].
  Matrix load_retrograde;
  // Streaming only: on the bar e_el^2 per element, on a matrix model the dof map
  // (MatrixMcreProblem::DofErrorMap) [J s].
  Vector error_map;
  // Streaming on a matrix model with element blocks: e_el^2 per element [J s].
  Vector element_error_map;
  // Streaming on a matrix model with element blocks: de^2/d ln E_el per element [J s]
  // (MatrixMcreProblem::ElementSensitivities).
  Vector element_sensitivity;
  // Streaming: the error map's space-time picture (StreamingTotals::gap_density).
  Matrix gap_density;
  // Streaming on a matrix model: MatrixMcreProblem::ZoneErrorMap of W and of U [J s].
  Vector zone_error_map, zone_strain_energy;

  // Whether U and W are stored (every solver but the streaming one).
  bool has_fields() const { return displacement.size() > 0; }
  // The unknown of the iterative solver that produced this solution, as SolveCoupled's
  // initial_guess: W, or the traces after a streaming solve (empty when there is none).
  const Matrix& WarmStart() const { return has_fields() ? retrograde : traces; }
  double cost = -1.0;          // e^2(E) [J s]
  double cost_gradient = 0.0;  // de^2/dE [J s / Pa] (several zones: sum_z de^2/dE_z)
  Vector cost_gradients;       // de^2/dE_z [J s / Pa], one per zone
};

// Solves the coupled problem at the problem's current moduli with every solver, for any
// structure, supports and sensors; streaming_conjugate_gradient needs a
// StreamingCoupledProblem. Riccati and shooting refuse, in the summary and naming
// conjugate_gradient or auto, when their dense n x n blocks exceed
// max_dense_solver_bytes, and when M, M + h^2 theta^2 K or P is not positive
// definite (docs/riccati_shooting.md section 5). auto is resolved first
// (ResolveCoupledSolverType), the summary's `type` the solver that ran. A method that
// would hold fields above max_field_bytes is refused before any work, its message
// naming the ways out.
// initial_guess (nullable) is the iterative solver's unknown at the start (warm start,
// e.g. the previous E's solution): W^(0), the problem's ZeroField() shape, for
// relaxation and conjugate_gradient; the traces y^(0),
// StreamingCoupledProblem::ZeroTraces() shape (a solution's `traces`), for
// streaming_conjugate_gradient, which starts from
// the data instead when they are farther from the solution. The direct solvers ignore
// it. Precondition: options.IsValid(). The solution's fields are meaningful only when
// the summary says so.
// reference_residual_norm > 0 (streaming_conjugate_gradient with an initial_guess; the
// others ignore it): ||c||_P of a nearby problem, the summary's reference_residual_norm
// of the solve the warm start came from (the same modulus on the previous mesh of a
// ladder, docs/multilevel.md). The relative residuals are then measured against it, and
// the data start's residual and norm (4 sweeps) are computed only when the warm start's
// residual is not below it.
CoupledSolverSummary SolveCoupled(const CoupledSolverOptions& options, CoupledProblem* problem,
                                  const Matrix* initial_guess, CoupledSolution* solution,
                                  double reference_residual_norm = 0.0);

}  // namespace mcrewave
