// The coupled problem on the sensor traces, as the streaming conjugate-gradient solver
// sees it (docs/streaming.md): what a coupled problem offers so that it is solved with
// O(n) states (or O(n sqrt(m)) checkpoints) instead of stored n x (m + 1) fields. A
// structure given by matrices (MatrixMcreProblem, matrix_mcre_problem.h), the built-in
// bar exported as matrices among them, implements it.
//
// A trace field y holds one row per observation row of H and one column per sample:
// num_traces() x (m + 1). The retrograde field depends on U only through y = H U, so
// the coupled problem is the fixed point y = Phi(y) with
//
//   Phi(y) = H Direct(Retrograde(y)),
//
// Retrograde(y) taking its load c_j H^T diag(beta) (y_j - d~_j) from y. With
// L y = Phi(y) - Phi(0), I - L is self-adjoint and positive definite in
// <a, b>_beta = sum_j c_j h sum_k beta_k a_kj b_kj on the weighted rows.
#pragma once

#include "mcrewave/mcre/coupled_problem.h"

namespace mcrewave {

class StreamingCoupledProblem : public CoupledProblem {
 public:
  // What a streaming application gathers at each sample when asked: the cost,
  // gradients and error maps of the fields it passes through, never stored. Entries a
  // structure has no use for stay empty (the bar: the zone maps, the element map and
  // G^T W; a matrix model: the element map and picture without element blocks).
  struct StreamingTotals {
    double cost = 0.0;      // e^2 [J s]
    Vector cost_gradients;  // de^2/dE_z [J s / Pa]
    // The bar: e_el^2 [J s] per element. A matrix model: the dof map
    // sum_j c_j h 1/2 W_ij (K W_j)_i [J s] (MatrixMcreProblem::DofErrorMap).
    Vector error_map;
    // A matrix model: each zone's share (E_z / E_z,nom) sum_j c_j h 1/2 W_j^T K_z W_j
    // [J s] (MatrixMcreProblem::ZoneErrorMap of W), and the same sum over U, the zone's
    // own strain energy (ZoneErrorMap of U).
    Vector zone_error_map, zone_strain_energy;
    // A matrix model with element blocks: e_el^2 per element [J s]
    // (mcre/element_error_map.h).
    Vector element_error_map;
    // The same: the sensitivity map de^2/d ln E_el per element [J s]
    // (MatrixMcreProblem::ElementSensitivities).
    Vector element_sensitivity;
    // The error map's space-time picture at every SpaceTimeStride(m)-th sample (rows):
    // the bar's gap energy density [J/m] on SpaceTimeColumnPositions (error_map.h); a
    // matrix model's element gap energy [J] on ElementColumnPositions
    // (element_error_map.h; empty without element blocks).
    Matrix gap_density;
    // A matrix model: G^T W_j of every load channel (G's columns), C x (m + 1) [m], from
    // which its forces F = F~ - diag(1/alpha) G^T W follow (MatrixMcreProblem::ModelChannels).
    Matrix load_retrograde;
    // ||omega_m|| / max_j ||omega_j|| of a retrograde state rebuilt by the reversed
    // recursion: 0 in exact arithmetic, the rebuild's round-off; 0 from checkpoints.
    double rebuild_error = 0.0;
  };

  // Rows of a trace field (the rows of H).
  virtual int num_traces() const = 0;
  Matrix ZeroTraces() const { return Matrix::Zero(num_traces(), num_steps() + 1); }
  // The data d~ in the trace rows' order: the traces at which the retrograde field
  // vanishes (W = 0).
  virtual Matrix DataTraces() const = 0;
  // <a, b>_beta = sum_j c_j h sum_k beta_k a_kj b_kj.
  virtual double TraceInnerProduct(const Matrix& a, const Matrix& b) const = 0;
  // ||R r||_P^2 = sum_j c_j h W_j^T P W_j for W = R r, the retrograde field driven by
  // the traces r without data: <r, -L r>_beta. One backward sweep, its state only.
  virtual double RetrogradeEnergy(const Matrix& traces) = 0;
  // image = Phi(traces) with the data (include_data), or its linear part without.
  // With totals (not null), the sums of the fields of that application are gathered.
  // traces and image of shape ZeroTraces(), distinct.
  virtual void StreamingMap(const Matrix& traces, bool include_data, Matrix* image,
                            StreamingTotals* totals = nullptr) = 0;
  // The streaming CG's preconditioner (inner.preconditioner: dense_traces,
  // docs/streaming.md section 6): makes M = I - L at moduli near the current ones
  // available, building it at the current moduli unless the one held was built where
  // every modulus was within rebuild_change (relative) of its value now. False when the
  // problem offers none (the default) or cannot build it (a row of weight 0, or
  // max_traces below num_traces() (m + 1)): CG then runs without.
  virtual bool PrepareTracePreconditioner(double rebuild_change, long max_traces) {
    (void)rebuild_change;
    (void)max_traces;
    return false;
  }
  // The next PrepareTracePreconditioner builds its factor anew, whatever the moduli, as
  // on a newly made problem (a problem may keep the factor's storage); nothing to do
  // for a problem that offers none (the default).
  virtual void ForgetTracePreconditioner() {}
  // result = M^-1 residual, of shape ZeroTraces(). Precondition: the last
  // PrepareTracePreconditioner returned true.
  virtual void PreconditionTraces(const Matrix& residual, Matrix* result) {
    (void)residual;
    (void)result;
  }
  // From now on, StreamingMap takes the retrograde field from checkpoints (exact)
  // rather than from a reversed recursion whose round-off drifted; nothing to do for a
  // problem that always uses them.
  virtual void UseCheckpoints() = 0;
  // The bytes a solve grants the retrograde field's history (inner.max_field_bytes,
  // passed by SolveCoupled before every streaming solve): a problem that can keep
  // omega's whole history within it sweeps omega once per application instead of
  // recomputing it from checkpoints, the same steps. Ignored by a problem that has no
  // such choice (the default).
  virtual void SetHistoryBudget(long bytes) { (void)bytes; }

  // --- What the outer objective needs beside the solves (mcre/objective.h) ---
  // J_rest [J s]: the functional of the structure left at rest (U = W = 0, zero loads),
  // which satisfies the state equation at any moduli, so 0 <= e^2 <= J_rest.
  virtual double RestCost() = 0;
  // The weight beta_k of each trace row (0 for a row left out).
  virtual Vector TraceWeights() const = 0;
  // traces = H U of the direct sweep with W = 0 and the measured loads (the structure
  // driven by the data alone, at the current moduli), num_traces() x (m + 1): the
  // predicted outputs whose valleys a global scan must resolve (optim/valley_spacing.h).
  // One direct sweep, its state only (no field stored); resizes traces.
  virtual void DataResponseTraces(Matrix* traces) = 0;
};

}  // namespace mcrewave
