#include "mcrewave/least_squares/output_error_modulus_objective.h"

#include <cassert>
#include <cmath>
#include <sstream>

#include "mcrewave/optim/valley_spacing.h"

namespace mcrewave {

OutputErrorModulusObjective::OutputErrorModulusObjective(const MatrixModelData& model,
                                                         const ChannelSet& data,
                                                         const NoiseLevels& misfit_levels,
                                                         double theta, double modulus_scale)
    : model_(model),
      data_(data),
      misfit_levels_(misfit_levels),
      theta_(theta),
      modulus_scale_(modulus_scale),
      objective_(model, data, misfit_levels, theta, Factorization::kAutomatic, modulus_scale) {
  assert(modulus_scale > 0.0);
}

std::unique_ptr<ModulusObjective> OutputErrorModulusObjective::CloneForScan(double) const {
  auto clone = std::make_unique<OutputErrorModulusObjective>(model_, data_, misfit_levels_, theta_,
                                                             modulus_scale_);
  clone->SetGradientMethod(objective_.gradient_method());
  return clone;
}

void OutputErrorModulusObjective::Solve(double modulus, bool gradient_requested,
                                        bool information_requested) {
  assert(modulus > 0.0 && std::isfinite(modulus));
  assert(gradient_requested || !information_requested);
  const Vector moduli = Vector::Constant(objective_.num_parameters(), modulus);
  fit_.modulus = modulus;
  fit_.cost = objective_.Cost(moduli, gradient_requested ? &gradient_ : nullptr,
                              information_requested ? &information_ : nullptr);
  // Every zone moves with E: dJ/dE = sum_z dJ/dE_z, I = 1^T I_zz' 1.
  fit_.cost_gradient = gradient_requested ? gradient_.sum() : 0.0;
  fit_.fisher_information = information_requested ? information_.sum() : 0.0;
}

const OutputErrorFit& OutputErrorModulusObjective::Predict(double modulus,
                                                           bool gradient_requested) {
  Solve(modulus, gradient_requested, gradient_requested);
  fit_.outputs = objective_.outputs();
  fit_.support_forces = objective_.support_forces();
  return fit_;
}

bool OutputErrorModulusObjective::Evaluate(const double* parameters, double* cost,
                                           double* gradient) {
  double modulus = 0.0;
  if (!TrialModulus(parameters[0], modulus_scale_, &modulus, &error_message_)) return false;
  Solve(modulus, gradient != nullptr, false);
  const OutputErrorFit& fit = fit_;
  if (!std::isfinite(fit.cost) || !std::isfinite(fit.cost_gradient)) {
    std::ostringstream why;
    why << "the output-error misfit at E = " << modulus << " Pa is not finite";
    error_message_ = why.str();
    return false;
  }
  *cost = fit.cost / cost_scale();
  if (gradient != nullptr) gradient[0] = fit.cost_gradient * modulus_scale_ / cost_scale();
  error_message_.clear();
  return true;
}

double OutputErrorModulusObjective::ValleySpacing() {
  Solve(modulus_scale_, false, false);
  const Matrix& outputs = objective_.outputs();
  const Matrix& support_forces = objective_.support_forces();
  const Eigen::Index sensors = outputs.rows();
  const Eigen::Index supports = support_forces.rows();
  Matrix traces(sensors + supports, outputs.cols());
  traces.topRows(sensors) = outputs;
  traces.bottomRows(supports) = support_forces;
  Vector weights(sensors + supports);
  weights.head(sensors) = objective_.sensor_weights();
  weights.tail(supports).setConstant(objective_.force_weight());
  return PredictedValleySpacing(traces, weights, data_.time_step);
}

}  // namespace mcrewave
