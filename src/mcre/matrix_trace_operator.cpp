// The trace operator -L of a structure given by matrices as a dense symmetric matrix,
// from one retrograde sweep per trace row (docs/streaming.md section 6), and the
// preconditioner of the streaming CG built from it.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {

void MatrixMcreProblem::TraceImpulseResponses(Matrix* impulse_responses) {
  const int n = num_nodes(), m = num_steps(), rows = num_traces();
  assert(m >= 2 && theta_ >= 0.5 && betas_.minCoeff() > 0.0);
  // a(j), j = 1..m: the traces' response at t_j to a unit force over the step
  // t_0 -> t_1 alone, one R x n block per sample, stored transposed (n x R m, column
  // (j - 1) R + k for row k). By the adjointness of the two sweeps,
  //   Z(i, l) = H D(i, l) = (c_l / c_i) [D* (h_k at t_i)]_l^T,
  // so the retrograde field driven by h_k at t_m alone gives every interior block
  // z(j) = Z(l + j, l) = (c_{m-j} / c_m) W_{m-j}^T, and z(j) = theta a(j + 1) +
  // (1 - theta) a(j) with a(0) = 0 gives a(j).
  Matrix& responses = *impulse_responses;
  responses.resize(n, rows * m);
  Matrix traces = ZeroTraces();
  Vector field(n), previous_response(n);
  for (int k = 0; k < rows; ++k) {
    // y = e_k / beta_k at t_m: the retrograde load c_m h_k.
    traces.setZero();
    traces(k, m) = 1.0 / betas_[k];
    velocity_[0].setZero();
    state_[0].setZero();
    previous_response.setZero();
    for (int j = m, s = 0; j > 0; --j, ++s) {
      const int current = s & 1, next = current ^ 1;
      RetrogradeTraceStep(j, traces, false, velocity_[current], state_[current], velocity_[next],
                          state_[next]);
      // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j; z(m - j) = (c_j / c_m) W_j.
      field =
          (theta_ * state_[next] + (1.0 - theta_) * state_[current]) * (1.0 / QuadratureWeight(m));
      // a(m - j + 1) = (z(m - j) - (1 - theta) a(m - j)) / theta.
      auto response = responses.col((m - j) * rows + k);
      response = (field - (1.0 - theta_) * previous_response) / theta_;
      previous_response = response;
    }
    ++sweep_count_;
  }
}

namespace {

// The time grid's facts the trace operator's assembly needs.
struct TraceGrid {
  int rows = 0;   // R, trace rows
  int steps = 0;  // m
  double theta = 0.5;
  double time_step = 0.0;     // h [s]
  double first_weight = 0.5;  // c_0
  double last_weight = 0.5;   // c_m
};

// The loads that act over an interval only, which the assembly's one P leaves out
// (MatrixMcreProblem::SteadyPenalty): null responses when every load acts throughout.
struct IntervalLoads {
  const Matrix* responses = nullptr;  // b_c(j) = a(j) g_c: R m x C, rows (j - 1) R + k
  const Matrix* active = nullptr;     // a_cj, C x (m + 1)
  const Vector* alphas = nullptr;     // alpha_c [m/N]
};

// Whether load c acts at every sample (then in the assembly's P).
bool ActsThroughout(const Matrix& active, int c) { return (active.row(c).array() != 0.0).all(); }

// The loads with an interval of a problem whose loads are G and a_cj active (empty: none),
// their b_c(j) = a(j) g_c computed into *load_responses (kept by the caller) from the
// impulse responses.
IntervalLoads TraceIntervalLoads(const Matrix& responses, const SparseMatrix& loads,
                                 const Matrix& active, const Vector& alphas,
                                 Matrix* load_responses) {
  IntervalLoads interval_loads;
  if (active.size() == 0) return interval_loads;
  // Every b_c(j) at once: (G^T responses)^T.
  load_responses->noalias() = responses.transpose() * loads;
  interval_loads.responses = load_responses;
  interval_loads.active = &active;
  interval_loads.alphas = &alphas;
  return interval_loads;
}

// S = (C beta)^1/2 Q (C beta)^1/2 from the impulse responses (SymmetricTraceOperator's
// formulas) into *result, in Scalar arithmetic: double for the operator, float for the
// preconditioner's factor, which needs I + S to a few digits only. Symmetric to
// round-off; its lower triangle is the product's. lower_only: the strict upper
// triangle is left undefined (a Cholesky factorisation reads the lower one). Works in
// *buffers (MatrixMcreProblem::TraceAssemblyScratch<Scalar>: weighted, responses, gram
// and load_terms), kept by the caller: no fresh megabytes a build once they have their
// sizes. penalty: the P of every sample, the loads with an interval (loads) left out
// and added sample by sample (below).
template <typename Scalar, typename Scratch>
void AssembleTraceOperator(const Matrix& responses, const SparseMatrix& penalty,
                           const IntervalLoads& loads, const TraceGrid& grid,
                           const Vector& weight_roots, bool lower_only, Scratch* buffers,
                           Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>* result) {
  using Dense = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  const int rows = grid.rows, m = grid.steps;
  // A(i, k) = a(i) P a(k)^T / h, R x R blocks, in a matrix over the samples 0..m
  // whose block row and column 0 stay zero (a(0) = 0): its lower triangle by one
  // product (P symmetric), the upper by symmetry.
  const int size = rows * (m + 1);
  Dense& weighted = buffers->weighted;
  Dense& cast_responses = buffers->responses;
  Dense& gram = buffers->gram;
  weighted = (penalty * responses).template cast<Scalar>();
  cast_responses = responses.template cast<Scalar>();
  gram.setZero(size, size);
  auto inner = gram.bottomRightCorner(rows * m, rows * m);
  inner.template triangularView<Eigen::Lower>() = cast_responses.transpose() * weighted;
  inner *= static_cast<Scalar>(1.0 / grid.time_step);
  if (lower_only) {
    // Q's lower triangle reads A's lower triangle and, through A(i - 1, k), its band
    // of R entries above the diagonal.
    for (int c = 1; c < size; ++c) {
      for (int r = std::max(0, c - rows); r < c; ++r) gram(r, c) = gram(c, r);
    }
  } else {
    inner.template triangularView<Eigen::StrictlyUpper>() = inner.transpose();
  }
  // Q = Z P C^-1 Z^T over the samples i, k = 0..m, Z(i, 0) = (1 - theta) a(i) and
  // Z(i, l) = theta a(i - l + 1) + (1 - theta) a(i - l) for l >= 1:
  //   Q(i, k) = Q(i - 1, k - 1) + D(i, k),
  //   D(i, k) = theta^2 A(i, k) + theta (1 - theta) (A(i, k - 1) + A(i - 1, k))
  //             + (1 - theta)^2 A(i - 1, k - 1) + (1 - theta)^2 / c_0 [A(i, k) - A(i - 1, k - 1)],
  // the term l = m counted twice at (m, m) (c_m = 1/2), and Q(0, .) = 0 (U_0 = 0).
  const double t = grid.theta, u = 1.0 - grid.theta, start = u * u / grid.first_weight;
  const int rest = size - rows;
  Dense& q = *result;
  q = static_cast<Scalar>(t * t + start) * gram;
  q.bottomRightCorner(rest, rest) +=
      static_cast<Scalar>(u * u - start) * gram.topLeftCorner(rest, rest);
  q.rightCols(rest) += static_cast<Scalar>(t * u) * gram.leftCols(rest);
  q.bottomRows(rest) += static_cast<Scalar>(t * u) * gram.topRows(rest);
  // The cumulative sums along the block diagonals, block row by block row.
  for (int i = 1; i <= m; ++i) {
    q.block(i * rows, rows, rows, rest) += q.block((i - 1) * rows, 0, rows, rest);
  }
  q.block(m * rows, m * rows, rows, rows) +=
      static_cast<Scalar>(t * t * (1.0 / grid.last_weight - 1.0)) *
      gram.block(rows, rows, rows, rows);
  if (loads.responses != nullptr) {
    // With P_l = P + G diag(a_l / alpha) G^T, P without the loads that have an interval,
    //   Q = Z blockdiag(P_l) C^-1 Z^T = (the above) + sum over a_cl = 1 of v_cl v_cl^T,
    //   v_cl = Z(., l) g_c / (alpha_c c_l h)^1/2,  block i: Z(i, l) g_c = theta b_c(i - l + 1)
    //          + (1 - theta) b_c(i - l) (l >= 1), (1 - theta) b_c(i) (l = 0),
    // b_c(j) = a(j) g_c (0 for j <= 0). The samples where a load acts are added to P
    // without it, rather than those where it does not taken off P with it: no difference
    // of terms of 1/alpha_u (1e6 k* at the default w_fu), and few terms for a brief load.
    const Matrix& b = *loads.responses;
    const Matrix& active = *loads.active;
    const int channels = static_cast<int>(active.rows());
    Eigen::Index count = 0;
    for (int c = 0; c < channels; ++c) {
      if (!ActsThroughout(active, c)) count += (active.row(c).array() != 0.0).count();
    }
    Dense& terms = buffers->load_terms;
    terms.resize(size, count);
    Eigen::Index column = 0;
    for (int c = 0; c < channels; ++c) {
      if (ActsThroughout(active, c)) continue;
      for (int l = 0; l <= m; ++l) {
        if (active(c, l) == 0.0) continue;
        const double weight = l == 0 ? grid.first_weight : (l == m ? grid.last_weight : 1.0);
        const double scale = 1.0 / std::sqrt((*loads.alphas)[c] * weight * grid.time_step);
        // theta b_c(later) + (1 - theta) b_c(later - 1), the first term absent at l = 0.
        Scalar* out = terms.col(column++).data();
        for (int i = 0; i <= m; ++i) {
          const int later = i - l + 1;
          for (int k = 0; k < rows; ++k) {
            double value = 0.0;
            // (At l = 0, later reaches m + 1, past b's last block: no term there.)
            if (later >= 1 && l > 0) value += t * b((later - 1) * rows + k, c);
            if (later >= 2) value += u * b((later - 2) * rows + k, c);
            out[i * rows + k] = static_cast<Scalar>(scale * value);
          }
        }
      }
    }
    if (count == 0) {
      // No load with an interval acts inside the window.
    } else if (lower_only) {
      q.template selfadjointView<Eigen::Lower>().rankUpdate(terms, Scalar(1));
    } else {
      q.noalias() += terms * terms.transpose();
    }
  }
  // S = (C beta)^1/2 Q (C beta)^1/2, C = diag(c_j h).
  const auto roots = weight_roots.template cast<Scalar>();
  q.array().colwise() *= roots.array();
  q.array().rowwise() *= roots.transpose().array();
}

}  // namespace

Matrix MatrixMcreProblem::SymmetricTraceOperator() {
  const TraceGrid grid{num_traces(), num_steps(),         theta_,
                       time_step(),  QuadratureWeight(0), QuadratureWeight(num_steps())};
  Matrix responses, load_responses, q;
  TraceImpulseResponses(&responses);
  TraceAssemblyScratch<double> buffers;
  const IntervalLoads loads =
      TraceIntervalLoads(responses, loads_, load_active_, alphas_, &load_responses);
  AssembleTraceOperator<double>(responses, SteadyPenalty(), loads, grid, TraceWeightRoots(),
                                /*lower_only=*/false, &buffers, &q);
  // Symmetric to round-off: the mean of the two triangles, in place.
  const auto size = q.rows();
  for (Eigen::Index c = 0; c < size; ++c) {
    for (Eigen::Index r = c + 1; r < size; ++r) {
      const double mean = 0.5 * (q(r, c) + q(c, r));
      q(r, c) = mean;
      q(c, r) = mean;
    }
  }
  return q;
}

SparseMatrix MatrixMcreProblem::SteadyPenalty() const {
  if (load_active_.size() == 0) return PenaltyMatrix();
  // K + G diag(s / alpha) G^T, s_c = 1 for a load acting at every sample, else 0.
  Vector inverse_alphas(alphas_.size());
  for (int c = 0; c < static_cast<int>(alphas_.size()); ++c) {
    inverse_alphas[c] = ActsThroughout(load_active_, c) ? 1.0 / alphas_[c] : 0.0;
  }
  const SparseMatrix scaled = loads_ * inverse_alphas.asDiagonal();
  return stiffness_ + SparseMatrix(scaled * loads_transposed_);
}

Vector MatrixMcreProblem::TraceWeightRoots() const {
  const int rows = num_traces(), m = num_steps();
  Vector roots(static_cast<Eigen::Index>(rows) * (m + 1));
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k < rows; ++k) {
      roots[j * rows + k] = std::sqrt(QuadratureWeight(j) * time_step() * betas_[k]);
    }
  }
  return roots;
}

void MatrixMcreProblem::ForgetTracePreconditioner() {
  if (trace_factor_ != nullptr && trace_factor_.use_count() == 1) {
    // No moduli: PrepareTracePreconditioner rebuilds it in the same storage.
    std::const_pointer_cast<TraceFactor>(trace_factor_)->moduli.resize(0);
  } else {
    trace_factor_.reset();
  }
}

bool MatrixMcreProblem::PrepareTracePreconditioner(double rebuild_change, long max_traces) {
  const int rows = num_traces(), m = num_steps();
  const long size = static_cast<long>(rows) * (m + 1);
  if (rows == 0 || m < 2 || theta_ < 0.5 || size > max_traces || !(betas_.minCoeff() > 0.0)) {
    return false;
  }
  trace_scratch_.resize(size);
  if (trace_factor_ != nullptr && trace_factor_->moduli.size() == moduli_.size()) {
    const double change = (moduli_.array() / trace_factor_->moduli.array() - 1.0).abs().maxCoeff();
    if (change <= rebuild_change) return true;
  }
  // The previous factor's storage when this problem alone holds it (shared, a new one).
  std::shared_ptr<TraceFactor> built = trace_factor_ != nullptr && trace_factor_.use_count() == 1
                                           ? std::const_pointer_cast<TraceFactor>(trace_factor_)
                                           : std::make_shared<TraceFactor>();
  trace_factor_.reset();
  built->weights = TraceWeightRoots();
  // I + S = L L^T in single precision, factorised in place (its lower triangle becomes
  // L): a preconditioner needs I + S to a few digits, and float halves the two O(size^3)
  // products. The factor is kept in double, so that PCG applies one fixed operator.
  const TraceGrid grid{rows, m, theta_, time_step(), QuadratureWeight(0), QuadratureWeight(m)};
  Matrix& responses = trace_build_.impulse_responses;
  TraceImpulseResponses(&responses);
  const SparseMatrix penalty = SteadyPenalty();
  const IntervalLoads loads =
      TraceIntervalLoads(responses, loads_, load_active_, alphas_, &trace_build_.load_responses);
  Eigen::MatrixXf& single = trace_build_.operator_plus_identity;
  AssembleTraceOperator<float>(responses, penalty, loads, grid, built->weights,
                               /*lower_only=*/true, &trace_build_.scratch, &single);
  single.diagonal().array() += 1.0f;
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXf>> single_factor(single);
  if (single_factor.info() == Eigen::Success) {
    built->factor = single.cast<double>();
    built->single_precision = true;
  } else {
    // Float's round-off of a large S broke I + S's definiteness: in double.
    TraceAssemblyScratch<double> double_buffers;
    AssembleTraceOperator<double>(responses, penalty, loads, grid, built->weights,
                                  /*lower_only=*/true, &double_buffers, &built->factor);
    built->factor.diagonal().array() += 1.0;
    const Eigen::LLT<Eigen::Ref<Matrix>> double_factor(built->factor);
    if (double_factor.info() != Eigen::Success) return false;
    built->single_precision = false;
  }
  built->moduli = moduli_;
  trace_factor_ = std::move(built);
  ++trace_preconditioner_builds_;
  return true;
}

void MatrixMcreProblem::PreconditionTraces(const Matrix& residual, Matrix* result) {
  assert(trace_factor_ != nullptr && residual.rows() == num_traces() &&
         residual.cols() == num_steps() + 1 && trace_scratch_.size() == residual.size());
  // z = (C beta)^-1/2 (I + S)^-1 (C beta)^1/2 r, the trace field as one column.
  const Eigen::Map<const Vector> r(residual.data(), residual.size());
  trace_scratch_ = trace_factor_->weights.cwiseProduct(r);
  const auto lower = trace_factor_->factor.triangularView<Eigen::Lower>();
  lower.solveInPlace(trace_scratch_);
  lower.transpose().solveInPlace(trace_scratch_);
  result->resize(residual.rows(), residual.cols());
  Eigen::Map<Vector>(result->data(), result->size()) =
      trace_scratch_.cwiseQuotient(trace_factor_->weights);
}

}  // namespace mcrewave
