// The sparse path of the theta integrator (linalg/sparse_theta_step.h) against the
// band path on the bar, against dense linear algebra on a random SPD system, and its
// order of convergence on a 2-D mass-spring lattice.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {
namespace {

TEST(FactorizationTest, NamesRoundTrip) {
  for (const Factorization f :
       {Factorization::kAutomatic, Factorization::kBand, Factorization::kSparse}) {
    Factorization back = Factorization::kAutomatic;
    ASSERT_TRUE(StringToFactorization(FactorizationToString(f), &back));
    EXPECT_EQ(back, f);
  }
  Factorization unchanged = Factorization::kBand;
  EXPECT_FALSE(StringToFactorization("cholmod", &unchanged));
  EXPECT_EQ(unchanged, Factorization::kBand);
}

// A scalar mass-spring lattice of nx x ny nodes numbered row by row (half bandwidth
// nx): unit springs between neighbours, a spring to the ground at the nodes of the
// first column (so K is positive definite), lumped unit masses.
struct Lattice {
  SparseMatrix mass, stiffness;
};

Lattice MakeLattice(int nx, int ny, double spring, double mass) {
  const int n = nx * ny;
  std::vector<Eigen::Triplet<double>> k;
  auto add_spring = [&](int a, int b) {
    k.emplace_back(a, a, spring);
    k.emplace_back(b, b, spring);
    k.emplace_back(a, b, -spring);
    k.emplace_back(b, a, -spring);
  };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int node = j * nx + i;
      if (i + 1 < nx) add_spring(node, node + 1);
      if (j + 1 < ny) add_spring(node, node + nx);
      if (i == 0) k.emplace_back(node, node, spring);
    }
  }
  Lattice lattice;
  lattice.stiffness.resize(n, n);
  lattice.stiffness.setFromTriplets(k.begin(), k.end());
  lattice.mass.resize(n, n);
  lattice.mass.setIdentity();
  lattice.mass *= mass;
  return lattice;
}

TEST(SparseThetaStepTest, AutomaticChoiceFollowsTheBandwidth) {
  BarProperties bar;
  bar.elements = 50;
  const BarModel model(bar);
  EXPECT_EQ(ChooseFactorization(Factorization::kAutomatic, model.mass(), model.Stiffness(1.0)),
            Factorization::kBand);
  const Lattice wide = MakeLattice(40, 10, 1.0, 1.0);
  EXPECT_EQ(HalfBandwidth(wide.stiffness), 40);
  EXPECT_EQ(ChooseFactorization(Factorization::kAutomatic, wide.mass, wide.stiffness),
            Factorization::kSparse);
  EXPECT_EQ(ChooseFactorization(Factorization::kBand, wide.mass, wide.stiffness),
            Factorization::kBand);
  ThetaIntegratorOptions options;
  options.time_step = 0.1;
  ThetaIntegrator integrator;
  integrator.Init(wide.mass, wide.stiffness, options);
  EXPECT_EQ(integrator.factorization(), Factorization::kSparse);
  EXPECT_EQ(integrator.size(), 400);
  integrator.Init(model.mass(), model.Stiffness(200e9), ThetaIntegratorOptions());
  EXPECT_EQ(integrator.factorization(), Factorization::kBand);
  EXPECT_EQ(integrator.size(), 51);
}

// Runs `steps` steps of the bar hit at x = L, with every kind of input (end loads, a
// shift z, point loads, a force vector), on one path; returns the displacements.
Matrix RunBar(const BarModel& model, const SparseMatrix& stiffness, Factorization factorization,
              int steps) {
  ThetaIntegratorOptions options;
  options.time_step = 0.36e-6;
  options.factorization = factorization;
  ThetaIntegrator integrator;
  integrator.Init(model.mass(), stiffness, options);
  EXPECT_EQ(integrator.factorization(), factorization);
  const int n = integrator.size();
  Matrix u = Matrix::Zero(n, steps + 1);
  Vector v = Vector::Zero(n), v_next(n), u_next(n), force = Vector::Zero(n);
  const Vector shift = Vector::LinSpaced(n, 0.0, 1e-9);  // z [m]
  const int nodes[2] = {n / 3, n / 2};
  for (int k = 0; k < steps; ++k) {
    const double load = 1000.0 * std::sin(M_PI * std::min(1.0, k / 250.0));  // [N]
    const double values[2] = {0.1 * load, -0.2 * load};
    const PointLoads point_loads{2, nodes, values};
    switch (k % 4) {
      case 0:
        integrator.StepWithEndLoads(v, u.col(k), 0.5 * load, -load, v_next, u_next, &point_loads);
        break;
      case 1:
        integrator.StepWithEndLoads(v, u.col(k), shift, 0.0, -load, v_next, u_next, &point_loads);
        break;
      case 2:
        force.setZero();
        force[n - 1] = -load;
        force[n / 4] = 0.3 * load;
        integrator.Step(v, u.col(k), force, v_next, u_next);
        break;
      default:
        integrator.StepShifted(v, u.col(k), shift, force, v_next, u_next);
        break;
    }
    v = v_next;
    u.col(k + 1) = u_next;
  }
  return u;
}

TEST(SparseThetaStepTest, EqualsTheBandPathOnTheBarToRoundOff) {
  BarProperties bar;
  bar.elements = 100;
  const BarModel model(bar);
  constexpr int kSteps = 2000;
  // Tridiagonal (the twisted fast path) and a half bandwidth of 2 (the band LDL^T).
  SparseMatrix wider = model.Stiffness(200e9);
  for (int i = 0; i + 2 < model.num_nodes(); ++i) {
    const double k = 0.05 * wider.coeff(i, i);
    wider.coeffRef(i, i) += k;
    wider.coeffRef(i + 2, i + 2) += k;
    wider.coeffRef(i, i + 2) -= k;
    wider.coeffRef(i + 2, i) -= k;
  }
  for (const SparseMatrix& stiffness : {model.Stiffness(200e9), wider}) {
    const Matrix band = RunBar(model, stiffness, Factorization::kBand, kSteps);
    const Matrix sparse = RunBar(model, stiffness, Factorization::kSparse, kSteps);
    // After 10 steps the two paths agree to a few ulps of the state (measured 8.7e-17
    // and 3.9e-16 of max |u_10|); the difference then grows with the steps' round-off.
    const double early =
        (band.col(10) - sparse.col(10)).cwiseAbs().maxCoeff() / band.col(10).cwiseAbs().maxCoeff();
    EXPECT_LT(early, 4e-15);
    const double scale = band.cwiseAbs().maxCoeff();
    const double difference = (band - sparse).cwiseAbs().maxCoeff() / scale;
    // Measured after 2000 steps: 1.0e-13 (against the twisted tridiagonal solve) and
    // 2.5e-11 (against the band LDL^T, half bandwidth 2); tolerances 10 times that.
    EXPECT_LT(difference, HalfBandwidth(stiffness) == 1 ? 1e-12 : 2.5e-10)
        << HalfBandwidth(stiffness);
    RecordProperty(HalfBandwidth(stiffness) == 1 ? "tridiagonal" : "band2",
                   std::to_string(difference));
    std::printf("sparse vs band, half bandwidth %d: max |u_sparse - u_band| / max |u| = %.2e\n",
                HalfBandwidth(stiffness), difference);
  }
}

// A random sparse SPD M and symmetric positive semi-definite K.
Lattice RandomSystem(int n, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> index(0, n - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> m, k;
  for (int e = 0; e < 3 * n; ++e) {
    const int a = index(generator), b = index(generator);
    if (a == b) continue;
    // A spring between a and b (PSD), a coupling mass (diagonally dominant below).
    const double spring = 1.0 + value(generator), coupling = 0.2 * value(generator);
    k.emplace_back(a, a, spring);
    k.emplace_back(b, b, spring);
    k.emplace_back(a, b, -spring);
    k.emplace_back(b, a, -spring);
    m.emplace_back(a, b, coupling);
    m.emplace_back(b, a, coupling);
    m.emplace_back(a, a, std::abs(coupling) + 0.01);
    m.emplace_back(b, b, std::abs(coupling) + 0.01);
  }
  Lattice system;
  system.mass.resize(n, n);
  system.mass.setFromTriplets(m.begin(), m.end());
  system.stiffness.resize(n, n);
  system.stiffness.setFromTriplets(k.begin(), k.end());
  return system;
}

TEST(SparseThetaStepTest, OneStepOnARandomSparseSystemEqualsDenseAlgebra) {
  constexpr int kSize = 300;
  const Lattice system = RandomSystem(kSize, 7u);
  const double h = 0.3, theta = 0.6;
  ThetaIntegratorOptions options;
  options.time_step = h;
  options.theta = theta;
  options.factorization = Factorization::kSparse;
  ThetaIntegrator integrator;
  integrator.Init(system.mass, system.stiffness, options);
  std::mt19937 generator(3u);
  std::normal_distribution<double> normal;
  Vector v(kSize), u(kSize), z(kSize), f(kSize);
  for (int i = 0; i < kSize; ++i) {
    v[i] = normal(generator);
    u[i] = normal(generator);
    z[i] = normal(generator);
    f[i] = normal(generator);
  }
  Vector v_next(kSize), u_next(kSize);
  integrator.StepShifted(v, u, z, f, v_next, u_next);
  const Matrix m = Matrix(system.mass), k = Matrix(system.stiffness);
  const Matrix s = m + h * h * theta * theta * k;
  const Vector rhs = (m - h * h * theta * (1.0 - theta) * k) * v - h * k * (u + z) + h * f;
  const Vector v_expected = s.ldlt().solve(rhs);
  const Vector u_expected = u + h * (1.0 - theta) * v + h * theta * v_expected;
  EXPECT_LT((v_next - v_expected).norm() / v_expected.norm(), 1e-12);
  EXPECT_LT((u_next - u_expected).norm() / u_expected.norm(), 1e-12);
  // A new K of the same pattern: one numeric factorisation, no new analysis.
  integrator.Init(system.mass, 2.0 * system.stiffness, options);
  EXPECT_EQ(integrator.sparse().analysis_count(), 1);
  EXPECT_GT(integrator.sparse().factor_nonzeros(), kSize);
}

TEST(SparseThetaStepTest, RefusesAnIterationMatrixThatIsNotPositiveDefinite) {
  const Lattice system = RandomSystem(50, 9u);
  ThetaIntegratorOptions options;
  options.time_step = 0.1;
  options.factorization = Factorization::kSparse;
  ThetaIntegrator integrator;
  const SparseMatrix negative_mass = -system.mass;
  EXPECT_THROW(integrator.Init(negative_mass, system.stiffness, options), std::runtime_error);
}

// Second order at theta = 1/2: a 12 x 9 lattice (108 dofs) from a smooth initial
// displacement under a smooth force, to T = 4 s, against the same scheme at h / 64.
TEST(SparseThetaStepTest, ConvergesAtOrderTwoOnALattice) {
  const Lattice lattice = MakeLattice(12, 9, 1.0, 1.0);
  constexpr int n = 12 * 9;
  constexpr double kEnd = 4.0;
  Vector u0(n);
  for (int j = 0; j < 9; ++j) {
    for (int i = 0; i < 12; ++i) u0[j * 12 + i] = std::sin(M_PI * i / 11.0) * std::cos(0.3 * j);
  }
  auto force = [](double t) {
    Vector f = Vector::Zero(n);
    f[n - 1] = std::sin(2.0 * t);
    f[n / 2] = 0.5 * std::cos(t);
    return f;
  };
  auto run = [&](int steps) {
    ThetaIntegratorOptions options;
    options.time_step = kEnd / steps;
    options.factorization = Factorization::kSparse;
    ThetaIntegrator integrator;
    integrator.Init(lattice.mass, lattice.stiffness, options);
    Vector v = Vector::Zero(n), u = u0, v_next(n), u_next(n);
    for (int k = 0; k < steps; ++k) {
      const double h = options.time_step;
      const Vector f = 0.5 * (force(k * h) + force((k + 1) * h));
      integrator.Step(v, u, f, v_next, u_next);
      v = v_next;
      u = u_next;
    }
    return u;
  };
  const Vector reference = run(40 * 64);
  const double e1 = (run(40) - reference).norm(), e2 = (run(80) - reference).norm(),
               e3 = (run(160) - reference).norm();
  const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e3);
  std::printf("lattice: errors %.3e %.3e %.3e, orders %.3f %.3f\n", e1, e2, e3, order1, order2);
  EXPECT_NEAR(order1, 2.0, 0.1);
  EXPECT_NEAR(order2, 2.0, 0.05);
}

}  // namespace
}  // namespace mcrewave
