// The one objective interface of the optimisers (shaped like ceres::FirstOrderFunction):
// a cost of num_parameters() parameters, an optional gradient, and false (never a
// made-up number) when the value cannot be had. Identify (identification.h) minimises
// one of one parameter (ModulusObjective, modulus_objective.h); MinimizeWithinBounds
// (bounded_minimizer.h) one of any number.
#pragma once

#include <string>

namespace mcrewave {

class FirstOrderObjective {
 public:
  virtual ~FirstOrderObjective() = default;
  virtual int num_parameters() const = 0;
  // Writes the cost at x (num_parameters() entries) to *cost and, when gradient is not
  // null, d cost / d x_i to gradient[i]. False when the value could not be computed
  // (error_message() says why; *cost and gradient are then meaningless). May throw: the
  // optimisers catch.
  virtual bool Evaluate(const double* x, double* cost, double* gradient) = 0;
  // Why the last failed Evaluate failed ("" when none failed).
  virtual std::string error_message() const { return ""; }
};

}  // namespace mcrewave
