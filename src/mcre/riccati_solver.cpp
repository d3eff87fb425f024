// The discrete Riccati (sweep) solver of the coupled MCRE system (D1, D2, R1, R2,
// R3 of docs/discrete_mcre.md), derived in docs/riccati_shooting.md section 2.
//
// Forward state Y_k = (U_k, V_k), retrograde state Z_k = (omega_k, y_k) (y the
// retrograde velocity v of R1, R2), both 2n. One theta step is
// (u', v') = Phi (u, v) + Psi f with Psi f = (h^2 theta S^-1 f, h S^-1 f)
// (discrete_mcre_operators.h), so that
//
//   (D)  Y_{k+1} = Phi Y_k + Psi [F~theta_k - Kp (theta W_{k+1} + (1 - theta) W_k)]
//   (R)  Z_{j-1} = Phi Z_j + Psi c_j beta (B U_j - U~_j)
//   (R3) c_j W_j = chi_j theta omega_{j-1} + (1 - theta) omega_j,  chi_j = [j >= 1].
//
// The sweep keeps Z_k = P_k Y_k + q_k, from P_m = 0, q_m = 0 (the final condition).
// W_k needs omega_{k-1}, which (R) gives explicitly from Z_k and U_k, so one step
// k+1 -> k of the sweep is (E_w picks the first n rows):
//
//   A_k = Phi P_{k+1} + c_{k+1} beta Psi B E_U,   a_k = Phi q_{k+1} - c_{k+1} beta Psi U~_{k+1}
//        (Z_k = A_k Y_{k+1} + a_k)
//   theta W_{k+1} + (1 - theta) W_k = C_k Y_{k+1} + delta_k S^-1 B U_k + d_k,
//   C_k = (theta/c_{k+1}) [theta E_w A_k + (1 - theta) E_w P_{k+1}]
//         + ((1 - theta)/c_k) E_w [chi_k theta Phi + (1 - theta) I] A_k,
//   delta_k = chi_k theta^2 (1 - theta) beta h^2,
//   (D) becomes X_k Y_{k+1} = R_k Y_k + r_k with X_k = I + Psi Kp C_k, rank n:
//   N_k = I_n + C_k Psi Kp = I_n + h (h theta C_U + C_V) S^-1 Kp,   G_k = N_k^-1 C_k,
//   X_k^-1 = I - Psi Kp G_k                                          (Woodbury)
//   Q_k = A_k X_k^-1 = A_k - (A_k Psi Kp) G_k,
//   P_k = Q_k R_k = Q_k Phi - h delta_k (T_k S^-1) Kp S^-1 B E_U,   T_k = Q_V + h theta Q_U,
//   q_k = Q_k Psi e_k + a_k,   e_k = F~theta_k - Kp d_k.
//
// The forward pass from Y_0 = 0 needs only G_k and e_k:
//   z = Phi Y_k + Psi (e_k - delta_k Kp S^-1 B U_k),   Y_{k+1} = z - Psi Kp (G_k z),
// and W follows from U by one retrograde sweep (R, R3). Stored: G_k (n x 2n) and e_k
// (n) for every step, 8 m (2 n^2 + n) bytes; P_k itself is kept for one step only.
// Work per step: the LU of N_k (n^3/3), G_k (2 n^3), the product (A Psi Kp) G_k
// (4 n^3), and O(n^2) band operations on the columns.

#include <Eigen/LU>
#include <array>
#include <sstream>
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

double RiccatiBytes(int num_nodes, int num_steps) {
  const double n = num_nodes;
  return 8.0 * (num_steps * (2.0 * n * n + n) + kWorkingMatrices * n * n);
}

}  // namespace

void SolveByRiccati(const CoupledSolverOptions& options, McreProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary) {
  const int n = problem->num_nodes(), m = problem->num_steps(), two_n = 2 * n, last = n - 1;
  summary->iterations = 0;
  const double bytes = RiccatiBytes(n, m);
  if (bytes > static_cast<double>(options.max_dense_solver_bytes)) {
    std::ostringstream why;
    why << "the Riccati solver needs " << static_cast<long long>(bytes)
        << " bytes (its gains G_k, n x 2n per step for the forward pass: 8 m (2 n^2 + n) + "
        << "8 * " << kWorkingMatrices << " n^2 with n = " << n << " nodes, m = " << m
        << " steps), above the limit of " << options.max_dense_solver_bytes
        << " bytes (inner.max_dense_solver_bytes); use conjugate_gradient";
    summary->message = why.str();
    return;
  }
  DiscreteMcreOperators ops(*problem);
  const double h = ops.time_step(), theta = ops.theta(), beta = ops.beta();
  // delta = theta^2 (1 - theta) beta h^2: the weight of U_k in W_k through omega_{k-1}.
  const double delta = theta * theta * (1.0 - theta) * beta * h * h;

  // S^-1 e_i, Kp S^-1 e_i and Psi e_i = (h^2 theta S^-1 e_i, h S^-1 e_i), i = 0, N.
  const std::array<int, 2> end_nodes{0, last};
  std::array<Vector, 2> step_solved_end, penalty_step_solved_end, psi_end;
  for (int i = 0; i < 2; ++i) {
    step_solved_end[i] = Vector::Unit(n, end_nodes[i]);
    ops.SolveStep(step_solved_end[i]);
    penalty_step_solved_end[i] = Vector::Zero(n);
    ops.PenaltyProduct(step_solved_end[i], penalty_step_solved_end[i]);
    psi_end[i].resize(two_n);
    psi_end[i] << (h * h * theta) * step_solved_end[i], h * step_solved_end[i];
    ops.CountMacs(2.0 * n);
  }

  Matrix riccati = Matrix::Zero(two_n, two_n);  // P_{k+1}, then P_k
  Vector offset = Vector::Zero(two_n);          // q_{k+1}, then q_k
  std::vector<Matrix> gains(m);                 // G_k, n x 2n
  Matrix forward_inputs(n, m);                  // e_k
  Matrix propagated(two_n, two_n);              // A_k
  Matrix propagated_step_top(n, two_n);         // E_w Phi A_k
  Matrix coupling(n, two_n);                    // C_k
  Matrix combined_transposed(n, n);             // Chat^T, then S^-1 Chat^T
  Matrix woodbury_image(n, n);                  // Kp S^-1 Chat^T
  Matrix projected(two_n, two_n);               // Q_k
  Matrix columns_transposed(n, two_n);          // Ahat^T, then T^T (solved in place)
  Matrix penalty_columns_transposed(n, two_n);  // (A Psi Kp)^T / h
  Matrix stiffness_columns(n, two_n), free_state_columns(n, two_n);
  Eigen::PartialPivLU<Matrix> woodbury_lu(n);
  Vector force(n), offset_propagated(two_n), offset_step_top(n), scratch(n), scratch_v(n);
  Vector data_term(n), input(n), psi_input(two_n);

  for (int k = m - 1; k >= 0; --k) {
    const double c_next = ops.QuadratureWeight(k + 1), c_now = ops.QuadratureWeight(k);
    const double chi = k >= 1 ? 1.0 : 0.0;

    // A_k = Phi P_{k+1} + c_{k+1} beta Psi B E_U  (B E_U: the U columns of the end nodes).
    for (int j = 0; j < two_n; ++j) {
      ops.ThetaStep(riccati.col(j).head(n), riccati.col(j).tail(n), nullptr,
                    propagated.col(j).head(n), propagated.col(j).tail(n));
    }
    for (int i = 0; i < 2; ++i) propagated.col(end_nodes[i]) += (c_next * beta) * psi_end[i];
    ops.CountMacs(2.0 * two_n);
    // a_k = Phi q_{k+1} + Psi (-c_{k+1} beta U~_{k+1}).
    force.setZero();
    ops.AddDisplacementData(k + 1, -c_next * beta, force);
    ops.ThetaStep(offset.head(n), offset.tail(n), &force, offset_propagated.head(n),
                  offset_propagated.tail(n));

    // E_w Phi A_k and E_w Phi a_k: the omega part of one more retrograde step, which
    // gives omega_{k-1} (its force c_k beta (B U_k - U~_k) enters through delta and d).
    for (int j = 0; j < two_n; ++j) {
      ops.ThetaStep(propagated.col(j).head(n), propagated.col(j).tail(n), nullptr,
                    propagated_step_top.col(j), scratch_v);
    }
    ops.ThetaStep(offset_propagated.head(n), offset_propagated.tail(n), nullptr, offset_step_top,
                  scratch_v);

    // C_k = (theta/c_{k+1}) [theta A_w + (1 - theta) P_w]
    //       + ((1 - theta)/c_k) [chi theta (E_w Phi A) + (1 - theta) A_w],  A_w = E_w A_k.
    const double weight_next = theta / c_next, weight_now = (1.0 - theta) / c_now;
    const double on_propagated = weight_next * theta + weight_now * (1.0 - theta);
    const double on_riccati = weight_next * (1.0 - theta);
    const double on_step = weight_now * chi * theta;
    coupling = on_propagated * propagated.topRows(n) + on_riccati * riccati.topRows(n) +
               on_step * propagated_step_top;
    ops.CountMacs(3.0 * n * two_n);
    // d_k: the same combination of the offsets, minus delta S^-1 U~_k (the data part of
    // omega_{k-1}'s force, chi theta (1 - theta) beta E_w Psi U~_k).
    Vector coupling_offset = on_propagated * offset_propagated.head(n) +
                             on_riccati * offset.head(n) + on_step * offset_step_top;
    data_term.setZero();
    ops.AddDisplacementData(k, 1.0, data_term);
    ops.SolveStep(data_term);
    coupling_offset -= (chi * delta) * data_term;
    ops.CountMacs(4.0 * n);

    // N_k = I + h Chat S^-1 Kp = I + h (Kp S^-1 Chat^T)^T,  Chat = h theta C_U + C_V.
    combined_transposed = ((h * theta) * coupling.leftCols(n) + coupling.rightCols(n)).transpose();
    ops.CountMacs(static_cast<double>(n) * n);
    for (int j = 0; j < n; ++j) {
      ops.SolveStep(combined_transposed.col(j));
      ops.PenaltyProduct(combined_transposed.col(j), woodbury_image.col(j));
    }
    Matrix woodbury = h * woodbury_image.transpose();
    woodbury.diagonal().array() += 1.0;
    ops.CountMacs(static_cast<double>(n) * n);
    // G_k = N_k^-1 C_k.
    woodbury_lu.compute(woodbury);
    gains[k] = woodbury_lu.solve(coupling);
    ops.CountMacs(counts::LuFactorization(n) + counts::LuSolve(n, two_n));

    // A_k Psi Kp = h Ahat S^-1 Kp = h (Kp S^-1 Ahat^T)^T,  Ahat = h theta A_U + A_V.
    columns_transposed =
        ((h * theta) * propagated.leftCols(n) + propagated.rightCols(n)).transpose();
    ops.CountMacs(static_cast<double>(two_n) * n);
    for (int j = 0; j < two_n; ++j) {
      ops.SolveStep(columns_transposed.col(j));
      ops.PenaltyProduct(columns_transposed.col(j), penalty_columns_transposed.col(j));
    }
    // Q_k = A_k - (A_k Psi Kp) G_k.
    projected = propagated;
    projected.noalias() -= h * (penalty_columns_transposed.transpose() * gains[k]);
    ops.CountMacs(counts::DenseProduct(two_n, n, two_n));

    // e_k = F~theta_k - Kp d_k, F~theta_k = theta F~_{k+1} + (1 - theta) F~_k.
    ops.PenaltyProduct(coupling_offset, input);
    input = -input;
    ops.AddForceData(k + 1, theta, input);
    ops.AddForceData(k, 1.0 - theta, input);
    forward_inputs.col(k) = input;
    if (k == 0) break;  // P_0, q_0 are not needed: Y_0 = 0 is known.

    // q_k = Q_k Psi e_k + a_k.
    scratch = input;
    ops.SolveStep(scratch);
    psi_input << (h * h * theta) * scratch, h * scratch;
    offset = offset_propagated;
    offset.noalias() += projected * psi_input;
    ops.CountMacs(2.0 * n + counts::DenseProduct(two_n, two_n, 1));

    // P_k = Q_k Phi - h delta (T S^-1) Kp S^-1 B E_U with T = Q_V + h theta Q_U:
    //   Q Phi = [Q_U - h (T S^-1) K,  h (1 - theta) Q_U + (T S^-1) R].
    columns_transposed = ((h * theta) * projected.leftCols(n) + projected.rightCols(n)).transpose();
    ops.CountMacs(static_cast<double>(two_n) * n);
    for (int j = 0; j < two_n; ++j) {
      ops.SolveStep(columns_transposed.col(j));
      ops.StiffnessProduct(columns_transposed.col(j), stiffness_columns.col(j));
      ops.FreeStateProduct(columns_transposed.col(j), free_state_columns.col(j));
    }
    riccati.leftCols(n) = projected.leftCols(n) - h * stiffness_columns.transpose();
    riccati.rightCols(n) =
        (h * (1.0 - theta)) * projected.leftCols(n) + free_state_columns.transpose();
    ops.CountMacs(3.0 * two_n * n);
    for (int i = 0; i < 2; ++i) {
      riccati.col(end_nodes[i]).noalias() -=
          (h * delta) * (columns_transposed.transpose() * penalty_step_solved_end[i]);
    }
    ops.CountMacs(2.0 * counts::DenseProduct(two_n, n, 1));
  }

  // Forward pass: z = Phi Y_k + Psi (e_k - delta_k Kp S^-1 B U_k),
  // Y_{k+1} = z - Psi Kp (G_k z).
  Matrix& displacement = solution->displacement;
  displacement = problem->ZeroField();
  Vector velocity = Vector::Zero(n), position = Vector::Zero(n);
  Vector next_position(n), next_velocity(n), gain_image(n), correction(n);
  for (int k = 0; k < m; ++k) {
    force = forward_inputs.col(k);
    if (k >= 1) {
      for (int i = 0; i < 2; ++i) {
        force -= (delta * position[end_nodes[i]]) * penalty_step_solved_end[i];
      }
      ops.CountMacs(2.0 * n);
    }
    ops.ThetaStep(position, velocity, &force, next_position, next_velocity);
    gain_image.noalias() = gains[k].leftCols(n) * next_position;
    gain_image.noalias() += gains[k].rightCols(n) * next_velocity;
    ops.CountMacs(counts::DenseProduct(n, two_n, 1));
    ops.PenaltyProduct(gain_image, correction);
    ops.SolveStep(correction);
    position = next_position - (h * h * theta) * correction;
    velocity = next_velocity - h * correction;
    ops.CountMacs(2.0 * n);
    displacement.col(k + 1) = position;
  }
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
