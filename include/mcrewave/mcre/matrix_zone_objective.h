// The MCRE cost of a structure given by matrices as a function of its zone moduli
// (docs/matrix_models.md), for MinimizeWithinBounds (optim/bounded_minimizer.h): the
// parameters are p_z = log(E_z / E_z,nom), so that a step in p is a relative step in E
// and positivity comes free, and
//
//   cost = e^2(E) / J_rest,   d cost / d p_z = (de^2/dE_z) E_z / J_rest,
//
// with de^2/dE_z from the one coupled solve (MatrixMcreProblem::CostGradients) and
// J_rest = MatrixMcreProblem::RestCost(), the functional of the structure left at rest
// (0 <= e^2 <= J_rest). Each solve starts from the previous usable one's W, or its
// traces after a streaming solve (warm start). A solve that is not usable makes
// Evaluate return false with the solver's report; nothing is thrown.
#pragma once

#include <string>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/optim/bounded_minimizer.h"

namespace mcrewave {

class MatrixZoneObjective : public MultiParameterObjective {
 public:
  // problem must outlive the objective; inner is the coupled solver of every
  // evaluation (an iterative one or all_at_once). Precondition: inner.IsValid().
  MatrixZoneObjective(MatrixMcreProblem* problem, const CoupledSolverOptions& inner);

  int num_parameters() const override { return problem_->num_zones(); }
  bool Evaluate(const double* p, double* cost, double* gradient) override;
  std::string error_message() const override { return error_message_; }

  // E_z = E_z,nom exp(p_z) [Pa].
  Vector Moduli(const double* p) const;
  // The cost scale J_rest [J s] (1 when the data are all zero).
  double cost_scale() const { return cost_scale_; }
  int evaluations() const { return evaluations_; }
  // The last usable solve (its moduli are the problem's current ones after it).
  const CoupledSolution& last_solution() const { return solution_; }

 private:
  MatrixMcreProblem* problem_;
  CoupledSolverOptions inner_;
  Vector nominal_;  // E_z,nom [Pa]
  double cost_scale_;
  CoupledSolution solution_;
  Matrix warm_start_;
  int evaluations_ = 0;
  std::string error_message_;
};

}  // namespace mcrewave
