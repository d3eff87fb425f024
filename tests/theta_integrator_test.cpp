// ThetaIntegrator: options, convergence order, agreement with a plain first-order
// theta integrator on the full state, time reversal and factorisation count.
#include "mcrewave/linalg/theta_integrator.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mcrewave/model/bar_model.h"

namespace mcrewave {
namespace {

// Least-squares slope of log(error) against log(step).
double LogLogSlope(const std::vector<double>& steps, const std::vector<double>& errors) {
  const int n = static_cast<int>(steps.size());
  double mean_x = 0.0, mean_y = 0.0;
  for (int i = 0; i < n; ++i) {
    mean_x += std::log(steps[i]) / n;
    mean_y += std::log(errors[i]) / n;
  }
  double sxy = 0.0, sxx = 0.0;
  for (int i = 0; i < n; ++i) {
    const double dx = std::log(steps[i]) - mean_x;
    sxy += dx * (std::log(errors[i]) - mean_y);
    sxx += dx * dx;
  }
  return sxy / sxx;
}

TEST(ThetaIntegratorOptionsTest, DefaultOptionsAreValid) {
  std::string error;
  EXPECT_TRUE(ThetaIntegratorOptions().IsValid(&error)) << error;
}

TEST(ThetaIntegratorOptionsTest, InvalidOptionsAreRejected) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // (time step, theta) pairs.
  const std::vector<std::pair<double, double>> invalid{
      {1e-6, 1.5}, {1e-6, -0.1}, {0.0, 0.5}, {-1e-6, 0.5}, {nan, 0.5}, {1e-6, nan}, {inf, 0.5}};
  for (const auto& [step, theta] : invalid) {
    ThetaIntegratorOptions options;
    options.time_step = step;
    options.theta = theta;
    std::string error;
    EXPECT_FALSE(options.IsValid(&error)) << "step " << step << ", theta " << theta;
    EXPECT_FALSE(error.empty());
  }
  // The bounds of [0, 1] are valid.
  ThetaIntegratorOptions bounds;
  bounds.theta = 0.0;
  EXPECT_TRUE(bounds.IsValid(nullptr));
  bounds.theta = 1.0;
  EXPECT_TRUE(bounds.IsValid(nullptr));
}

// Undamped 2-dof oscillator M u'' + K u = (p sin(Omega t), 0), u(0) = u'(0) = 0, with
// M = m I and K = k [2 -1; -1 2]. With u = a (1, 1) + b (1, -1) the two rows decouple:
//   a'' + omega_1^2 a = p sin(Omega t) / (2 m),  omega_1^2 = k / m,
//   b'' + omega_2^2 b = p sin(Omega t) / (2 m),  omega_2^2 = 3 k / m,
// and y'' + omega^2 y = g sin(Omega t) from rest is
//   y(t) = g / (omega^2 - Omega^2) (sin(Omega t) - (Omega / omega) sin(omega t)).
// Returns the largest |u_k - u(t_k)| over one second with num_steps steps, scaled by the
// static displacement p / k.
double OscillatorError(double theta, int num_steps) {
  const double mass = 2.0, stiffness = 2.0 * 4.0 * M_PI * M_PI;  // omega_1 = 2 pi
  const double amplitude = 3.0, frequency = 3.0;                 // p, Omega
  const double h = 1.0 / num_steps;
  SparseMatrix mass_matrix(2, 2), stiffness_matrix(2, 2);
  std::vector<Eigen::Triplet<double>> m_entries{{0, 0, mass}, {1, 1, mass}};
  std::vector<Eigen::Triplet<double>> k_entries{
      {0, 0, 2.0 * stiffness}, {1, 1, 2.0 * stiffness}, {0, 1, -stiffness}, {1, 0, -stiffness}};
  mass_matrix.setFromTriplets(m_entries.begin(), m_entries.end());
  stiffness_matrix.setFromTriplets(k_entries.begin(), k_entries.end());
  ThetaIntegratorOptions options;
  options.time_step = h;
  options.theta = theta;
  ThetaIntegrator integrator;
  integrator.Init(mass_matrix, stiffness_matrix, options);

  auto force = [&](double t) { return amplitude * std::sin(frequency * t); };
  auto modal_response = [&](double omega_squared, double t) {
    const double g = amplitude / (2.0 * mass);
    return g / (omega_squared - frequency * frequency) *
           (std::sin(frequency * t) -
            frequency / std::sqrt(omega_squared) * std::sin(std::sqrt(omega_squared) * t));
  };
  double max_error = 0.0;
  const Vector zero = Vector::Zero(2);
  integrator.SweepForward(
      num_steps, zero, zero,
      [&](int k, Eigen::Ref<Vector> f) {
        // f_theta = theta f(t_{k+1}) + (1 - theta) f(t_k).
        f[0] = theta * force((k + 1) * h) + (1.0 - theta) * force(k * h);
        f[1] = 0.0;
      },
      [&](int k, const Vector& /*velocity*/, const Vector& displacement) {
        const double t = k * h;
        const double a = modal_response(stiffness / mass, t);
        const double b = modal_response(3.0 * stiffness / mass, t);
        // u = a (1, 1) + b (1, -1).
        max_error = std::max(
            {max_error, std::abs(displacement[0] - (a + b)), std::abs(displacement[1] - (a - b))});
      });
  return max_error / (amplitude / stiffness);
}

TEST(ThetaIntegratorTest, ConvergesAtOrderOneForBackwardEulerAndTwoForTrapezoidal) {
  for (const auto& [theta, low, high] :
       std::vector<std::tuple<double, double, double>>{{1.0, 0.9, 1.1}, {0.5, 1.9, 2.1}}) {
    std::vector<double> steps, errors;
    for (int num_steps = 200; num_steps <= 6400; num_steps *= 2) {
      steps.push_back(1.0 / num_steps);
      errors.push_back(OscillatorError(theta, num_steps));
    }
    const double order = LogLogSlope(steps, errors);
    RecordProperty(theta == 1.0 ? "order_theta_1" : "order_theta_half", std::to_string(order));
    EXPECT_GE(order, low) << "theta = " << theta;
    EXPECT_LE(order, high) << "theta = " << theta;
    // And it converges to the exact solution, not to something else.
    EXPECT_LT(errors.back(), theta == 1.0 ? 1e-2 : 1e-5) << "theta = " << theta;
  }
}

// The textbook theta method on the full first-order state x = (v, u):
//   Mx = diag(M, I), A = [0 -K; I 0], b = (f_theta, 0),
//   (Mx - h theta A) x_{k+1} = (Mx + h (1 - theta) A) x_k + h b,
// with W = Mx - h theta A factorised by a dense partial-pivoting LU.
class DenseFirstOrderTheta {
 public:
  DenseFirstOrderTheta(const Matrix& mass, const Matrix& stiffness, double h, double theta)
      : n_(static_cast<int>(mass.rows())), h_(h) {
    Matrix mass_x = Matrix::Zero(2 * n_, 2 * n_);
    mass_x.topLeftCorner(n_, n_) = mass;
    mass_x.bottomRightCorner(n_, n_).setIdentity();
    Matrix a = Matrix::Zero(2 * n_, 2 * n_);
    a.topRightCorner(n_, n_) = -stiffness;
    a.bottomLeftCorner(n_, n_).setIdentity();
    explicit_part_ = mass_x + h * (1.0 - theta) * a;
    lu_.compute(mass_x - h * theta * a);
  }
  // x = (v, u) -> x_{k+1}.
  Vector Step(const Vector& x, const Vector& force_theta) const {
    Vector rhs = explicit_part_ * x;
    rhs.head(n_) += h_ * force_theta;
    return lu_.solve(rhs);
  }

 private:
  int n_;
  double h_;
  Matrix explicit_part_;
  Eigen::PartialPivLU<Matrix> lu_;
};

class ThetaIntegratorBarTest : public ::testing::TestWithParam<std::tuple<double, MassType>> {};

TEST_P(ThetaIntegratorBarTest, MatchesTheDenseFirstOrderIntegrator) {
  const double theta = std::get<0>(GetParam());
  const MassType mass_type = std::get<1>(GetParam());
  BarProperties properties;
  properties.elements = 10;
  properties.mass = mass_type;
  const BarModel model(properties);
  const int n = model.num_nodes();
  const SparseMatrix stiffness = model.Stiffness(properties.modulus);
  const double h = 1e-6;  // about 1/6 of the transit time of one element
  ThetaIntegratorOptions options;
  options.time_step = h;
  options.theta = theta;
  ThetaIntegrator integrator;
  integrator.Init(model.mass(), stiffness, options);
  const DenseFirstOrderTheta reference(Matrix(model.mass()), Matrix(stiffness), h, theta);

  // A non-zero initial state and end forces of both signs (the bar is free).
  const Vector v0 = 0.5 * Vector::LinSpaced(n, -1.0, 1.0);                // [m/s]
  const Vector u0 = 1e-6 * Vector::LinSpaced(n, 0.0, 1.0).array().sin();  // [m]
  auto end_forces = [&](int k, Eigen::Ref<Vector> f) {
    f.setZero();
    f[0] = -300.0 * std::cos(2e4 * k * h);
    f[n - 1] = 1000.0 * std::sin(3e4 * k * h);
  };
  const int num_steps = 200;
  std::vector<Vector> velocities, displacements;
  Vector f(n);
  integrator.SweepForward(
      num_steps, v0, u0,
      [&](int k, Eigen::Ref<Vector> force) {
        // f_theta = theta f(t_{k+1}) + (1 - theta) f(t_k).
        Vector next(n);
        end_forces(k + 1, next);
        end_forces(k, force);
        force = theta * next + (1.0 - theta) * force;
      },
      [&](int /*k*/, const Vector& v, const Vector& u) {
        velocities.push_back(v);
        displacements.push_back(u);
      });
  ASSERT_EQ(static_cast<int>(displacements.size()), num_steps + 1);

  Vector x(2 * n);
  x << v0, u0;
  double max_v = 0.0, max_u = 0.0, max_v_error = 0.0, max_u_error = 0.0;
  for (int k = 0; k < num_steps; ++k) {
    Vector next(n);
    end_forces(k + 1, next);
    end_forces(k, f);
    x = reference.Step(x, theta * next + (1.0 - theta) * f);
    max_v = std::max(max_v, x.head(n).lpNorm<Eigen::Infinity>());
    max_u = std::max(max_u, x.tail(n).lpNorm<Eigen::Infinity>());
    max_v_error = std::max(max_v_error, (velocities[k + 1] - x.head(n)).lpNorm<Eigen::Infinity>());
    max_u_error =
        std::max(max_u_error, (displacements[k + 1] - x.tail(n)).lpNorm<Eigen::Infinity>());
  }
  EXPECT_LT(max_v_error, 1e-12 * max_v);
  EXPECT_LT(max_u_error, 1e-12 * max_u);
}

INSTANTIATE_TEST_SUITE_P(ThetaAndMass, ThetaIntegratorBarTest,
                         ::testing::Combine(::testing::Values(0.5, 0.75, 1.0),
                                            ::testing::Values(MassType::kConsistent,
                                                              MassType::kLumped)));

// Runs the bar forward from a non-zero state, then backward from the final state with
// the velocity sign flipped (SweepBackward carries du/dtau = -du/dt) and the forcing of
// the reversed step, and returns the largest relative difference between the two
// trajectories (displacements, and velocities with the sign restored).
double TimeReversalMismatch(double theta) {
  BarProperties properties;
  properties.elements = 20;
  const BarModel model(properties);
  const int n = model.num_nodes();
  ThetaIntegratorOptions options;
  options.time_step = 0.5e-6;
  options.theta = theta;
  ThetaIntegrator integrator;
  integrator.Init(model.mass(), model.Stiffness(properties.modulus), options);
  auto end_force = [&](int k) { return 800.0 * std::sin(4e4 * k * options.time_step); };
  const int num_steps = 300;
  std::vector<Vector> forward_v(num_steps + 1), forward_u(num_steps + 1);
  const Vector u0 = 1e-6 * Vector::LinSpaced(n, 0.0, 3.0).array().cos();
  const Vector v0 = Vector::Zero(n);
  integrator.SweepForward(
      num_steps, v0, u0,
      [&](int k, Eigen::Ref<Vector> f) {
        f.setZero();
        // Step t_k -> t_{k+1}: f_theta = theta f(t_{k+1}) + (1 - theta) f(t_k).
        f[n - 1] = theta * end_force(k + 1) + (1.0 - theta) * end_force(k);
      },
      [&](int k, const Vector& v, const Vector& u) {
        forward_v[k] = v;
        forward_u[k] = u;
      });
  double v_scale = 0.0, u_scale = 0.0, v_error = 0.0, u_error = 0.0;
  for (int k = 0; k <= num_steps; ++k) {
    v_scale = std::max(v_scale, forward_v[k].lpNorm<Eigen::Infinity>());
    u_scale = std::max(u_scale, forward_u[k].lpNorm<Eigen::Infinity>());
  }
  int observed = 0;
  integrator.SweepBackward(
      num_steps, -forward_v[num_steps], forward_u[num_steps],
      [&](int k, Eigen::Ref<Vector> f) {
        f.setZero();
        // Step t_{k+1} -> t_k, in reversed time tau from T - t_{k+1} to T - t_k:
        // f_theta = theta f(t_k) + (1 - theta) f(t_{k+1}).
        f[n - 1] = theta * end_force(k) + (1.0 - theta) * end_force(k + 1);
      },
      [&](int k, const Vector& v, const Vector& u) {
        ++observed;
        v_error = std::max(v_error, (v + forward_v[k]).lpNorm<Eigen::Infinity>());
        u_error = std::max(u_error, (u - forward_u[k]).lpNorm<Eigen::Infinity>());
      });
  EXPECT_EQ(observed, num_steps + 1);
  return std::max(v_error / v_scale, u_error / u_scale);
}

TEST(ThetaIntegratorTest, BackwardSweepOfTheReversedProblemRetracesTheForwardSweep) {
  // The trapezoidal rule is symmetric in time: the reversed sweep gives the same states.
  EXPECT_LT(TimeReversalMismatch(0.5), 1e-11);
  // Backward Euler is not (reversed, it is forward Euler): the check can fail.
  EXPECT_GT(TimeReversalMismatch(1.0), 1e-3);
}

TEST(ThetaIntegratorTest, FactorisesOncePerInit) {
  const BarModel model{BarProperties{}};
  ThetaIntegrator integrator;
  EXPECT_EQ(integrator.factorization_count(), 0);
  integrator.Init(model.mass(), model.Stiffness(200e9), ThetaIntegratorOptions());
  EXPECT_EQ(integrator.factorization_count(), 1);
  EXPECT_EQ(integrator.size(), model.num_nodes());
  const Vector zero = Vector::Zero(model.num_nodes());
  auto unit_end_force = [](int /*k*/, Eigen::Ref<Vector> f) {
    f.setZero();
    f[f.size() - 1] = 1.0;
  };
  auto ignore = [](int, const Vector&, const Vector&) {};
  for (int sweep = 0; sweep < 3; ++sweep) {
    integrator.SweepForward(50, zero, zero, unit_end_force, ignore);
    integrator.SweepBackward(50, zero, zero, unit_end_force, ignore);
  }
  EXPECT_EQ(integrator.factorization_count(), 1);
  integrator.Init(model.mass(), model.Stiffness(150e9), ThetaIntegratorOptions());
  EXPECT_EQ(integrator.factorization_count(), 2);
}

// A symmetric positive definite n x n matrix of half bandwidth 2 (diagonally dominant):
// a band that is not tridiagonal, for the general band and sparse paths.
SparseMatrix PentadiagonalMatrix(int n, double scale, double coupling) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, scale * (1.0 + 0.1 * (i % 3)));
    for (int d = 1; d <= 2 && i + d < n; ++d) {
      const double value = -coupling * scale / (d + 0.5 * (i % 2));
      entries.emplace_back(i, i + d, value);
      entries.emplace_back(i + d, i, value);
    }
  }
  SparseMatrix matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

// The dot-product test of StepTransposed against Step: for random (v_k, u_k, f) and
// (a_{k+1}, e_{k+1}), a_{k+1}.v_{k+1} + e_{k+1}.u_{k+1} = a_k.v_k + e_k.u_k + h y.f.
// Returns the mismatch relative to the largest of the terms.
double TransposedStepMismatch(const SparseMatrix& mass, const SparseMatrix& stiffness,
                              Factorization factorization, double theta, double time_step) {
  ThetaIntegratorOptions options;
  options.time_step = time_step;
  options.theta = theta;
  options.factorization = factorization;
  ThetaIntegrator integrator;
  integrator.Init(mass, stiffness, options);
  const auto n = static_cast<Eigen::Index>(integrator.size());
  std::srand(7);
  const Vector v = Vector::Random(n), u = Vector::Random(n), f = Vector::Random(n) * 1e3;
  const Vector a_next = Vector::Random(n), e_next = Vector::Random(n) * 1e6;
  Vector v_next(n), u_next(n), y(n), a(n), e(n);
  integrator.Step(v, u, f, v_next, u_next);
  integrator.StepTransposed(a_next, e_next, y, a, e);
  const double left = a_next.dot(v_next) + e_next.dot(u_next);
  const double right = a.dot(v) + e.dot(u) + time_step * y.dot(f);
  const double scale = std::max({std::abs(a_next.dot(v_next)), std::abs(e_next.dot(u_next)),
                                 std::abs(a.dot(v)), std::abs(e.dot(u))});
  return std::abs(left - right) / scale;
}

TEST(ThetaIntegratorTest, TransposedStepIsTheAdjointOfTheStepOnEveryPath) {
  // Measured: at most 3.0e-15 (the sparse path, theta 1/2), 0 to 2.2e-15 elsewhere.
  const BarModel bar{BarProperties{}};
  const SparseMatrix mass = PentadiagonalMatrix(40, 1.0, 0.2);
  const SparseMatrix stiffness = PentadiagonalMatrix(40, 4e6, 0.4);
  for (const double theta : {0.5, 0.75, 1.0}) {
    SCOPED_TRACE(theta);
    EXPECT_LT(TransposedStepMismatch(bar.mass(), bar.Stiffness(200e9), Factorization::kBand, theta,
                                     0.36e-6),
              1e-14);
    EXPECT_LT(TransposedStepMismatch(mass, stiffness, Factorization::kBand, theta, 1e-3), 1e-14);
    EXPECT_LT(TransposedStepMismatch(mass, stiffness, Factorization::kSparse, theta, 1e-3), 1e-14);
  }
}

TEST(ThetaIntegratorTest, InitRejectsAnIndefiniteIterationMatrix) {
  const BarModel model{BarProperties{}};
  ThetaIntegrator integrator;
  const SparseMatrix negative_mass = -model.mass();
  EXPECT_THROW(integrator.Init(negative_mass, model.Stiffness(200e9), ThetaIntegratorOptions()),
               std::runtime_error);
}

}  // namespace
}  // namespace mcrewave
