// LogModuliObjective (optim/log_moduli_objective.h) on a closed-form cost of the moduli:
// the map p -> E, the scaled cost and its gradient in p against central differences,
// and every way an evaluation can fail.
#include "mcrewave/optim/log_moduli_objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace mcrewave {
namespace {

// J(E) = sum_z (E_z / T_z - 1)^2 [-] with T = (2e11, 1.5e11) Pa, J_scale = 4; fails
// on request, or returns NaN.
class QuadraticModuliCost : public LogModuliObjective {
 public:
  QuadraticModuliCost() : LogModuliObjective((Vector(2) << 2e11, 1e11).finished()) {}
  double cost_scale() const override { return 4.0; }
  bool fail = false;
  bool not_a_number = false;
  int reported = 0;
  double reported_gradient_norm = -1.0;

 protected:
  bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient, std::string* why) override {
    if (fail) {
      *why = "no solve at evaluation " + std::to_string(evaluations());
      return false;
    }
    const Vector target = (Vector(2) << 2e11, 1.5e11).finished();
    const Vector ratio = moduli.cwiseQuotient(target);
    *cost = not_a_number ? std::numeric_limits<double>::quiet_NaN()
                         : (ratio.array() - 1.0).square().sum();
    if (gradient != nullptr) {
      *gradient = (2.0 * (ratio.array() - 1.0) / target.array()).matrix();
    }
    return true;
  }
  void OnEvaluated(const Vector& moduli, double cost, double gradient_norm) override {
    (void)moduli;
    (void)cost;
    ++reported;
    reported_gradient_norm = gradient_norm;
  }
};

TEST(LogModuliObjectiveTest, ModuliAreTheReferenceTimesTheExponentialOfP) {
  QuadraticModuliCost objective;
  const double p[2] = {0.0, std::log(1.5)};
  const Vector moduli = objective.Moduli(p);
  EXPECT_EQ(objective.num_parameters(), 2);
  EXPECT_EQ(moduli[0], 2e11);
  EXPECT_NEAR(moduli[1], 1.5e11, 1e-4);
}

TEST(LogModuliObjectiveTest, ScaledCostAndItsGradientInPMatchCentralDifferences) {
  QuadraticModuliCost objective;
  const double p[2] = {0.1, 0.2};
  double cost = 0.0, gradient[2] = {0.0, 0.0};
  ASSERT_TRUE(objective.Evaluate(p, &cost, gradient)) << objective.error_message();
  // J / J_scale at E = (2e11 e^0.1, 1e11 e^0.2).
  const double r0 = std::exp(0.1) - 1.0, r1 = 1e11 * std::exp(0.2) / 1.5e11 - 1.0;
  EXPECT_NEAR(cost, (r0 * r0 + r1 * r1) / 4.0, 1e-15);
  const double step = 1e-6;
  for (int z = 0; z < 2; ++z) {
    double plus[2] = {p[0], p[1]}, minus[2] = {p[0], p[1]};
    plus[z] += step;
    minus[z] -= step;
    double cost_plus = 0.0, cost_minus = 0.0;
    ASSERT_TRUE(objective.Evaluate(plus, &cost_plus, nullptr));
    ASSERT_TRUE(objective.Evaluate(minus, &cost_minus, nullptr));
    // Central differences with a step of 1e-6: 2.8e-12 and 3.6e-12 off, measured.
    EXPECT_NEAR(gradient[z], (cost_plus - cost_minus) / (2.0 * step), 3e-11);
  }
  EXPECT_EQ(objective.evaluations(), 5);
  EXPECT_EQ(objective.reported, 5);
  // Without the gradient the reported norm is 0.
  EXPECT_EQ(objective.reported_gradient_norm, 0.0);
}

TEST(LogModuliObjectiveTest, AModulusOutOfRangeIsRefusedBeforeTheCost) {
  QuadraticModuliCost objective;
  const double p[2] = {1e6, 0.0};  // exp overflows: E is infinite
  double cost = 0.0;
  EXPECT_FALSE(objective.Evaluate(p, &cost, nullptr));
  EXPECT_NE(objective.error_message().find("not a positive finite number"), std::string::npos);
  EXPECT_EQ(objective.reported, 0);
}

TEST(LogModuliObjectiveTest, AFailedCostKeepsItsReasonAndASuccessClearsIt) {
  QuadraticModuliCost objective;
  const double p[2] = {0.0, 0.0};
  double cost = 0.0;
  objective.fail = true;
  EXPECT_FALSE(objective.Evaluate(p, &cost, nullptr));
  EXPECT_EQ(objective.error_message(), "no solve at evaluation 1");
  objective.fail = false;
  EXPECT_TRUE(objective.Evaluate(p, &cost, nullptr));
  EXPECT_EQ(objective.error_message(), "");
  EXPECT_EQ(objective.reported, 1);
}

TEST(LogModuliObjectiveTest, ANonFiniteCostIsAFailureNotANumber) {
  QuadraticModuliCost objective;
  objective.not_a_number = true;
  const double p[2] = {0.0, 0.0};
  double cost = 0.0;
  EXPECT_FALSE(objective.Evaluate(p, &cost, nullptr));
  EXPECT_NE(objective.error_message().find("evaluation 1 is not finite"), std::string::npos);
  EXPECT_EQ(objective.reported, 0);
}

}  // namespace
}  // namespace mcrewave
