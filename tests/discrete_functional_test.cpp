// The coupled solution minimises the discrete MCRE functional: a check that does
// not go through the sweeps, the adjoint derivation or the all-at-once assembly.
//
// On a tiny bar the functional of docs/discrete_mcre.md section 1,
//
//   J = sum_j c_j h [ 1/2 W_j^T K W_j + alpha/2 |F_j - F~_j|^2 + beta/2 |B U_j - U~_j|^2 ],
//
// is minimised over every unknown z = (U_1..U_m, V_1..V_m, W_0..W_m, F_0..F_m) (F_j
// the two end forces; U_0 = V_0 = 0) subject to the theta scheme (D1, D2) of that
// section, written here as dense matrices from M, K = E K1 and the data alone. The
// KKT system [H A^T; A 0] [z; lambda] = [g; 0] is solved by a dense, equilibrated,
// fully pivoted LU. W is defined up to a rigid translation (K W and the constraints
// do not see it), so it is fixed to zero mean there and U, F, K W and J, which are
// unique, are compared with the conjugate-gradient and all-at-once solvers' (F =
// F~ - B W / alpha from their W), which solve the bar as every run does (BarRunModel).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <tuple>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;

struct KktSolution {
  Eigen::MatrixXd displacement;  // n x (m + 1), U_0 = 0
  Eigen::MatrixXd velocity;      // n x (m + 1), V_0 = 0
  Eigen::MatrixXd retrograde;    // n x (m + 1), W up to a rigid translation
  Eigen::MatrixXd end_forces;    // 2 x (m + 1): f0, fL
  double cost = 0.0;             // J at the minimum [J s]
};

// Offsets of the unknowns in z = (U_1..U_m, V_1..V_m, W_0..W_m, F_0..F_m).
struct KktOffsets {
  int n, m;
  int u(int k) const { return (k - 1) * n; }  // k = 1..m
  int v(int k) const { return n * m + (k - 1) * n; }
  int w(int j) const { return 2 * n * m + j * n; }  // j = 0..m
  int f(int j) const { return 2 * n * m + n * (m + 1) + 2 * j; }
  int unknowns() const { return 2 * n * m + n * (m + 1) + 2 * (m + 1); }
  int constraints() const { return 2 * n * m; }
};

// J = 1/2 z^T H z - g^T z + constant: the hessian H, the linear term g and the constant.
void DenseFunctionalTerms(const ChannelSet& data, const Eigen::MatrixXd& stiffness,
                          const KktOffsets& at, double alpha, double beta, Eigen::MatrixXd* hessian,
                          Eigen::VectorXd* linear, double* constant) {
  const int n = at.n, m = at.m;
  const double h = data.time_step;
  auto c = [m](int j) { return (j == 0 || j == m) ? 0.5 : 1.0; };
  *hessian = Eigen::MatrixXd::Zero(at.unknowns(), at.unknowns());
  *linear = Eigen::VectorXd::Zero(at.unknowns());
  *constant = 0.0;
  const int ends[2] = {0, n - 1};
  for (int j = 0; j <= m; ++j) {
    const double weight = c(j) * h;
    hessian->block(at.w(j), at.w(j), n, n) += weight * stiffness;
    const double measured_force[2] = {data.Values("f0")[j], data.Values("fL")[j]};
    const double measured_displacement[2] = {data.Values("u0")[j], data.Values("uL")[j]};
    for (int e = 0; e < 2; ++e) {
      (*hessian)(at.f(j) + e, at.f(j) + e) += weight * alpha;
      (*linear)[at.f(j) + e] += weight * alpha * measured_force[e];
      *constant += 0.5 * weight * alpha * measured_force[e] * measured_force[e];
      *constant += 0.5 * weight * beta * measured_displacement[e] * measured_displacement[e];
      if (j > 0) {
        (*hessian)(at.u(j) + ends[e], at.u(j) + ends[e]) += weight * beta;
        (*linear)[at.u(j) + ends[e]] += weight * beta * measured_displacement[e];
      }
    }
  }
}

// The theta scheme's constraints A z = 0:
// (D1) M (V_{k+1} - V_k) + h K [theta (U + W)_{k+1} + (1 - theta)(U + W)_k]
//        - h [theta F_{k+1} + (1 - theta) F_k] = 0,
// (D2) U_{k+1} - U_k - h [theta V_{k+1} + (1 - theta) V_k] = 0, k = 0..m-1.
Eigen::MatrixXd DenseSchemeConstraints(const Eigen::MatrixXd& mass,
                                       const Eigen::MatrixXd& stiffness, const KktOffsets& at,
                                       double h, double theta) {
  const int n = at.n, m = at.m;
  const int ends[2] = {0, n - 1};
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(at.constraints(), at.unknowns());
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n, n);
  for (int k = 0; k < m; ++k) {
    const int d1 = 2 * n * k, d2 = d1 + n;
    a.block(d1, at.v(k + 1), n, n) += mass;
    if (k > 0) a.block(d1, at.v(k), n, n) -= mass;
    a.block(d1, at.u(k + 1), n, n) += h * theta * stiffness;
    if (k > 0) a.block(d1, at.u(k), n, n) += h * (1.0 - theta) * stiffness;
    a.block(d1, at.w(k + 1), n, n) += h * theta * stiffness;
    a.block(d1, at.w(k), n, n) += h * (1.0 - theta) * stiffness;
    for (int e = 0; e < 2; ++e) {
      a(d1 + ends[e], at.f(k + 1) + e) -= h * theta;
      a(d1 + ends[e], at.f(k) + e) -= h * (1.0 - theta);
    }
    a.block(d2, at.u(k + 1), n, n) += identity;
    if (k > 0) a.block(d2, at.u(k), n, n) -= identity;
    a.block(d2, at.v(k + 1), n, n) -= h * theta * identity;
    if (k > 0) a.block(d2, at.v(k), n, n) -= h * (1.0 - theta) * identity;
  }
  return a;
}

// z minimising 1/2 z^T H z - g^T z subject to A z = 0, with W fixed to zero mean at
// every j (its rigid translation is seen by neither J nor the constraints): m + 1 more
// rows, so that the KKT matrix is regular.
Eigen::VectorXd SolveGaugedKkt(const Eigen::MatrixXd& hessian, const Eigen::VectorXd& linear,
                               const Eigen::MatrixXd& a, const KktOffsets& at) {
  const int n = at.n, m = at.m;
  const int unknowns = at.unknowns(), constraints = at.constraints();
  const int gauges = m + 1;
  Eigen::MatrixXd gauge = Eigen::MatrixXd::Zero(gauges, unknowns);
  for (int j = 0; j <= m; ++j) gauge.block(j, at.w(j), 1, n).setOnes();
  const int size = unknowns + constraints + gauges;
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(size, size);
  kkt.topLeftCorner(unknowns, unknowns) = hessian;
  kkt.block(0, unknowns, unknowns, constraints) = a.transpose();
  kkt.block(unknowns, 0, constraints, unknowns) = a;
  kkt.block(0, unknowns + constraints, unknowns, gauges) = gauge.transpose();
  kkt.block(unknowns + constraints, 0, gauges, unknowns) = gauge;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(size);
  rhs.head(unknowns) = linear;
  // Symmetric Ruiz equilibration (M, h K, alpha and beta span many decades), then a
  // fully pivoted LU: kkt = D^-1 S D^-1, x = D solve(S, D rhs).
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(size);
  Eigen::MatrixXd scaled = kkt;
  for (int pass = 0; pass < 20; ++pass) {
    const Eigen::VectorXd row = scaled.cwiseAbs().rowwise().maxCoeff().cwiseSqrt().cwiseInverse();
    scaled = row.asDiagonal() * scaled * row.asDiagonal();
    scale = scale.cwiseProduct(row);
  }
  return scale.cwiseProduct(scaled.fullPivLu().solve(scale.cwiseProduct(rhs))).head(unknowns);
}

KktSolution MinimiseDenseFunctional(const BarModel& model, const ChannelSet& data, double modulus,
                                    double alpha, double beta, double theta) {
  const Eigen::MatrixXd mass = Eigen::MatrixXd(model.mass());
  const Eigen::MatrixXd stiffness = modulus * Eigen::MatrixXd(model.unit_stiffness());
  const int n = model.num_nodes(), m = data.num_steps();
  const KktOffsets at{n, m};
  Eigen::MatrixXd hessian;
  Eigen::VectorXd linear;
  double constant = 0.0;
  DenseFunctionalTerms(data, stiffness, at, alpha, beta, &hessian, &linear, &constant);
  const Eigen::MatrixXd a = DenseSchemeConstraints(mass, stiffness, at, data.time_step, theta);
  const Eigen::VectorXd z = SolveGaugedKkt(hessian, linear, a, at);

  KktSolution solution;
  solution.displacement = Eigen::MatrixXd::Zero(n, m + 1);
  solution.velocity = Eigen::MatrixXd::Zero(n, m + 1);
  solution.retrograde = Eigen::MatrixXd::Zero(n, m + 1);
  solution.end_forces = Eigen::MatrixXd::Zero(2, m + 1);
  for (int k = 1; k <= m; ++k) {
    solution.displacement.col(k) = z.segment(at.u(k), n);
    solution.velocity.col(k) = z.segment(at.v(k), n);
  }
  for (int j = 0; j <= m; ++j) {
    solution.retrograde.col(j) = z.segment(at.w(j), n);
    solution.end_forces.col(j) = z.segment(at.f(j), 2);
  }
  solution.cost = 0.5 * z.dot(hessian * z) - linear.dot(z) + constant;
  return solution;
}

using Case = std::tuple<MassType, double>;  // mass, theta

class DiscreteFunctionalTest : public ::testing::TestWithParam<Case> {};

TEST_P(DiscreteFunctionalTest, CoupledSolutionIsTheMinimumOfTheConstrainedFunctional) {
  const auto [mass, theta] = GetParam();
  testing::SmallCase tiny = MakeSmallCase(4, 8, 5.0, 2);
  tiny.bar.mass = mass;
  testing::BarRunProblem bundle(tiny, testing::Weights(0.3, 1.0), theta);
  const double modulus = 0.9 * testing::kReferenceModulus;
  bundle.problem.SetModulus(modulus);
  // One alpha for every load channel and one beta for every displacement row (the
  // weights' w_f and w_u).
  const double alpha = bundle.problem.alphas()[0];
  const double beta = bundle.problem.betas()[0];
  ASSERT_EQ(bundle.problem.alphas().minCoeff(), bundle.problem.alphas().maxCoeff());
  ASSERT_EQ(bundle.problem.betas().minCoeff(), bundle.problem.betas().maxCoeff());
  const KktSolution kkt =
      MinimiseDenseFunctional(bundle.model, bundle.data, modulus, alpha, beta, theta);
  const Eigen::MatrixXd stiffness = modulus * Eigen::MatrixXd(bundle.model.unit_stiffness());
  const int last = bundle.model.num_nodes() - 1;
  // Relative tolerances on U, K W, F and e^2, within 10x of the largest figure
  // measured over both masses and thetas (the same figures on the built-in bar's own
  // problem before the bar was solved as matrices): all-at-once (a direct solve of the
  // stationarity system) U 1.3e-15, K W 5.9e-14, F 4.5e-16, e^2 6e-14; conjugate
  // gradients at the tolerance 1e-13 U 4.9e-13, K W 8e-11, F 3.2e-13, e^2 6e-14.
  struct Tolerances {
    CoupledSolverType type;
    double displacement, gap_force, end_force, cost;
  };
  for (const Tolerances& tolerance :
       {Tolerances{CoupledSolverType::kAllAtOnce, 1e-14, 5e-13, 5e-15, 5e-13},
        Tolerances{CoupledSolverType::kConjugateGradient, 5e-12, 5e-10, 3e-12, 5e-13}}) {
    CoupledSolution solution;
    const CoupledSolverSummary summary =
        SolveCoupled(testing::Options(tolerance.type, 1e-13), &bundle.problem, nullptr, &solution);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    const char* name = CoupledSolverTypeToString(tolerance.type);
    EXPECT_LT(testing::RelativeDifference(solution.displacement, kkt.displacement),
              tolerance.displacement)
        << name;
    EXPECT_LT(
        testing::RelativeDifference(stiffness * solution.retrograde, stiffness * kkt.retrograde),
        tolerance.gap_force)
        << name;
    Eigen::MatrixXd forces(2, solution.retrograde.cols());
    for (int j = 0; j < forces.cols(); ++j) {
      // F = F~ - B W / alpha (docs/discrete_mcre.md section 2).
      forces(0, j) = bundle.data.Values("f0")[j] - solution.retrograde(0, j) / alpha;
      forces(1, j) = bundle.data.Values("fL")[j] - solution.retrograde(last, j) / alpha;
    }
    EXPECT_LT(testing::RelativeDifference(forces, kkt.end_forces), tolerance.end_force) << name;
    EXPECT_NEAR(solution.cost, kkt.cost, tolerance.cost * kkt.cost) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(
    MassAndTheta, DiscreteFunctionalTest,
    ::testing::Values(Case{MassType::kConsistent, 0.5}, Case{MassType::kLumped, 0.5},
                      Case{MassType::kConsistent, 1.0}, Case{MassType::kLumped, 1.0}),
    [](const ::testing::TestParamInfo<Case>& info) {
      return std::string(MassTypeToString(std::get<0>(info.param))) +
             (std::get<1>(info.param) == 0.5 ? "_trapezoidal" : "_backward_euler");
    });

}  // namespace
}  // namespace mcrewave
