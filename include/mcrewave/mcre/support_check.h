// A test of the measured data against a trusted support (docs/boundaries.md section 2).
//
// A trusted support holds its dofs at rest (mcre.clamp: trusted): its measured
// displacement u~ is then noise alone, independent of the force f~ it carries. A
// support that gives (a spring, a load cell, a clamp that is not rigid) moves with its
// force: u = -f / k_s for a spring of stiffness k_s between the structure and the wall.
// The test regresses u~ on z, the measured force f~ or a pre-filtered f~ (the
// regressor: less noise, the same signal),
//   c   = -<u~, z> / <z, z>          the support's compliance [m/N] (1 / k_s),
//   s_c = s_u / ||z||                its standard deviation when u~ is white noise,
//   t   = c / s_c = -<u~, z> / (s_u ||z||),
// with s_u the noise level of the raw u~ from its second differences
// (DifferenceNoiseStd, modulus_uncertainty.h). Given z, t is standard normal when the
// support is rigid and the noise of u~ is white and independent of z's, whatever the
// noise of z. A passive support moves against the force it applies: a spring and a
// dashpot from rest give -<u, f> = k_s ||u||^2 + eta u(T)^2 / 2 >= 0. So the test is
// one-sided: the data contradict the support when t exceeds the threshold (a false
// alarm rate of 1 - Phi(threshold) on a rigid support).
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

struct SupportCheck {
  std::string support;               // the support's name
  std::string displacement_channel;  // u~
  std::string force_channel;         // f~
  double displacement_std = 0.0;     // s_u [m]
  double compliance = 0.0;           // c [m/N]
  double compliance_std = 0.0;       // s_c [m/N]
  double statistic = 0.0;            // t (0 when z vanishes: nothing to test against)
  double threshold = 0.0;            // t above which the support is contradicted
  bool contradicted = false;         // t > threshold

  // 1 / c [N/m]: the spring to the wall that explains the motion (+inf when c <= 0).
  double SupportStiffness() const;
  // One line: the support, t against the threshold, c and the spring it implies.
  std::string BriefReport() const;
};

// The test of one displacement history u~ (raw) against the regressor z (above).
// Precondition: equal sizes, finite values, threshold > 0.
SupportCheck CheckSupport(const Vector& displacement, const Vector& regressor, double threshold);

// One test per support of `model` whose displacement channel `raw` holds and whose force
// channel `regressors` holds, in the model's order (the others are not tested): u~ from
// `raw` (the test assumes white noise on it), z from `regressors` (the raw data or
// pre-filtered ones, on the same samples).
std::vector<SupportCheck> CheckSupports(const MatrixModelData& model, const ChannelSet& raw,
                                        const ChannelSet& regressors, double threshold);

// Whether any of the checks contradicts its support.
bool AnySupportContradicted(const std::vector<SupportCheck>& checks);

// The weight a in [0, 1] of the paper's formulation in a run's E,
//   E = (1 - a) E_trusted + a E_measured,  a = (t - t1) / (t2 - t1) clipped to [0, 1],
// t the largest statistic of the checks, t1 = ramp_start, t2 = threshold
// (docs/boundaries.md section 10): 0 below t1 (or without checks), 1 above t2. With
// t1 = t2, 1 when t > t2 and 0 otherwise: the hard switch. Precondition:
// 0 < ramp_start <= threshold.
double SupportSwitchWeight(const std::vector<SupportCheck>& checks, double ramp_start,
                           double threshold);

}  // namespace mcrewave
