// The time-discrete coupled direct / retrograde MCRE problem of the built-in bar on its
// own band model, for one set of trial zone moduli (docs/discrete_mcre.md; zones and
// sensors: docs/zones_and_sensors.md): the tests' independent reference for
// MatrixMcreProblem on the bar exported as matrices (model/matrix_export.h), which
// identify run and the studies solve. The library held it as its bar road until
// issue 39; it lives here as the other code path the one road is checked against. It
// is a StreamingCoupledProblem, so every coupled solver runs on it.
//
// Fields are stored as n x (m + 1) matrices, column j = time t_j = j h:
// U (displacement), W (retrograde field, the constitutive gap). The problem owns
// one ThetaIntegrator, factorised once per set of moduli (SetModuli), and offers the
// two sweeps that every coupled solver is built from:
//
//   DirectSweep:      W -> U,  (D1, D2) forward with the force F~ - (K + B/alpha) W
//   RetrogradeSweep:  U -> W,  (R1, R2) backward with the force
//                              c_j H^T diag(beta_k) (H U_j - d~_j),
//                              then W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j
//
// and the inner product <x, y>_P in which the reduced operator A = I - G is
// self-adjoint, the cost e^2, its derivatives de^2/dE_z and the error map.
//
// The observation H stacks the end displacement rows e_0^T, e_N^T (each unless left
// out of data.channels) and one row per interior sensor of the data (u@X, e@X; rows of
// BarModel::DisplacementRow / StrainRow), with weights beta_u = w_u S E0 / L for
// displacements and beta_e = w_e S E0 L for strains. With the two end rows only, it is
// the paper's B = e_0 e_0^T + e_N e_N^T and every number is the one of the paper's case.
// The measured end forces f0, fL are the model's loads and keep their alpha term.
//
// Pinned clamp (ClampModel::kPinned, docs/trusted_clamp.md section 9): the paper's
// free-free model and data term, with two changes at x = 0. The datum of the u0 row
// is the known u(0) = 0 instead of the measured u0, with the weight
// beta_0 = w_u0 S E0 / L; and f0 stays a load, with alpha_0 = w_r L / (S E0) in place of
// alpha: the direct force is f0~ - W_0 / alpha_0, P = K + e_0 e_0^T / alpha_0 +
// e_N e_N^T / alpha and the cost's force term at x = 0 is W_0^2 / (2 alpha_0).
//
// Trusted clamp (ClampModel::kTrusted, docs/trusted_clamp.md): u(0) = 0 is imposed
// exactly instead of being a measured output. Row and column 0 of M and K are
// decoupled (their diagonals kept), so that U_0 = W_0 = 0 through every sweep: the
// fields keep their n = N + 1 rows and the bar's clamped dofs are those of the
// comparator. Then fL is the only load (P = K + e_N e_N^T / alpha), u0 is not an
// output, and f0 becomes one: the last row of the sensors is the clamp reaction of
// the kinematic field,
//   r(U) = K_01(E) U_1 = -(E_1 S / l_1) U_1,   weight alpha_r = w_r L / (S E0), data f0~,
// the stress of the first element, which equals -S sigma(0) to O(l^2) because
// sigma_x(0) = rho u_tt(0) = 0 at a fixed end. The row depends on the modulus E_1 of
// the first element's zone, so that de^2/dE_z gains the explicit term
//   sum_j c_j h alpha_r (r(U_j) / E_1) (r(U_j) - f0~_j)   (the zone of element 1).
#pragma once

#include <vector>

#include "mcrewave/data/measurement.h"
#include "mcrewave/linalg/sparse_bilinear_form.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/coupled_problem.h"
#include "mcrewave/mcre/mcre_weights.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/mcre/streaming_coupled_problem.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {
namespace testing {

class BarMcreProblem : public StreamingCoupledProblem {
 public:
  // Keeps references to model and data: both must outlive the problem.
  // reference_modulus is E0 of the weights [Pa]; theta of the time scheme. The zones
  // are the model's; every zone starts at the model's properties().modulus.
  // Precondition: data.num_steps() >= 1, weights valid, theta in [0, 1], every sensor
  // position in [0, L].
  // clamp: kTrusted imposes u(0) = 0 (ends.u0 is then ignored) and observes f0 with
  // weights.reaction_weight; kPinned keeps the free-free model, always observes u0
  // (ends.u0 = false is overridden) against the known 0 with
  // weights.clamp_displacement_weight and loads node 0 with f0 weighed by
  // weights.reaction_weight in place of alpha.
  BarMcreProblem(const BarModel& model, const ChannelSet& data, const McreWeights& weights,
                 double reference_modulus, double theta, EndDisplacementChannels ends = {},
                 ClampModel clamp = ClampModel::kMeasured);

  // Sets every zone's modulus to E [Pa] and refactorises the integrator (once per change);
  // hides CoupledProblem::SetModulus, since moduli() is empty until the first call.
  void SetModulus(double modulus);
  // Sets the zone moduli E_z [Pa] (model().num_zones() entries) and refactorises the
  // integrator when they changed: K = sum_z (E_z / E_nom) K_z, K_z = E_nom K1_z (E_nom
  // the model's modulus).
  void SetModuli(const Vector& zone_moduli) override;
  // The modulus of a one-zone model, else the first zone's [Pa].
  double modulus() const { return moduli_.size() > 0 ? moduli_[0] : 0.0; }
  const Vector& moduli() const override { return moduli_; }

  int num_nodes() const override { return model_.num_nodes(); }
  int num_steps() const override { return data_.num_steps(); }
  double time_step() const override { return data_.time_step; }
  double theta() const override { return theta_; }
  double alpha() const { return alpha_; }  // force weight [m/N]
  // 1 / alpha of f0: 1 / alpha (measured), 0 (trusted), 1 / alpha_0 (pinned) [N/m].
  double inverse_alpha0() const { return force0_gain_ / alpha0_; }
  double beta() const { return beta_; }                // displacement weight beta_u [N/m]
  double strain_beta() const { return strain_beta_; }  // strain weight beta_e [N m]
  const EndDisplacementChannels& end_channels() const { return ends_; }
  ClampModel clamp() const { return clamp_; }
  // The datum of the u0 row at sample j [m]: the measured u0, or 0 under a pinned clamp.
  double U0Datum(int j) const { return clamp_ == ClampModel::kPinned ? 0.0 : measured_.u0[j]; }
  // Trusted clamp: the reaction r(U_j) = K_01(E) U_1 [N] of the displacement column
  // U_j (n entries); 0 when the clamp is measured or pinned.
  double ClampReaction(const double* displacement) const {
    return reaction_row_ >= 0 ? sensor_rows_[reaction_row_].Apply(displacement) : 0.0;
  }
  // Number of sensor rows of H besides the end displacements: the interior sensors of
  // the data (u@X, e@X), then the clamp reaction when the clamp is trusted; 0 in the
  // paper's case.
  int num_interior_sensors() const { return static_cast<int>(sensor_rows_.size()); }
  // True when the data term is the paper's: H = B (both end displacements, weight
  // beta, no interior sensor) and the clamp measured (f0 a load with alpha).
  bool observes_ends_only() const {
    return clamp_ == ClampModel::kMeasured && ends_.u0 && ends_.uL && num_interior_sensors() == 0;
  }
  const BarModel& model() const { return model_; }
  const ChannelSet& data() const { return data_; }
  // The end channels of data(), looked up once.
  const BarEnds& measured() const { return measured_; }
  // W -> U. With include_data the force data F~ enter; without, the sweep is the
  // linear part only. U is resized if needed (outside the time loop).
  void DirectSweep(const Matrix& retrograde, bool include_data, Matrix* displacement) override;
  // U -> W. With include_data the displacement data U~ enter.
  void RetrogradeSweep(const Matrix& displacement, bool include_data, Matrix* retrograde) override;
  // The batched sweeps of CoupledProblem: the time steps of the sweeps run
  // interleaved (ThetaIntegrator::StepsWithEndLoads), for the cost of fewer than that
  // many sweeps, and give the results of the single sweeps bit for bit.
  void DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
                            const std::vector<Matrix*>& displacement) override;
  void RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
                                const std::vector<Matrix*>& retrograde) override;

  // <x, y>_P = sum_j c_j h x_j^T (K + B/alpha) y_j.
  double InnerProduct(const Matrix& x, const Matrix& y) override;

  // e^2 = sum_j c_j h [1/2 W^T K W + W^T B W / (2 alpha)
  //                    + 1/2 (H U - d~)^T diag(beta_k) (H U - d~)]  [J s].
  double Cost(const Matrix& displacement, const Matrix& retrograde) override;
  // de^2/dE = sum_z de^2/dE_z [J s / Pa], the derivative along a common change of every
  // zone's modulus (one zone: the modulus).
  double CostGradient(const Matrix& displacement, const Matrix& retrograde);
  // de^2/dE_z = -(1/(2 E_nom)) sum_j c_j h W_j^T K_z (W_j + 2 U_j) [J s / Pa] with
  // K_z = E_nom K1_z (E_nom the model's modulus), plus under a trusted clamp the
  // reaction's explicit term sum_j c_j h alpha_r (r(U_j) - f0~_j) e_0^T K_z U_j / E_nom,
  // every zone from the one pair of fields, summed as MatrixMcreProblem::CostGradients
  // sums them (the same bits); gradient is resized to num_zones().
  void CostGradients(const Matrix& displacement, const Matrix& retrograde,
                     Vector* gradient) override;
  // The error map: the share of each element in the constitutive part of e^2,
  //   e_el^2 = sum_j c_j h 1/2 W_j^T K_el W_j  [J s],
  // one entry per element; their sum is sum_j c_j h 1/2 W_j^T K W_j.
  Vector ErrorMap(const Matrix& retrograde) const;

  // The operators of the space-time system: M, K = sum_z (E_z / E_nom) K_z, P = K + B/alpha,
  // H^T diag(beta_k) H (the paper's case: beta B), H^T diag(beta_k) d~_j and the
  // measured end forces f0~_j e_0 + fL~_j e_N. Trusted clamp: M and K with row and
  // column 0 decoupled, B = e_N e_N^T, the load fL~_j e_N alone.
  SparseMatrix MassMatrix() const override;
  SparseMatrix StiffnessMatrix() const override;
  SparseMatrix PenaltyMatrix() const override;
  SparseMatrix WeightedObservation() const override;
  void WeightedData(int j, Eigen::Ref<Vector> load) const override;
  void MeasuredForce(int j, Eigen::Ref<Vector> load) const override;

  // --- Streaming: the coupled problem on the sensor traces (docs/streaming.md) ---
  // A trace field y holds one row per channel of H, in the order u0, uL, then the
  // interior sensors (a row whose channel is left out has weight 0), and one column
  // per sample: num_traces() x (m + 1). The retrograde field depends on U only
  // through y = H U, so the coupled problem is a fixed point y = Phi(y) with
  //   Phi(y) = H Direct(Retrograde(y)),
  // where Retrograde(y) takes its load c_j H^T diag(beta) (y_j - d~_j) from y. Phi is
  // applied with O(n) memory: the retrograde sweep runs backward keeping only its
  // state, then a forward pass rebuilds W_j by stepping the trapezoidal recursion the
  // other way (exactly invertible for theta = 1/2 and no damping) and runs the direct
  // sweep beside it. Three sweeps per application. For theta != 1/2 the retrograde
  // field comes from checkpoints instead (CheckpointedStreamingMap: four sweeps, memory
  // O(n sqrt(m))).
  int num_traces() const override { return 2 + num_interior_sensors(); }
  // The data d~ in the trace rows' order (u0, uL, the sensors; f0 in the reaction
  // row): the traces at which the retrograde field vanishes (W = 0).
  Matrix DataTraces() const override;
  // From now on, StreamingMap takes the retrograde field from checkpoints (four sweeps,
  // W the stored sweep's to the bit) instead of the reversed recursion, whose
  // round-off grows with the Courant number (docs/streaming.md).
  // Allocates the checkpoints, O(n sqrt(m)), on the first call; theta != 1/2 always
  // uses them.
  void UseCheckpoints() override;
  bool uses_checkpoints() const { return checkpoints_.size() > 0; }
  // <a, b>_beta = sum_j c_j h sum_k beta_k a_kj b_kj, in which I - (Phi - Phi(0)) is
  // self-adjoint and positive definite on the weighted rows.
  double TraceInnerProduct(const Matrix& a, const Matrix& b) const override;
  // ||R r||_P^2 = sum_j c_j h W_j^T (K + B/alpha) W_j for W = R r, the retrograde field
  // driven by the traces r without data; in trace terms <r, -L r>_beta with
  // L = Phi - Phi(0). For a trace residual r = Phi(y) - y it is the squared P-norm of the
  // stored-field solvers' residual at W = Retrograde(y), whose tolerance is relative
  // to it. One backward sweep, its state only (O(n) memory, no allocation).
  double RetrogradeEnergy(const Matrix& traces) override;
  // The sums a streaming application gathers (StreamingCoupledProblem): cost,
  // gradients, the error map per element, its space-time picture, W at the ends and the
  // rebuild's round-off; the zone maps stay empty.
  // image = Phi(traces) with the data (include_data), or its linear part without.
  // With totals (not null), the sums of the fields of that application are gathered.
  // traces and image of shape ZeroTraces(), distinct. No
  // allocation but image's and totals' (resized once).
  void StreamingMap(const Matrix& traces, bool include_data, Matrix* image,
                    StreamingTotals* totals = nullptr) override;

  // beta_k [N/m or N m] of the trace rows u0, uL and the interior sensors (0 for an end
  // channel left out), and their data response (StreamingCoupledProblem).
  Vector TraceWeights() const override;
  void DataResponseTraces(Matrix* traces) override;
  // J_rest = Cost(0, 0) + sum_j c_j h [alpha_0/2 f~0_j^2 + alpha/2 f~L_j^2] [J s], alpha_0
  // of the clamp (0 trusted: f0 is an output, in Cost(0, 0)). O(n) memory: no field.
  double RestCost() override;

  // Number of factorisations of the integrator's iteration matrix since construction
  // (the constructor's SetModulus included): one per change of modulus.
  int factorization_count() const { return integrator_.factorization_count(); }

 private:
  template <int B>
  void DirectSweeps(const Matrix* const (&retrograde)[B], Matrix* const (&displacement)[B]);
  template <int B>
  void RetrogradeSweeps(const Matrix* const (&displacement)[B], Matrix* const (&retrograde)[B]);

  // The integrand of e^2 at sample j without c_j h:
  // 1/2 W^T K W + W_0^2 / (2 alpha_0) + W_N^2 / (2 alpha)
  //   + 1/2 (H U - d~_j)^T diag(beta) (H U - d~_j) (the force terms: EndForceForm).
  double SampleCost(int j, const double* displacement, const double* retrograde);
  // cost_misfits_ = H U_j - d~_j of the displacement U_j in the rows uL, the interior
  // sensors, then u0 (its datum 0 when pinned) or a trusted clamp's reaction. No
  // allocation.
  void Misfits(int j, const double* displacement);
  // (x_N / alpha) y_N + (x_0 / alpha_0) y_0 (no f0 term when the clamp is trusted).
  double EndForceForm(const double* x, const double* y) const;
  // x^T (K + e_0 e_0^T / alpha_0 + e_N e_N^T / alpha) y of two nodal vectors (n
  // entries each).
  double PenaltyForm(const double* x, const double* y) const;
  // gradient[z] += sample j's term of de^2/dE_z (CostGradients) from U_j and W_j (n
  // entries each), for every zone. No allocation.
  void AddSampleCostGradients(int j, const double* displacement, const double* retrograde,
                              Vector* gradient);

  // Sets the totals of a streaming application to zero and sizes them (the error
  // map's picture takes every picture_stride-th sample).
  void ResetStreamingTotals(int picture_stride, StreamingTotals* totals);
  // Adds sample j of a streaming application (U_j, W_j) to the totals: cost,
  // gradients, error map, the picture's row when j is a multiple of picture_stride,
  // and W at the ends. No allocation.
  void AddStreamingSample(int j, const Vector& displacement, const Vector& retrograde,
                          int picture_stride, StreamingTotals* totals);

  // StreamingMap from checkpoints, for theta != 1/2 (the step is not its own inverse)
  // or after UseCheckpoints: the
  // retrograde sweep keeps its state every checkpoint_stride_ steps, then each segment
  // between checkpoints is swept again, its omega kept, and consumed in forward order
  // (four sweeps; memory 2 n m / stride + n stride, stride = ceil(sqrt(2 m))).
  template <typename Observe, typename DirectStep>
  void CheckpointedStreamingMap(const Matrix& traces, bool include_data, Observe& observe,
                                DirectStep& direct_step);

  // column[0 .. num_traces()) = H U_j of the displacement U_j (the trace rows' order).
  void ObserveTraces(const Vector& displacement, double* column) const;

  // The retrograde loads of step t_j -> t_{j-1} from traces y_j (end loads f0, fL
  // and the sensors' point loads into stream_loads_).
  void TraceLoads(int j, const Matrix& traces, bool include_data, double* f0, double* fL);
  // The retrograde step t_j -> t_{j-1} with the loads of TraceLoads: from (v, omega)
  // into (v_next, omega_next) (the rebuild runs the same step the other way). No
  // allocation.
  void RetrogradeTraceStep(int j, const Matrix& traces, bool include_data, const Vector& velocity,
                           const Vector& state, Vector& velocity_next, Vector& state_next);

  // The retrograde force of step t_j -> t_{j-1} at the interior sensors,
  // c_j H_s^T diag(beta_s) (H_s U_j - d~_j) (without the data when include_data is
  // false), into loads' values (two nodes per sensor). U_j may be null (zero).
  void SensorLoads(int j, const double* displacement_j, bool include_data, double* values) const;

  const BarModel& model_;
  const ChannelSet& data_;
  BarEnds measured_;  // data_'s end channels
  double theta_;
  double alpha_;
  double beta_;
  double strain_beta_;
  EndDisplacementChannels ends_;
  ClampModel clamp_;
  double beta_u0_, beta_uL_;  // beta_u for an end displacement channel in use, else 0
  // f0 as a load: its weight alpha_0 (alpha when measured, alpha_0 when pinned) and the
  // gain 1 of its terms; when the clamp is trusted, alpha and the gain 0 that cancels
  // them.
  double alpha0_, force0_gain_;
  // Trusted clamp: the index of the reaction row in sensor_rows_, else -1.
  int reaction_row_ = -1;
  Vector moduli_;  // E_z [Pa]
  // Interior sensors: H's rows, their weights beta_k and data d~_k (one per sample).
  std::vector<ObservationRow> sensor_rows_;
  Vector sensor_weights_;
  // The weights of the rows of Misfits and their misfits (scratch, sized in the
  // constructor).
  Vector cost_weights_, cost_misfits_;
  // CostGradients' operators (those of the bar exported as matrices): E_nom [Pa], the
  // model's modulus; K_z = E_nom K1_z; a trusted clamp's rows e_0^T K_z / E_nom (held
  // column dropped) and their sum at moduli_; and scratch of n entries.
  double nominal_modulus_ = 0.0;
  std::vector<SparseMatrix> zone_stiffness_, reaction_zone_rows_;
  // Their bilinear forms on the dofs they touch (linalg/sparse_bilinear_form.h).
  std::vector<SparseBilinearForm> zone_forms_, reaction_zone_forms_;
  SparseMatrix reactions_;
  Vector gradient_shift_, reaction_trace_;
  std::vector<const Vector*> sensor_data_;
  // Point loads of the retrograde sweeps at the sensors' nodes, values per sweep
  // of a batch (column b), allocated in the constructor.
  std::vector<int> load_nodes_;
  Matrix load_values_;
  PointLoads point_loads_[ThetaIntegrator::kMaxBatch];
  ThetaIntegrator integrator_;
  // Streaming scratch (double buffers of the three sweeps' states, W_{j-1}, W_j, the
  // direct step's shift), allocated in the constructor: O(n).
  Vector stream_velocity_[2], stream_omega_[2], stream_rebuilt_velocity_[2],
      stream_rebuilt_omega_[2], stream_direct_velocity_[2], stream_displacement_[2],
      stream_retrograde_[2], stream_shift_;
  // One row of the space-time picture's gap density (SpaceTimeColumnPositions entries).
  Vector stream_density_row_;
  // theta != 1/2 or after UseCheckpoints: the checkpoints (2n x (m / stride + 1)) and
  // one segment's omega (n x (stride + 1)), allocated by UseCheckpoints.
  int checkpoint_stride_ = 1;
  Matrix checkpoints_, segment_;
  // Scratch, allocated in the constructor.
  Vector velocity_[2], omega_[2];  // double buffers of the sweeps' velocity and omega
  Vector shift_;                   // W_theta of the direct sweep's step
  // The same for the batched sweeps: columns [2 b, 2 b + 1] of sweep b's double buffers.
  Matrix batch_velocity_, batch_state_, batch_shift_;
};

// The MCRE objective of the built-in bar on its own band model: an McreObjective over
// BarMcreProblems on model and data with mcre's weights and clamp, as the library made
// it before the bar was exported as matrices. Keeps references to model and data: both
// must outlive the objective. Preconditions: mcre.IsValid(), inner.IsValid(), theta in
// [0, 1], modulus_scale > 0, data.num_steps() >= 1. ends: the end displacement channels
// in use; the interior sensors are those of data.
McreObjective BarMcreObjective(const BarModel& model, const ChannelSet& data,
                               const McreOptions& mcre, double theta,
                               const CoupledSolverOptions& inner, double modulus_scale,
                               EndDisplacementChannels ends = {});

}  // namespace testing
}  // namespace mcrewave
