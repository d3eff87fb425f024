#include "mcre/discrete_mcre_operators.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mcrewave/core/operation_counts.h"

namespace mcrewave::internal {

namespace counts = operation_counts;

bool BandCholesky::Compute(const SymmetricBandMatrix& matrix) {
  const int n = matrix.size(), p = matrix.half_bandwidth();
  lower_ = Matrix::Zero(p + 1, n);
  // L_jj = sqrt(A_jj - sum_k L_jk^2),  L_ij = (A_ij - sum_k L_ik L_jk) / L_jj,  j < i <= j + p.
  for (int j = 0; j < n; ++j) {
    double pivot = matrix.lower(0, j);
    for (int k = std::max(0, j - p); k < j; ++k) pivot -= lower_(j - k, j) * lower_(j - k, j);
    if (!(pivot > 0.0)) return false;
    lower_(0, j) = std::sqrt(pivot);
    for (int i = j + 1; i <= std::min(n - 1, j + p); ++i) {
      double entry = matrix.lower(i - j, i);
      for (int k = std::max(0, i - p); k < j; ++k) entry -= lower_(i - k, i) * lower_(j - k, j);
      lower_(i - j, i) = entry / lower_(0, j);
    }
  }
  return true;
}

void BandCholesky::MultiplyTransposed(const Eigen::Ref<const Vector>& x,
                                      Eigen::Ref<Vector> y) const {
  const int n = static_cast<int>(lower_.cols()), p = static_cast<int>(lower_.rows()) - 1;
  // y_j = sum_{i = j..j+p} L_ij x_i.
  for (int j = 0; j < n; ++j) {
    double sum = lower_(0, j) * x[j];
    for (int d = 1; d <= p && j + d < n; ++d) sum += lower_(d, j + d) * x[j + d];
    y[j] = sum;
  }
}

void BandCholesky::SolveTransposed(Eigen::Ref<Vector> x) const {
  const int n = static_cast<int>(lower_.cols()), p = static_cast<int>(lower_.rows()) - 1;
  // Backward substitution: x_j = (b_j - sum_{i = j+1..j+p} L_ij x_i) / L_jj.
  for (int j = n - 1; j >= 0; --j) {
    double sum = x[j];
    for (int d = 1; d <= p && j + d < n; ++d) sum -= lower_(d, j + d) * x[j + d];
    x[j] = sum / lower_(0, j);
  }
}

double BandCholesky::entries() const {
  const double n = static_cast<double>(lower_.cols()), p = static_cast<double>(lower_.rows()) - 1;
  return n * (p + 1.0) - 0.5 * p * (p + 1.0);
}

std::vector<int> ObservedDofs(const SparseMatrix& weighted_observation) {
  std::vector<int> observed;
  const Vector diagonal = weighted_observation.diagonal();
  for (int i = 0; i < static_cast<int>(diagonal.size()); ++i) {
    if (diagonal[i] != 0.0) observed.push_back(i);
  }
  return observed;
}

DiscreteMcreOperators::DiscreteMcreOperators(const CoupledProblem& problem)
    : problem_(problem),
      num_nodes_(problem.num_nodes()),
      num_steps_(problem.num_steps()),
      time_step_(problem.time_step()),
      theta_(problem.theta()),
      observation_(problem.WeightedObservation()),
      observed_(ObservedDofs(observation_)),
      load_(num_nodes_) {
  if (problem.TimeVaryingPenalty()) {
    throw std::runtime_error(
        "a load known to vanish outside an interval makes P = K + G diag(1/alpha) G^T change "
        "with time, and these operators take it as one matrix");
  }
  const SymmetricBandMatrix mass(problem.MassMatrix());
  stiffness_ = SymmetricBandMatrix(problem.StiffnessMatrix());
  penalty_ = SymmetricBandMatrix(problem.PenaltyMatrix());
  bandwidth_ =
      std::max({mass.half_bandwidth(), stiffness_.half_bandwidth(), penalty_.half_bandwidth()});
  const double h = time_step_, theta = theta_;
  // R = M - h^2 theta (1 - theta) K.
  free_state_ =
      SymmetricBandMatrix::LinearCombination(1.0, mass, -h * h * theta * (1.0 - theta), stiffness_);
  // S = M + h^2 theta^2 K,  S' = M + h^2 (1 - theta)^2 K.
  const SymmetricBandMatrix step_matrix =
      SymmetricBandMatrix::LinearCombination(1.0, mass, h * h * theta * theta, stiffness_);
  const SymmetricBandMatrix reversed_step_matrix = SymmetricBandMatrix::LinearCombination(
      1.0, mass, h * h * (1.0 - theta) * (1.0 - theta), stiffness_);
  const char* failed = nullptr;
  if (!step_factor_.Compute(step_matrix)) {
    failed = "M + h^2 theta^2 K";
  } else if (!reversed_step_factor_.Compute(reversed_step_matrix)) {
    failed = "M + h^2 (1 - theta)^2 K";
  } else if (!penalty_factor_.Compute(penalty_)) {
    failed = "the penalty matrix P = K + G diag(1/alpha) G^T";
  } else if (!mass_factor_.Compute(mass)) {
    failed = "the mass matrix M";
  }
  if (failed != nullptr) {
    throw std::runtime_error(std::string("discrete MCRE operators: ") + failed +
                             " is not positive definite");
  }
}

Vector DiscreteMcreOperators::ObservationColumn(int i) const {
  return observation_.col(observed_[i]).toDense();
}

void DiscreteMcreOperators::AddMeasuredForce(int j, double scale, Eigen::Ref<Vector> x) {
  problem_.MeasuredForce(j, load_);
  x += scale * load_;
  macs_ += num_nodes_;
}

void DiscreteMcreOperators::AddWeightedData(int j, double scale, Eigen::Ref<Vector> x) {
  problem_.WeightedData(j, load_);
  x += scale * load_;
  macs_ += num_nodes_;
}

void DiscreteMcreOperators::ObservationProduct(const Eigen::Ref<const Vector>& x,
                                               Eigen::Ref<Vector> y) {
  y.noalias() = observation_ * x;
  macs_ += static_cast<double>(observation_.nonZeros());
}

void DiscreteMcreOperators::StiffnessProduct(const Eigen::Ref<const Vector>& x,
                                             Eigen::Ref<Vector> y) {
  stiffness_.Multiply(x, y);
  macs_ += counts::BandProduct(num_nodes_, bandwidth_);
}

void DiscreteMcreOperators::StiffnessProductAdd(double scale, const Eigen::Ref<const Vector>& x,
                                                Eigen::Ref<Vector> y) {
  stiffness_.MultiplyAdd(scale, x, y);
  macs_ += counts::BandProductAdd(num_nodes_, bandwidth_);
}

void DiscreteMcreOperators::PenaltyProduct(const Eigen::Ref<const Vector>& x,
                                           Eigen::Ref<Vector> y) {
  penalty_.Multiply(x, y);
  macs_ += counts::BandProduct(num_nodes_, penalty_.half_bandwidth());
}

void DiscreteMcreOperators::FreeStateProduct(const Eigen::Ref<const Vector>& x,
                                             Eigen::Ref<Vector> y) {
  free_state_.Multiply(x, y);
  macs_ += counts::BandProduct(num_nodes_, bandwidth_);
}

void DiscreteMcreOperators::SolveStep(Eigen::Ref<Vector> x) {
  step_factor_.SolveInPlace(x);
  macs_ += counts::BandSolve(num_nodes_, bandwidth_);
}

void DiscreteMcreOperators::SolveReversedStep(Eigen::Ref<Vector> x) {
  reversed_step_factor_.SolveInPlace(x);
  macs_ += counts::BandSolve(num_nodes_, bandwidth_);
}

void DiscreteMcreOperators::ToEnergyCoordinates(const Eigen::Ref<const Vector>& displacement_like,
                                                const Eigen::Ref<const Vector>& velocity_like,
                                                Eigen::Ref<Vector> displacement_coordinates,
                                                Eigen::Ref<Vector> velocity_coordinates) {
  penalty_factor_.MultiplyTransposed(displacement_like, displacement_coordinates);
  mass_factor_.MultiplyTransposed(velocity_like, velocity_coordinates);
  macs_ += penalty_factor_.entries() + mass_factor_.entries();
}

void DiscreteMcreOperators::FromEnergyCoordinates(Eigen::Ref<Vector> displacement_like,
                                                  Eigen::Ref<Vector> velocity_like) {
  penalty_factor_.SolveTransposed(displacement_like);
  mass_factor_.SolveTransposed(velocity_like);
  macs_ += penalty_factor_.entries() + mass_factor_.entries();
}

void DiscreteMcreOperators::ThetaStep(const Eigen::Ref<const Vector>& u,
                                      const Eigen::Ref<const Vector>& v, const Vector* force,
                                      Eigen::Ref<Vector> u_next, Eigen::Ref<Vector> v_next) {
  const double h = time_step_, theta = theta_;
  // v' = S^-1 (R v - h K u + h f).
  free_state_.Multiply(v, v_next);
  stiffness_.MultiplyAdd(-h, u, v_next);
  if (force != nullptr) v_next += h * (*force);
  step_factor_.SolveInPlace(v_next);
  // u' = u + h (1 - theta) v + h theta v'.
  u_next = u + (h * (1.0 - theta)) * v + (h * theta) * v_next;
  macs_ += counts::ThetaStep(num_nodes_, bandwidth_, force != nullptr);
}

}  // namespace mcrewave::internal
