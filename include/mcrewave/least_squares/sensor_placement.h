// Sensor placement by greedy D-optimal design on the Fisher information of the zone
// moduli (docs/matrix_models.md section 15).
//
// Each candidate sensor k brings its own information about p_z = ln E_z, the Z x Z
// matrix I_k (MatrixOutputErrorObjective::Cost's sensor_information in moduli, taken to
// log moduli as D I_k D with D = diag(E_z)): under independent white noise the
// information of a set of sensors is the sum of theirs. With a prior of standard
// deviation sigma_p on every p_z (a zone the data say nothing of keeps sigma_p), the
// information of a set A is
//
//   F(A) = I / sigma_p^2 + I_0 + sum_{k in A} I_k,
//
// I_0 the information every design has (the supports' measured forces, or none),
// and its Cramer-Rao standard deviations are sqrt(diag(F(A)^-1)) (of ln E_z: relative
// errors of E_z). D-optimal design chooses the A of the given size that maximises
// log det F(A), the volume of the information's ellipsoid; the greedy rule adds, one at a
// time, the candidate of the largest gain
//
//   log det F(A + k) - log det F(A) = log det (I + L^-1 I_k L^-T),  F(A) = L L^T,
//
// (the lowest index among equal gains), the forward form of Kammer's effective
// independence (J. Guid. Control Dyn. 14, 1991), within 1 - 1/e of the best set's gain
// for this submodular objective.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

struct SensorPlacementOptions {
  int count = 20;                    // sensors to choose, at most the candidates'
  double prior_log_modulus_std = 1;  // sigma_p [-]: the prior's std of every ln E_z

  bool IsValid(std::string* error) const;
};

struct SensorPlacementSummary {
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  // The candidates chosen (indices into the information list), in the order chosen,
  // and the gain in log det F of each.
  std::vector<int> chosen;
  std::vector<double> log_det_gain;
  // Row i: the Cramer-Rao std of every ln E_z with the first i + 1 chosen sensors
  // (count x Z).
  Matrix chosen_std;
  // The same with every candidate, and with none (the prior and I_0 alone), Z entries.
  Vector all_candidates_std, no_sensor_std;

  std::string BriefReport() const;
};

// Chooses options.count of the candidates by the greedy rule above. sensor_information
// holds one symmetric positive semi-definite Z x Z matrix per candidate, in log moduli;
// base_information I_0 is such a matrix too, or empty (none). Fails (termination
// kFailure, with why in message) when the options are not valid, a matrix is not Z x Z
// or not finite, or the count exceeds the candidates.
SensorPlacementSummary PlaceSensors(const SensorPlacementOptions& options,
                                    const std::vector<Matrix>& sensor_information,
                                    const Matrix& base_information = Matrix());

// sqrt(diag(F^-1)) of a symmetric positive definite F (the Cramer-Rao standard
// deviations of its parameters).
Vector CramerRaoStd(const Matrix& information);

}  // namespace mcrewave
