// The coupled direct / retrograde MCRE problem of a structure given by matrices
// (docs/matrix_models.md section 2): mass M, zone stiffnesses K_z assembled at their
// nominal moduli, load vectors G = [g_1 ... g_C] whose histories F~ are measured, and
// observation rows H (one per sensor channel) whose histories d~ are measured.
//
// Scheme (the theta method of M U'' + K (U + W) = G f, K = sum_z (E_z / E_z,nom) K_z):
//
//   DirectSweep:      W -> U, from rest, step t_k -> t_{k+1} with
//                       f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta),
//                       X_theta = theta X_{k+1} + (1 - theta) X_k
//                     (ThetaIntegrator::StepWithEndLoads: z = W_theta, G (...) as point
//                     loads on G's rows);
//   RetrogradeSweep:  U -> W, from rest at T in reversed time, step t_j -> t_{j-1}
//                     with the force c_j H^T diag(beta) (H U_j - d~_j), then
//                       W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j,
//
// the bar's sweeps (mcre_problem.h) with its end loads and rows replaced by G and H.
// Weights from the structure's scales (section 3): k* = E0 a*,
//   beta_k = w_u k* (displacement row), w_e k* l*^2 (strain row),  alpha_c = w_f / k*,
// so that the bar exported with a* = S / L and l* = L has the bar's weights. An
// unmeasured load (UnmeasuredLoad, docs/unmeasured_loads.md) has the datum 0 and
// alpha_u = w_fu / k*; outside its interval it is 0 (a_cj = 0, P_j = K + G diag(a_j /
// alpha) G^T), and the sweeps take the theta average of the samples' forces.
//
// Supports (MatrixModelData::supports, docs/matrix_models.md section 11), each with its
// reaction vector g and held dofs D, enter by one treatment per problem (mcre.clamp;
// the bar's clamp of docs/formulation.md section 7 is the support g = e_0, D = {0}):
//   measured: D free; g a load with the force channel's history, alpha = w_f / k*; the
//             displacement channel (if any) an output of row g^T / (g^T g), beta = w_u k*;
//   trusted:  D held (rows and columns of M and K decoupled, diagonals kept; the
//             entries of the loads and rows on D dropped), so U = W = 0 on D; the
//             reaction r(U) = g^T K(E) U an output against the force channel,
//             alpha_r = w_r / k*; the displacement channel ignored;
//   pinned:   D free; g a load with alpha_0 = w_r / k*; a datum 0 of row e_i^T for
//             every i in D with beta_0 = w_u0 k*; the displacement channel ignored.
// So the loads G are the model's then (measured, pinned) the supports', the rows H
// the model's sensors, then the supports' rows (measured: displacement; pinned: the
// data 0; trusted: the reactions, which depend on the moduli).
//
// The integrator is factorised once per set of moduli (SetModuli), by the sparse
// LDL^T or the band path (ThetaIntegratorOptions::factorization). The sweeps allocate
// nothing: every scratch vector is sized in the constructor.
//
// Streaming (StreamingCoupledProblem, docs/streaming.md section 5): the trace rows are
// H's rows, the reactions' included under a trusted treatment. StreamingMap takes the
// retrograde field from checkpoints, always: a backward sweep driven by the traces
// keeps the state (v, omega) every s = ceil(sqrt(2 m)) steps; then, segment by segment
// from t = 0, the segment's omega is swept again from its upper checkpoint into an
// n x (s + 1) buffer and consumed in forward order by the direct sweep. Three sweeps
// per application, memory 2 n m / s + n s = O(n sqrt(m)), W the stored sweep's to the
// bit (the same steps), no drift. When omega's whole history fits
// SetHistoryBudget (64 MB by default; inner.max_field_bytes in a solve), s = m: one
// segment, swept once, two sweeps per application. Its totals are the cost, the zone
// gradients, the zone maps of W and U, the dof map and the element map, summed as the
// fields pass, and G^T W of every sample (the model's forces, ModelChannels).
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/data/channel_set.h"
#include "mcrewave/linalg/sparse_bilinear_form.h"
#include "mcrewave/linalg/sparse_columns.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/coupled_problem.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/mcre_weights.h"
#include "mcrewave/mcre/streaming_coupled_problem.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

// A load channel whose history was not measured (docs/unmeasured_loads.md). Its force
// is found with the admissible fields: the load enters as a measured one whose datum is
// 0, weighted by alpha_u = w_fu / k* (McreWeights::unmeasured_force_weight), at the
// samples t_j in [start, end] [s]; outside that interval it is known to vanish, F = 0
// exactly (1/alpha = 0 there). The data need not hold its channel.
struct UnmeasuredLoad {
  std::string channel;
  double start = -std::numeric_limits<double>::infinity();
  double end = std::numeric_limits<double>::infinity();
};

// The channel set of a model's channels from their histories at t_j = j h, j = 0..m,
// in the model's order (MatrixModelData::loads, ::sensors): a channel per load (named
// as it, kForce, a row of loads, C x (m + 1)) then per sensor (named as it, of its
// kind, a row of outputs, S x (m + 1)).
ChannelSet MatrixChannelSet(const MatrixModelData& model, double time_step, const Matrix& loads,
                            const Matrix& outputs);

// The matrix with the rows and columns of the held dofs (held[i] != 0; held has one
// entry per row) decoupled from the others, diagonals kept: a held dof stays at rest
// while its load is zero (docs/formulation.md section 7, the bar's node 0; the trusted
// supports of docs/matrix_models.md section 11).
SparseMatrix WithHeldDofs(SparseMatrix matrix, const std::vector<char>& held);

class MatrixMcreProblem : public StreamingCoupledProblem {
 public:
  // Keeps a reference to model, which must outlive the problem; copies the histories
  // of data's channels named as the model's loads and sensors and the supports'
  // channels the treatment reads (data may go). reference_modulus is E0 of the weights
  // [Pa]; every zone starts at its nominal modulus. supports is the treatment of every
  // support of the model (ignored without supports). Preconditions: data has a channel
  // of each of the model's loads and sensors and each support's force channel, and its
  // displacement channel when it has one and supports is kMeasured (else throws
  // std::logic_error), on t_j = j h and m >= 1 steps, the model's scales positive,
  // weights valid, theta in [0, 1]. unmeasured names some of the model's load channels
  // (not its supports'), each once, with start <= end; data need not hold them.
  MatrixMcreProblem(const MatrixModelData& model, const ChannelSet& data,
                    const McreWeights& weights, double reference_modulus, double theta,
                    Factorization factorization = Factorization::kAutomatic,
                    ClampModel supports = ClampModel::kMeasured,
                    const std::vector<UnmeasuredLoad>& unmeasured = {});

  int num_nodes() const override { return model_.dofs(); }
  int num_steps() const override { return static_cast<int>(measured_loads_.cols()) - 1; }
  double time_step() const override { return time_step_; }
  double theta() const override { return theta_; }
  const Vector& moduli() const override { return moduli_; }
  // K = sum_z (E_z / E_z,nom) K_z (held dofs decoupled under a trusted treatment) and the
  // trusted reaction rows g^T K(E), refactorised when the moduli changed.
  void SetModuli(const Vector& zone_moduli) override;

  void DirectSweep(const Matrix& retrograde, bool include_data, Matrix* displacement) override;
  void RetrogradeSweep(const Matrix& displacement, bool include_data, Matrix* retrograde) override;
  // Up to kMaxSweepBatch sweeps with the data at once (CoupledProblem): their steps run
  // through ThetaIntegrator::StepsWithEndLoads, interleaved on the tridiagonal path;
  // the bits of the single sweeps. No allocation once the batch scratch is sized (the
  // constructor).
  void DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
                            const std::vector<Matrix*>& displacement) override;
  void RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
                                const std::vector<Matrix*>& retrograde) override;
  double InnerProduct(const Matrix& x, const Matrix& y) override;
  double Cost(const Matrix& displacement, const Matrix& retrograde) override;
  // de^2/dE_z = -(1/(2 E_z,nom)) sum_j c_j h W_j^T K_z (W_j + 2 U_j) [J s / Pa], plus
  // under a trusted treatment the reactions' dependence on the moduli,
  //   sum_j c_j h sum_s alpha_r (r_s(U_j) - f~_sj) g_s^T K_z U_j / E_z,nom.
  void CostGradients(const Matrix& displacement, const Matrix& retrograde,
                     Vector* gradient) override;
  // Each zone's share of the constitutive part of e^2,
  //   e_z^2 = (E_z / E_z,nom) sum_j c_j h 1/2 W_j^T K_z W_j  [J s];
  // from matrices alone a zone is the finest unit (docs/matrix_models.md section 2).
  Vector ZoneErrorMap(const Matrix& retrograde);
  // The same energy split by dof, e_i^2 = sum_j c_j h 1/2 W_ij (K W_j)_i [J s]: it sums
  // to the constitutive part and shows where in a zone the gap sits (a nodal
  // density for a figure over the mesh; an entry can be slightly negative).
  Vector DofErrorMap(const Matrix& retrograde);
  // The sensitivity map s_el = de^2/d ln E_el [J s] of the model's elements at the
  // current moduli from a coupled solution's U and W (mcre/element_error_map.h), the
  // trusted reactions' part included: the elements of zone z sum to E_z de^2/dE_z of
  // CostGradients. Precondition: the model has element blocks.
  void ElementSensitivities(const Matrix& displacement, const Matrix& retrograde,
                            Vector* sensitivity);

  SparseMatrix MassMatrix() const override { return mass_; }
  SparseMatrix StiffnessMatrix() const override { return stiffness_; }
  SparseMatrix PenaltyMatrix() const override;
  // True when an unmeasured load acts only over an interval shorter than the window:
  // P_j = K + G diag(a_cj / alpha_c) G^T, a_cj = 1 where load c may act at t_j, else 0.
  bool TimeVaryingPenalty() const override { return load_active_.size() > 0; }
  SparseMatrix PenaltyMatrixAt(int j) const override;
  SparseMatrix WeightedObservation() const override;
  void WeightedData(int j, Eigen::Ref<Vector> load) const override;
  void MeasuredForce(int j, Eigen::Ref<Vector> load) const override;

  // H U of DirectSweep(0) with the data: the model's outputs driven by the measured
  // loads alone, S x (m + 1), the rows of the model's sensors only (synthetic data of
  // this model, MatrixChannelSet's outputs). One direct sweep keeping its state only:
  // no n x (m + 1) field (the stored sweep's numbers to the bit).
  Matrix ModelOutputs();
  // The supports' reactions r_s(U) = g_s^T K(E) U of the same U, one row per support in
  // the model's order [N], by the same sweep. Precondition: the treatment is trusted
  // (the supports held).
  Matrix ModelSupportForces();

  // The model's channels at a coupled solution of this problem at its current moduli
  // (stored fields, or a streaming solve's traces and load_retrograde), named as the
  // data's: each load channel's force F = F~ - diag(1/alpha) G^T W, the direct sweep's
  // load [N] (the model's loads, then each support's force channel when measured or
  // pinned); each sensor's H U; each support's displacement channel, H U (measured),
  // held at rest (trusted) or g^T U / (g^T g) from the data 0 of its dofs (pinned);
  // and, trusted, each support's reaction r(U) = g^T K(E) U on its force channel [N].
  // Precondition: the solution is this problem's, of m + 1 samples.
  ChannelSet ModelChannels(const CoupledSolution& solution) const;

  // J_rest = sum_j c_j h [1/2 F~_j^T diag(alpha) F~_j + 1/2 d~_j^T diag(beta) d~_j]
  // [J s]: the functional of the structure left at rest (U = W = 0, zero loads), which
  // satisfies the state equation at any moduli, so 0 <= e^2 <= J_rest.
  double RestCost() override;
  // beta_k of H's rows (betas()), and H U of the data response (StreamingCoupledProblem).
  Vector TraceWeights() const override { return betas_; }
  void DataResponseTraces(Matrix* traces) override;
  // E_z,nom of every zone [Pa].
  Vector NominalModuli() const;

  // alpha_c [m/N]: the model's load channels, then (measured, pinned) the supports'.
  const Vector& alphas() const { return alphas_; }
  // beta_k [N/m, N m or m/N]: the model's sensors, then the supports' rows (above).
  const Vector& betas() const { return betas_; }
  ClampModel support_treatment() const { return treatment_; }
  int factorization_count() const { return integrator_.factorization_count(); }
  const ThetaIntegrator& integrator() const { return integrator_; }

  // --- Streaming: the coupled problem on the traces H U (StreamingCoupledProblem) ---
  // One trace row per row of H: the sensors, then the supports' rows (betas()).
  int num_traces() const override { return static_cast<int>(betas_.size()); }
  // d~ in H's rows' order (a trusted reaction's row: the support's force f~_s).
  Matrix DataTraces() const override { return measured_outputs_; }
  double TraceInnerProduct(const Matrix& a, const Matrix& b) const override;
  // One backward sweep, its state only; no allocation.
  double RetrogradeEnergy(const Matrix& traces) override;
  // From checkpoints (above): three sweeps. Allocates the checkpoints on its first call
  // (and the image and totals when not of their size); nothing in the time loops.
  void StreamingMap(const Matrix& traces, bool include_data, Matrix* image,
                    StreamingTotals* totals = nullptr) override;
  // The checkpoints are always used: nothing to switch.
  void UseCheckpoints() override {}
  // StreamingMap keeps the whole history of omega, n x (m + 1) doubles, from its one
  // backward sweep when it holds at most `bytes`: two sweeps per application instead
  // of three, the same steps, so the same bits. 0: checkpoints always. The default
  // budget, until a solve or a caller sets one, is kDefaultHistoryBytes. A budget that
  // changes the layout takes effect at the next StreamingMap (which allocates again).
  static constexpr long kDefaultHistoryBytes = 1L << 26;
  void SetHistoryBudget(long bytes) override;
  // Whether StreamingMap's totals gather the element map and its picture (true by
  // default). Off, StreamingTotals::element_error_map and gap_density stay empty: for
  // solves whose maps nobody reads (a minimiser's, the uncertainty's);
  // StreamingElementMaps then gives a solution's maps from its traces.
  void set_element_maps(bool gather) { element_maps_ = gather; }
  // A streaming solution's element map and picture at the current moduli, from its
  // traces: one application of the map (two or three sweeps), the same sums as a
  // final pass that gathered them. Precondition: traces of this problem's size.
  void StreamingElementMaps(const Matrix& traces, CoupledSolution* solution);
  // H U of a displacement field, num_traces() x (m + 1): the traces of stored fields.
  Matrix ObservedTraces(const Matrix& displacement) const { return observation_ * displacement; }
  // The trace operator -L at the current moduli as a dense symmetric matrix
  // (docs/streaming.md section 6),
  //   S = (C beta)^1/2 Z blockdiag(P_j) C^-1 Z^T (C beta)^1/2,  C = diag(c_j h),  Z = H D,
  // num_traces() (m + 1) square, row k at sample j at index j num_traces() + k (a trace
  // field's column-major order): -L y = (C beta)^-1/2 S (C beta)^1/2 y. From one
  // retrograde sweep per trace row (the impulse responses, by time invariance) and one
  // product of n x R m matrices; a load acting over an interval only (TimeVaryingPenalty)
  // adds one rank-one term per sample where it acts, (R (m + 1))^2 operations each.
  // Preconditions: m >= 2, theta >= 1/2 (the recursion from the responses to Z's blocks
  // divides by theta), every beta_k > 0.
  Matrix SymmetricTraceOperator();
  // The Cholesky factor of I + S (above) at the current moduli, in single precision
  // where that keeps it definite (TraceFactor::single_precision); none (false) when the
  // traces exceed max_traces or SymmetricTraceOperator's preconditions fail. Rebuilt
  // when a modulus moved by more than rebuild_change since it was built; (C beta)^-1/2
  // (I + S)^-1 (C beta)^1/2 applied by PreconditionTraces.
  bool PrepareTracePreconditioner(double rebuild_change, long max_traces) override;
  // Keeps the factor's storage when this problem alone holds it.
  void ForgetTracePreconditioner() override;
  void PreconditionTraces(const Matrix& residual, Matrix* result) override;
  // The factor of I + S with the weights and moduli it was built at (null before the
  // first build): it depends on the model, the weights, theta, the time grid, the loads'
  // intervals and the moduli, not on the data, so problems of the same model and options
  // at the same moduli share it (the uncertainty's noise problems).
  struct TraceFactor {
    Matrix factor;   // L of I + S = L L^T in its lower triangle
    Vector weights;  // (c_j h beta_k)^1/2 in a trace field's order
    Vector moduli;   // E_z [Pa] it was built at
    // Factorised in float (false: in double, where float's round-off of a large S,
    // about 1e7 and more, broke I + S's definiteness).
    bool single_precision = true;
  };
  std::shared_ptr<const TraceFactor> trace_factor() const { return trace_factor_; }
  // Takes `factor` (of a problem of the same model, weights, theta, time grid and loads'
  // intervals) as this problem's preconditioner; PrepareTracePreconditioner keeps it
  // while the moduli stay within its rebuild_change.
  void ShareTraceFactor(std::shared_ptr<const TraceFactor> factor) {
    trace_factor_ = std::move(factor);
  }
  // Factorisations of I + S by this problem so far.
  int trace_preconditioner_builds() const { return trace_preconditioner_builds_; }

  // The checkpoints' stride s (0 before the first StreamingMap).
  int checkpoint_stride() const { return checkpoint_stride_; }

 private:
  // (c_j h beta_k)^1/2 of every trace entry, in a trace field's (column-major) order.
  Vector TraceWeightRoots() const;
  // The P the trace operator's assembly takes for every sample: K + G diag(s / alpha) G^T,
  // s_c = 1 for a load acting at every sample, 0 for one with an interval (whose samples
  // the assembly adds one by one); PenaltyMatrix() when every load acts throughout.
  SparseMatrix SteadyPenalty() const;
  // The traces' impulse responses a(j), j = 1..m, n x R m (column (j - 1) R + k for
  // row k), from one retrograde sweep per trace row (matrix_trace_operator.cpp).
  void TraceImpulseResponses(Matrix* impulse_responses);
  // x^T K y on either path of the integrator: from its band of K on the band path (as
  // the bar's McreProblem::PenaltyForm), else through product_ = K y. No allocation.
  double StiffnessForm(const double* x, const double* y);
  // The load channels of the direct step t_k -> t_{k+1}, the theta average of the
  // samples' F_j = F~_j - diag(a_j / alpha) G^T W_j,
  //   channel = F~_theta - diag(1/alpha) G^T W_theta  (F~ only with include_data)
  // where a load acts at both ends of the step (its sum: the same bits as before loads
  // had intervals), 0 from its G^T W where it acts at neither, and the two samples'
  // terms apart where it starts or stops. From W_theta, W_k and W_{k+1} (shift null:
  // the zero field, no G^T W term). No allocation.
  void DirectChannels(int k, bool include_data, const double* shift, const double* previous,
                      const double* next, Eigen::Ref<Vector> channel) const;
  // Zeroes the entries of G^T W_j (channel) of the loads that do not act at sample j.
  void MaskInactiveLoads(int j, Eigen::Ref<Vector> channel) const {
    if (load_active_.size() > 0) channel.array() *= load_active_.col(j).array();
  }
  // The weighted traces of the retrograde step t_j -> t_{j-1}: y_j (H U_j or a trace)
  // in, c_j diag(beta) (y_j - d~_j) out (d~ only with include_data). No allocation.
  void WeightTraces(int j, bool include_data, Eigen::Ref<Vector> trace) const;
  // The direct step t_k -> t_{k+1} from (v, u) into (v_next, u_next), W_theta in shift_,
  // W_k and W_{k+1} in previous and next:
  // f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta) (DirectChannels),
  // F~ only with include_data; G's entries as the integrator's point loads. No
  // allocation.
  void DirectStep(int k, bool include_data, const double* previous, const double* next,
                  const Vector& velocity, const Eigen::Ref<const Vector>& displacement,
                  Vector& velocity_next, Eigen::Ref<Vector> displacement_next);
  // The retrograde step t_j -> t_{j-1} from (v, omega) into (v_next, omega_next), y_j
  // (H U_j or a trace) in trace_: the force c_j H^T diag(beta) (y_j - d~_j), d~ only
  // with include_data; H's entries as point loads. Overwrites trace_. No allocation.
  void RetrogradeStep(int j, bool include_data, const Vector& velocity, const Vector& state,
                      Vector& velocity_next, Vector& state_next);
  // B sweeps with the data at once, a null input the zero field (DirectSweepsWithData).
  template <int B>
  void DirectSweeps(const Matrix* const (&retrograde)[B], Matrix* const (&displacement)[B]);
  template <int B>
  void RetrogradeSweeps(const Matrix* const (&displacement)[B], Matrix* const (&retrograde)[B]);
  // The retrograde step driven by the traces y_j (RetrogradeStep). No allocation.
  void RetrogradeTraceStep(int j, const Matrix& traces, bool include_data, const Vector& velocity,
                           const Vector& state, Vector& velocity_next, Vector& state_next);
  // x^T P_j y = x^T (K + G diag(a_j / alpha) G^T) y of two columns at sample j; uses
  // product_ and the channel vectors.
  double PenaltyForm(int j, const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& y);
  // The direct sweep from rest with W = 0 and the measured loads, DirectSweep's steps
  // with its state only: observe(j, U_j) for j = 0..m.
  template <typename Observe>
  void DataResponseSweep(Observe&& observe);
  // Adds sample j (U_j, W_j) of a streaming application to the totals, and the element
  // map's picture row when j is a multiple of picture_stride. No allocation.
  void AddStreamingSample(int j, const Vector& displacement, const Vector& retrograde,
                          int picture_stride, StreamingTotals* totals);
  // Zeroes the totals of a streaming application, sized for the dofs, the zones and the
  // elements (the picture: every picture_stride-th sample).
  void ResetStreamingTotals(int picture_stride, StreamingTotals* totals) const;
  // Step 1 of StreamingMap: the retrograde sweep from rest at T driven by the traces,
  // keeping its state (v_j, omega_j) at the checkpoints j = m - i s (column i of
  // checkpoints_: v over omega). No allocation.
  void CheckpointRetrogradeSweep(const Matrix& traces, bool include_data);
  // reaction_trace_ = r(U_j) - f~_j: the trusted supports' reactions of the kinematic
  // field at sample j against their data. No allocation.
  void FormReactionMisfit(int j, const Eigen::Ref<const Vector>& displacement);
  // The trusted reactions' part of the sensitivity map at one sample, from
  // reaction_trace_ = r(U_j) - f~_j: sensitivity[el] += weight alpha_r (E_z / E_z,nom)
  // sum_s (r_s(U_j) - f~_sj) phi_s^T K_el U_j over reaction_elements_. No allocation.
  void AddSampleReactionSensitivities(const double* displacement, double weight,
                                      Vector* sensitivity) const;

  const MatrixModelData& model_;
  double time_step_;         // h [s]
  Matrix measured_loads_;    // F~ [N], C x (m + 1), rows in G's order
  Matrix measured_outputs_;  // d~ [m], [-] or [N], S x (m + 1), rows in H's order
  // The data's channel of each column of G and each row of H ("" for a datum 0), and
  // the kind of each row.
  std::vector<std::string> load_channels_, output_channels_;
  std::vector<ChannelKind> output_kinds_;
  double theta_;
  Factorization factorization_;
  ClampModel treatment_;
  // Trusted treatment: 1 on the held dofs, else 0 (empty otherwise).
  std::vector<char> held_;
  int num_reactions_ = 0;   // trusted: one reaction row per support (H's last rows)
  double reaction_weight_;  // alpha_r = w_r / k* [m/N]
  Vector moduli_;           // E_z [Pa]
  Vector alphas_, betas_;   // alpha_c [m/N], beta_k
  // a_cj: 1 where load c may act at sample j, else 0, C x (m + 1); empty when every
  // load acts throughout (no unmeasured load with an interval inside the window).
  Matrix load_active_;
  SparseMatrix mass_;               // M, held dofs decoupled under a trusted treatment
  SparseMatrix loads_;              // G, n x C
  SparseMatrix loads_transposed_;   // G^T, C x n
  SparseMatrix fixed_observation_;  // H's rows that do not depend on the moduli
  // Trusted: per zone z, the rows g_s^T K_z / E_z,nom (held columns dropped), R x n; and
  // their sum at moduli_, sum_z E_z (...) = g_s^T K(E).
  std::vector<SparseMatrix> reaction_zone_rows_;
  // The bilinear forms of every K_z and of those rows on the dofs they touch
  // (linalg/sparse_bilinear_form.h): the zone sums in O(n) per sample, not O(n Z).
  std::vector<SparseBilinearForm> zone_forms_, reaction_zone_forms_;
  // Trusted, with element blocks: (support s, element el) wherever phi_s is nonzero on
  // one of the element's dofs, the elements the reactions' sensitivity touches.
  std::vector<std::pair<int, int>> reaction_elements_;
  SparseMatrix reactions_;
  SparseRow reaction_rows_;              // reactions_ stored by rows
  SparseMatrix observation_;             // H, S x n
  SparseMatrix observation_transposed_;  // H^T, n x S
  // G and H^T by columns: the sweeps' products G^T x and H x, and G c, H^T y as point
  // loads (linalg/sparse_columns.h: the bits of the sparse products).
  SparseColumns load_columns_, observation_columns_;
  SparseMatrix stiffness_;  // K at moduli_ (held dofs decoupled when trusted)
  ThetaIntegrator integrator_;
  // Scratch, allocated in the constructor: double buffers of the sweeps' velocity and
  // state, W_theta, a product K x, two vectors per load channel, one
  // per row of H and one per reaction.
  Vector velocity_[2], state_[2], shift_, product_, channel_, other_channel_, trace_,
      reaction_trace_;
  // G^T W_k and G^T W_{k+1} where a load starts or stops acting (DirectChannels).
  mutable Vector edge_channel_[2];
  // Streaming: the checkpoints (v over omega, 2n x (m / s + 1)) and one segment's omega
  // (n x (s + 1)), allocated by the first StreamingMap; the double buffers of the
  // direct sweep (velocity, displacement), W_{j-1} and W_j, allocated in the constructor.
  int checkpoint_stride_ = 0;
  long history_budget_bytes_ = kDefaultHistoryBytes;
  // Whether omega's whole history, n x (m + 1) doubles, fits `bytes`.
  bool HistoryFits(long bytes) const;
  bool element_maps_ = true;
  Matrix checkpoints_, segment_;
  Vector stream_velocity_[2], stream_displacement_[2], stream_retrograde_[2];
  // The streaming CG's preconditioner (null: none yet), a scratch vector of a trace
  // field's size, and the builds so far.
  std::shared_ptr<const TraceFactor> trace_factor_;
  // The trace operator's assembly scratch in Scalar arithmetic (P times the impulse
  // responses, the responses, A), matrix_trace_operator.cpp.
  template <typename Scalar>
  struct TraceAssemblyScratch {
    Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> weighted, responses, gram;
    // The rank-one terms of the loads with an interval, one column per sample where one
    // acts (empty without such loads).
    Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> load_terms;
  };
  // The preconditioner build's buffers, kept between builds (their megabytes are not
  // allocated and faulted in again).
  struct TraceBuildBuffers {
    Matrix impulse_responses;
    Matrix load_responses;  // a(j) g_c of the loads, R m x C (loads with an interval only)
    TraceAssemblyScratch<float> scratch;
    Eigen::MatrixXf operator_plus_identity;
  };
  TraceBuildBuffers trace_build_;
  Vector trace_scratch_;
  int trace_preconditioner_builds_ = 0;
  // One row of the element map's picture (ElementColumnPositions entries; empty without
  // elements), allocated in the constructor.
  Vector stream_density_row_;
  // Batched sweeps, per sweep b: the double buffers of the velocity (columns 2b, 2b + 1)
  // and of omega, W_theta, the load channels or the weighted traces, and the point
  // loads' values; sized in the constructor.
  Matrix batch_velocity_, batch_state_, batch_shift_, batch_channel_, batch_trace_,
      batch_load_values_;
  PointLoads batch_loads_[kMaxSweepBatch];
};

}  // namespace mcrewave
