#include "mcrewave/mcre/coupled_solver.h"

#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/enum_names.h"
#include "mcre/coupled_solver_internal.h"

namespace mcrewave {

bool CoupledSolverOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    why << "inner.tolerance must lie in (0, 1), got " << tolerance;
  } else if (!(unchecked_tolerance > 0.0 && unchecked_tolerance <= 1.0)) {
    why << "inner.unchecked_tolerance must lie in (0, 1], got " << unchecked_tolerance;
  } else if (max_iterations < 1) {
    why << "inner.max_iterations must be at least 1, got " << max_iterations;
  } else if (!(relaxation_coefficient > 0.0 && relaxation_coefficient < 2.0)) {
    why << "inner.omega must lie in (0, 2), got " << relaxation_coefficient;
  } else if (spectrum_estimation_steps < 2) {
    why << "inner.spectrum_steps must be at least 2, got " << spectrum_estimation_steps;
  } else if (!(spectrum_safety_factor >= 1.0 && std::isfinite(spectrum_safety_factor))) {
    why << "inner.spectrum_safety_factor must be at least 1, got " << spectrum_safety_factor;
  } else if (!(divergence_factor > 1.0)) {
    why << "inner.divergence_factor must be above 1, got " << divergence_factor;
  } else if (max_all_at_once_unknowns < 1) {
    why << "inner.max_all_at_once_unknowns must be positive, got " << max_all_at_once_unknowns;
  } else if (max_all_at_once_bytes < 1) {
    why << "inner.max_all_at_once_bytes must be positive, got " << max_all_at_once_bytes;
  } else if (max_dense_solver_bytes < 1) {
    why << "inner.max_dense_solver_bytes must be positive, got " << max_dense_solver_bytes;
  } else if (!(max_rebuild_error > 0.0 && max_rebuild_error < 1.0)) {
    why << "max_rebuild_error must lie in (0, 1), got " << max_rebuild_error;
  } else if (max_field_bytes < 1) {
    why << "inner.max_field_bytes must be positive, got " << max_field_bytes;
  } else if (!(preconditioner_rebuild_change >= 0.0 && preconditioner_rebuild_change < 1.0)) {
    why << "inner.preconditioner_rebuild_change must lie in [0, 1), got "
        << preconditioner_rebuild_change;
  } else if (max_preconditioner_traces < 1) {
    why << "inner.max_preconditioner_traces must be positive, got " << max_preconditioner_traces;
  } else if (preconditioner != TracePreconditioner::kNone &&
             type != CoupledSolverType::kStreamingConjugateGradient) {
    why << "inner.preconditioner " << TracePreconditionerToString(preconditioner)
        << " preconditions inner.method streaming_conjugate_gradient only, got inner.method "
        << CoupledSolverTypeToString(type)
        << "; set inner.method: streaming_conjugate_gradient, or inner.preconditioner: none";
  } else if (!(shooting_condition_limit > 1.0)) {
    why << "inner.shooting_condition_limit must be above 1, got " << shooting_condition_limit;
  } else if (!(shooting_segment_growth > 1.0 && std::isfinite(shooting_segment_growth))) {
    why << "inner.shooting_segment_growth must be a finite number above 1, got "
        << shooting_segment_growth;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

std::string CoupledSolverSummary::BriefReport() const {
  std::ostringstream out;
  out << CoupledSolverTypeToString(type) << ": " << TerminationTypeToString(termination) << ", "
      << iterations << " iterations, " << sweeps << " sweeps, relative residual "
      << relative_residual << ", " << wall_time_s << " s";
  return out.str();
}

std::string CoupledSolverSummary::FullReport() const {
  std::ostringstream out;
  out << "Coupled direct/retrograde solve\n"
      << "  method                 " << CoupledSolverTypeToString(type) << "\n"
      << "  termination            " << TerminationTypeToString(termination) << "\n"
      << "  message                " << message << "\n"
      << "  iterations             " << iterations << "\n"
      << "  sweeps                 " << sweeps << "\n"
      << "  relative residual      " << relative_residual << "\n";
  if (relaxation_coefficient > 0.0) {
    out << "  relaxation coefficient " << relaxation_coefficient << "\n";
  }
  if (spectrum_max > 0.0) {
    out << "  spectrum of I - G      [" << spectrum_min << ", " << spectrum_max << "]\n";
  }
  if (type == CoupledSolverType::kAdaptiveRelaxation) {
    out << "  safeguard restarts     " << safeguard_restarts << "\n";
  }
  if (shooting_segments > 0) {
    out << "  shooting segments      " << shooting_segments << "\n"
        << "  shooting condition     " << shooting_condition_number << "\n";
  }
  if (multiply_accumulates >= 0.0) {
    out << "  multiply-accumulates   " << multiply_accumulates << "\n";
  }
  out << "  wall time              " << wall_time_s << " s\n";
  return out.str();
}

double IterativeSolverFieldBytes(double num_nodes, double num_steps) {
  return static_cast<double>(kIterativeSolverFields) * sizeof(double) * num_nodes *
         (num_steps + 1.0);
}

bool HoldsIterativeSolverFields(CoupledSolverType type) {
  return type == CoupledSolverType::kRelaxation || type == CoupledSolverType::kAdaptiveRelaxation ||
         type == CoupledSolverType::kConjugateGradient;
}

CoupledSolverType ResolveCoupledSolverType(const CoupledSolverOptions& options, double num_nodes,
                                           double num_steps, bool streaming_available) {
  if (options.type != CoupledSolverType::kAuto) return options.type;
  const bool fits = IterativeSolverFieldBytes(num_nodes, num_steps) <=
                    static_cast<double>(options.max_field_bytes);
  return fits || !streaming_available ? CoupledSolverType::kConjugateGradient
                                      : CoupledSolverType::kStreamingConjugateGradient;
}

std::string CoupledSolverName(CoupledSolverType requested, CoupledSolverType used) {
  if (requested == CoupledSolverType::kAuto && used != CoupledSolverType::kAuto) {
    return std::string("auto (") + CoupledSolverTypeToString(used) + ")";
  }
  return CoupledSolverTypeToString(used);
}

namespace {

// Why the solver name, holding fields of field_bytes, refuses to run above the limit
// inner.max_field_bytes, with the ways around it for this kind of problem.
std::string FieldLimitRefusal(const std::string& name, double field_bytes,
                              const CoupledSolverOptions& options, CoupledProblem* problem,
                              bool is_streaming) {
  std::ostringstream refusal;
  refusal << name << " needs " << static_cast<long long>(field_bytes) << " bytes ("
          << kIterativeSolverFields
          << " fields of n x (m + 1) doubles, n = " << problem->num_nodes()
          << " nodes, m = " << problem->num_steps() << " steps), above the limit of "
          << options.max_field_bytes << " bytes (inner.max_field_bytes); ";
  if (is_streaming) {
    refusal << "use inner.method: streaming_conjugate_gradient (or auto), which stores no "
               "space-time field, ";
  }
  refusal << "raise inner.max_field_bytes, or use a coarser mesh (fewer dofs; the bar's "
             "model.elements), a shorter window or a larger time step";
  return refusal.str();
}

// Why the resolved method type cannot solve this problem, "" when it can: the
// streaming solver needs a problem on sensor traces (streaming). Riccati and shooting
// solve any CoupledProblem from its operators (docs/riccati_shooting.md); they refuse
// themselves above inner.max_dense_solver_bytes or when M, S or P is not positive
// definite.
std::string UnsupportedProblemMessage(CoupledSolverType type,
                                      const StreamingCoupledProblem* streaming) {
  if (type == CoupledSolverType::kStreamingConjugateGradient && streaming == nullptr) {
    return "streaming_conjugate_gradient needs a problem on sensor traces "
           "(StreamingCoupledProblem); "
           "use inner.method: conjugate_gradient, adaptive_relaxation, relaxation or all_at_once";
  }
  return "";
}

// Runs the solver of resolved.type (resolved, never auto); false, with the message in
// summary, if it was left auto.
bool RunResolvedSolver(const CoupledSolverOptions& resolved, CoupledProblem* problem,
                       StreamingCoupledProblem* streaming, const Matrix* initial_guess,
                       double reference_residual_norm, CoupledSolution* solution,
                       CoupledSolverSummary* summary) {
  switch (resolved.type) {
    case CoupledSolverType::kAllAtOnce:
      internal::SolveAllAtOnce(resolved, problem, solution, summary);
      break;
    case CoupledSolverType::kRelaxation:
    case CoupledSolverType::kAdaptiveRelaxation:
      internal::SolveByRelaxation(resolved, problem, initial_guess, solution, summary);
      break;
    case CoupledSolverType::kConjugateGradient:
      internal::SolveByConjugateGradient(resolved, problem, initial_guess, solution, summary);
      break;
    case CoupledSolverType::kRiccati:
      internal::SolveByRiccati(resolved, problem, solution, summary);
      break;
    case CoupledSolverType::kSingleShooting:
    case CoupledSolverType::kMultipleShooting:
      internal::SolveByShooting(resolved, problem, solution, summary);
      break;
    case CoupledSolverType::kStreamingConjugateGradient:
      // Fills the cost and the gradients itself, from its final streaming pass.
      internal::SolveByStreamingConjugateGradient(resolved, streaming, initial_guess,
                                                  reference_residual_norm, solution, summary);
      break;
    case CoupledSolverType::kAuto:
      // ResolveCoupledSolverType never returns it.
      summary->message = "inner.method auto was not resolved";
      return false;
  }
  return true;
}

}  // namespace

CoupledSolverSummary SolveCoupled(const CoupledSolverOptions& options, CoupledProblem* problem,
                                  const Matrix* initial_guess, CoupledSolution* solution,
                                  double reference_residual_norm) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const long sweeps_before = problem->sweep_count();
  CoupledSolverSummary summary;
  summary.type = options.type;
  std::string why;
  if (!options.IsValid(&why)) {
    summary.message = "invalid options: " + why;
    return summary;
  }
  // The streaming solver needs a problem on sensor traces (a structure given by
  // matrices, the bar's among them); the field-limit refusal names the ways out.
  StreamingCoupledProblem* streaming = dynamic_cast<StreamingCoupledProblem*>(problem);
  const CoupledSolverType type = ResolveCoupledSolverType(
      options, problem->num_nodes(), problem->num_steps(), streaming != nullptr);
  summary.type = type;
  const std::string name = CoupledSolverName(options.type, type);
  const double field_bytes = IterativeSolverFieldBytes(problem->num_nodes(), problem->num_steps());
  if (HoldsIterativeSolverFields(type) &&
      field_bytes > static_cast<double>(options.max_field_bytes)) {
    summary.message = FieldLimitRefusal(name, field_bytes, options, problem, streaming != nullptr);
    return summary;
  }
  const std::string unsupported = UnsupportedProblemMessage(type, streaming);
  if (!unsupported.empty()) {
    summary.message = unsupported;
    return summary;
  }
  // The solvers below see the resolved method; a streaming one keeps omega's whole
  // history when it fits the same budget as the stored fields.
  CoupledSolverOptions resolved = options;
  resolved.type = type;
  if (type == CoupledSolverType::kStreamingConjugateGradient) {
    streaming->SetHistoryBudget(options.max_field_bytes);
  }
  if (!RunResolvedSolver(resolved, problem, streaming, initial_guess, reference_residual_norm,
                         solution, &summary)) {
    return summary;
  }
  if (summary.IsSolutionUsable() && type != CoupledSolverType::kStreamingConjugateGradient) {
    solution->cost = problem->Cost(solution->displacement, solution->retrograde);
    problem->CostGradients(solution->displacement, solution->retrograde, &solution->cost_gradients);
    // One zone: de^2/dE; several: the derivative along a common change of every zone.
    solution->cost_gradient = solution->cost_gradients.sum();
  }
  summary.sweeps = problem->sweep_count() - sweeps_before;
  summary.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

}  // namespace mcrewave
