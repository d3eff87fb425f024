// Identification of every zone modulus at once (docs/zones_and_sensors.md,
// "Identification of zone moduli") of a structure given by matrices (the bar's:
// BarRunModel), by the MCRE (IdentifyZoneModuli) or, as its comparator, by output-error
// least squares (IdentifyZoneModuliByLeastSquares: the same steps on J).
// K = sum_z (E_z / E_z,nom) K_z, and every zone's gradient comes from the one coupled
// solve, de^2/dE_z = -(1/(2 E_z,nom)) sum_j c_j h W_j^T K_z (W_j + 2 U_j)
// (MatrixMcreProblem::CostGradients).
//
// Started from the homogeneous E* of the scalar identification (or, on a structure whose
// zones' nominal moduli differ, from those), on p_z = log(E_z / E_z,ref) with
// d cost / d p_z = (d cost / d E_z) E_z, E_z,ref the objective's reference (E* on the bar,
// the nominal moduli on a structure given by matrices), the cost the scaled e^2 / J_rest
// (least squares: J / J_rest), every zone within [outer.lower_bound, outer.upper_bound].
//
// The regularisation's discrepancy target (optim/regularization.h) and the merging of
// zones need the misfit the noise alone explains: ExpectedNoiseCost, the mean scaled e^2
// of data made of noise alone (white, at the levels DifferenceNoiseLevels estimates from
// the measurements, passed through the data's pre-filter) at E*. The coupled solution is
// affine in the data and e^2 a quadratic form of its residuals, which vanish for data of
// the model at the true moduli, so e^2(truth + noise) = e^2(noise) exactly: the mean is
// the misfit the truth itself would show.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mcrewave/data/prefilter.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/optim/bounded_minimizer.h"
#include "mcrewave/optim/log_moduli_objective.h"
#include "mcrewave/optim/regularization.h"

namespace mcrewave {

// The `zone_identification:` section.
struct ZoneIdentificationOptions {
  BoundedMinimizerOptions minimizer;
  RegularizationOptions regularization;
  // The zones whose jumps the penalty counts: consecutive zones in the model's order (the
  // bar's chain), or the zones that share a node (ZoneNeighbours: a 2-D or 3-D layout's
  // edges and faces).
  ZoneNeighbourhood neighbours = ZoneNeighbourhood::kOrder;
  // Noise draws of the discrepancy target (ExpectedNoiseCost; least squares:
  // ExpectedLeastSquaresNoiseCost).
  int noise_samples = 4;
  std::uint64_t noise_seed = 1;
  // Merge neighbouring zones after the regularised minimisation while an unpenalised
  // refit of the groups meets the discrepancy target (MergeNeighbouringZones). Off by
  // default: each trial is a minimisation, O(zones^2) of them at worst
  // (docs/zones_and_sensors.md, "Merging neighbouring zones").
  bool merge_zones = false;
  // A run whose clamp is trusted (mcre.clamp) and whose data hold u0 identifies its zones
  // with the clamp measured, the paper's formulation (MeasuredSupportConfig; read by
  // app/zone_identification_run.h, docs/boundaries.md section 8). false: the run's own
  // treatment.
  bool measured_clamp = true;
  // A structure given by matrices: every zone starts from this modulus [Pa], without the
  // homogeneous stage (a start chosen by the user, as a basin-of-attraction study asks);
  // 0: from the homogeneous stage's E* when the zones share one nominal modulus, else
  // from their nominal moduli.
  double start_modulus = 0.0;
  // A structure given by matrices: zone z starts from start_moduli[z] [Pa], one per zone
  // in the model's order, without the homogeneous stage (a coarser mesh's moduli, say);
  // empty: start_modulus or E*. Not with start_modulus.
  std::vector<double> start_moduli;
  // How least squares gets its gradient (MatrixOutputErrorObjective): forward
  // sensitivities, 1 + Z sweeps an evaluation, or the discrete adjoint, 2 sweeps and the
  // trajectory in memory. The same derivative up to round-off.
  LeastSquaresGradient least_squares_gradient = LeastSquaresGradient::kForwardSensitivities;

  // Messages name the zone_identification.* keys.
  bool IsValid(std::string* error) const;
};

// One evaluation of the zones' data cost, as a minimiser asked for it.
struct ZoneEvaluation {
  Vector moduli;                // E_z [Pa]
  double cost = 0.0;            // e^2 / J_rest (least squares: J / J_rest); NaN when not usable
  bool usable = false;          // the inner solve was usable (least squares: J finite)
  double gradient_norm = -1.0;  // |d cost / d p|; -1 without gradient
};

struct ZoneIdentificationSummary {
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  bool least_squares = false;           // the cost is least squares' J [s], not e^2 [J s]
  double homogeneous_modulus = -1.0;    // E* when every zone started from it [Pa]; else -1
  Vector start_moduli;                  // E_z at the start [Pa]
  Vector moduli;                        // E_z [Pa], one per zone (empty: none usable)
  std::vector<double> zone_start;       // [m], per zone of a bar: the first element's left
                                        // node (SetBarZoneExtents; empty: not a bar's)
  std::vector<double> zone_end;         // [m], per zone of a bar: the last element's right node
  double cost = -1.0;                   // e^2 at moduli [J s] (least squares: J [s])
  double homogeneous_cost = -1.0;       // e^2 at the start moduli [J s] (J [s])
  double cost_scale = -1.0;             // J_rest [J s] (least squares: [s])
  NoiseLevels noise;                    // levels of the discrepancy target's draws
  double noise_cost = -1.0;             // ExpectedNoiseCost or ExpectedLeastSquaresNoiseCost
                                        // (scaled); -1: not computed
  double noise_cost_std_dev = -1.0;     // its draws' standard deviation (scaled); -1: one
                                        // draw, or not computed
  RegularizedMinimization regularized;  // weight, its choice, the path, the minimiser
  ZoneMerge merge;                      // merge.groups -1: not run; with merges kept,
                                        // moduli and cost are its last refit's
  std::vector<int> zones_on_bounds;     // zones whose modulus lies on a bound
  int evaluations = 0;                  // cost evaluations of the zone identification (MCRE:
                                        // coupled solves)
  // Every evaluation of the data cost by the minimisations (the regularised ones and the
  // merges' refits), in order.
  std::vector<ZoneEvaluation> history;
  long sweeps = 0;
  double wall_time_s = -1.0;

  bool IsSolutionUsable() const { return termination == TerminationType::kConvergence; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Mean over `samples` draws of e^2(noise alone) / cost_scale at the zone moduli of
// `model`, the noise white at `noise`'s levels on every channel the data have
// (DrawWhiteNoise), then pre-filtered as `prefilter` says (enabled with its cutoff;
// disabled: as drawn). -1 when a solve is not usable. With std_dev, the draws' sample
// standard deviation / cost_scale into it (-1 with fewer than 2 draws or when not usable).
double ExpectedNoiseCost(const MatrixModelData& model, const ChannelSet& data,
                         const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
                         const Vector& moduli, const NoiseLevels& noise,
                         const PrefilterOptions& prefilter, int samples, std::uint64_t seed,
                         double cost_scale, double* std_dev = nullptr);

// ExpectedNoiseCost for the output-error misfit (MatrixOutputErrorObjective with the
// normalisation misfit_levels): the mean over `samples` draws of J(noise alone) /
// cost_scale at the zone moduli of `model`, the model driven by the loads' noise and
// compared with the other channels' (white at `noise`'s levels, then pre-filtered as
// `prefilter` says). -1 when J is not finite. std_dev as in ExpectedNoiseCost.
double ExpectedLeastSquaresNoiseCost(const MatrixModelData& model, const ChannelSet& data,
                                     const NoiseLevels& misfit_levels, double theta,
                                     const Vector& moduli, const NoiseLevels& noise,
                                     const PrefilterOptions& prefilter, int samples,
                                     std::uint64_t seed, double cost_scale,
                                     double* std_dev = nullptr);

// The zones whose jumps of log E the penalty counts (RegularizationOptions::neighbours):
// zones a < b are neighbours when their stiffness matrices K_a and K_b both touch a dof
// (a node of both), the pair's weight the dofs they share over the most that any pair
// shares, so that an interface counts by its size: in 2-D zones that meet along an edge
// of k elements weigh by its k + 1 nodes, zones that meet at a corner by one node, and
// the zones of a bar, consecutive zones sharing one node, form the chain (z, z + 1) of
// weight 1. In order of (first, second).
std::vector<ZonePair> ZoneNeighbours(const MatrixModelData& model);

// Identifies the zone moduli of `model` (its zones; the bar's: BarRunModel of the zoned
// bar) from `data` (as the objective sees them: pre-filtered when the pre-filter is on),
// from the homogeneous E* within [lower_bound, upper_bound] on every zone. noise: the
// estimated noise levels of the measurements (for the discrepancy target); prefilter:
// the pre-filter the data went through, its cutoff_frequency the one used. warm_start:
// the scalar identification's solution at E* (CoupledSolution::WarmStart() of the same
// model's problem, nullable). The summary's zone extents are left empty (the bar's:
// SetBarZoneExtents). Never throws for a failed identification.
// Preconditions: options valid, 0 < lower_bound < E* < upper_bound.
ZoneIdentificationSummary IdentifyZoneModuli(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
    double homogeneous_modulus, double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter, const Matrix* warm_start = nullptr);

// The same on the caller's objective: a McreObjective of model and data with mcre's
// weights, theta and inner (its warm start, cost scale and element-map switch as the
// caller made them; its last solution is then the minimiser's last evaluation's), on
// p_z = log(E_z / E_z,ref) with E_z,ref = reference_moduli [Pa], from start_moduli [Pa]
// (E* in every zone, or a structure's nominal moduli). The discrepancy target's noise
// draws are solved at start_moduli, and homogeneous_cost is e^2 there. Preconditions:
// options valid, lower_bound < every start modulus < upper_bound.
ZoneIdentificationSummary IdentifyZoneModuli(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
    McreObjective* objective, const Vector& reference_moduli, const Vector& start_moduli,
    double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter);

// The extents [m] of the bar's zones (summary->zone_start, zone_end): each zone's first
// element's left node and last element's right node.
void SetBarZoneExtents(const BarModel& model, ZoneIdentificationSummary* summary);

// The same identification on the output-error misfit J of least squares
// (MatrixOutputErrorObjective, normalised by misfit_levels: > 0 for every kind the
// model observes; its supports held) instead of the MCRE's e^2: the same parameters,
// bounds, start, regularisation, weight rule (its target ExpectedLeastSquaresNoiseCost
// with the noise levels `noise`) and merging. summary.cost and homogeneous_cost are J
// [s], cost_scale J_rest [s], sweeps the simulations (1 + zones with the gradient). The
// zone extents are left empty. Never throws for a failed identification. Preconditions
// as IdentifyZoneModuli's.
ZoneIdentificationSummary IdentifyZoneModuliByLeastSquares(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const NoiseLevels& misfit_levels, double theta, double homogeneous_modulus, double lower_bound,
    double upper_bound, const NoiseLevels& noise, const PrefilterOptions& prefilter);

// The same on the caller's objective (MatrixOutputErrorObjective of model, data,
// misfit_levels and theta), on p_z = log(E_z / E_z,ref) with its reference moduli, from
// start_moduli [Pa]; homogeneous_cost is J there. Preconditions as the MCRE's.
ZoneIdentificationSummary IdentifyZoneModuliByLeastSquares(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const NoiseLevels& misfit_levels, double theta, MatrixOutputErrorObjective* zones,
    const Vector& start_moduli, double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter);

}  // namespace mcrewave
