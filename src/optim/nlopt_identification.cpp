// The NLopt back end of Identify (identification.h).
#include <cmath>
#include <new>
#include <nlopt.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "optim/identification_internal.h"
#include "optim/nlopt_results.h"

namespace mcrewave::internal {
namespace {

nlopt::algorithm NloptAlgorithm(OuterAlgorithm algorithm) {
  switch (algorithm) {
    case OuterAlgorithm::kCobyla:
      return nlopt::LN_COBYLA;
    case OuterAlgorithm::kSbplx:
      return nlopt::LN_SBPLX;
    case OuterAlgorithm::kMma:
      return nlopt::LD_MMA;
    case OuterAlgorithm::kLbfgs:
      return nlopt::LD_LBFGS;
    default:
      return nlopt::LN_BOBYQA;
  }
}

// What the NLopt callback needs: the guarded objective and the optimiser to
// force-stop.
struct CallbackData {
  GuardedObjective* objective;
  nlopt::opt* optimizer;
  double cost_unit;  // NLopt sees cost / cost_unit and gradient / cost_unit
};

// The NLopt objective. Never throws (GuardedObjective catches): on a failed or
// refused evaluation it force-stops NLopt and returns +HUGE_VAL, which no
// algorithm takes for a best point.
double NloptObjective(const std::vector<double>& x, std::vector<double>& gradient, void* data) {
  auto* callback = static_cast<CallbackData*>(data);
  double cost = HUGE_VAL;
  double* gradient_out = gradient.empty() ? nullptr : gradient.data();
  if (!callback->objective->Evaluate(x[0], &cost, gradient_out)) {
    callback->optimizer->force_stop();
    if (gradient_out != nullptr) gradient_out[0] = 0.0;
    return HUGE_VAL;
  }
  if (gradient_out != nullptr) gradient_out[0] /= callback->cost_unit;
  return cost / callback->cost_unit;
}

}  // namespace

void MinimizeWithNlopt(const IdentificationOptions& options, GuardedObjective* objective,
                       double curvature, IdentificationSummary* summary) {
  const double scale = objective->modulus_scale();
  nlopt::opt optimizer(NloptAlgorithm(summary->algorithm), 1);
  // The gradient methods (MMA's convexity term, L-BFGS' first step) assume cost
  // changes of order one across the bounds; a flat e^2 stops MMA at its start. Their
  // cost unit is the change the curvature k predicts over the bounds' width w: k w^2.
  const double width = (options.upper_bound - options.lower_bound) / scale;
  const double predicted_change = curvature * width * width;
  const double cost_unit = UsesGradient(options.optimizer, summary->algorithm) &&
                                   predicted_change > 0.0 && std::isfinite(predicted_change)
                               ? predicted_change
                               : 1.0;
  CallbackData data{objective, &optimizer, cost_unit};
  optimizer.set_min_objective(NloptObjective, &data);
  optimizer.set_lower_bounds(options.lower_bound / scale);
  optimizer.set_upper_bounds(options.upper_bound / scale);
  optimizer.set_xtol_rel(options.relative_tolerance);
  optimizer.set_maxeval(options.max_evaluations);
  optimizer.set_maxtime(options.max_time);
  std::vector<double> x{options.initial / scale};
  double cost = HUGE_VAL;
  try {
    const nlopt::result result = optimizer.optimize(x, cost);
    summary->optimizer_message = NloptResultName(result);
    if (result == nlopt::MAXEVAL_REACHED || result == nlopt::MAXTIME_REACHED) {
      summary->termination = TerminationType::kNoConvergence;
      summary->message = result == nlopt::MAXEVAL_REACHED
                             ? "outer.max_evaluations (" + std::to_string(options.max_evaluations) +
                                   ") reached before convergence"
                             : "outer.max_time reached before convergence";
    } else {
      summary->termination = TerminationType::kConvergence;
      summary->message = "converged (" + summary->optimizer_message + ")";
    }
  } catch (const nlopt::roundoff_limited&) {
    // The tolerance asked for is below what round-off in the cost allows: the
    // best point seen is as good as this objective can tell.
    summary->optimizer_message = "roundoff limited";
    summary->termination = TerminationType::kConvergence;
    summary->message = "converged to round-off (NLopt: roundoff limited)";
  } catch (const nlopt::forced_stop&) {
    summary->optimizer_message = "forced stop";
    if (objective->stop() != StopReason::kNone) {
      objective->ReportStop(summary);
    } else {
      summary->termination = TerminationType::kFailure;
      summary->message = "NLopt was force-stopped for no reason the objective knows";
    }
  } catch (const std::invalid_argument& error) {
    summary->optimizer_message = error.what();
    summary->termination = TerminationType::kFailure;
    summary->message = std::string("NLopt refused its arguments: ") + error.what();
  } catch (const std::bad_alloc&) {
    summary->optimizer_message = "out of memory";
    summary->termination = TerminationType::kFailure;
    summary->message = "NLopt ran out of memory";
  } catch (const std::runtime_error& error) {
    summary->optimizer_message = error.what();
    if (IsLineSearchStallAfterProgress(error, UsesGradient(options.optimizer, summary->algorithm),
                                       objective->improved(),
                                       objective->stop() != StopReason::kNone)) {
      summary->termination = TerminationType::kConvergence;
      summary->message = kLineSearchStallMessage;
    } else {
      summary->termination = TerminationType::kFailure;
      summary->message = std::string("NLopt failed: ") + error.what();
    }
  }
  // A failure inside the objective is the real reason, whatever NLopt says.
  if (objective->stop() == StopReason::kFailure) objective->ReportStop(summary);
}

}  // namespace mcrewave::internal
