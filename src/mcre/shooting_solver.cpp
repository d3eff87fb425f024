// Single and multiple shooting for the coupled MCRE system (D1, D2, R1, R2, R3 of
// docs/discrete_mcre.md), derived in docs/riccati_shooting.md section 3.
//
// The coupled recursion is marched forward in time. Its state at level k is
// Y_k = (U_k, V_k), Z_k = (omega_k, y_k) and omega_{k-1} (W_k needs it). One step
// k -> k+1 (notation of discrete_mcre_operators.h):
//
//   W_k        = (chi_k theta omega_{k-1} + (1 - theta) omega_k) / c_k,  chi_k = [k >= 1]
//   (R) run backwards, free part: S' yhat = R y_k + h K omega_k + h c_{k+1} b_{k+1}
//              omegahat = omega_k - h theta y_k - h (1 - theta) yhat
//   (D) with W_{k+1} taken at omegahat: (Uhat, Vhat) = Phi Y_k + Psi [F~theta_k
//              - Kp ((theta/c_{k+1}) (theta omega_k + (1 - theta) omegahat) + (1 - theta) W_k)]
//   the observed values x = E_o^T U_{k+1} close the implicit coupling (W_obs U_{k+1}
//   = E_o W_s x enters (R)):
//              (I_s + E_o^T Gamma_U) x = E_o^T Uhat,
//              Gamma_U = theta^2 (1 - theta)^2 h^4 S^-1 Kp S'^-1 W_obs E_o   (n x s),
//   U_{k+1}     = Uhat - Gamma_U x,   V_{k+1} = Vhat - Gamma_V x,
//   omega_{k+1} = omegahat + h^2 (1 - theta) c_{k+1} S'^-1 W_obs E_o x,
//   y_{k+1}     = yhat - h c_{k+1} S'^-1 W_obs E_o x,
//
// with W_obs = H^T diag(beta) H = E_o W_s E_o^T on the s observed dofs and b_j =
// H^T diag(beta) d~_j (the paper's end sensors: s = 2, W_obs E_o = beta (e_0, e_N)).
// (Gamma_V = theta (1 - theta)^2 h^3 S^-1 Kp S'^-1 W_obs E_o is kept separately so
// that theta = 0 is covered.)
//
// Single shooting: Y_0 = 0 is known, Z_0 is not. March the particular solution
// (Z_0 = 0, with the data) and the 2n unit columns of Z_0 (without data) to m: the
// final condition Z_m = 0 reads Phi_ZZ Z_0 = -Z_m^part (the shooting matrix). Its
// condition number grows like the square of the largest growth factor of the
// recursion over the window, so past some window length it breaks down.
// Multiple shooting: a segment ends where its fundamental solutions (started from
// unit states) have grown by options.shooting_segment_growth, so segment lengths
// follow the measured growth rate of the recursion; the unknown full states (Y, Z)
// at the cuts are joined by continuity, and the block
// bidiagonal system is solved by a staircase Householder QR (a QR of the whole
// system that keeps its structure: backward stable).
//
// Unknowns and equations are in energy coordinates (the states' energy norm is the
// 2-norm), where the uncoupled trapezoidal step is nearly an isometry: growth then
// measures the coupling, not the units or the mesh.

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "mcre/coupled_solver_internal.h"
#include "mcre/direct_solution_check.h"
#include "mcre/discrete_mcre_operators.h"
#include "mcrewave/core/operation_counts.h"

namespace mcrewave::internal {
namespace {

namespace counts = operation_counts;

// Several solutions of the coupled recursion, one column each.
struct CoupledColumns {
  Matrix displacement, velocity;      // U, V
  Matrix omega, retrograde_velocity;  // omega, y
  Matrix previous_omega;              // omega_{k-1}

  void SetZero(int num_nodes, int num_columns) {
    for (Matrix* field :
         {&displacement, &velocity, &omega, &retrograde_velocity, &previous_omega}) {
      field->setZero(num_nodes, num_columns);
    }
  }
};

// The coupled step k -> k+1 applied to columns, with its constant blocks on the s
// observed dofs (W_obs = E_o W_s E_o^T, discrete_mcre_operators.h).
class CoupledMarch {
 public:
  // Throws std::runtime_error when I + E_o^T Gamma_U is singular (theta != 1/2 only:
  // at theta = 1/2 its eigenvalues are those of I + (SPD)(PSD), at least 1).
  explicit CoupledMarch(DiscreteMcreOperators* ops)
      : ops_(*ops), n_(ops->num_nodes()), observed_(ops->observed_dofs()) {
    const double h = ops_.time_step(), theta = ops_.theta();
    const int s = static_cast<int>(observed_.size());
    reversed_solved_.resize(n_, s);
    displacement_gamma_.resize(n_, s);
    velocity_gamma_.resize(n_, s);
    Vector response(n_);
    for (int i = 0; i < s; ++i) {
      // S'^-1 W_obs e_{o_i} and S^-1 Kp S'^-1 W_obs e_{o_i}.
      reversed_solved_.col(i) = ops_.ObservationColumn(i);
      ops_.SolveReversedStep(reversed_solved_.col(i));
      ops_.PenaltyProduct(reversed_solved_.col(i), response);
      ops_.SolveStep(response);
      // Gamma_U = theta^2 (1 - theta)^2 h^4 (.),  Gamma_V = theta (1 - theta)^2 h^3 (.).
      displacement_gamma_.col(i) =
          (theta * theta * std::pow(1.0 - theta, 2) * std::pow(h, 4)) * response;
      velocity_gamma_.col(i) = (theta * std::pow(1.0 - theta, 2) * std::pow(h, 3)) * response;
      ops_.CountMacs(2.0 * n_);
    }
    // I + E_o^T Gamma_U (s x s): (I + E_o^T Gamma_U) E_o^T U_{k+1} = E_o^T Uhat.
    Matrix coupling = Matrix::Identity(s, s);
    for (int a = 0; a < s; ++a) coupling.row(a) += displacement_gamma_.row(observed_[a]);
    if (s > 0) coupling_lu_.compute(coupling);
    // The reciprocal condition estimate, not the determinant (a product of s pivots that
    // under- or overflows for many observed dofs).
    if (s > 0 && !(coupling_lu_.rcond() > std::numeric_limits<double>::epsilon())) {
      throw std::runtime_error(
          "the implicit coupling of a shooting step, I + E_o^T Gamma_U on the observed dofs, "
          "is singular");
    }
    ops_.CountMacs(counts::LuFactorization(s));
    for (Vector* v : {&y_hat_, &omega_hat_, &mixed_, &force_, &u_hat_, &v_hat_}) {
      v->resize(n_);
    }
    observed_values_.resize(s);
    observed_solution_.resize(s);
  }

  // One step k -> k+1 of every column of x; column 0 carries the data when with_data.
  void Step(int k, bool with_data, CoupledColumns* x) {
    const double h = ops_.time_step(), theta = ops_.theta();
    const double c_now = ops_.QuadratureWeight(k), c_next = ops_.QuadratureWeight(k + 1);
    const double chi = k >= 1 ? 1.0 : 0.0;
    const int s = static_cast<int>(observed_.size());
    for (int j = 0; j < x->displacement.cols(); ++j) {
      const bool data = with_data && j == 0;
      auto omega = x->omega.col(j);
      auto retrograde_velocity = x->retrograde_velocity.col(j);
      // (R) backwards, free part: S' yhat = R y + h K omega (+ h c_{k+1} b_{k+1}).
      ops_.FreeStateProduct(retrograde_velocity, y_hat_);
      ops_.StiffnessProductAdd(h, omega, y_hat_);
      if (data) ops_.AddWeightedData(k + 1, h * c_next, y_hat_);
      ops_.SolveReversedStep(y_hat_);
      // omegahat = omega - h theta y - h (1 - theta) yhat.
      omega_hat_ = omega - (h * theta) * retrograde_velocity - (h * (1.0 - theta)) * y_hat_;
      // theta W_{k+1}(omegahat) + (1 - theta) W_k
      //   = (theta/c_{k+1}) (theta omega + (1 - theta) omegahat)
      //     + ((1 - theta)/c_k) (chi theta omega_{k-1} + (1 - theta) omega).
      mixed_ = (theta * theta / c_next + (1.0 - theta) * (1.0 - theta) / c_now) * omega +
               (theta * (1.0 - theta) / c_next) * omega_hat_ +
               (chi * theta * (1.0 - theta) / c_now) * x->previous_omega.col(j);
      // force = F~theta_k - Kp (.).
      ops_.PenaltyProduct(mixed_, force_);
      force_ = -force_;
      if (data) {
        ops_.AddMeasuredForce(k + 1, theta, force_);
        ops_.AddMeasuredForce(k, 1.0 - theta, force_);
      }
      ops_.ThetaStep(x->displacement.col(j), x->velocity.col(j), &force_, u_hat_, v_hat_);
      // (I + E_o^T Gamma_U) E_o^T U_{k+1} = E_o^T Uhat.
      for (int i = 0; i < s; ++i) observed_values_[i] = u_hat_[observed_[i]];
      if (s > 0) {
        // Into a separate vector: an in-place solve permutes with a temporary mask.
        observed_solution_.noalias() = coupling_lu_.solve(observed_values_);
        observed_values_ = observed_solution_;
      }
      x->displacement.col(j) = u_hat_;
      x->velocity.col(j) = v_hat_;
      x->previous_omega.col(j) = omega;
      // U_{k+1} = Uhat - Gamma_U x, V_{k+1} = Vhat - Gamma_V x,
      // omega_{k+1} = omegahat + h^2 (1 - theta) c_{k+1} S'^-1 W_obs E_o x,
      // y_{k+1} = yhat - h c_{k+1} S'^-1 W_obs E_o x,   x = E_o^T U_{k+1}.
      omega = omega_hat_;
      retrograde_velocity = y_hat_;
      for (int i = 0; i < s; ++i) {
        const double value = observed_values_[i], response = h * c_next * value;
        x->displacement.col(j) -= value * displacement_gamma_.col(i);
        x->velocity.col(j) -= value * velocity_gamma_.col(i);
        omega += (h * (1.0 - theta) * response) * reversed_solved_.col(i);
        retrograde_velocity -= response * reversed_solved_.col(i);
      }
    }
    // omegahat 2n, the mix 3n, the corrections of U, V, omega, y 4 s n, the s x s solve.
    ops_.CountMacs(x->displacement.cols() *
                   (5.0 * n_ + 4.0 * s * n_ + counts::LuSolve(s, 1) + 2.0 * s));
  }

  // omega_{k-1} of every column from (Z_k, U_k) by one retrograde step (R) with the
  // force c_k (W_obs U_k - b_k); the data only in column 0 when with_data. k >= 1.
  void SetPreviousOmega(int k, bool with_data, CoupledColumns* x) {
    const double c_now = ops_.QuadratureWeight(k);
    for (int j = 0; j < x->displacement.cols(); ++j) {
      ops_.ObservationProduct(x->displacement.col(j), force_);
      force_ *= c_now;
      if (with_data && j == 0) ops_.AddWeightedData(k, -c_now, force_);
      ops_.ThetaStep(x->omega.col(j), x->retrograde_velocity.col(j), &force_,
                     x->previous_omega.col(j), v_hat_);
    }
  }

 private:
  DiscreteMcreOperators& ops_;
  int n_;
  const std::vector<int> observed_;  // o_1..o_s
  // S'^-1 W_obs E_o, Gamma_U = theta^2 (1 - theta)^2 h^4 S^-1 Kp S'^-1 W_obs E_o and
  // Gamma_V = theta (1 - theta)^2 h^3 S^-1 Kp S'^-1 W_obs E_o, n x s each.
  Matrix reversed_solved_, displacement_gamma_, velocity_gamma_;
  Eigen::PartialPivLU<Matrix> coupling_lu_;  // of I + E_o^T Gamma_U
  Vector y_hat_, omega_hat_, mixed_, force_, u_hat_, v_hat_, observed_values_,
      observed_solution_;  // scratch
};

// The unknowns of shooting are full states in energy coordinates
// (discrete_mcre_operators.h): x = (Lp^T U, Lm^T V, Lp^T omega, Lm^T y), 4n, so that
// |x|^2 is the energy of the direct state plus that of the retrograde one.
enum StateBlock { kDisplacement = 0, kVelocity = 1, kOmega = 2, kRetrogradeVelocity = 3 };

// Writes the coordinates of column j of x into `state` (4n).
void StateCoordinates(const CoupledColumns& x, int j, DiscreteMcreOperators* ops,
                      Eigen::Ref<Vector> state) {
  const int n = static_cast<int>(x.displacement.rows());
  ops->ToEnergyCoordinates(x.displacement.col(j), x.velocity.col(j),
                           state.segment(kDisplacement * n, n), state.segment(kVelocity * n, n));
  ops->ToEnergyCoordinates(x.omega.col(j), x.retrograde_velocity.col(j),
                           state.segment(kOmega * n, n), state.segment(kRetrogradeVelocity * n, n));
}

// Sets column j of x to the state of the given coordinates.
void SetStateFromCoordinates(const Eigen::Ref<const Vector>& state, int j,
                             DiscreteMcreOperators* ops, CoupledColumns* x) {
  const int n = static_cast<int>(x->displacement.rows());
  x->displacement.col(j) = state.segment(kDisplacement * n, n);
  x->velocity.col(j) = state.segment(kVelocity * n, n);
  x->omega.col(j) = state.segment(kOmega * n, n);
  x->retrograde_velocity.col(j) = state.segment(kRetrogradeVelocity * n, n);
  ops->FromEnergyCoordinates(x->displacement.col(j), x->velocity.col(j));
  ops->FromEnergyCoordinates(x->omega.col(j), x->retrograde_velocity.col(j));
}

// The growth of the fundamental solutions (columns 1.. of x, started from unit
// coordinates): the largest coordinate norm among them.
double FundamentalGrowth(const CoupledColumns& x, DiscreteMcreOperators* ops, Vector* scratch) {
  double largest = 0.0;
  for (int j = 1; j < x.displacement.cols(); ++j) {
    StateCoordinates(x, j, ops, *scratch);
    largest = std::max(largest, scratch->squaredNorm());
  }
  ops->CountMacs((x.displacement.cols() - 1.0) * scratch->size());
  return std::sqrt(largest);
}

constexpr int kGrowthCheckInterval = 4;

// Bytes of the shooting solver's dense storage for `segments` segments: the
// triangular factor and coupling block of every stage (4n x 4n each), the columns
// of one segment's march (5 fields of n x (4n + 1)) and the stage's panel (6n x (8n + 1))
// with its transformed copy, and the march's three n x s blocks on the s observed dofs.
double ShootingBytes(int num_nodes, int segments, int num_observed) {
  const double n = num_nodes;
  return 8.0 * (segments * (32.0 * n * n + 4.0 * n) + 5.0 * n * (4.0 * n + 1.0) +
                2.0 * 6.0 * n * (8.0 * n + 1.0) + 3.0 * n * num_observed);
}

// One stage of the staircase QR, kept for the back substitution:
// R_s x_s + F_s x_{s+1} = f_s.
struct StageFactor {
  Matrix triangular;  // R_s, upper triangular
  Matrix coupling;    // F_s
  Vector rhs;         // f_s
};

// The staircase QR as it goes, segment by segment: the segments' first levels, the
// stages eliminated so far, the rows carried into the next block, and the extremes
// of |diag R| over all stages (the multiple-shooting condition estimate).
struct Staircase {
  std::vector<int> starts;
  std::vector<StageFactor> stages;
  Matrix carry;  // rows left over for the next block, and their right-hand side
  Vector carry_rhs;
  Vector start_solution;  // the unknown of the last block, once solved
  double condition = 0.0;
  double largest_diagonal = 0.0, smallest_diagonal = std::numeric_limits<double>::infinity();

  // Widens the extremes of |diag R| by the diagonal of one more triangular factor.
  void TrackDiagonal(const Vector& diagonal) {
    largest_diagonal = std::max(largest_diagonal, diagonal.maxCoeff());
    smallest_diagonal = std::min(smallest_diagonal, diagonal.minCoeff());
  }
};

// The failure message when `segments` segments' dense storage exceeds the limit.
std::string ShootingMemoryMessage(const char* name, double bytes, int segments, int num_nodes,
                                  long limit) {
  std::ostringstream why;
  why << name << " needs at least " << static_cast<long long>(bytes) << " bytes (" << segments
      << " segments of 4n x 4n factors, n = " << num_nodes << " dofs), above the limit of " << limit
      << " bytes (inner.max_dense_solver_bytes); use inner.method: conjugate_gradient or auto, "
         "which hold no dense n x n block, or raise inner.max_dense_solver_bytes";
  return why.str();
}

// Sets columns to the particular column 0 and `block` unit columns (coordinates
// offset.. of the state) at level first, then marches them with the data until the
// fundamental columns have grown by shooting_segment_growth (multiple shooting,
// checked every kGrowthCheckInterval steps) or to level m; returns the level reached.
int MarchSegment(const CoupledSolverOptions& options, bool multiple, int first, int block,
                 int offset, DiscreteMcreOperators* ops, CoupledMarch* march,
                 CoupledColumns* columns) {
  const int n = ops->num_nodes(), m = ops->num_steps();
  columns->SetZero(n, 1 + block);
  Vector unit(4 * n);
  for (int i = 0; i < block; ++i) {
    unit.setZero();
    unit[offset + i] = 1.0;
    SetStateFromCoordinates(unit, 1 + i, ops, columns);
  }
  if (first >= 1) march->SetPreviousOmega(first, true, columns);
  int end = first;
  while (end < m) {
    march->Step(end, true, columns);
    ++end;
    // The growth is checked every kGrowthCheckInterval steps (its cost is a fifth of
    // a step's), so a segment may overshoot the limit by a few steps' growth.
    if (multiple && end < m && (end - first) % kGrowthCheckInterval == 0 &&
        FundamentalGrowth(*columns, ops, &unit) > options.shooting_segment_growth) {
      break;
    }
  }
  return end;
}

// Eliminates block s (width `block`) of an inner segment: the rows
// [carry; x_{s+1} - G_s x_s = g_s] over the columns [block s | block s+1 | rhs] are
// reduced by a Householder QR of block s's columns into a stage and new carried rows.
void EliminateStage(const Matrix& transition, const Vector& particular, int block,
                    DiscreteMcreOperators* ops, Staircase* staircase) {
  const int four_n = 4 * ops->num_nodes();
  Matrix& carry = staircase->carry;
  Vector& carry_rhs = staircase->carry_rhs;
  const int carried = static_cast<int>(carry.rows());
  Matrix panel = Matrix::Zero(carried + four_n, block + four_n + 1);
  if (carried > 0) {
    panel.topLeftCorner(carried, block) = carry;
    panel.block(0, block + four_n, carried, 1) = carry_rhs;
  }
  panel.block(carried, 0, four_n, block) = -transition;
  panel.block(carried, block, four_n, four_n).setIdentity();
  panel.block(carried, block + four_n, four_n, 1) = particular;
  Eigen::HouseholderQR<Matrix> qr(panel.leftCols(block));
  Matrix rest = qr.householderQ().transpose() * panel.rightCols(four_n + 1);
  ops->CountMacs(counts::HouseholderQr(carried + four_n, block) +
                 counts::ApplyHouseholderReflectors(carried + four_n, block, four_n + 1));
  StageFactor stage;
  stage.triangular = qr.matrixQR().topRows(block).triangularView<Eigen::Upper>();
  stage.coupling = rest.topLeftCorner(block, four_n);
  stage.rhs = rest.topRightCorner(block, 1);
  carry = rest.bottomLeftCorner(carried + four_n - block, four_n);
  carry_rhs = rest.bottomRightCorner(carried + four_n - block, 1);
  const Vector diagonal = stage.triangular.diagonal().cwiseAbs();
  staircase->TrackDiagonal(diagonal);
  staircase->stages.push_back(std::move(stage));
}

// The last block's rows [carry; E_Z G x = -E_Z g] (square) and their right-hand side.
void AssembleLastBlock(const Staircase& staircase, const Matrix& transition,
                       const Vector& particular, int block, Matrix* last_rows, Vector* last_rhs) {
  const int carried = static_cast<int>(staircase.carry.rows());
  const int two_n = static_cast<int>(transition.rows()) / 2;
  last_rows->resize(carried + two_n, block);
  last_rhs->resize(carried + two_n);
  if (carried > 0) {
    last_rows->topRows(carried) = staircase.carry;
    last_rhs->head(carried) = staircase.carry_rhs;
  }
  last_rows->bottomRows(two_n) = transition.bottomRows(two_n);
  last_rhs->tail(two_n) = -particular.tail(two_n);
}

// The failure message when the final system's condition number is over the limit.
std::string ConditionMessage(const char* name, bool multiple, int s, double condition, double limit,
                             int m, double window) {
  std::ostringstream why;
  why << name << " breaks down: the " << (s == 0 ? "shooting matrix" : "multiple-shooting system")
      << " has condition number " << condition << " > " << limit
      << " (inner.shooting_condition_limit) over the window of " << m << " steps (" << window
      << " s, " << s + 1 << " segment" << (s == 0 ? "" : "s") << ")";
  if (!multiple) why << "; use multiple_shooting or riccati";
  return why.str();
}

// Solves the last block (block s, width `block`) into staircase->start_solution by
// an equilibrated (single shooting) Householder QR, after the condition number
// (into staircase->condition and the summary) has passed the limit. Returns the
// failure message, or an empty string on success.
std::string SolveLastBlock(const CoupledSolverOptions& options, const char* name, int s,
                           const Matrix& transition, const Vector& particular, int block,
                           DiscreteMcreOperators* ops, Staircase* staircase,
                           CoupledSolverSummary* summary) {
  const bool multiple = options.type == CoupledSolverType::kMultipleShooting;
  const int m = ops->num_steps();
  const double window = m * ops->time_step();
  Matrix last_rows;
  Vector last_rhs;
  AssembleLastBlock(*staircase, transition, particular, block, &last_rows, &last_rhs);
  // Single shooting: equilibrate the shooting matrix (rows, then columns, to unit
  // largest entry) so that its condition number does not depend on units. Multiple
  // shooting keeps the scaling of the earlier stages (one global QR).
  Vector row_scale = Vector::Ones(block), column_scale = Vector::Ones(block);
  if (s == 0) {
    row_scale = last_rows.rowwise().lpNorm<Eigen::Infinity>().cwiseInverse();
    column_scale = (row_scale.asDiagonal() * last_rows)
                       .colwise()
                       .lpNorm<Eigen::Infinity>()
                       .transpose()
                       .cwiseInverse();
  }
  const Matrix equilibrated = row_scale.asDiagonal() * last_rows * column_scale.asDiagonal();
  ops->CountMacs(2.0 * last_rows.size() + block);
  if (!equilibrated.allFinite()) {
    return std::string(name) + " breaks down: the final shooting block has a zero or " +
           "non-finite row or column over the window of " + std::to_string(m) + " steps";
  }
  Eigen::HouseholderQR<Matrix> qr(equilibrated);
  ops->CountMacs(counts::HouseholderQr(block, block));
  const Vector diagonal = qr.matrixQR().diagonal().cwiseAbs();
  staircase->TrackDiagonal(diagonal);
  double& condition = staircase->condition;
  if (s == 0) {
    const Vector singular = Eigen::BDCSVD<Matrix>(equilibrated).singularValues();
    ops->CountMacs(counts::SingularValues(block));
    condition = singular[0] / singular[singular.size() - 1];
  } else {
    condition = staircase->largest_diagonal / staircase->smallest_diagonal;
  }
  summary->shooting_condition_number = condition;
  if (!std::isfinite(condition) || condition > options.shooting_condition_limit) {
    return ConditionMessage(name, multiple, s, condition, options.shooting_condition_limit, m,
                            window);
  }
  Vector transformed = qr.householderQ().transpose() * (row_scale.asDiagonal() * last_rhs);
  qr.matrixQR().triangularView<Eigen::Upper>().solveInPlace(transformed);
  staircase->start_solution = column_scale.asDiagonal() * transformed;
  ops->CountMacs(counts::ApplyHouseholderReflectors(block, block, 1) +
                 counts::TriangularSolve(block, 1) + 2.0 * block);
  return "";
}

// Back substitution x_s = R_s^-1 (f_s - F_s x_{s+1}): the start states of the
// segments (in coordinates; the first one is Z_0 alone, 2n).
std::vector<Vector> BackSubstitute(const Staircase& staircase, DiscreteMcreOperators* ops) {
  const int four_n = 4 * ops->num_nodes();
  const std::vector<StageFactor>& stages = staircase.stages;
  const int segments = static_cast<int>(staircase.starts.size());
  std::vector<Vector> start_states(segments);
  start_states[segments - 1] = staircase.start_solution;
  for (int s = segments - 2; s >= 0; --s) {
    Vector x = stages[s].rhs - stages[s].coupling * start_states[s + 1];
    stages[s].triangular.triangularView<Eigen::Upper>().solveInPlace(x);
    start_states[s] = x;
    ops->CountMacs(counts::DenseProduct(stages[s].rhs.size(), four_n, 1) +
                   counts::TriangularSolve(stages[s].rhs.size(), 1));
  }
  return start_states;
}

// Marches each segment once more from its start state with the data, recording U
// and W_k = (chi theta omega_{k-1} + (1 - theta) omega_k) / c_k into the solution.
void RecordShootingSolution(const std::vector<int>& starts, const std::vector<Vector>& start_states,
                            CoupledProblem* problem, DiscreteMcreOperators* ops,
                            CoupledMarch* march, CoupledColumns* columns,
                            CoupledSolution* solution) {
  const int n = problem->num_nodes(), m = problem->num_steps(), two_n = 2 * n, four_n = 4 * n;
  const int segments = static_cast<int>(starts.size());
  const double theta = problem->theta();
  Matrix& displacement = solution->displacement;
  Matrix& retrograde = solution->retrograde;
  displacement = problem->ZeroField();
  retrograde = problem->ZeroField();
  auto record = [&](int k, const CoupledColumns& x) {
    const double chi = k >= 1 ? 1.0 : 0.0;
    displacement.col(k) = x.displacement.col(0);
    retrograde.col(k) = (chi * theta * x.previous_omega.col(0) + (1.0 - theta) * x.omega.col(0)) /
                        problem->QuadratureWeight(k);
    ops->CountMacs(3.0 * n);
  };
  Vector state(four_n);
  for (int s = 0; s < segments; ++s) {
    const int first = starts[s], end = s + 1 < segments ? starts[s + 1] : m;
    columns->SetZero(n, 1);
    state.setZero();
    if (s == 0) {
      state.tail(two_n) = start_states[0];
    } else {
      state = start_states[s];
    }
    SetStateFromCoordinates(state, 0, ops, columns);
    if (first >= 1) march->SetPreviousOmega(first, true, columns);
    for (int k = first; k < end; ++k) {
      record(k, *columns);
      march->Step(k, true, columns);
    }
    if (end == m) record(m, *columns);
  }
}

}  // namespace

void SolveByShooting(const CoupledSolverOptions& options, CoupledProblem* problem,
                     CoupledSolution* solution, CoupledSolverSummary* summary) {
  const bool multiple = options.type == CoupledSolverType::kMultipleShooting;
  const char* name = CoupledSolverTypeToString(options.type);
  const int n = problem->num_nodes(), m = problem->num_steps(), two_n = 2 * n, four_n = 4 * n;
  summary->iterations = 0;
  // The dense storage of the first segment, checked before any of it is allocated.
  const int num_observed = static_cast<int>(ObservedDofs(problem->WeightedObservation()).size());
  const double first_bytes = ShootingBytes(n, 1, num_observed);
  if (first_bytes > static_cast<double>(options.max_dense_solver_bytes)) {
    summary->termination = TerminationType::kFailure;
    summary->message =
        ShootingMemoryMessage(name, first_bytes, 1, n, options.max_dense_solver_bytes);
    return;
  }
  std::unique_ptr<DiscreteMcreOperators> operators;
  std::unique_ptr<CoupledMarch> coupled_march;
  try {
    operators = std::make_unique<DiscreteMcreOperators>(*problem);
    coupled_march = std::make_unique<CoupledMarch>(operators.get());
  } catch (const std::runtime_error& error) {
    summary->termination = TerminationType::kFailure;
    summary->message = std::string(name) + " does not apply: " + error.what() +
                       "; use inner.method: conjugate_gradient or all_at_once";
    return;
  }
  DiscreteMcreOperators& ops = *operators;
  CoupledMarch& march = *coupled_march;
  const double window = m * problem->time_step();
  auto fail = [&](const std::string& why) {
    summary->termination = TerminationType::kFailure;
    summary->message = why;
    summary->multiply_accumulates = ops.macs();
  };

  // Segment by segment: march the particular column 0 (with the data) and the unit
  // columns of the segment's unknown start state until the fundamental columns have
  // grown by shooting_segment_growth (multiple shooting) or to the end, then
  // eliminate the segment's block of unknowns.
  Staircase staircase;
  CoupledColumns columns;
  for (int first = 0; first < m;) {
    const int s = static_cast<int>(staircase.starts.size());
    staircase.starts.push_back(first);
    summary->shooting_segments = s + 1;
    const double bytes = ShootingBytes(n, s + 1, ops.num_observed());
    if (bytes > static_cast<double>(options.max_dense_solver_bytes)) {
      fail(ShootingMemoryMessage(name, bytes, s + 1, n, options.max_dense_solver_bytes));
      return;
    }
    // Block s: Z_0 (2n) for the first segment, the full state (4n) after.
    const int block = s == 0 ? two_n : four_n;
    const int offset = s == 0 ? two_n : 0;  // where the block's unknowns sit in the state
    const int end = MarchSegment(options, multiple, first, block, offset, &ops, &march, &columns);
    // End states: G_s (4n x block) and g_s.
    Matrix transition(four_n, block);
    Vector particular(four_n);
    StateCoordinates(columns, 0, &ops, particular);
    for (int i = 0; i < block; ++i) StateCoordinates(columns, 1 + i, &ops, transition.col(i));
    if (!transition.allFinite() || !particular.allFinite()) {
      fail(std::string(name) + " breaks down: the fundamental matrix overflowed on the segment " +
           "of levels " + std::to_string(first) + ".." + std::to_string(end) + " (window of " +
           std::to_string(m) + " steps)" + (multiple ? "" : "; use multiple_shooting or riccati"));
      return;
    }
    if (end < m) {
      EliminateStage(transition, particular, block, &ops, &staircase);
    } else {
      const std::string why = SolveLastBlock(options, name, s, transition, particular, block, &ops,
                                             &staircase, summary);
      if (!why.empty()) {
        fail(why);
        return;
      }
    }
    first = end;
  }
  const int segments = static_cast<int>(staircase.starts.size());
  const std::vector<Vector> start_states = BackSubstitute(staircase, &ops);
  RecordShootingSolution(staircase.starts, start_states, problem, &ops, &march, &columns, solution);
  summary->multiply_accumulates = ops.macs();

  std::ostringstream description;
  description << name << " over " << m << " steps (" << window << " s) in " << segments
              << " segment" << (segments == 1 ? "" : "s") << ", condition number "
              << ScientificString(staircase.condition) << (segments == 1 ? "" : " (lower bound)");
  CheckDirectSolution(options, description.str(), problem, *solution, summary);
}

}  // namespace mcrewave::internal
