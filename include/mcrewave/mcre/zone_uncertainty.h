// The first-order uncertainty of the zone moduli identified on a structure given by
// matrices (docs/matrix_models.md section 13), the n-parameter form of
// modulus_uncertainty.h.
//
// E* is where g(E) = de^2/dE (one entry per zone) vanishes. The coupled solution s is
// affine in the data d, s(d + n) = s_d + s_n with s_n the solution with the noise n
// alone as data, and g a quadratic form of (s, d). Noise therefore moves the minimum,
// to first order in n, by
//   dE = -H^-1 dg,   dg = (g(s_d + s_n; d + n) - g(s_d - s_n; d - n)) / 2,
// (polarisation: exact for a quadratic form) with H the curvature of e^2, taken as the
// secant of g over the bar's window (kCurvatureWindow, +- 5 % of each E*_z):
//   H_{:,z} = (g(E* + w E*_z e_z) - g(E* - w E*_z e_z)) / (2 w E*_z),
// symmetrised, or H as the caller gives it (the bar's run: the slope of its cost curve,
// modulus_uncertainty.h). Over `samples` seeded draws, Cov(E*) = mean_i dE_i dE_i^T (dE is linear
// in n: zero mean). Each draw costs one coupled solve; H costs 2Z.
//
// On a model with element blocks the same draws give the noise's part of the
// sensitivity map s_el = de^2/d ln E_el at the moduli (mcre/element_error_map.h), the
// moduli held: ds_el = (s_el(s_d + s_n; d + n) - s_el(s_d - s_n; d - n)) / 2 and
// std(s_el) = sqrt(mean_i ds_el,i^2), against which a peak of the map is significant or
// not (docs/boundaries.md section 11).
#pragma once

#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

struct ZoneUncertainty {
  bool available = false;
  std::string message = "not computed";  // why not available, or "ok"
  Vector std_dev;                        // sqrt(Cov_zz) [Pa], one per zone
  Matrix covariance;                     // Cov(E*) [Pa^2]
  Matrix curvature;                      // H [J s / Pa^2]
  int samples = 0;                       // noise draws used
  NoiseLevels noise;                     // the levels drawn
  long sweeps = 0;                       // of the curvature's and the noise's solves
  // std(s_el) [J s], one per element (above); empty without element blocks.
  Vector sensitivity_std;
};

// The figure at the identified moduli (see the top of this file). `solution` is the
// coupled solution of `data` at `moduli` with mcre's weights and treatment of the
// supports; noise holds the levels to draw: displacement_std on every displacement
// channel of data, strain_std on every strain channel, force_std on every force channel
// (in the set's order, a channel's samples, then the next; StandardNormal seeded with
// options.seed). curvature: H [J s / Pa^2] (zones x zones), or nullptr for the secants.
// A streaming solution (its traces, no fields) gives dg from one application of the
// plus and minus problems' maps at y_d +- y_n. Not available (with a message) when no
// level is positive, the solution holds neither fields nor traces, a solve is not usable, or H is
// not positive definite, or options.samples is 0 (kUncertaintyOffMessage). Precondition:
// options.samples >= 0 (one draw is the covariance of that draw; the config asks for 0 or
// 2 to 1000, UncertaintyOptions::IsValid).
ZoneUncertainty EstimateZoneUncertainty(const UncertaintyOptions& options,
                                        const MatrixModelData& model, const ChannelSet& data,
                                        const McreOptions& mcre, double theta,
                                        const CoupledSolverOptions& inner, const Vector& moduli,
                                        const CoupledSolution& solution, const NoiseLevels& noise,
                                        const Matrix* curvature = nullptr);

}  // namespace mcrewave
