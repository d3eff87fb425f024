// The MCRE cost of a structure given by matrices as a function of its zone moduli
// (docs/matrix_models.md), for MinimizeWithinBounds (optim/bounded_minimizer.h), in
// p_z = log(E_z / E_z,nom) (optim/log_moduli_objective.h): J = e^2 with de^2/dE_z from
// the one coupled solve (MatrixMcreProblem::CostGradients), and J_scale =
// MatrixMcreProblem::RestCost(), the functional of the structure left at rest
// (0 <= e^2 <= J_rest). Each solve starts from the previous usable one's W, or its
// traces after a streaming solve (warm start). A solve that is not usable makes
// Evaluate return false with the solver's report; nothing is thrown.
#pragma once

#include <string>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/optim/log_moduli_objective.h"

namespace mcrewave {

class MatrixZoneObjective : public LogModuliObjective {
 public:
  // problem must outlive the objective; inner is the coupled solver of every
  // evaluation (an iterative one or all_at_once). Precondition: inner.IsValid().
  MatrixZoneObjective(MatrixMcreProblem* problem, const CoupledSolverOptions& inner);

  // The cost scale J_rest [J s] (1 when the data are all zero).
  double cost_scale() const override { return cost_scale_; }
  // The last usable solve (its moduli are the problem's current ones after it).
  const CoupledSolution& last_solution() const { return solution_; }

 protected:
  bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient, std::string* why) override;

 private:
  MatrixMcreProblem* problem_;
  CoupledSolverOptions inner_;
  double cost_scale_;
  CoupledSolution solution_;
  Matrix warm_start_;
};

}  // namespace mcrewave
