// The all-at-once reference solver: the whole space-time system of
// docs/discrete_mcre.md (D1, D2, R1, R2, R3) assembled as one sparse matrix from
// M, K and B, without the integrator, and solved by sparse LU.
//
// Unknowns are interleaved by time, t = 0..m, five blocks of n each:
// [U_t, V_t, Omega_t, Y_t, W_t] (Y = the retrograde velocity v of R1, R2). U_0, V_0
// (rest) and Omega_m, Y_m (final condition) are kept as unknowns fixed to zero by
// identity rows, so that the indexing stays uniform.

#include <Eigen/SparseLU>
#include <sstream>
#include <vector>

#include "coupled_solver_internal.h"

namespace mcrewave::internal {
namespace {

enum Block { kU = 0, kV = 1, kOmega = 2, kY = 3, kW = 4, kNumBlocks = 5 };

class SpaceTimeAssembler {
 public:
  SpaceTimeAssembler(int num_nodes, int num_steps) : n_(num_nodes), m_(num_steps) {}

  long size() const { return static_cast<long>(kNumBlocks) * n_ * (m_ + 1); }
  int Index(Block block, int t) const { return (t * kNumBlocks + block) * n_; }

  // Rows of `row_block` at time row_t += scale * matrix * (column block at col_t).
  void Add(Block row_block, int row_t, Block col_block, int col_t, const SparseMatrix& matrix,
           double scale) {
    const int row0 = Index(row_block, row_t), col0 = Index(col_block, col_t);
    for (int j = 0; j < matrix.outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
        entries_.emplace_back(row0 + it.row(), col0 + it.col(), scale * it.value());
      }
    }
  }
  // The same with the identity matrix.
  void AddIdentity(Block row_block, int row_t, Block col_block, int col_t, double scale) {
    const int row0 = Index(row_block, row_t), col0 = Index(col_block, col_t);
    for (int i = 0; i < n_; ++i) entries_.emplace_back(row0 + i, col0 + i, scale);
  }
  SparseMatrix Build() const {
    SparseMatrix matrix(size(), size());
    matrix.setFromTriplets(entries_.begin(), entries_.end());
    return matrix;
  }

 private:
  int n_, m_;
  std::vector<Eigen::Triplet<double>> entries_;
};

// Bytes of the assembled system alone, a lower bound of what the solve needs: each
// row has at least 3 entries per coupled block (the 3-point stencil of M and K)
// in 3 blocks, stored as triplets (16 bytes) and then compressed (12 bytes), plus
// the right-hand side and solution.
double MatrixBytesLowerBound(long unknowns) {
  const double entries = 9.0 * static_cast<double>(unknowns);
  return entries * (16.0 + 12.0) + 2.0 * sizeof(double) * static_cast<double>(unknowns);
}

}  // namespace

void SolveAllAtOnce(const CoupledSolverOptions& options, McreProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary) {
  const int n = problem->num_nodes(), m = problem->num_steps(), last = n - 1;
  SpaceTimeAssembler system(n, m);
  summary->iterations = 0;
  if (system.size() > options.max_all_at_once_unknowns) {
    std::ostringstream why;
    why << "the all-at-once system has " << system.size() << " unknowns (5 n (m + 1), n = " << n
        << " nodes, m = " << m << " steps) and would need more than "
        << static_cast<long long>(MatrixBytesLowerBound(system.size()))
        << " bytes (its matrix alone; the LU factors need more), above the limit of "
        << options.max_all_at_once_unknowns
        << " unknowns (inner.max_all_at_once_unknowns); use an iterative solver";
    summary->message = why.str();
    return;
  }
  const BarModel& model = problem->model();
  const MeasurementSet& data = problem->data();
  const double h = problem->time_step(), theta = problem->theta();
  const double alpha = problem->alpha(), beta = problem->beta();
  const SparseMatrix& mass = model.mass();
  const SparseMatrix stiffness = model.Stiffness(problem->modulus());
  const SparseMatrix& selector = model.boundary_selector();
  const SparseMatrix penalty = stiffness + selector / alpha;  // P = K + B / alpha
  Vector rhs = Vector::Zero(system.size());

  // Rest and final conditions: U_0 = V_0 = 0, Omega_m = Y_m = 0.
  system.AddIdentity(kU, 0, kU, 0, 1.0);
  system.AddIdentity(kV, 0, kV, 0, 1.0);
  system.AddIdentity(kOmega, m, kOmega, m, 1.0);
  system.AddIdentity(kY, m, kY, m, 1.0);
  for (int k = 0; k < m; ++k) {
    // (D1) in the rows of V_{k+1}:
    // M (V_{k+1} - V_k) + h theta K U_{k+1} + h (1-theta) K U_k
    //   + h theta P W_{k+1} + h (1-theta) P W_k = h theta F~_{k+1} + h (1-theta) F~_k.
    system.Add(kV, k + 1, kV, k + 1, mass, 1.0);
    system.Add(kV, k + 1, kV, k, mass, -1.0);
    system.Add(kV, k + 1, kU, k + 1, stiffness, h * theta);
    system.Add(kV, k + 1, kU, k, stiffness, h * (1.0 - theta));
    system.Add(kV, k + 1, kW, k + 1, penalty, h * theta);
    system.Add(kV, k + 1, kW, k, penalty, h * (1.0 - theta));
    const int row = system.Index(kV, k + 1);
    rhs[row] = h * (theta * data.f0[k + 1] + (1.0 - theta) * data.f0[k]);
    rhs[row + last] = h * (theta * data.fL[k + 1] + (1.0 - theta) * data.fL[k]);
    // (D2) in the rows of U_{k+1}: U_{k+1} - U_k - h theta V_{k+1} - h (1-theta) V_k = 0.
    system.AddIdentity(kU, k + 1, kU, k + 1, 1.0);
    system.AddIdentity(kU, k + 1, kU, k, -1.0);
    system.AddIdentity(kU, k + 1, kV, k + 1, -h * theta);
    system.AddIdentity(kU, k + 1, kV, k, -h * (1.0 - theta));
  }
  for (int j = m; j >= 1; --j) {
    const double c_j = problem->QuadratureWeight(j);
    // (R1) in the rows of Omega_{j-1}:
    // Omega_{j-1} - h theta Y_{j-1} - Omega_j - h (1-theta) Y_j = 0.
    system.AddIdentity(kOmega, j - 1, kOmega, j - 1, 1.0);
    system.AddIdentity(kOmega, j - 1, kY, j - 1, -h * theta);
    system.AddIdentity(kOmega, j - 1, kOmega, j, -1.0);
    system.AddIdentity(kOmega, j - 1, kY, j, -h * (1.0 - theta));
    // (R2) in the rows of Y_{j-1}:
    // M Y_{j-1} + h theta K Omega_{j-1} - M Y_j + h (1-theta) K Omega_j - h c_j beta B U_j
    //   = -h c_j beta U~_j.
    system.Add(kY, j - 1, kY, j - 1, mass, 1.0);
    system.Add(kY, j - 1, kOmega, j - 1, stiffness, h * theta);
    system.Add(kY, j - 1, kY, j, mass, -1.0);
    system.Add(kY, j - 1, kOmega, j, stiffness, h * (1.0 - theta));
    system.Add(kY, j - 1, kU, j, selector, -h * c_j * beta);
    const int row = system.Index(kY, j - 1);
    rhs[row] = -h * c_j * beta * data.u0[j];
    rhs[row + last] = -h * c_j * beta * data.uL[j];
  }
  for (int j = 0; j <= m; ++j) {
    // (R3) in the rows of W_j: c_j W_j - theta Omega_{j-1} - (1-theta) Omega_j = 0.
    system.AddIdentity(kW, j, kW, j, problem->QuadratureWeight(j));
    if (j > 0) system.AddIdentity(kW, j, kOmega, j - 1, -theta);
    system.AddIdentity(kW, j, kOmega, j, -(1.0 - theta));
  }

  const SparseMatrix matrix = system.Build();
  Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>> lu;
  lu.compute(matrix);
  if (lu.info() != Eigen::Success) {
    summary->message = "the all-at-once system could not be factorised: " + lu.lastErrorMessage();
    return;
  }
  const Vector unknowns = lu.solve(rhs);
  const double rhs_norm = rhs.norm();
  summary->relative_residual =
      rhs_norm > 0.0 ? (matrix * unknowns - rhs).norm() / rhs_norm : (matrix * unknowns).norm();
  if (!unknowns.allFinite()) {
    summary->message = "the all-at-once solve produced non-finite values";
    return;
  }
  solution->displacement.resize(n, m + 1);
  solution->retrograde.resize(n, m + 1);
  for (int t = 0; t <= m; ++t) {
    solution->displacement.col(t) = unknowns.segment(system.Index(kU, t), n);
    solution->retrograde.col(t) = unknowns.segment(system.Index(kW, t), n);
  }
  summary->termination = TerminationType::kConvergence;
  summary->message = "sparse LU of " + std::to_string(system.size()) + " unknowns";
}

}  // namespace mcrewave::internal
