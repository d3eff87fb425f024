// A cost of zone moduli seen by the optimisers (bounded_minimizer.h) as a function of
// p_z = log(E_z / E_z,ref), so that a step in p is a relative step in E and positivity
// comes free:
//
//   cost = J(E) / J_scale,   d cost / d p_z = (dJ/dE_z) E_z / J_scale,
//
// J_scale the cost of the structure at rest (the data's own scale). One Evaluate for
// every zone objective (the MCRE's and least squares', on the bar and on matrices):
// a derived class gives J and dJ/dE through ModuliCost, and this class maps the
// parameters, checks that the moduli and the results are finite, and scales.
#pragma once

#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/optim/first_order_objective.h"

namespace mcrewave {

class LogModuliObjective : public FirstOrderObjective {
 public:
  // reference_moduli: E_z,ref [Pa], one per zone, positive and finite.
  explicit LogModuliObjective(Vector reference_moduli);

  int num_parameters() const final { return static_cast<int>(reference_moduli_.size()); }
  // cost = J / cost_scale() and, when gradient is not null, d cost / d p_z. False when
  // a modulus is not a finite positive number, ModuliCost fails, or J or its gradient
  // is not finite (the reason in error_message()). Never throws for a failed solve.
  bool Evaluate(const double* p, double* cost, double* gradient) final;
  std::string error_message() const final { return error_message_; }

  // E_z = E_z,ref exp(p_z) [Pa].
  Vector Moduli(const double* p) const;
  const Vector& reference_moduli() const { return reference_moduli_; }
  // Evaluate calls so far, failed ones included.
  int evaluations() const { return evaluations_; }
  // J_scale, positive.
  virtual double cost_scale() const = 0;

 protected:
  // J at the zone moduli into *cost and, when gradient is not null, dJ/dE_z into
  // *gradient (resized to the zones). False with the reason in *why when the value
  // cannot be had (evaluations() already counts this evaluation).
  virtual bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient,
                          std::string* why) = 0;
  // Called after every usable evaluation with its moduli, scaled cost and
  // max_z |d cost / d p_z| (0 without the gradient); nothing by default.
  virtual void OnEvaluated(const Vector& moduli, double cost, double gradient_norm) {
    (void)moduli;
    (void)cost;
    (void)gradient_norm;
  }

 private:
  Vector reference_moduli_;
  int evaluations_ = 0;
  std::string error_message_;
};

}  // namespace mcrewave
