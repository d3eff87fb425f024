// Shared by the NLopt and Ceres back ends of Identify (identification.h).
#pragma once

#include <chrono>
#include <string>

#include "mcrewave/optim/identification.h"

namespace mcrewave::internal {

// Why the guarded objective refused to (or could not) evaluate.
enum class StopReason {
  kNone,
  kEvaluationLimit,  // options.max_evaluations reached
  kTimeLimit,        // options.max_time elapsed
  kFailure,          // the objective returned false or threw
};

// The objective as an optimiser must see it: every call counted and logged,
// the limits enforced before each evaluation, exceptions caught (what() kept),
// and the best usable point remembered. Once it has stopped, every later call
// returns false without evaluating.
class GuardedObjective {
 public:
  GuardedObjective(const IdentificationOptions& options, ModulusObjective* objective);

  // Evaluates at the scaled parameter x. False when stopped (see stop()).
  bool Evaluate(double x, double* cost, double* gradient);

  StopReason stop() const { return stop_; }
  const std::string& stop_message() const { return stop_message_; }
  bool has_best() const { return has_best_; }
  double best_x() const { return best_x_; }
  // Whether a usable evaluation has a lower cost than the first usable one.
  bool improved() const { return has_best_ && best_cost_ < initial_cost_; }
  double modulus_scale() const { return objective_->modulus_scale(); }
  double ElapsedSeconds() const;

  // The termination and message that stop() calls for: kNoConvergence for a
  // limit, kFailure for a failed evaluation. Precondition: stop() != kNone.
  void ReportStop(IdentificationSummary* summary) const;
  // Sets the best point, the counts and the wall time.
  void FillSummary(IdentificationSummary* summary) const;

 private:
  const IdentificationOptions& options_;
  ModulusObjective* objective_;
  std::chrono::steady_clock::time_point start_;
  StopReason stop_ = StopReason::kNone;
  std::string stop_message_;
  int evaluations_ = 0;
  int gradient_evaluations_ = 0;
  bool has_best_ = false;
  double initial_cost_ = 0.0;  // of the first usable evaluation
  double best_x_ = 0.0;
  double best_cost_ = 0.0;
  bool best_has_gradient_ = false;
  double best_gradient_ = 0.0;
};

// The back ends. Each runs its optimiser on the guarded objective and sets the
// summary's termination, message, optimizer_message and (Ceres) iterations;
// Identify then calls FillSummary.
// curvature as for Ceres: the gradient methods see the cost in units of its change
// over the bounds (curvature x width^2).
void MinimizeWithNlopt(const IdentificationOptions& options, GuardedObjective* objective,
                       double curvature, IdentificationSummary* summary);
// curvature: an estimate of d^2 cost / dx^2 at options.initial (0: unknown), which
// scales Ceres' parameter so that its first step is the Newton step.
void MinimizeWithCeres(const IdentificationOptions& options, GuardedObjective* objective,
                       double curvature, IdentificationSummary* summary);
void MinimizeWithBrent(const IdentificationOptions& options, GuardedObjective* objective,
                       IdentificationSummary* summary);

}  // namespace mcrewave::internal
