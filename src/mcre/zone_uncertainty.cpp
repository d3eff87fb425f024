#include "mcrewave/mcre/zone_uncertainty.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <cassert>
#include <cmath>
#include <memory>

#include "mcrewave/core/random.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {
namespace {

// The coupled solve at `moduli` (warm start nullable); false with *why when not usable.
bool SolveUsable(const CoupledSolverOptions& inner, const Vector& moduli,
                 MatrixMcreProblem* problem, const Matrix* warm_start, CoupledSolution* solution,
                 long* sweeps, std::string* why) {
  problem->SetModuli(moduli);
  const CoupledSolverSummary summary = SolveCoupled(inner, problem, warm_start, solution);
  *sweeps += summary.sweeps;
  if (summary.IsSolutionUsable() && std::isfinite(solution->cost)) return true;
  *why = summary.BriefReport() + " (" + summary.message + ")";
  return false;
}

// H by the secants of the adjoint gradient over +- kCurvatureWindow E*_z, symmetrised;
// false with *why when a solve is not usable.
bool SecantCurvature(const CoupledSolverOptions& inner, const Vector& moduli,
                     const CoupledSolution& solution, MatrixMcreProblem* problem, Matrix* curvature,
                     long* sweeps, std::string* why) {
  const int zones = static_cast<int>(moduli.size());
  curvature->resize(zones, zones);
  CoupledSolution trial;
  for (int z = 0; z < zones; ++z) {
    Vector gradients[2];
    for (int side = 0; side < 2; ++side) {
      Vector shifted = moduli;
      shifted[z] *= side == 0 ? 1.0 + kCurvatureWindow : 1.0 - kCurvatureWindow;
      const Matrix* warm_start = solution.has_fields() ? &solution.retrograde : &solution.traces;
      if (!SolveUsable(inner, shifted, problem, warm_start, &trial, sweeps, why)) {
        *why = "the curvature's solve at zone " + std::to_string(z) + " is not usable: " + *why;
        return false;
      }
      gradients[side] = trial.cost_gradients;
    }
    // H_{:,z} = (g(E* + w E*_z e_z) - g(E* - w E*_z e_z)) / (2 w E*_z)
    curvature->col(z) = (gradients[0] - gradients[1]) / (2.0 * kCurvatureWindow * moduli[z]);
  }
  *curvature = 0.5 * (*curvature + curvature->transpose()).eval();
  return true;
}

// The problem of the figure's solves on `data`: they read costs and gradients, never
// the element map (set_element_maps).
std::unique_ptr<MatrixMcreProblem> FigureProblem(const MatrixModelData& model,
                                                 const ChannelSet& data, const McreOptions& mcre,
                                                 double theta) {
  auto problem = std::make_unique<MatrixMcreProblem>(
      model, data, mcre.weights, mcre.reference_modulus, theta, Factorization::kAutomatic,
      mcre.clamp, UnmeasuredLoads(mcre));
  problem->set_element_maps(false);
  return problem;
}

}  // namespace

ZoneUncertainty EstimateZoneUncertainty(const UncertaintyOptions& options,
                                        const MatrixModelData& model, const ChannelSet& data,
                                        const McreOptions& mcre, double theta,
                                        const CoupledSolverOptions& inner, const Vector& moduli,
                                        const CoupledSolution& solution, const NoiseLevels& noise,
                                        const Matrix* curvature) {
  assert(options.samples >= 0 && moduli.size() == static_cast<Eigen::Index>(model.zones.size()));
  ZoneUncertainty result;
  result.noise = noise;
  if (options.samples == 0) {
    result.message = kUncertaintyOffMessage;
    return result;
  }
  if (!(noise.displacement_std > 0.0 || noise.strain_std > 0.0 || noise.force_std > 0.0)) {
    result.message = "no noise to propagate (every noise level is 0)";
    return result;
  }
  if (!solution.has_fields() && solution.traces.size() == 0) {
    result.message = "the figure needs the coupled solution's fields or traces";
    return result;
  }
  auto make_problem = [&](const ChannelSet& set) { return FigureProblem(model, set, mcre, theta); };
  std::string why;
  if (curvature != nullptr) {
    assert(curvature->rows() == moduli.size() && curvature->cols() == moduli.size());
    result.curvature = *curvature;
  } else {
    const std::unique_ptr<MatrixMcreProblem> problem = make_problem(data);
    if (!SecantCurvature(inner, moduli, solution, problem.get(), &result.curvature, &result.sweeps,
                         &why)) {
      result.message = why;
      return result;
    }
  }
  const Eigen::LLT<Matrix> factor(result.curvature);
  if (factor.info() != Eigen::Success) {
    result.message = curvature != nullptr
                         ? "the cost is not convex around the identified moduli (the curvature "
                           "given is not positive definite)"
                         : "the cost is not convex around the identified moduli (the secant "
                           "curvature over +- 5 % is not positive definite)";
    return result;
  }
  const int zones = static_cast<int>(moduli.size());
  ChannelSet noise_data = data, plus_data = data, minus_data = data;
  StandardNormal normal(options.seed);
  Matrix sum = Matrix::Zero(zones, zones);
  CoupledSolution noise_solution;
  std::shared_ptr<const MatrixMcreProblem::TraceFactor> shared_factor;
  Vector plus_gradient, minus_gradient;
  // The sensitivity map's draws on a model with element blocks: sum_i ds_el,i^2.
  const bool elements = !model.elements.empty();
  Vector plus_sensitivity, minus_sensitivity;
  Vector sensitivity_square_sum = Vector::Zero(static_cast<Eigen::Index>(model.elements.size()));
  Matrix image;
  StreamingCoupledProblem::StreamingTotals totals;
  for (int sample = 0; sample < options.samples; ++sample) {
    DrawWhiteNoise(noise, &normal, &noise_data);
    for (std::size_t c = 0; c < data.channels.size(); ++c) {
      plus_data.channels[c].values = data.channels[c].values + noise_data.channels[c].values;
      minus_data.channels[c].values = data.channels[c].values - noise_data.channels[c].values;
    }
    const std::unique_ptr<MatrixMcreProblem> noise_problem = make_problem(noise_data);
    // Every draw at the same moduli: the first draw's preconditioner serves them all.
    noise_problem->ShareTraceFactor(shared_factor);
    if (!SolveUsable(inner, moduli, noise_problem.get(), nullptr, &noise_solution, &result.sweeps,
                     &why)) {
      result.message = "a noise solve is not usable: " + why;
      return result;
    }
    shared_factor = noise_problem->trace_factor();
    // dg = (g(s_d + s_n; d + n) - g(s_d - s_n; d - n)) / 2
    const std::unique_ptr<MatrixMcreProblem> plus = make_problem(plus_data),
                                             minus = make_problem(minus_data);
    plus->SetModuli(moduli);
    minus->SetModuli(moduli);
    if (solution.has_fields()) {
      const Matrix plus_displacement = solution.displacement + noise_solution.displacement;
      const Matrix plus_retrograde = solution.retrograde + noise_solution.retrograde;
      plus->CostGradients(plus_displacement, plus_retrograde, &plus_gradient);
      if (elements)
        plus->ElementSensitivities(plus_displacement, plus_retrograde, &plus_sensitivity);
      const Matrix minus_displacement = solution.displacement - noise_solution.displacement;
      const Matrix minus_retrograde = solution.retrograde - noise_solution.retrograde;
      minus->CostGradients(minus_displacement, minus_retrograde, &minus_gradient);
      if (elements) {
        minus->ElementSensitivities(minus_displacement, minus_retrograde, &minus_sensitivity);
      }
    } else {
      // A streaming solution: s_d +- s_n are the fixed points y_d +- y_n on the traces,
      // whose fields one application of each problem's map passes through.
      plus->set_element_maps(elements);
      minus->set_element_maps(elements);
      plus->StreamingMap(solution.traces + noise_solution.traces, true, &image, &totals);
      plus_gradient = totals.cost_gradients;
      plus_sensitivity = totals.element_sensitivity;
      minus->StreamingMap(solution.traces - noise_solution.traces, true, &image, &totals);
      minus_gradient = totals.cost_gradients;
      minus_sensitivity = totals.element_sensitivity;
      result.sweeps += plus->sweep_count() + minus->sweep_count();
    }
    if (elements) {
      // ds_el = (s_el(s_d + s_n; d + n) - s_el(s_d - s_n; d - n)) / 2
      sensitivity_square_sum += (0.5 * (plus_sensitivity - minus_sensitivity)).cwiseAbs2();
    }
    // dE = -H^-1 dg
    const Vector change = -factor.solve(0.5 * (plus_gradient - minus_gradient));
    sum += change * change.transpose();
    std::string changes;
    for (int z = 0; z < zones; ++z)
      changes += (z == 0 ? "" : ", ") + fmt::format("{:.4g}", change[z]);
    spdlog::debug("uncertainty sample {}: dE = [{}] Pa", sample + 1, changes);
  }
  result.samples = options.samples;
  // Cov(E*) = mean_i dE_i dE_i^T
  result.covariance = sum / options.samples;
  result.std_dev = result.covariance.diagonal().cwiseSqrt();
  // std(s_el) = sqrt(mean_i ds_el,i^2)
  if (elements) result.sensitivity_std = (sensitivity_square_sum / options.samples).cwiseSqrt();
  result.available = true;
  result.message = "ok";
  return result;
}

}  // namespace mcrewave
