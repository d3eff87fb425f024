// The Ceres back end of Identify (identification.h): the scalar loop's map and settings
// of the one Ceres driver (ceres_driver.h).
#include <cmath>
#include <vector>

#include "optim/ceres_driver.h"
#include "optim/identification_internal.h"

namespace mcrewave::internal {
namespace {

// The bounded map between Ceres' free parameter z and x = E / E_scale:
//   x(z) = x_lo + (x_hi - x_lo) s(sigma z),  s(y) = 1 / (1 + exp(-y)),
//   dx/dz = sigma (x_hi - x_lo) s (1 - s),
// smooth, increasing, and inside [x_lo, x_hi] for every z. The scale sigma sets
// the curvature of the cost in z: Ceres' first line-search step is
// -g min(1, 1 / |g|) in z, the Newton step -g / c'' when c'' = d^2 cost / dz^2 = 1,
// so sigma = 1 / (sqrt(k) dx/dz|_{sigma=1}) with k the curvature in x at the start
// makes the first step follow the curvature of e^2 instead of a unit step in z.
class LogisticMap : public BoundMap {
 public:
  LogisticMap(double x_lower, double x_upper) : x_lower_(x_lower), x_upper_(x_upper) {}

  double X(int /*i*/, double z) const override {
    return x_lower_ + (x_upper_ - x_lower_) * Logistic(sigma_ * z);
  }
  double DxDz(int /*i*/, double z) const override {
    const double s = Logistic(sigma_ * z);
    return sigma_ * (x_upper_ - x_lower_) * s * (1.0 - s);
  }
  // z(x) = log(s / (1 - s)) / sigma, s = (x - x_lo) / (x_hi - x_lo); x strictly inside.
  double Z(double x) const {
    const double s = (x - x_lower_) / (x_upper_ - x_lower_);
    return std::log(s / (1.0 - s)) / sigma_;
  }
  void set_sigma(double sigma) { sigma_ = sigma; }

 private:
  // 1 / (1 + exp(-y)), written so that exp never overflows.
  static double Logistic(double y) {
    if (y >= 0.0) return 1.0 / (1.0 + std::exp(-y));
    const double e = std::exp(y);
    return e / (1.0 + e);
  }

  double x_lower_;
  double x_upper_;
  double sigma_ = 1.0;
};

}  // namespace

void MinimizeWithCeres(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, double curvature, IdentificationSummary* summary) {
  LogisticMap map(options.lower_bound / modulus_scale, options.upper_bound / modulus_scale);
  const double x0 = options.initial / modulus_scale;
  if (curvature > 0.0 && std::isfinite(curvature)) {
    // d^2 cost / dz^2 = k (dx/dz)^2 = 1 at the start (the term g d^2x/dz^2 left out).
    map.set_sigma(1.0 / (std::sqrt(curvature) * map.DxDz(0, map.Z(x0))));
  }
  std::vector<double> z{map.Z(x0)};
  CeresSettings settings;
  settings.direction = summary->algorithm == OuterAlgorithm::kBfgs ? ceres::BFGS : ceres::LBFGS;
  settings.max_iterations = options.max_evaluations;
  settings.max_time = options.max_time;
  // The step test of NLopt's xtol_rel, on E rather than on z.
  settings.step_relative = options.relative_tolerance;
  const OptimizerOutcome outcome = RunCeres(map, settings, objective, &z);
  summary->termination = outcome.termination;
  summary->message = outcome.message;
  summary->optimizer_message = outcome.optimizer_message;
  summary->iterations = outcome.iterations;
}

}  // namespace mcrewave::internal
