#include "mcrewave/linalg/sparse_theta_step.h"

#include <cassert>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mcrewave/linalg/theta_integrator.h"

namespace mcrewave {
namespace {

// The same pattern (sizes, column starts, row indices).
bool SamePattern(const SparseMatrix& a, const SparseMatrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
  for (Eigen::Index j = 0; j <= a.outerSize(); ++j) {
    if (a.outerIndexPtr()[j] != b.outerIndexPtr()[j]) return false;
  }
  for (Eigen::Index p = 0; p < a.nonZeros(); ++p) {
    if (a.innerIndexPtr()[p] != b.innerIndexPtr()[p]) return false;
  }
  return true;
}

// y = A x over a compressed symmetric matrix (column j = row j).
void MultiplySymmetric(const SparseMatrix& a, const double* x, double* y) {
  const int n = static_cast<int>(a.cols());
  const int* start = a.outerIndexPtr();
  const int* rows = a.innerIndexPtr();
  const double* values = a.valuePtr();
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (int p = start[i]; p < start[i + 1]; ++p) sum += values[p] * x[rows[p]];
    y[i] = sum;
  }
}

}  // namespace

bool SparseThetaStepper::Compute(const SparseMatrix& mass, const SparseMatrix& stiffness,
                                 double time_step, double theta) {
  assert(mass.rows() == mass.cols() && stiffness.rows() == mass.rows() &&
         stiffness.cols() == mass.cols());
  mass_ = mass;
  stiffness_ = stiffness;
  mass_.makeCompressed();
  stiffness_.makeCompressed();
  time_step_ = time_step;
  theta_ = theta;
  const double h = time_step;
  const int n = size();
  // M and K on their union pattern (Eigen's sum keeps the union, zeros included).
  SparseMatrix union_mass = mass_ + 0.0 * stiffness_;
  SparseMatrix union_stiffness = 0.0 * mass_ + stiffness_;
  union_mass.makeCompressed();
  union_stiffness.makeCompressed();
  if (!SamePattern(union_mass, union_stiffness)) {
    throw std::logic_error("SparseThetaStepper: the union patterns of M and K differ");
  }
  const long entries = static_cast<long>(union_mass.nonZeros());
  pattern_start_.assign(union_mass.outerIndexPtr(), union_mass.outerIndexPtr() + n + 1);
  pattern_rows_.assign(union_mass.innerIndexPtr(), union_mass.innerIndexPtr() + entries);
  free_values_.resize(static_cast<std::size_t>(entries));
  stiffness_values_.resize(static_cast<std::size_t>(entries));
  const double free_factor = h * h * theta * (1.0 - theta);
  for (long p = 0; p < entries; ++p) {
    const double m = union_mass.valuePtr()[p], k = union_stiffness.valuePtr()[p];
    free_values_[static_cast<std::size_t>(p)] = m - free_factor * k;  // R
    stiffness_values_[static_cast<std::size_t>(p)] = -h * k;          // -h K
  }
  // S = M + h^2 theta^2 K; the symbolic analysis is kept while its pattern is.
  SparseMatrix schur = union_mass + (h * h * theta * theta) * union_stiffness;
  schur.makeCompressed();
  if (!analysed_ || !SamePattern(schur, schur_)) {
    factor_.analyzePattern(schur);
    analysed_ = true;
    ++analysis_count_;
  }
  schur_ = std::move(schur);
  factor_.factorize(schur_);
  if (factor_.info() != Eigen::Success) return false;
  const Vector& pivots = factor_.vectorD();
  for (int i = 0; i < n; ++i) {
    if (!(pivots[i] > 0.0)) return false;
  }
  inverse_pivot_ = pivots.cwiseInverse();
  const auto& indices = factor_.permutationP().indices();
  permutation_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) permutation_[static_cast<std::size_t>(i)] = indices[i];
  scratch_ = Vector::Zero(n);
  return true;
}

long SparseThetaStepper::factor_nonzeros() const {
  return static_cast<long>(factor_.matrixL().nestedExpression().nonZeros()) + size();
}

void SparseThetaStepper::SolveInPlace(double* x) {
  const int n = size();
  double* y = scratch_.data();
  const int* p = permutation_.data();
  // y = P x: y[P[i]] = x[i].
  for (int i = 0; i < n; ++i) y[p[i]] = x[i];
  const SparseMatrix& l = factor_.matrixL().nestedExpression();
  const int* start = l.outerIndexPtr();
  const int* counts = l.innerNonZeroPtr();
  const int* rows = l.innerIndexPtr();
  const double* values = l.valuePtr();
  // L y' = y (unit lower, by columns), then D^-1.
  for (int j = 0; j < n; ++j) {
    const double yj = y[j];
    const int stop = counts != nullptr ? start[j] + counts[j] : start[j + 1];
    for (int q = start[j]; q < stop; ++q) y[rows[q]] -= values[q] * yj;
  }
  const double* inverse_pivot = inverse_pivot_.data();
  for (int j = 0; j < n; ++j) y[j] *= inverse_pivot[j];
  // L^T y'' = y' (by columns of L: dot products with the rows already solved).
  for (int j = n - 1; j >= 0; --j) {
    double sum = y[j];
    const int stop = counts != nullptr ? start[j] + counts[j] : start[j + 1];
    for (int q = start[j]; q < stop; ++q) sum -= values[q] * y[rows[q]];
    y[j] = sum;
  }
  // x = P^T y: x[i] = y[P[i]].
  for (int i = 0; i < n; ++i) x[i] = y[p[i]];
}

void SparseThetaStepper::Step(const double* v_k, const double* u_k, const double* z,
                              const double* force, double f0, double fL,
                              const PointLoads* point_loads, double* v_next, double* u_next) {
  const int n = size();
  const double h = time_step_;
  const int* start = pattern_start_.data();
  const int* rows = pattern_rows_.data();
  const double* r = free_values_.data();
  const double* k = stiffness_values_.data();
  // rhs_i = sum_j R_ij v_j + (-h K_ij) (u_j + z_j) + h f_i   (one pass, symmetric).
  if (z != nullptr) {
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int q = start[i]; q < start[i + 1]; ++q) {
        const int j = rows[q];
        sum += r[q] * v_k[j] + k[q] * (u_k[j] + z[j]);
      }
      v_next[i] = sum;
    }
  } else {
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int q = start[i]; q < start[i + 1]; ++q) {
        const int j = rows[q];
        sum += r[q] * v_k[j] + k[q] * u_k[j];
      }
      v_next[i] = sum;
    }
  }
  if (force != nullptr) {
    for (int i = 0; i < n; ++i) v_next[i] += h * force[i];
  }
  v_next[0] += h * f0;
  v_next[n - 1] += h * fL;
  if (point_loads != nullptr) {
    for (int i = 0; i < point_loads->count; ++i) {
      v_next[point_loads->nodes[i]] += h * point_loads->values[i];
    }
  }
  SolveInPlace(v_next);
  // u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1}.
  const double a = h * (1.0 - theta_), b = h * theta_;
  for (int i = 0; i < n; ++i) u_next[i] = u_k[i] + a * v_k[i] + b * v_next[i];
}

void SparseThetaStepper::StepTransposed(const double* a_next, const double* e_next, double* y,
                                        double* a_k, double* e_k) {
  const int n = size();
  const double h = time_step_;
  // y = S^-1 (a_{k+1} + h theta e_{k+1})
  for (int i = 0; i < n; ++i) y[i] = a_next[i] + h * theta_ * e_next[i];
  SolveInPlace(y);
  const int* start = pattern_start_.data();
  const int* rows = pattern_rows_.data();
  const double* r = free_values_.data();
  const double* k = stiffness_values_.data();
  const double a = h * (1.0 - theta_);
  // a_k = R y + h (1 - theta) e_{k+1},  e_k = e_{k+1} + (-h K) y   (one pass, symmetric).
  for (int i = 0; i < n; ++i) {
    double free_sum = 0.0, stiffness_sum = 0.0;
    for (int q = start[i]; q < start[i + 1]; ++q) {
      const int j = rows[q];
      free_sum += r[q] * y[j];
      stiffness_sum += k[q] * y[j];
    }
    a_k[i] = free_sum + a * e_next[i];
    e_k[i] = e_next[i] + stiffness_sum;
  }
}

void SparseThetaStepper::MultiplyMass(const double* x, double* y) const {
  MultiplySymmetric(mass_, x, y);
}

void SparseThetaStepper::MultiplyStiffness(const double* x, double* y) const {
  MultiplySymmetric(stiffness_, x, y);
}

}  // namespace mcrewave
