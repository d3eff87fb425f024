// Output-error least squares on one modulus of a structure given by matrices: the
// misfit J of MatrixOutputErrorObjective (matrix_output_error_objective.h, docs/
// formulation.md section 8) with every zone at the same E, seen by the optimisers of
// optim/identification.h as a ModulusObjective: x = E / modulus_scale, cost J / J_rest,
//   d cost / dx = (sum_z dJ/dE_z) modulus_scale / J_rest.
// The bar's least squares is this objective on BarRunModel: its clamp held, f0 the
// clamp's reaction with the inertia of the free nodes, uL and the interior sensors
// outputs, the measured fL the load.
#pragma once

#include <memory>
#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/modulus_objective.h"

namespace mcrewave {

// The model's outputs at one modulus, on the data's samples.
struct OutputErrorFit {
  double modulus = -1.0;       // E [Pa]
  double cost = -1.0;          // J(E) [s]
  double cost_gradient = 0.0;  // dJ/dE [s / Pa] (0 when not asked for)
  // The Fisher information of E, the sum of MatrixOutputErrorObjective's matrix
  // (every zone moves with E) [1/Pa^2], with the gradient (0 when not asked for);
  // std(E) >= 1 / sqrt(I).
  double fisher_information = 0.0;
  Matrix outputs;         // H U_j, one row per sensor in the model's order [m] or [-]
  Matrix support_forces;  // r_s,j, one row per support in the model's order [N]
};

class OutputErrorModulusObjective : public ModulusObjective {
 public:
  // Keeps references to model and data, which must outlive the objective.
  // misfit_levels and theta: as MatrixOutputErrorObjective's; modulus_scale > 0 [Pa].
  OutputErrorModulusObjective(const MatrixModelData& model, const ChannelSet& data,
                              const NoiseLevels& misfit_levels, double theta, double modulus_scale);

  double modulus_scale() const override { return modulus_scale_; }
  // cost = J(E) / cost_scale(), gradient = dJ/dE modulus_scale / cost_scale() at
  // E = x modulus_scale. False when x is not a positive finite number or J is not
  // finite (the reason in error_message()).
  bool Evaluate(const double* parameters, double* cost, double* gradient) override;
  std::string error_message() const override { return error_message_; }
  std::unique_ptr<ModulusObjective> CloneForScan(double inner_tolerance) const override;
  long sweeps() const override { return objective_.sweeps(); }
  // From the outputs and reactions at E = modulus_scale, each row weighted by 1 / s^2
  // of its kind: one sweep.
  double ValleySpacing() override;

  // J, its outputs and reactions at E [Pa] (> 0), and dJ/dE with the Fisher
  // information when gradient_requested.
  const OutputErrorFit& Predict(double modulus, bool gradient_requested);

  // How dJ/dE = sum_z dJ/dE_z is computed (MatrixOutputErrorObjective::SetGradientMethod;
  // the Fisher information of Predict always by the sensitivities); clones for the
  // scan take it too.
  void SetGradientMethod(LeastSquaresGradient method) { objective_.SetGradientMethod(method); }

  // J_rest [s]; the cost scale (1 when J_rest = 0).
  double rest_cost() const { return objective_.rest_cost(); }
  double cost_scale() const { return objective_.cost_scale(); }

 private:
  // J at E [Pa] into fit_.cost, and dJ/dE (with gradient_requested) and the Fisher
  // information (with information_requested, which needs the gradient) into fit_; the
  // outputs stay in objective_ (Predict copies them, an evaluation does not).
  void Solve(double modulus, bool gradient_requested, bool information_requested);

  const MatrixModelData& model_;
  const ChannelSet& data_;
  NoiseLevels misfit_levels_;
  double theta_;
  double modulus_scale_;
  MatrixOutputErrorObjective objective_;
  Vector gradient_;
  Matrix information_;
  OutputErrorFit fit_;
  std::string error_message_;
};

}  // namespace mcrewave
