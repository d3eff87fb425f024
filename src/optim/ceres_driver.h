// Ceres behind the one optimiser layer: ceres::GradientProblemSolver (a line search
// with the gradient) on free variables z, each parameter x_i = X_i(z_i) through a map
// of the caller's that keeps it inside its bounds, with one step test on x and one
// reading of Ceres' ends, for every caller (Identify's one parameter,
// MinimizeWithinBounds' many).
#pragma once

#include <ceres/ceres.h>

#include <vector>

#include "optim/guarded_objective.h"
#include "optim/nlopt_driver.h"

namespace mcrewave::internal {

// x_i = X(i, z_i), increasing, within the bounds of parameter i for every z_i.
class BoundMap {
 public:
  virtual ~BoundMap() = default;
  virtual double X(int i, double z) const = 0;
  virtual double DxDz(int i, double z) const = 0;
};

struct CeresSettings {
  ceres::LineSearchDirectionType direction = ceres::LBFGS;
  int max_lbfgs_rank = 20;  // Ceres' default
  int max_iterations = 1000;
  double max_time = 600.0;  // [s]
  // Ceres' own test on the relative change of the cost; round-off by default, so that
  // it ends only a run that can make no more progress.
  double function_tolerance = 1e-15;
  // The run ends once an accepted step changes every x_i by at most
  // step_absolute + step_relative |x_i|.
  double step_absolute = 0.0;
  double step_relative = 0.0;
};

// Minimises the guarded objective over z from *z (num_parameters() entries; the last
// iterate is left there, though the guard's best is the one to report). The run is
// aborted once the guard has stopped, whose reason then wins. Never throws.
OptimizerOutcome RunCeres(const BoundMap& map, const CeresSettings& settings,
                          GuardedObjective* guard, std::vector<double>* z);

}  // namespace mcrewave::internal
