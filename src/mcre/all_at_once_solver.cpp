// The all-at-once reference solver: the whole space-time system of
// docs/discrete_mcre.md (D1, D2, R1, R2, R3) assembled as one sparse matrix from
// M, K and B, without the integrator, and solved by sparse LU.
//
// Unknowns are interleaved by time, t = 0..m, five blocks of n each:
// [U_t, V_t, Omega_t, Y_t, W_t] (Y = the retrograde velocity v of R1, R2). U_0, V_0
// (rest) and Omega_m, Y_m (final condition) are kept as unknowns fixed to zero by
// identity rows, so that the indexing stays uniform.
//
// Memory. The LU keeps this time-interleaved (natural) order: the matrix is then
// banded (every row couples times t - 1, t, t + 1 only) and its fill is predictable,
// so the solver can refuse before it allocates (AllAtOnceBytes). Measured with
// Eigen 3.4 SparseLU on 2 <= n <= 321 nodes, 20 <= m <= 3200 steps, consistent and
// lumped mass, theta 0.5 to 1: nnz(L) + nnz(U) = 7.9 n .. 8.5 n + 4 per unknown
// with w_u / w_f from 1e-8 to 1e4 (n = 11, m = 800: 96.4; n = 81, m = 200: 674;
// n = 321, m = 25: 2548), up to 9.0 n + 4 when extreme weights (w_u / w_f = 1e12
// .. 1e40) change the pivots (n = 81, m = 100: 725); estimated as 9.5 n + 4.
// COLAMD, the previous ordering, gave less fill on consistent mass when n is
// large (n = 81, m = 200: 392 per unknown; n = 321, m = 25: 246) but much more on
// lumped mass, growing with m (n = 41, m = 800: 1811 per unknown, 4.3 GB and 197 s
// against 345, 0.74 GB and 2.3 s in natural order), and no estimate of it holds
// before the factorisation.

#include <Eigen/SparseLU>
#include <algorithm>
#include <cassert>
#include <limits>
#include <sstream>
#include <vector>

#include "mcre/coupled_solver_internal.h"
#include "mcre/direct_solution_check.h"

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
  // The assembled matrix; the triplets are released (they would otherwise stay
  // allocated through the factorisation).
  SparseMatrix Build() {
    SparseMatrix matrix(size(), size());
    matrix.setFromTriplets(entries_.begin(), entries_.end());
    std::vector<Eigen::Triplet<double>>().swap(entries_);
    return matrix;
  }

 private:
  int n_, m_;
  std::vector<Eigen::Triplet<double>> entries_;
};

// Nonzeros of the assembled matrix, from those of M, K, P = K + B / alpha and B:
// the identity rows of U_0, V_0, Omega_m, Y_m; per step, D1 (2 M, 2 K, 2 P) and D2
// (4 identities), R1 (4 identities) and R2 (2 M, 2 K, B); R3 (3 identities but
// the first, which has 2). No two terms share an entry.
double MatrixNonZeros(int n, int m, double mass, double stiffness, double penalty,
                      double selector) {
  const double per_step = (2.0 * mass + 2.0 * stiffness + 2.0 * penalty + 4.0 * n) +
                          (4.0 * n + 2.0 * mass + 2.0 * stiffness + selector);
  return 4.0 * n + m * per_step + (3.0 * m + 2.0) * n;
}

// Measured bound of nnz(L) + nnz(U) per unknown of the LU in natural order (above).
double FactorNonZerosPerUnknown(int n) { return 9.5 * n + 4.0; }

// Bytes the solver would hold at its peak, the factorisation: the matrix and the
// LU's own permuted copy of it (12 bytes per nonzero each: a double and an int
// index), the factors at 16 bytes per nonzero (a double, an index, and the slack of
// SparseLU's storage, which grows by 1.5x when its first guess is short), and 400
// bytes per unknown (right-hand side, solution, SparseLU's permutations, supernode
// tables and panel workspace). Fitted to the growth of the peak resident memory
// during SolveCoupled on 15 of the cases above (3 <= n <= 161, both masses, theta
// 0.5 to 1, extreme weights included): measured / estimated = 0.62 .. 0.88. Plus
// 1 MiB for the allocator's granularity, which dominates tiny systems (n = 3,
// m = 20: 0.5 MB measured for 0.3 MB of the terms above). Assembly holds less
// (triplets at 16 bytes per nonzero, then 2 x 12 while compressing), but is
// counted too.
double AllAtOnceBytes(double unknowns, double matrix_nonzeros, double factor_nonzeros) {
  const double assembly = (16.0 + 12.0 + 12.0) * matrix_nonzeros + 16.0 * unknowns;
  const double factorisation =
      2.0 * 12.0 * matrix_nonzeros + 16.0 * factor_nonzeros + 400.0 * unknowns;
  constexpr double kAllocatorGranularity = 1 << 20;
  return kAllocatorGranularity + std::max(assembly, factorisation);
}

// Why the solver refuses a system of `unknowns` unknowns (too many, too much
// memory, or past the 32-bit indices of the sparse LU), or an empty string.
std::string AllAtOnceRefusal(const CoupledSolverOptions& options, int n, int m, long unknowns,
                             double matrix_nonzeros, double factor_nonzeros, double bytes) {
  const double num_unknowns = static_cast<double>(unknowns);
  std::ostringstream sizes;
  sizes << "about " << static_cast<long long>(bytes) << " bytes (matrix "
        << static_cast<long long>(matrix_nonzeros) << " nonzeros x 12 bytes, twice; LU factors "
        << "about (9.5 n + 4) nonzeros per unknown x 16 bytes; 400 bytes per unknown; 1 MiB; n = "
        << n << " nodes, m = " << m << " steps)";
  if (unknowns > options.max_all_at_once_unknowns) {
    std::ostringstream why;
    why << "the all-at-once system has " << unknowns << " unknowns (5 n (m + 1), n = " << n
        << " nodes, m = " << m << " steps), above the limit of " << options.max_all_at_once_unknowns
        << " unknowns (inner.max_all_at_once_unknowns), and would need " << sizes.str()
        << "; use an iterative solver";
    return why.str();
  }
  if (bytes > static_cast<double>(options.max_all_at_once_bytes)) {
    std::ostringstream why;
    why << "the all-at-once solver would need " << sizes.str() << ", above the limit of "
        << options.max_all_at_once_bytes
        << " bytes (inner.max_all_at_once_bytes); raise it or use an iterative solver";
    return why.str();
  }
  // Eigen's sparse matrices and SparseLU index with int here.
  constexpr double kMaxIndex = std::numeric_limits<int>::max();
  if (num_unknowns > kMaxIndex || matrix_nonzeros > kMaxIndex || factor_nonzeros > kMaxIndex) {
    return "the all-at-once system is too large for the 32-bit indices of its sparse "
           "LU: it would need " +
           sizes.str() + "; use an iterative solver";
  }
  return "";
}

// The rows of the rest and final conditions (U_0 = V_0 = 0, Omega_m = Y_m = 0) and
// of (D1, D2) into system, the measured forces of (D1) into rhs (zero before).
void AssembleDirectRows(CoupledProblem* problem, const SparseMatrix& mass,
                        const SparseMatrix& stiffness, const SparseMatrix& penalty,
                        SpaceTimeAssembler* system, Vector* rhs) {
  const int n = problem->num_nodes(), m = problem->num_steps();
  const double h = problem->time_step(), theta = problem->theta();
  // The measured forces G F~_k and G F~_{k+1} of the step being assembled.
  Vector force_now(n), force_next(n);
  problem->MeasuredForce(0, force_next);
  // Rest and final conditions: U_0 = V_0 = 0, Omega_m = Y_m = 0.
  system->AddIdentity(kU, 0, kU, 0, 1.0);
  system->AddIdentity(kV, 0, kV, 0, 1.0);
  system->AddIdentity(kOmega, m, kOmega, m, 1.0);
  system->AddIdentity(kY, m, kY, m, 1.0);
  for (int k = 0; k < m; ++k) {
    // (D1) in the rows of V_{k+1}:
    // M (V_{k+1} - V_k) + h theta K U_{k+1} + h (1-theta) K U_k
    //   + h theta P W_{k+1} + h (1-theta) P W_k = h theta F~_{k+1} + h (1-theta) F~_k.
    system->Add(kV, k + 1, kV, k + 1, mass, 1.0);
    system->Add(kV, k + 1, kV, k, mass, -1.0);
    system->Add(kV, k + 1, kU, k + 1, stiffness, h * theta);
    system->Add(kV, k + 1, kU, k, stiffness, h * (1.0 - theta));
    // P_{k+1} and P_k: the same matrix unless a load acts only over an interval.
    if (problem->TimeVaryingPenalty()) {
      system->Add(kV, k + 1, kW, k + 1, problem->PenaltyMatrixAt(k + 1), h * theta);
      system->Add(kV, k + 1, kW, k, problem->PenaltyMatrixAt(k), h * (1.0 - theta));
    } else {
      system->Add(kV, k + 1, kW, k + 1, penalty, h * theta);
      system->Add(kV, k + 1, kW, k, penalty, h * (1.0 - theta));
    }
    force_now.swap(force_next);
    problem->MeasuredForce(k + 1, force_next);
    rhs->segment(system->Index(kV, k + 1), n) =
        h * (theta * force_next + (1.0 - theta) * force_now);
    // (D2) in the rows of U_{k+1}: U_{k+1} - U_k - h theta V_{k+1} - h (1-theta) V_k = 0.
    system->AddIdentity(kU, k + 1, kU, k + 1, 1.0);
    system->AddIdentity(kU, k + 1, kU, k, -1.0);
    system->AddIdentity(kU, k + 1, kV, k + 1, -h * theta);
    system->AddIdentity(kU, k + 1, kV, k, -h * (1.0 - theta));
  }
}

// The rows of (R1, R2, R3) into system, the displacement data of (R2) into rhs.
void AssembleRetrogradeRows(CoupledProblem* problem, const SparseMatrix& mass,
                            const SparseMatrix& stiffness, const SparseMatrix& observation,
                            SpaceTimeAssembler* system, Vector* rhs) {
  const int n = problem->num_nodes(), m = problem->num_steps();
  const double h = problem->time_step(), theta = problem->theta();
  for (int j = m; j >= 1; --j) {
    const double c_j = problem->QuadratureWeight(j);
    // (R1) in the rows of Omega_{j-1}:
    // Omega_{j-1} - h theta Y_{j-1} - Omega_j - h (1-theta) Y_j = 0.
    system->AddIdentity(kOmega, j - 1, kOmega, j - 1, 1.0);
    system->AddIdentity(kOmega, j - 1, kY, j - 1, -h * theta);
    system->AddIdentity(kOmega, j - 1, kOmega, j, -1.0);
    system->AddIdentity(kOmega, j - 1, kY, j, -h * (1.0 - theta));
    // (R2) in the rows of Y_{j-1}:
    // M Y_{j-1} + h theta K Omega_{j-1} - M Y_j + h (1-theta) K Omega_j
    //   - h c_j H^T diag(beta) H U_j = -h c_j H^T diag(beta) d~_j.
    system->Add(kY, j - 1, kY, j - 1, mass, 1.0);
    system->Add(kY, j - 1, kOmega, j - 1, stiffness, h * theta);
    system->Add(kY, j - 1, kY, j, mass, -1.0);
    system->Add(kY, j - 1, kOmega, j, stiffness, h * (1.0 - theta));
    system->Add(kY, j - 1, kU, j, observation, -h * c_j);
    problem->WeightedData(j, rhs->segment(system->Index(kY, j - 1), n));
    rhs->segment(system->Index(kY, j - 1), n) *= -h * c_j;
  }
  for (int j = 0; j <= m; ++j) {
    // (R3) in the rows of W_j: c_j W_j - theta Omega_{j-1} - (1-theta) Omega_j = 0.
    system->AddIdentity(kW, j, kW, j, problem->QuadratureWeight(j));
    if (j > 0) system->AddIdentity(kW, j, kOmega, j - 1, -theta);
    system->AddIdentity(kW, j, kOmega, j, -(1.0 - theta));
  }
}

// Builds the matrix, factorises it by sparse LU in natural order and solves for
// rhs with one step of iterative refinement, U and W into the solution and the
// method's description into *description. Returns the failure message, or an
// empty string. The matrix and its factors are released on return.
std::string FactorAndSolve(SpaceTimeAssembler* system, const Vector& rhs, int n, int m,
                           [[maybe_unused]] double matrix_nonzeros, double factor_nonzeros,
                           CoupledSolution* solution, std::string* description) {
  const SparseMatrix matrix = system->Build();
  assert(matrix.nonZeros() == static_cast<long>(matrix_nonzeros));
  // Natural order: the time-interleaved one, banded (see the top of this file).
  Eigen::SparseLU<SparseMatrix, Eigen::NaturalOrdering<int>> lu;
  lu.compute(matrix);
  if (lu.info() != Eigen::Success) {
    return "the all-at-once system could not be factorised: " + lu.lastErrorMessage();
  }
  // One step of iterative refinement (in double): the retrograde blocks are many
  // orders smaller than the direct ones when w_u / w_f is small (or the reverse),
  // and the plain LU solution, accurate relative to the whole vector, left W
  // inaccurate: relative residual ||T(W) - W||_P / ||T(0)||_P (below) of 8.8e-5 at
  // w_u = 1e-6, 5.1e-9 at w_u = 1e-4, 2.0e-9 on configs/quick.yaml (w_u = 0.01),
  // 2.2e-5 at w_u / w_f = 1e20; after one step 8.0e-14, 3.5e-14, 1.1e-12, 7.1e-12,
  // all below the round-off floor; a second step changed nothing.
  Vector unknowns = lu.solve(rhs);
  Vector residual = rhs - matrix * unknowns;
  unknowns += lu.solve(residual);
  if (!unknowns.allFinite()) return "the all-at-once solve produced non-finite values";
  // ||A x - b|| / ||b|| of the space-time system: how well the LU solved it, which
  // says little of W when the system is ill-conditioned; for the message only.
  residual = rhs - matrix * unknowns;
  const double rhs_norm = rhs.norm();
  const double space_time_residual = rhs_norm > 0.0 ? residual.norm() / rhs_norm : residual.norm();
  solution->displacement.resize(n, m + 1);
  solution->retrograde.resize(n, m + 1);
  for (int t = 0; t <= m; ++t) {
    solution->displacement.col(t) = unknowns.segment(system->Index(kU, t), n);
    solution->retrograde.col(t) = unknowns.segment(system->Index(kW, t), n);
  }
  std::ostringstream text;
  text << "sparse LU of " << system->size() << " unknowns, " << lu.nnzL() + lu.nnzU()
       << " nonzeros in L and U (" << static_cast<long long>(factor_nonzeros)
       << " estimated), space-time residual " << ScientificString(space_time_residual);
  *description = text.str();
  return "";
}

}  // namespace

void SolveAllAtOnce(const CoupledSolverOptions& options, CoupledProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary) {
  const int n = problem->num_nodes(), m = problem->num_steps();
  SpaceTimeAssembler system(n, m);
  summary->iterations = 0;
  const SparseMatrix mass = problem->MassMatrix();
  const SparseMatrix stiffness = problem->StiffnessMatrix();
  // P = K + G diag(1/alpha) G^T (the bar: K + B / alpha).
  const SparseMatrix penalty = problem->PenaltyMatrix();
  // H^T diag(beta_k) H (the paper's case: beta B).
  const SparseMatrix observation = problem->WeightedObservation();
  const double num_unknowns = static_cast<double>(system.size());
  const double matrix_nonzeros = MatrixNonZeros(n, m, mass.nonZeros(), stiffness.nonZeros(),
                                                penalty.nonZeros(), observation.nonZeros());
  const double factor_nonzeros = FactorNonZerosPerUnknown(n) * num_unknowns;
  const double bytes = AllAtOnceBytes(num_unknowns, matrix_nonzeros, factor_nonzeros);
  const std::string refusal =
      AllAtOnceRefusal(options, n, m, system.size(), matrix_nonzeros, factor_nonzeros, bytes);
  if (!refusal.empty()) {
    summary->message = refusal;
    return;
  }
  Vector rhs = Vector::Zero(system.size());
  AssembleDirectRows(problem, mass, stiffness, penalty, &system, &rhs);
  AssembleRetrogradeRows(problem, mass, stiffness, observation, &system, &rhs);

  // The factorisation in a function of its own, so that the matrix and its factors
  // are released before the check below allocates its fields.
  std::string description;
  const std::string failure =
      FactorAndSolve(&system, rhs, n, m, matrix_nonzeros, factor_nonzeros, solution, &description);
  if (!failure.empty()) {
    summary->message = failure;
    return;
  }
  // Converged only when W meets the tolerance in the measure of every other solver,
  // ||T(W) - W||_P / ||T(0)||_P (or its round-off floor), and U = Direct(W): the
  // LU's own residual stays small even where the system is so ill-conditioned that
  // W is not (w_u / w_f = 1e28 on 10 elements: 3e-16 against a relative residual of
  // 7e-4).
  CheckDirectSolution(options, description, problem, *solution, summary);
}

}  // namespace mcrewave::internal
