#include "optim/nlopt_driver.h"

#include <algorithm>
#include <cmath>
#include <new>
#include <stdexcept>

namespace mcrewave::internal {
namespace {

struct CallbackData {
  GuardedObjective* guard;
  nlopt::opt* optimizer;
};

// Never throws (the guard catches).
double NloptCallback(const std::vector<double>& x, std::vector<double>& gradient, void* data) {
  auto* callback = static_cast<CallbackData*>(data);
  double cost = HUGE_VAL;
  double* gradient_out = gradient.empty() ? nullptr : gradient.data();
  if (!callback->guard->Evaluate(x.data(), &cost, gradient_out)) {
    callback->optimizer->force_stop();
    std::fill(gradient.begin(), gradient.end(), 0.0);
    return HUGE_VAL;
  }
  return cost;
}

void Set(OptimizerOutcome* outcome, TerminationType termination, std::string optimizer_message,
         std::string message) {
  outcome->termination = termination;
  outcome->optimizer_message = std::move(optimizer_message);
  outcome->message = std::move(message);
}

}  // namespace

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
    case OuterAlgorithm::kSlsqp:
      return nlopt::LD_SLSQP;
    default:
      return nlopt::LN_BOBYQA;
  }
}

std::string NloptResultName(nlopt::result result) {
  switch (result) {
    case nlopt::SUCCESS:
      return "success";
    case nlopt::STOPVAL_REACHED:
      return "stopval reached";
    case nlopt::FTOL_REACHED:
      return "ftol reached";
    case nlopt::XTOL_REACHED:
      return "xtol reached";
    case nlopt::MAXEVAL_REACHED:
      return "maxeval reached";
    case nlopt::MAXTIME_REACHED:
      return "maxtime reached";
    default:
      return "result code " + std::to_string(static_cast<int>(result));
  }
}

OptimizerOutcome RunNlopt(nlopt::opt* optimizer, GuardedObjective* guard, std::vector<double>* x,
                          bool gradient_based) {
  OptimizerOutcome outcome;
  CallbackData data{guard, optimizer};
  double cost = HUGE_VAL;
  try {
    optimizer->set_min_objective(NloptCallback, &data);
    const nlopt::result result = optimizer->optimize(*x, cost);
    const std::string name = NloptResultName(result);
    if (result == nlopt::MAXEVAL_REACHED) {
      Set(&outcome, TerminationType::kNoConvergence, name,
          guard->LimitMessage(StopReason::kEvaluationLimit));
    } else if (result == nlopt::MAXTIME_REACHED) {
      Set(&outcome, TerminationType::kNoConvergence, name,
          guard->LimitMessage(StopReason::kTimeLimit));
    } else {
      Set(&outcome, TerminationType::kConvergence, name, "converged (NLopt: " + name + ")");
    }
  } catch (const nlopt::roundoff_limited&) {
    // The tolerance asked for is below what round-off in the cost allows: the best
    // point seen is as good as this objective can tell.
    Set(&outcome, TerminationType::kConvergence, "roundoff limited",
        "converged to round-off (NLopt: roundoff limited)");
  } catch (const nlopt::forced_stop&) {
    Set(&outcome, TerminationType::kFailure, "forced stop",
        "NLopt was force-stopped for no reason the objective knows");
  } catch (const std::invalid_argument& error) {
    Set(&outcome, TerminationType::kFailure, error.what(),
        std::string("NLopt refused its arguments: ") + error.what());
  } catch (const std::bad_alloc&) {
    Set(&outcome, TerminationType::kFailure, "out of memory", "NLopt ran out of memory");
  } catch (const std::exception& error) {
    const bool stall = gradient_based && guard->improved() && guard->stop() == StopReason::kNone &&
                       std::string(error.what()) == "nlopt failure";
    if (stall) {
      Set(&outcome, TerminationType::kConvergence, error.what(),
          "converged to the objective's precision (NLopt: line search without decrease)");
    } else {
      Set(&outcome, TerminationType::kFailure, error.what(),
          std::string("NLopt failed: ") + error.what());
    }
  }
  if (guard->stop() != StopReason::kNone) {
    outcome.termination = guard->StopTermination();
    outcome.message = guard->stop_message();
  }
  return outcome;
}

}  // namespace mcrewave::internal
