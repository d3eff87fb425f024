#include "mcrewave/least_squares/sensor_placement.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <sstream>

namespace mcrewave {
namespace {

// log det F = 2 sum_i ln L_ii of F's Cholesky factor already computed in *llt.
double LogDeterminant(const Eigen::LLT<Matrix>& llt) {
  return 2.0 * llt.matrixLLT().diagonal().array().log().sum();
}

}  // namespace

bool SensorPlacementOptions::IsValid(std::string* error) const {
  if (count < 1) {
    *error = "count must be at least 1, got " + std::to_string(count);
    return false;
  }
  if (!(prior_log_modulus_std > 0.0 && std::isfinite(prior_log_modulus_std))) {
    *error = "prior_log_modulus_std must be positive and finite";
    return false;
  }
  return true;
}

std::string SensorPlacementSummary::BriefReport() const {
  std::ostringstream out;
  out << "sensor placement: " << TerminationTypeToString(termination) << ", " << chosen.size()
      << " sensors";
  if (chosen_std.rows() > 0) {
    out << ", Cramer-Rao std of ln E_z from " << chosen_std.row(chosen_std.rows() - 1).minCoeff()
        << " to " << chosen_std.row(chosen_std.rows() - 1).maxCoeff();
  }
  out << " (" << message << ")";
  return out.str();
}

Vector CramerRaoStd(const Matrix& information) {
  const Eigen::LLT<Matrix> llt(information);
  const Matrix inverse = llt.solve(Matrix::Identity(information.rows(), information.cols()));
  return inverse.diagonal().cwiseMax(0.0).cwiseSqrt();
}

SensorPlacementSummary PlaceSensors(const SensorPlacementOptions& options,
                                    const std::vector<Matrix>& sensor_information,
                                    const Matrix& base_information) {
  SensorPlacementSummary summary;
  std::string why;
  if (!options.IsValid(&why)) {
    summary.message = "invalid options: " + why;
    return summary;
  }
  const int candidates = static_cast<int>(sensor_information.size());
  if (options.count > candidates) {
    summary.message = "count " + std::to_string(options.count) + " exceeds the " +
                      std::to_string(candidates) + " candidates";
    return summary;
  }
  const auto zones = sensor_information.front().rows();
  for (int k = 0; k < candidates; ++k) {
    const Matrix& information = sensor_information[static_cast<std::size_t>(k)];
    if (information.rows() != zones || information.cols() != zones || !information.allFinite()) {
      summary.message = "the information of candidate " + std::to_string(k) + " is not a finite " +
                        std::to_string(zones) + " x " + std::to_string(zones) + " matrix";
      return summary;
    }
  }

  if (base_information.size() > 0 &&
      (base_information.rows() != zones || base_information.cols() != zones ||
       !base_information.allFinite())) {
    summary.message = "the base information is not a finite " + std::to_string(zones) + " x " +
                      std::to_string(zones) + " matrix";
    return summary;
  }

  // F(A) = I / sigma_p^2 + I_0 + sum_{k in A} I_k, from A empty.
  const double prior = 1.0 / (options.prior_log_modulus_std * options.prior_log_modulus_std);
  Matrix information = prior * Matrix::Identity(zones, zones);
  if (base_information.size() > 0) information += base_information;
  summary.no_sensor_std = CramerRaoStd(information);
  Matrix every = information;
  for (const Matrix& sensor : sensor_information) every += sensor;
  summary.all_candidates_std = CramerRaoStd(every);

  std::vector<char> taken(static_cast<std::size_t>(candidates), 0);
  summary.chosen_std.resize(options.count, zones);
  Eigen::LLT<Matrix> llt(zones);
  Matrix trial(zones, zones);
  llt.compute(information);
  double log_det = LogDeterminant(llt);
  for (int pick = 0; pick < options.count; ++pick) {
    int best = -1;
    double best_log_det = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < candidates; ++k) {
      if (taken[static_cast<std::size_t>(k)]) continue;
      // log det F(A + k): F(A) is positive definite, I_k semi-definite.
      trial = information + sensor_information[static_cast<std::size_t>(k)];
      llt.compute(trial);
      if (llt.info() != Eigen::Success) continue;
      const double value = LogDeterminant(llt);
      if (value > best_log_det) {
        best_log_det = value;
        best = k;
      }
    }
    if (best < 0) {
      summary.message = "no candidate keeps the information positive definite at pick " +
                        std::to_string(pick + 1);
      summary.chosen_std.conservativeResize(pick, zones);
      return summary;
    }
    taken[static_cast<std::size_t>(best)] = 1;
    information += sensor_information[static_cast<std::size_t>(best)];
    summary.chosen.push_back(best);
    summary.log_det_gain.push_back(best_log_det - log_det);
    log_det = best_log_det;
    summary.chosen_std.row(pick) = CramerRaoStd(information).transpose();
  }
  summary.termination = TerminationType::kConvergence;
  summary.message = "chose " + std::to_string(options.count) + " of " + std::to_string(candidates) +
                    " candidates";
  return summary;
}

}  // namespace mcrewave
