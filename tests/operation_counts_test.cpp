// Tests of the multiply-accumulate counts: the kernel formulas against their
// closed forms and against reference kernels that count what they execute (band and
// dense kernels, the theta step, the MCRE sweeps and inner product), and
// the Riccati solver's count against its loop structure (exactly affine in the
// number of steps, about 6.3 n^3 per step).
#include "mcrewave/core/operation_counts.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

namespace counts = operation_counts;

TEST(OperationCountsTest, BandKernelsCountEveryStoredEntry) {
  // Tridiagonal: 3n - 2 entries; L has n - 1 entries below the diagonal.
  EXPECT_EQ(counts::BandProduct(10, 1), 28.0);
  EXPECT_EQ(counts::BandSolve(10, 1), 2.0 * 9.0 + 10.0);
  EXPECT_EQ(counts::BandProductAdd(10, 1), 38.0);
  // Pentadiagonal: n + 2 (n - 1) + 2 (n - 2).
  EXPECT_EQ(counts::BandProduct(10, 2), 10.0 + 18.0 + 16.0);
}

TEST(OperationCountsTest, DenseKernelsMatchTheirClosedForms) {
  EXPECT_EQ(counts::LuFactorization(3), 8.0);  // (27 - 3) / 3
  EXPECT_EQ(counts::LuSolve(4, 2), 32.0);
  EXPECT_EQ(counts::DenseProduct(2, 3, 4), 24.0);
  EXPECT_EQ(counts::TriangularSolve(4, 1), 10.0);
  // Householder QR of a square N x N: 2 N^3 / 3 + O(N^2).
  const double n = 300;
  EXPECT_NEAR(counts::HouseholderQr(n, n) / (n * n * n), 2.0 / 3.0, 0.01);
  EXPECT_NEAR(counts::ApplyHouseholderReflectors(n, n, 1) / (n * n), 1.0, 0.01);
}

TEST(OperationCountsTest, RiccatiCountIsAffineInTheStepsWithSixAndAThirdNCubedPerStep) {
  const int elements = 40, n = elements + 1;
  auto riccati_macs = [&](int steps) {
    testing::ProblemBundle bundle(testing::MakeSmallCase(elements, steps, 5.0, 1), McreWeights());
    CoupledSolverOptions options;
    options.type = CoupledSolverType::kRiccati;
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(options, &bundle.problem, nullptr, &solution);
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    return summary.multiply_accumulates;
  };
  const double m10 = riccati_macs(10), m20 = riccati_macs(20), m30 = riccati_macs(30);
  EXPECT_NEAR(m30 - m20, m20 - m10, 1e-9 * m30);
  const double per_step = (m20 - m10) / 10.0;
  const double cube = static_cast<double>(n) * n * n;
  // 6.33 n^3 of dense work and O(n^2) band work on the columns (about 112 n^2).
  EXPECT_GT(per_step, 6.33 * cube);
  EXPECT_LT(per_step, 6.34 * cube + 130.0 * n * n);
}

}  // namespace
}  // namespace mcrewave

namespace mcrewave {
namespace {

// Reference kernels written out loop by loop with a counter: each multiplication
// or division is one MAC, as in operation_counts.h. They compute real results
// (checked against Eigen) and their counts must equal the closed forms for every
// size: a wrong formula fails here.
struct Counter {
  long macs = 0;
  double Multiply(double a, double b) {
    ++macs;
    return a * b;
  }
  double Divide(double a, double b) {
    ++macs;
    return a / b;
  }
};

// A random symmetric positive definite n x n matrix of half bandwidth p.
Eigen::MatrixXd RandomBand(int n, int p, unsigned seed) {
  std::srand(seed);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j <= std::min(n - 1, i + p); ++j) {
      a(i, j) = a(j, i) = std::rand() / (2.0 * RAND_MAX) - 0.25;
    }
    a(i, i) = 2.0 * p + 1.0;
  }
  return a;
}

Eigen::VectorXd CountedBandProduct(const Eigen::MatrixXd& a, int p, const Eigen::VectorXd& x,
                                   Counter* counter) {
  const int n = static_cast<int>(a.rows());
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    for (int j = std::max(0, i - p); j <= std::min(n - 1, i + p); ++j) {
      y[i] += counter->Multiply(a(i, j), x[j]);
    }
  }
  return y;
}

// x = A^-1 b with A = L D L^T (L unit lower of half bandwidth p): forward, scaling,
// backward; only the solve is counted.
Eigen::VectorXd CountedBandSolve(const Eigen::MatrixXd& a, int p, const Eigen::VectorXd& b,
                                 Counter* counter) {
  const int n = static_cast<int>(a.rows());
  Eigen::MatrixXd lower = Eigen::MatrixXd::Identity(n, n);
  Eigen::VectorXd diagonal(n);
  for (int j = 0; j < n; ++j) {
    double d = a(j, j);
    for (int k = std::max(0, j - p); k < j; ++k) d -= lower(j, k) * lower(j, k) * diagonal[k];
    diagonal[j] = d;
    for (int i = j + 1; i <= std::min(n - 1, j + p); ++i) {
      double s = a(i, j);
      for (int k = std::max(0, i - p); k < j; ++k) s -= lower(i, k) * lower(j, k) * diagonal[k];
      lower(i, j) = s / d;
    }
  }
  Eigen::VectorXd x = b;
  for (int i = 0; i < n; ++i) {
    for (int k = std::max(0, i - p); k < i; ++k) x[i] -= counter->Multiply(lower(i, k), x[k]);
  }
  for (int i = 0; i < n; ++i) x[i] = counter->Divide(x[i], diagonal[i]);
  for (int i = n - 1; i >= 0; --i) {
    for (int k = i + 1; k <= std::min(n - 1, i + p); ++k) {
      x[i] -= counter->Multiply(lower(k, i), x[k]);
    }
  }
  return x;
}

TEST(OperationCountsTest, BandKernelsCountedOnRealProductsAndSolves) {
  for (const int n : {1, 2, 5, 9}) {
    for (const int p : {1, 2, 3}) {
      if (p >= n && n > 1) continue;
      const Eigen::MatrixXd a = RandomBand(n, p, 10 * n + p);
      const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
      Counter product;
      // Against Eigen's product and solve: measured 0 (product) and at most 1.5e-16 (solve).
      EXPECT_LT((CountedBandProduct(a, p, x, &product) - a * x).norm(), 2e-15 * (a * x).norm());
      EXPECT_EQ(product.macs, counts::BandProduct(n, std::min(p, n - 1))) << n << ", " << p;
      Counter solve;
      const Eigen::VectorXd solved = CountedBandSolve(a, p, x, &solve);
      EXPECT_LT((a * solved - x).norm(), 2e-15 * x.norm());
      EXPECT_EQ(solve.macs, counts::BandSolve(n, std::min(p, n - 1))) << n << ", " << p;
    }
  }
}

TEST(OperationCountsTest, DenseKernelsCountedOnRealFactorisations) {
  for (const int size : {1, 2, 3, 6, 11}) {
    const Eigen::MatrixXd a =
        Eigen::MatrixXd::Random(size, size) + size * Eigen::MatrixXd::Identity(size, size);
    // LU with partial pivoting (Doolittle, in place): the multipliers and the
    // rank-one updates.
    Counter factorisation;
    Eigen::MatrixXd lu = a;
    std::vector<int> pivots(size);
    for (int k = 0; k < size; ++k) {
      int pivot = k;
      for (int i = k + 1; i < size; ++i) {
        if (std::abs(lu(i, k)) > std::abs(lu(pivot, k))) pivot = i;
      }
      lu.row(k).swap(lu.row(pivot));
      pivots[k] = pivot;
      for (int i = k + 1; i < size; ++i) {
        lu(i, k) = factorisation.Divide(lu(i, k), lu(k, k));
        for (int j = k + 1; j < size; ++j) lu(i, j) -= factorisation.Multiply(lu(i, k), lu(k, j));
      }
    }
    EXPECT_EQ(factorisation.macs, counts::LuFactorization(size)) << size;
    // One right-hand side: forward with the unit lower factor, backward with U.
    Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(size, -1.0, 1.0), x = b;
    for (int k = 0; k < size; ++k) std::swap(x[k], x[pivots[k]]);
    Counter substitution;
    for (int i = 0; i < size; ++i) {
      for (int j = 0; j < i; ++j) x[i] -= substitution.Multiply(lu(i, j), x[j]);
    }
    const long forward = substitution.macs;
    for (int i = size - 1; i >= 0; --i) {
      for (int j = i + 1; j < size; ++j) x[i] -= substitution.Multiply(lu(i, j), x[j]);
      x[i] = substitution.Divide(x[i], lu(i, i));
    }
    // Measured residual at most 1.7e-16.
    EXPECT_LT((a * x - b).norm(), 2e-15 * b.norm());
    EXPECT_EQ(substitution.macs, counts::LuSolve(size, 1)) << size;
    EXPECT_EQ(substitution.macs - forward, counts::TriangularSolve(size, 1)) << size;

    // Householder QR of a (size + 3) x size matrix, R only: per reflector the norm of
    // its column, then a dot product and an update per column to its right.
    const int rows = size + 3;
    Eigen::MatrixXd r = Eigen::MatrixXd::Random(rows, size);
    const Eigen::MatrixXd original = r;
    Counter qr;
    for (int k = 0; k < size; ++k) {
      double norm2 = 0.0;
      for (int i = k; i < rows; ++i) norm2 += qr.Multiply(r(i, k), r(i, k));
      Eigen::VectorXd v = r.col(k).tail(rows - k);
      v[0] += (v[0] >= 0.0 ? 1.0 : -1.0) * std::sqrt(norm2);
      // |v|^2 = 2 (|x|^2 + |x_0| |x|): O(1), not counted (as the closed form).
      const double vv = 2.0 * (norm2 + std::abs(r(k, k)) * std::sqrt(norm2));
      for (int j = k; j < size; ++j) {
        if (j == k) {
          r(k, k) = -(r(k, k) >= 0.0 ? 1.0 : -1.0) * std::sqrt(norm2);
          r.col(k).tail(rows - k - 1).setZero();
          continue;
        }
        double dot = 0.0;
        for (int i = k; i < rows; ++i) dot += qr.Multiply(v[i - k], r(i, j));
        const double factor = 2.0 * dot / vv;
        for (int i = k; i < rows; ++i) r(i, j) -= qr.Multiply(factor, v[i - k]);
      }
    }
    EXPECT_EQ(qr.macs, counts::HouseholderQr(rows, size)) << size;
    // R^T R = A^T A.
    const Eigen::MatrixXd upper = r.topRows(size).triangularView<Eigen::Upper>();
    // Measured at most 4.0e-16.
    EXPECT_LT((upper.transpose() * upper - original.transpose() * original).norm(),
              4e-15 * (original.transpose() * original).norm())
        << size;
  }
}

// The theta step and the MCRE sweeps written out with the counted kernels, as the
// formulas of operation_counts.h describe them (band algorithm: rhs = R v - h K u + h f,
// S v' = rhs, u' = u + h (1 - theta) v + h theta v'; the direct sweep's g_j per level,
// the retrograde sweep's end forces per step and W_j per level). They compute what the
// library's sweeps compute (checked on a tiny bar) and count what they execute.
struct CountedSweeps {
  CountedSweeps(const testing::BarMcreProblem& problem, const ChannelSet& data)
      : problem(problem), data(data) {
    const Eigen::MatrixXd mass(problem.MassMatrix()), stiffness(problem.StiffnessMatrix());
    h = problem.time_step();
    theta = problem.theta();
    k = stiffness;
    r = mass - h * h * theta * (1.0 - theta) * stiffness;
    s = mass + h * h * theta * theta * stiffness;
  }

  void Step(const Eigen::VectorXd& v, const Eigen::VectorXd& u, const Eigen::VectorXd& f,
            Eigen::VectorXd* v_next, Eigen::VectorXd* u_next, Counter* counter) const {
    const int n = static_cast<int>(v.size());
    Eigen::VectorXd rhs = CountedBandProduct(r, 1, v, counter);
    const Eigen::VectorXd ku = CountedBandProduct(k, 1, u, counter);
    for (int i = 0; i < n; ++i) rhs[i] += -counter->Multiply(h, ku[i]) + counter->Multiply(h, f[i]);
    *v_next = CountedBandSolve(s, 1, rhs, counter);
    u_next->resize(n);
    const double a = h * (1.0 - theta), b = h * theta;
    for (int i = 0; i < n; ++i) {
      (*u_next)[i] = u[i] + counter->Multiply(a, v[i]) + counter->Multiply(b, (*v_next)[i]);
    }
  }

  Eigen::MatrixXd Direct(const Eigen::MatrixXd& w, Counter* counter) const {
    const int n = static_cast<int>(w.rows()), m = static_cast<int>(w.cols()) - 1;
    // g_j = F~_j - (K + B / alpha) W_j, per level.
    Eigen::MatrixXd g(n, m + 1);
    for (int j = 0; j <= m; ++j) {
      g.col(j) = -CountedBandProduct(k, 1, w.col(j), counter);
      g(0, j) += data.Values("f0")[j] - counter->Divide(w(0, j), problem.alpha());
      g(n - 1, j) += data.Values("fL")[j] - counter->Divide(w(n - 1, j), problem.alpha());
    }
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, m + 1);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n), v_next, u_next, f(n);
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < n; ++i) {
        f[i] = counter->Multiply(theta, g(i, j + 1)) + counter->Multiply(1.0 - theta, g(i, j));
      }
      Step(v, u.col(j), f, &v_next, &u_next, counter);
      v = v_next;
      u.col(j + 1) = u_next;
    }
    return u;
  }

  Eigen::MatrixXd Retrograde(const Eigen::MatrixXd& u, Counter* counter) const {
    const int n = static_cast<int>(u.rows()), m = static_cast<int>(u.cols()) - 1;
    // omega_j for j = m..0 (omega_m = 0), then W_j per level.
    Eigen::MatrixXd omega = Eigen::MatrixXd::Zero(n, m + 1);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n), v_next, omega_next, f(n);
    for (int j = m; j > 0; --j) {
      const double weight = problem.QuadratureWeight(j) * problem.beta();
      f.setZero();
      f[0] = counter->Multiply(weight, u(0, j) - data.Values("u0")[j]);
      f[n - 1] = counter->Multiply(weight, u(n - 1, j) - data.Values("uL")[j]);
      Step(v, omega.col(j), f, &v_next, &omega_next, counter);
      v = v_next;
      omega.col(j - 1) = omega_next;
    }
    Eigen::MatrixXd w(n, m + 1);
    for (int j = 0; j <= m; ++j) {
      for (int i = 0; i < n; ++i) {
        const double before = j > 0 ? omega(i, j - 1) : 0.0;
        w(i, j) = counter->Divide(counter->Multiply(theta, before) +
                                      counter->Multiply(1.0 - theta, omega(i, j)),
                                  problem.QuadratureWeight(j));
      }
    }
    return w;
  }

  double InnerProduct(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, Counter* counter) const {
    const int n = static_cast<int>(x.rows()), m = static_cast<int>(x.cols()) - 1;
    double sum = 0.0;
    for (int j = 0; j <= m; ++j) {
      const Eigen::VectorXd ky = CountedBandProduct(k, 1, y.col(j), counter);
      double term = 0.0;
      for (int i = 0; i < n; ++i) term += counter->Multiply(x(i, j), ky[i]);
      term += counter->Divide(counter->Multiply(x(0, j), y(0, j)) +
                                  counter->Multiply(x(n - 1, j), y(n - 1, j)),
                              problem.alpha());
      sum += counter->Multiply(problem.QuadratureWeight(j) * h, term);
    }
    return sum;
  }

  const testing::BarMcreProblem& problem;
  const ChannelSet& data;
  double h = 0.0, theta = 0.0;
  Eigen::MatrixXd k, r, s;
};

TEST(OperationCountsTest, SweepsCountedOnRealSweepsOfATinyBar) {
  for (const double theta : {0.5, 1.0}) {
    // 6 elements (7 nodes, half bandwidth 1), 5 steps, noise-free data.
    testing::ProblemBundle bundle(testing::MakeSmallCase(6, 5, INFINITY, 1),
                                  testing::Weights(0.01, 1.0), theta);
    testing::BarMcreProblem& problem = bundle.problem;
    problem.SetModulus(0.9 * bundle.model.properties().modulus);
    const CountedSweeps counted(problem, bundle.data);
    const int n = problem.num_nodes(), m = problem.num_steps();
    std::srand(3);
    const Matrix w_in = 1e-7 * Matrix::Random(n, m + 1);

    Matrix u, w;
    problem.DirectSweep(w_in, true, &u);
    Counter direct;
    const Eigen::MatrixXd u_counted = counted.Direct(w_in, &direct);
    // The library forms W_theta before K W_theta, the count's algorithm g_j per level:
    // the same U to round-off (measured 2.9e-16 and 7.2e-16 relative, theta 1/2 and 1).
    EXPECT_LT((u_counted - u).norm(), 5e-15 * u.norm()) << theta;
    EXPECT_EQ(direct.macs, counts::DirectSweep(n, 1, m)) << theta;

    problem.RetrogradeSweep(u, true, &w);
    Counter retrograde;
    const Eigen::MatrixXd w_counted = counted.Retrograde(u, &retrograde);
    // Measured 8.4e-17 and 8.1e-17 relative.
    EXPECT_LT((w_counted - w).norm(), 8e-16 * w.norm()) << theta;
    EXPECT_EQ(retrograde.macs, counts::RetrogradeSweep(n, 1, m)) << theta;

    Counter inner;
    const double product = counted.InnerProduct(u, w, &inner);
    // Measured the same bits.
    EXPECT_NEAR(product, problem.InnerProduct(u, w), 1e-15 * std::abs(product)) << theta;
    EXPECT_EQ(inner.macs, counts::InnerProduct(n, 1, m)) << theta;

    Counter step;
    Eigen::VectorXd v_next, u_next;
    counted.Step(Eigen::VectorXd::Ones(n), Eigen::VectorXd::Ones(n), Eigen::VectorXd::Ones(n),
                 &v_next, &u_next, &step);
    EXPECT_EQ(step.macs, counts::ThetaStep(n, 1, true)) << theta;
  }
}

}  // namespace
}  // namespace mcrewave
