// The discrete Riccati (sweep) solver of the coupled MCRE system (D1, D2, R1, R2,
// R3 of docs/discrete_mcre.md), derived in docs/riccati_shooting.md section 2.
//
// Forward state Y_k = (U_k, V_k), retrograde state Z_k = (omega_k, y_k) (y the
// retrograde velocity v of R1, R2), both 2n. One theta step is
// (u', v') = Phi (u, v) + Psi f with Psi f = (h^2 theta S^-1 f, h S^-1 f)
// (discrete_mcre_operators.h), so that
//
//   (D)  Y_{k+1} = Phi Y_k + Psi [F~theta_k - Kp (theta W_{k+1} + (1 - theta) W_k)]
//   (R)  Z_{j-1} = Phi Z_j + Psi c_j (W_obs U_j - b_j)
//   (R3) c_j W_j = chi_j theta omega_{j-1} + (1 - theta) omega_j,  chi_j = [j >= 1].
//
// with F~theta_k = theta G F~_{k+1} + (1 - theta) G F~_k, the data term
// W_obs = H^T diag(beta) H and the weighted data b_j = H^T diag(beta) d~_j (the paper's
// end sensors: W_obs = beta B, b_j = beta U~_j).
// The sweep keeps Z_k = P_k Y_k + q_k, from P_m = 0, q_m = 0 (the final condition).
// W_k needs omega_{k-1}, which (R) gives explicitly from Z_k and U_k, so one step
// k+1 -> k of the sweep is (E_w picks the first n rows):
//
//   A_k = Phi P_{k+1} + c_{k+1} Psi W_obs E_U,   a_k = Phi q_{k+1} - c_{k+1} Psi b_{k+1}
//        (Z_k = A_k Y_{k+1} + a_k)
//   theta W_{k+1} + (1 - theta) W_k = C_k Y_{k+1} + delta_k S^-1 W_obs U_k + d_k,
//   C_k = (theta/c_{k+1}) [theta E_w A_k + (1 - theta) E_w P_{k+1}]
//         + ((1 - theta)/c_k) E_w [chi_k theta Phi + (1 - theta) I] A_k,
//   delta_k = chi_k theta^2 (1 - theta) h^2,
//   (D) becomes X_k Y_{k+1} = R_k Y_k + r_k with X_k = I + Psi Kp C_k, rank n:
//   N_k = I_n + C_k Psi Kp = I_n + h (h theta C_U + C_V) S^-1 Kp,   G_k = N_k^-1 C_k,
//   X_k^-1 = I - Psi Kp G_k                                          (Woodbury)
//   Q_k = A_k X_k^-1 = A_k - (A_k Psi Kp) G_k,
//   P_k = Q_k R_k = Q_k Phi - h delta_k (T_k S^-1) Kp S^-1 W_obs E_U,   T_k = Q_V + h theta Q_U,
//   q_k = Q_k Psi e_k + a_k,   e_k = F~theta_k - Kp d_k.
//
// The forward pass from Y_0 = 0 needs only G_k and e_k:
//   z = Phi Y_k + Psi (e_k - delta_k Kp S^-1 W_obs U_k),   Y_{k+1} = z - Psi Kp (G_k z),
// and W follows from U by one retrograde sweep (R, R3). Stored: G_k (n x 2n) and e_k
// (n) for every step, 8 m (2 n^2 + n) bytes; P_k itself is kept for one step only.
// Work per step: the LU of N_k (n^3/3), G_k (2 n^3), the product (A Psi Kp) G_k
// (4 n^3), the data term's (T S^-1) Kp S^-1 W_obs E_o (2 n^2 s, s observed dofs) and
// O(n^2) band operations on the columns. W_obs = E_o W_s E_o^T lives on the s observed
// dofs (discrete_mcre_operators.h), so W_obs E_U touches s columns of the U block only.

#include <Eigen/LU>
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

// Working matrices of the sweep, in units of n^2 doubles: P, A, Q (4 each), the
// n x 2n blocks E_w Phi A, C, G, Ahat^T, (A Psi Kp)^T, T^T, K T^T, R T^T (2 each) and
// the n x n blocks Chat^T, its image, N and its LU (1 each).
constexpr double kWorkingMatrices = 3 * 4 + 8 * 2 + 4 * 1;

// The data term's blocks, in units of n s doubles (s observed dofs): Psi W_obs E_o
// (2), Kp S^-1 W_obs E_o (1) and (T S^-1) Kp S^-1 W_obs E_o (2).
constexpr double kObservedBlocks = 5;

double RiccatiBytes(int num_nodes, int num_steps, int num_observed) {
  const double n = num_nodes;
  return 8.0 * (num_steps * (2.0 * n * n + n) + kWorkingMatrices * n * n +
                kObservedBlocks * n * num_observed);
}

// The sweep's operators, its constant end vectors and its working matrices (those
// counted by kWorkingMatrices), the stored gains G_k and inputs e_k, and one helper
// per stage of the backward step k+1 -> k and of the forward pass (the formulas of
// the top of this file; docs/riccati_shooting.md section 2).
class RiccatiSweep {
 public:
  // Factorises the operators at the problem's modulus and forms the end vectors; the
  // problem must outlive the sweep.
  explicit RiccatiSweep(const CoupledProblem& problem);

  // The backward sweep from P_m = 0, q_m = 0: the gains G_k and inputs e_k, k = m-1..0.
  void Backward();
  // The forward pass from Y_0 = 0 into displacement (columns 1..m; column 0 stays).
  void Forward(Matrix* displacement);
  // The operators, which count the sweep's multiply-accumulates.
  DiscreteMcreOperators& ops() { return ops_; }

 private:
  // A_k = Phi P_{k+1} + c_{k+1} Psi W_obs E_U and a_k, then E_w Phi A_k and E_w Phi a_k.
  void Propagate(int k);
  // C_k into coupling_; returns d_k.
  Vector Coupling(int k);
  // N_k and G_k = N_k^-1 C_k into gains_[k].
  void Gain(int k);
  // Q_k = A_k - (A_k Psi Kp) G_k into projected_.
  void Project(int k);
  // e_k = F~theta_k - Kp d_k into input_ and forward_inputs_.col(k).
  void ForwardInput(int k, const Vector& coupling_offset);
  // q_k = Q_k Psi e_k + a_k into offset_.
  void UpdateOffset();
  // P_k = Q_k Phi - h delta (T S^-1) Kp S^-1 W_obs E_U into riccati_.
  void UpdateRiccati();

  DiscreteMcreOperators ops_;
  const int n_, m_, two_n_;
  const double h_, theta_;
  // delta = theta^2 (1 - theta) h^2: the weight of S^-1 W_obs U_k in W_k through omega_{k-1}.
  const double delta_;
  const std::vector<int> observed_;  // o_1..o_s
  // Kp S^-1 W_obs E_o (n x s) and Psi W_obs E_o = (h^2 theta S^-1 W_obs E_o,
  // h S^-1 W_obs E_o) (2n x s).
  Matrix penalty_step_solved_observed_, psi_observed_;
  Matrix observed_correction_;  // (T S^-1) Kp S^-1 W_obs E_o, 2n x s

  Matrix riccati_;                     // P_{k+1}, then P_k
  Vector offset_;                      // q_{k+1}, then q_k
  std::vector<Matrix> gains_;          // G_k, n x 2n
  Matrix forward_inputs_;              // e_k
  Matrix propagated_;                  // A_k
  Matrix propagated_step_top_;         // E_w Phi A_k
  Matrix coupling_;                    // C_k
  Matrix combined_transposed_;         // Chat^T, then S^-1 Chat^T
  Matrix woodbury_image_;              // Kp S^-1 Chat^T
  Matrix projected_;                   // Q_k
  Matrix columns_transposed_;          // Ahat^T, then T^T (solved in place)
  Matrix penalty_columns_transposed_;  // (A Psi Kp)^T / h
  Matrix stiffness_columns_, free_state_columns_;
  Eigen::PartialPivLU<Matrix> woodbury_lu_;
  Vector force_, offset_propagated_, offset_step_top_, scratch_, scratch_v_;
  Vector data_term_, input_, psi_input_;
};

RiccatiSweep::RiccatiSweep(const CoupledProblem& problem)
    : ops_(problem),
      n_(ops_.num_nodes()),
      m_(ops_.num_steps()),
      two_n_(2 * n_),
      h_(ops_.time_step()),
      theta_(ops_.theta()),
      delta_(theta_ * theta_ * (1.0 - theta_) * h_ * h_),
      observed_(ops_.observed_dofs()),
      penalty_step_solved_observed_(n_, observed_.size()),
      psi_observed_(two_n_, observed_.size()),
      observed_correction_(two_n_, observed_.size()),
      riccati_(Matrix::Zero(two_n_, two_n_)),
      offset_(Vector::Zero(two_n_)),
      gains_(m_),
      forward_inputs_(n_, m_),
      propagated_(two_n_, two_n_),
      propagated_step_top_(n_, two_n_),
      coupling_(n_, two_n_),
      combined_transposed_(n_, n_),
      woodbury_image_(n_, n_),
      projected_(two_n_, two_n_),
      columns_transposed_(n_, two_n_),
      penalty_columns_transposed_(n_, two_n_),
      stiffness_columns_(n_, two_n_),
      free_state_columns_(n_, two_n_),
      woodbury_lu_(n_),
      force_(n_),
      offset_propagated_(two_n_),
      offset_step_top_(n_),
      scratch_(n_),
      scratch_v_(n_),
      data_term_(n_),
      input_(n_),
      psi_input_(two_n_) {
  for (int i = 0; i < static_cast<int>(observed_.size()); ++i) {
    // S^-1 W_obs e_{o_i}, then Kp S^-1 W_obs e_{o_i} and Psi W_obs e_{o_i}.
    Vector step_solved = ops_.ObservationColumn(i);
    ops_.SolveStep(step_solved);
    ops_.PenaltyProduct(step_solved, penalty_step_solved_observed_.col(i));
    psi_observed_.col(i) << (h_ * h_ * theta_) * step_solved, h_ * step_solved;
    ops_.CountMacs(2.0 * n_);
  }
}

void RiccatiSweep::Backward() {
  for (int k = m_ - 1; k >= 0; --k) {
    Propagate(k);
    const Vector coupling_offset = Coupling(k);
    Gain(k);
    Project(k);
    ForwardInput(k, coupling_offset);
    if (k == 0) break;  // P_0, q_0 are not needed: Y_0 = 0 is known.
    UpdateOffset();
    UpdateRiccati();
  }
}

void RiccatiSweep::Propagate(int k) {
  const int n = n_, two_n = two_n_;
  const double c_next = ops_.QuadratureWeight(k + 1);
  // A_k = Phi P_{k+1} + c_{k+1} Psi W_obs E_U  (W_obs E_U: the U columns of the observed dofs).
  for (int j = 0; j < two_n; ++j) {
    ops_.ThetaStep(riccati_.col(j).head(n), riccati_.col(j).tail(n), nullptr,
                   propagated_.col(j).head(n), propagated_.col(j).tail(n));
  }
  for (int i = 0; i < static_cast<int>(observed_.size()); ++i) {
    propagated_.col(observed_[i]) += c_next * psi_observed_.col(i);
  }
  ops_.CountMacs(static_cast<double>(observed_.size()) * two_n);
  // a_k = Phi q_{k+1} + Psi (-c_{k+1} b_{k+1}).
  force_.setZero();
  ops_.AddWeightedData(k + 1, -c_next, force_);
  ops_.ThetaStep(offset_.head(n), offset_.tail(n), &force_, offset_propagated_.head(n),
                 offset_propagated_.tail(n));

  // E_w Phi A_k and E_w Phi a_k: the omega part of one more retrograde step, which
  // gives omega_{k-1} (its force c_k (W_obs U_k - b_k) enters through delta and d).
  for (int j = 0; j < two_n; ++j) {
    ops_.ThetaStep(propagated_.col(j).head(n), propagated_.col(j).tail(n), nullptr,
                   propagated_step_top_.col(j), scratch_v_);
  }
  ops_.ThetaStep(offset_propagated_.head(n), offset_propagated_.tail(n), nullptr, offset_step_top_,
                 scratch_v_);
}

Vector RiccatiSweep::Coupling(int k) {
  const int n = n_, two_n = two_n_;
  const double theta = theta_;
  const double c_next = ops_.QuadratureWeight(k + 1), c_now = ops_.QuadratureWeight(k);
  const double chi = k >= 1 ? 1.0 : 0.0;
  // C_k = (theta/c_{k+1}) [theta A_w + (1 - theta) P_w]
  //       + ((1 - theta)/c_k) [chi theta (E_w Phi A) + (1 - theta) A_w],  A_w = E_w A_k.
  const double weight_next = theta / c_next, weight_now = (1.0 - theta) / c_now;
  const double on_propagated = weight_next * theta + weight_now * (1.0 - theta);
  const double on_riccati = weight_next * (1.0 - theta);
  const double on_step = weight_now * chi * theta;
  coupling_ = on_propagated * propagated_.topRows(n) + on_riccati * riccati_.topRows(n) +
              on_step * propagated_step_top_;
  ops_.CountMacs(3.0 * n * two_n);
  // d_k: the same combination of the offsets, minus delta S^-1 b_k (the data part of
  // omega_{k-1}'s force, chi theta (1 - theta) E_w Psi b_k).
  Vector coupling_offset = on_propagated * offset_propagated_.head(n) +
                           on_riccati * offset_.head(n) + on_step * offset_step_top_;
  data_term_.setZero();
  ops_.AddWeightedData(k, 1.0, data_term_);
  ops_.SolveStep(data_term_);
  coupling_offset -= (chi * delta_) * data_term_;
  ops_.CountMacs(4.0 * n);
  return coupling_offset;
}

void RiccatiSweep::Gain(int k) {
  const int n = n_, two_n = two_n_;
  const double h = h_, theta = theta_;
  // N_k = I + h Chat S^-1 Kp = I + h (Kp S^-1 Chat^T)^T,  Chat = h theta C_U + C_V.
  combined_transposed_ = ((h * theta) * coupling_.leftCols(n) + coupling_.rightCols(n)).transpose();
  ops_.CountMacs(static_cast<double>(n) * n);
  for (int j = 0; j < n; ++j) {
    ops_.SolveStep(combined_transposed_.col(j));
    ops_.PenaltyProduct(combined_transposed_.col(j), woodbury_image_.col(j));
  }
  Matrix woodbury = h * woodbury_image_.transpose();
  woodbury.diagonal().array() += 1.0;
  ops_.CountMacs(static_cast<double>(n) * n);
  // G_k = N_k^-1 C_k.
  woodbury_lu_.compute(woodbury);
  gains_[k] = woodbury_lu_.solve(coupling_);
  ops_.CountMacs(counts::LuFactorization(n) + counts::LuSolve(n, two_n));
}

void RiccatiSweep::Project(int k) {
  const int n = n_, two_n = two_n_;
  const double h = h_, theta = theta_;
  // A_k Psi Kp = h Ahat S^-1 Kp = h (Kp S^-1 Ahat^T)^T,  Ahat = h theta A_U + A_V.
  columns_transposed_ =
      ((h * theta) * propagated_.leftCols(n) + propagated_.rightCols(n)).transpose();
  ops_.CountMacs(static_cast<double>(two_n) * n);
  for (int j = 0; j < two_n; ++j) {
    ops_.SolveStep(columns_transposed_.col(j));
    ops_.PenaltyProduct(columns_transposed_.col(j), penalty_columns_transposed_.col(j));
  }
  // Q_k = A_k - (A_k Psi Kp) G_k.
  projected_ = propagated_;
  projected_.noalias() -= h * (penalty_columns_transposed_.transpose() * gains_[k]);
  ops_.CountMacs(counts::DenseProduct(two_n, n, two_n));
}

void RiccatiSweep::ForwardInput(int k, const Vector& coupling_offset) {
  // e_k = F~theta_k - Kp d_k, F~theta_k = theta G F~_{k+1} + (1 - theta) G F~_k.
  ops_.PenaltyProduct(coupling_offset, input_);
  input_ = -input_;
  ops_.AddMeasuredForce(k + 1, theta_, input_);
  ops_.AddMeasuredForce(k, 1.0 - theta_, input_);
  forward_inputs_.col(k) = input_;
}

void RiccatiSweep::UpdateOffset() {
  const int n = n_, two_n = two_n_;
  const double h = h_, theta = theta_;
  // q_k = Q_k Psi e_k + a_k.
  scratch_ = input_;
  ops_.SolveStep(scratch_);
  psi_input_ << (h * h * theta) * scratch_, h * scratch_;
  offset_ = offset_propagated_;
  offset_.noalias() += projected_ * psi_input_;
  ops_.CountMacs(2.0 * n + counts::DenseProduct(two_n, two_n, 1));
}

void RiccatiSweep::UpdateRiccati() {
  const int n = n_, two_n = two_n_;
  const double h = h_, theta = theta_;
  // P_k = Q_k Phi - h delta (T S^-1) Kp S^-1 W_obs E_U with T = Q_V + h theta Q_U:
  //   Q Phi = [Q_U - h (T S^-1) K,  h (1 - theta) Q_U + (T S^-1) R].
  columns_transposed_ =
      ((h * theta) * projected_.leftCols(n) + projected_.rightCols(n)).transpose();
  ops_.CountMacs(static_cast<double>(two_n) * n);
  for (int j = 0; j < two_n; ++j) {
    ops_.SolveStep(columns_transposed_.col(j));
    ops_.StiffnessProduct(columns_transposed_.col(j), stiffness_columns_.col(j));
    ops_.FreeStateProduct(columns_transposed_.col(j), free_state_columns_.col(j));
  }
  riccati_.leftCols(n) = projected_.leftCols(n) - h * stiffness_columns_.transpose();
  riccati_.rightCols(n) =
      (h * (1.0 - theta)) * projected_.leftCols(n) + free_state_columns_.transpose();
  ops_.CountMacs(3.0 * two_n * n);
  const int s = static_cast<int>(observed_.size());
  observed_correction_.noalias() = columns_transposed_.transpose() * penalty_step_solved_observed_;
  for (int i = 0; i < s; ++i) {
    riccati_.col(observed_[i]) -= (h * delta_) * observed_correction_.col(i);
  }
  ops_.CountMacs(counts::DenseProduct(two_n, n, s) + static_cast<double>(s) * two_n);
}

void RiccatiSweep::Forward(Matrix* displacement) {
  const int n = n_, two_n = two_n_;
  const double h = h_, theta = theta_;
  // z = Phi Y_k + Psi (e_k - delta_k Kp S^-1 W_obs U_k),  Y_{k+1} = z - Psi Kp (G_k z).
  Vector velocity = Vector::Zero(n), position = Vector::Zero(n);
  Vector next_position(n), next_velocity(n), gain_image(n), correction(n);
  for (int k = 0; k < m_; ++k) {
    force_ = forward_inputs_.col(k);
    if (k >= 1) {
      for (int i = 0; i < static_cast<int>(observed_.size()); ++i) {
        force_ -= (delta_ * position[observed_[i]]) * penalty_step_solved_observed_.col(i);
      }
      ops_.CountMacs(static_cast<double>(observed_.size()) * n);
    }
    ops_.ThetaStep(position, velocity, &force_, next_position, next_velocity);
    gain_image.noalias() = gains_[k].leftCols(n) * next_position;
    gain_image.noalias() += gains_[k].rightCols(n) * next_velocity;
    ops_.CountMacs(counts::DenseProduct(n, two_n, 1));
    ops_.PenaltyProduct(gain_image, correction);
    ops_.SolveStep(correction);
    position = next_position - (h * h * theta) * correction;
    velocity = next_velocity - h * correction;
    ops_.CountMacs(2.0 * n);
    displacement->col(k + 1) = position;
  }
}

}  // namespace

void SolveByRiccati(const CoupledSolverOptions& options, CoupledProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary) {
  const int n = problem->num_nodes(), m = problem->num_steps();
  summary->iterations = 0;
  const int s = static_cast<int>(ObservedDofs(problem->WeightedObservation()).size());
  const double bytes = RiccatiBytes(n, m, s);
  if (bytes > static_cast<double>(options.max_dense_solver_bytes)) {
    std::ostringstream why;
    why << "the Riccati solver needs " << static_cast<long long>(bytes)
        << " bytes (its gains G_k, n x 2n per step for the forward pass: 8 m (2 n^2 + n) + "
        << "8 (" << kWorkingMatrices << " n^2 + " << kObservedBlocks << " n s) with n = " << n
        << " dofs, m = " << m << " steps, s = " << s << " observed dofs), above the limit of "
        << options.max_dense_solver_bytes
        << " bytes (inner.max_dense_solver_bytes); use inner.method: conjugate_gradient or "
           "auto, which hold no dense n x n block, or raise inner.max_dense_solver_bytes";
    summary->termination = TerminationType::kFailure;
    summary->message = why.str();
    return;
  }
  std::unique_ptr<RiccatiSweep> sweep;
  try {
    sweep = std::make_unique<RiccatiSweep>(*problem);
  } catch (const std::runtime_error& error) {
    summary->termination = TerminationType::kFailure;
    summary->message = std::string("the Riccati solver does not apply: ") + error.what() +
                       "; use inner.method: conjugate_gradient or all_at_once";
    return;
  }
  DiscreteMcreOperators& ops = sweep->ops();
  sweep->Backward();
  Matrix& displacement = solution->displacement;
  displacement = problem->ZeroField();
  sweep->Forward(&displacement);
  // W from U: (R) backward from Z_m = 0 and (R3).
  problem->RetrogradeSweep(displacement, true, &solution->retrograde);
  ops.CountMacs(counts::RetrogradeSweep(n, ops.half_bandwidth(), m));
  summary->multiply_accumulates = ops.macs();

  std::ostringstream description;
  description << "Riccati sweep over " << m << " steps, dense 2n x 2n P_k (n = " << n
              << "), gains stored in " << static_cast<long long>(bytes) << " bytes";
  CheckDirectSolution(options, description.str(), problem, *solution, summary);
}

}  // namespace mcrewave::internal
