// An uncertainty figure for the identified modulus: the first-order standard deviation
// of E* under white measurement noise (README, "Uncertainty figure").
//
// E* is where g(E) = de^2/dE vanishes. The coupled solution s = (U, W) is affine in the
// data d and g a quadratic form of (s, d), so noise n added to the data moves the
// minimum, to first order in n, by dE = -dg_1 / k with
//   dg_1 = (g(s_d + s_n; d + n) - g(s_d - s_n; d - n)) / 2   (polarisation),
//   k    = d^2 e^2 / dE^2,
// s_n one coupled solve with the noise alone as data, at E*: the one-zone case of
// zone_uncertainty.h. Over `samples` seeded draws, std(E*) = sqrt(mean_i dE_i^2) (dE is
// linear in n: zero mean).
//
// k is the least-squares slope of g over the cost-curve points within
// +- kCurvatureWindow E* of E*, not the local second derivative: at low SNR the cost has
// noise-made ripples whose local curvature says nothing about how far the minimum
// moves. The figure is trustworthy when small against that window, indicative otherwise.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mcrewave/core/random.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

// The `uncertainty:` section of the config.
struct UncertaintyOptions {
  // Noise draws, in [2, 1000]; 0: not estimated (EstimateModulusUncertainty and
  // EstimateZoneUncertainty return at once, not available, saying so).
  int samples = 16;
  std::uint64_t seed = 1;  // seed of the draws (independent of data.seed's noise)

  bool IsValid(std::string* error) const;
};

// The message of an uncertainty not estimated because uncertainty.samples is 0.
inline constexpr const char* kUncertaintyOffMessage = "not estimated: uncertainty.samples is 0";

// Standard deviations of white noise per quantity.
struct NoiseLevels {
  double displacement_std = 0.0;  // [m], every displacement channel (u0, uL, u@X)
  double force_std = 0.0;         // [N]
  double strain_std = 0.0;        // [-], every strain channel (e@X); 0 without any
};

// The level of a channel of `kind`: displacement_std, strain_std or force_std.
double NoiseLevel(const NoiseLevels& noise, ChannelKind kind);
// Replaces the values of every channel of *set, in the set's order, by white noise at
// its kind's level: level x (*normal)() sample by sample.
void DrawWhiteNoise(const NoiseLevels& noise, StandardNormal* normal, ChannelSet* set);

// Noise levels estimated from the data alone, channel by channel, from second
// differences d2_j = x_{j+1} - 2 x_j + x_{j-1}: for white noise of std s they have
// std sqrt(6) s, while a signal smooth on the sampling scale adds little, and
// the median absolute deviation ignores the few samples at wave fronts:
//   s = 1.4826 median_j |d2_j - median d2| / sqrt(6),
// then s^2 averaged over the channels of each type (displacements: the two ends and
// every u@X; forces: the two ends; strains: every e@X). For measured data, whose noise
// is not known.
NoiseLevels DifferenceNoiseLevels(const ChannelSet& data);
// s = 1.4826 MAD(d2) / sqrt(6) of one channel, the estimate above (0 with fewer than 3
// samples).
double DifferenceNoiseStd(const Vector& channel);

// RMS misfits at the optimum of the model's end channels (`model`: u0, uL, f0, fL at
// the optimum, as MatrixMcreProblem::ModelChannels gives them) against the measured
// ones (`data`): displacement sqrt(mean_{ends, j} (u_end,j - u~_end,j)^2) and force
// sqrt(mean_{ends, j} (f_end,j - f~_end,j)^2), where f - f~ = -G^T W / alpha for a load
// and r(U) - f0~ for a trusted clamp's reaction (f0 an output). An end channel `model`
// does not hold is left out of its mean.
NoiseLevels EndMisfitLevels(const ChannelSet& data, const ChannelSet& model);

// A point of the cost curve e^2(E).
struct CostCurvePoint {
  double modulus = 0.0;        // E [Pa]
  double cost = -1.0;          // e^2 [J s]
  double cost_gradient = 0.0;  // de^2/dE [J s / Pa]
  bool usable = false;
};

// Half-width of the window of the curvature fit, as a fraction of E*.
inline constexpr double kCurvatureWindow = 0.05;

// Least-squares slope k of de^2/dE against E over the usable points with
// |E - center| <= window * center [J s / Pa^2]; all usable points when fewer
// than 3 lie in the window. *points_used receives the count. Returns 0 when
// fewer than 2 points are usable.
double CostGradientSlope(const std::vector<CostCurvePoint>& curve, double center, double window,
                         int* points_used);

struct ModulusUncertainty {
  bool available = false;
  std::string message = "not computed";  // why not available, or "ok"
  double std_dev = -1.0;                 // std(E*) [Pa]
  double relative_std_dev = -1.0;        // std(E*) / E*
  double curvature = -1.0;               // k [J s / Pa^2]
  int curvature_points = 0;              // cost-curve points of the fit
  int samples = 0;                       // noise draws used
  NoiseLevels noise;                     // the levels drawn
  long sweeps = 0;                       // of the noise solves
  // std(s_el) [J s] of the sensitivity map at E* under the same draws, E* held, one per
  // element (zone_uncertainty.h); empty without element blocks.
  Vector sensitivity_std;
};

// The figure at the identified modulus (see the top of this file) of a model of one
// zone given by matrices (the bar's run: BarRunModel), EstimateZoneUncertainty with the
// curvature k: `solution` is the coupled solution of `data` at `modulus` with mcre's
// weights and treatment of the supports; noise the levels to draw on every channel of
// data, by its kind, in the set's order (the bar's: u0 and uL, f0 and fL, then the
// interior sensors). Not available (with a message) when curvature <= 0, no noise level
// is positive, the solution holds no fields (a streaming solve) or a noise solve is not
// usable. Preconditions: options.IsValid(), the model has one zone.
ModulusUncertainty EstimateModulusUncertainty(const UncertaintyOptions& options,
                                              const MatrixModelData& model, const ChannelSet& data,
                                              const McreOptions& mcre, double theta,
                                              const CoupledSolverOptions& inner, double modulus,
                                              const CoupledSolution& solution,
                                              const NoiseLevels& noise, double curvature,
                                              int curvature_points);

}  // namespace mcrewave
