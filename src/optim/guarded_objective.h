// The objective as every optimiser of the one layer sees it (NLopt, Ceres, Brent; one
// parameter or many): each call counted, the evaluation and time limits enforced before
// it, exceptions caught (what() kept), non-finite values refused, the best usable point
// remembered, and the cost handed on divided by a cost scale. Once it has stopped,
// every later call returns false without evaluating.
#pragma once

#include <chrono>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/optim/first_order_objective.h"

namespace mcrewave::internal {

// Why the guarded objective refused to (or could not) evaluate.
enum class StopReason {
  kNone,
  kEvaluationLimit,  // max_evaluations reached
  kTimeLimit,        // max_time elapsed
  kFailure,          // the objective returned false, threw, or gave a non-finite value
};

// The limits of one minimisation and the config section that sets them, for messages
// ("outer" names outer.max_evaluations).
struct GuardLimits {
  int max_evaluations = 0;
  double max_time = 0.0;  // [s]
  std::string section;
};

class GuardedObjective {
 public:
  // Called after every evaluation the guard lets through: x, and the cost and gradient
  // as the objective gave them (cost null when the evaluation failed; gradient null
  // when not asked for).
  using Observer = std::function<void(const GuardedObjective& guard, const double* x,
                                      const double* cost, const double* gradient)>;

  // Keeps the objective, which must outlive the guard; the clock starts now.
  GuardedObjective(FirstOrderObjective* objective, GuardLimits limits);

  int num_parameters() const { return objective_->num_parameters(); }
  // The objective's cost and gradient at x, each divided by the cost scale. False when
  // stopped (see stop()).
  bool Evaluate(const double* x, double* cost, double* gradient);

  // From now on the optimiser sees cost / scale and gradient / scale (the best cost
  // kept is the objective's own). Precondition: scale > 0.
  void set_cost_scale(double scale) { cost_scale_ = scale; }
  void set_observer(Observer observer) { observer_ = std::move(observer); }

  StopReason stop() const { return stop_; }
  const std::string& stop_message() const { return stop_message_; }
  // The termination stop() calls for: kNoConvergence for a limit, kFailure for a
  // failure. Precondition: stop() != kNone.
  TerminationType StopTermination() const;
  // The message of NLopt's own evaluation or time limit, naming the section's key.
  std::string LimitMessage(StopReason limit) const;

  int evaluations() const { return evaluations_; }  // failed ones included
  int gradient_evaluations() const { return gradient_evaluations_; }
  bool has_best() const { return !best_x_.empty(); }
  const std::vector<double>& best_x() const { return best_x_; }  // empty: none usable
  double best_cost() const { return best_cost_; }
  // d cost / dx at best_x (empty when that evaluation had no gradient).
  const std::vector<double>& best_gradient() const { return best_gradient_; }
  // The cost of the first usable evaluation (NaN: none).
  double initial_cost() const { return initial_cost_; }
  // Whether a usable evaluation has a lower cost than the first usable one.
  bool improved() const { return has_best() && best_cost_ < initial_cost_; }
  double ElapsedSeconds() const;

 private:
  void Stop(StopReason reason, std::string message);

  FirstOrderObjective* objective_;
  GuardLimits limits_;
  std::chrono::steady_clock::time_point start_;
  Observer observer_;
  StopReason stop_ = StopReason::kNone;
  std::string stop_message_;
  int evaluations_ = 0;
  int gradient_evaluations_ = 0;
  std::vector<double> best_x_;
  std::vector<double> best_gradient_;
  double best_cost_ = 0.0;
  double initial_cost_ = std::numeric_limits<double>::quiet_NaN();
  double cost_scale_ = 1.0;
};

}  // namespace mcrewave::internal
