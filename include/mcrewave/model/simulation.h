// Direct simulation of the reference experiment and synthetic measurements.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/data/measurement.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/experiment.h"

namespace mcrewave {

// Simulates the bar clamped at x = 0, at rest at t = 0, loaded at x = L by
// load.Value(t), with the FE model of `bar` and the theta method of `time`, and
// returns the four channels at t_k = k h (k = 0..m), and the interior sensors named
// in `sensors` (u@X, e@X: the observation rows of this mesh, model/bar_model.h). With
// `zones`, the modulus is bar.modulus but over the zones (ElementModuli: an element
// partly covered has its pieces in series).
//
// The clamp reaction is the force the free bar needs at node 0 to reproduce the
// clamped motion: f0_k = row_0(M a_k + K u_k), with the accelerations a_k of the
// free nodes from M_r a_k = f_k - K_r u_k. For any theta this makes the free bar,
// driven by (f0, fL) with the same scheme, reproduce the clamped trajectory to
// round-off (v_{k+1} - v_k = h (theta a_{k+1} + (1 - theta) a_k) holds exactly).
ChannelSet SimulateClampedBar(const BarProperties& bar, const LoadOptions& load,
                              const TimeOptions& time, const std::vector<ModulusZone>& zones = {},
                              const std::vector<std::string>& sensors = {});

// The noise-free "truth" sampled on the model's grid t_k = k h: the simulation on a
// mesh and step refined by data.truth_refinement (every r-th step kept) with
// data.truth_zones and data.sensors, clamped or, with a finite
// data.support_stiffness k_s, held at x = 0 by a spring (K + k_s e_0 e_0^T, u0 = u_0,
// f0 = -k_s u_0), or the exact solution
// (exact_solution.h; uniform bar, end channels only: ValidateDataAgainstBar refuses
// the rest).
ChannelSet SimulateTruth(const BarProperties& bar, const LoadOptions& load, const TimeOptions& time,
                         const DataOptions& data);

// SimulateTruth, then AddMeasurementNoise(data.snr, data.seed).
ChannelSet MakeSyntheticMeasurements(const BarProperties& bar, const LoadOptions& load,
                                     const TimeOptions& time, const DataOptions& data);

}  // namespace mcrewave
