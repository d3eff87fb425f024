// `identify run` and `identify simulate` on a structure given by matrices
// (model.kind: matrix; docs/matrix_models.md section 9):
//
//   1. LoadMatrixModel: the manifest of model.manifest (model/matrix_export.h), each
//      channel read from the CSV column model.channel_map gives it (its own name
//      otherwise);
//   2. LoadMatrixMeasurements: the CSV of data.path, its columns picked by that map and
//      resampled onto the config's grid t_j = j time.step, j = 0..time.window /
//      time.step (data/resample.h); or synthetic data: the truth's manifest
//      (data.truth_manifest, default the model's own) at data.truth_moduli (default
//      its nominal moduli), every load channel driven by the load: history, on the
//      same grid and theta, white noise per quantity at data.snr (AddMatrixModelNoise);
//   3. RunMatrixIdentification: the pre-filter of prefilter: on every channel; when
//      every zone has the same nominal modulus, the homogeneous stage first
//      (identification_run.h: one E in every zone by outer:'s global scan, on the search
//      functional of search: by default, and its refinements, as the bar's E is
//      identified); then every zone modulus at once, p_z = log(E_z / E_z,nom), by the
//      bar's zone steps (identification/zone_identification.h: the minimiser of
//      zone_identification:, its penalty on the jumps between consecutive zones of the
//      manifest, its weight and the merging) from E* (or from the nominal moduli when
//      they differ) within [outer.lower_bound, outer.upper_bound] Pa in every zone, inner
//      solves by inner:. Then the error maps (zone and dof, and element when the
//      model has element blocks) at the nominal and the identified moduli and the model's
//      outputs at the identified moduli.
//      With outer.functional: least_squares, the same stages on the output-error misfit
//      J instead (the homogeneous one by OutputErrorModulusObjective, the zones by
//      least_squares/matrix_output_error_objective.h), each sensor kind normalised by its
//      misfit level (MatrixLeastSquaresMisfitLevels); no error map. The supports are
//      held whatever mcre.clamp says (the bar's least squares keeps its clamp rigid),
//      their forces outputs weighted by 1 / s_f^2.
//
// Results: WriteIdentificationResults (app/results.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/identification/zone_identification.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/zone_uncertainty.h"
#include "mcrewave/optim/bounded_minimizer.h"

namespace mcrewave {

// The measurements of a matrix model on the config's time grid.
struct MatrixMeasurements {
  // The model's channels, named as the model names them, in its order (loads then
  // sensors, MatrixChannelSet), on t_j = j time.step.
  ChannelSet histories;
  std::string source;  // the CSV's path, or "synthetic"
  // Synthetic data: the truth's modulus of each of the model's zones [Pa], matched by
  // zone name; empty for CSV data or when a zone of the model is not one of the truth's.
  Vector truth_moduli;
  // Synthetic data: the standard deviations of the noise added (AddMatrixModelNoise;
  // all 0 without noise); CSV data: all 0.
  NoiseLevels noise;
};

// Reads the manifest of config.structure.manifest, its zones regrouped by model.zoning
// and, when data.channels lists channels, only those of its sensors kept (in the
// manifest's order). Throws InputError naming the file and line (ReadMatrixModel), or
// the config and the key: a model.channel_map channel that is not one of the
// manifest's; a data.channels channel that is not one of its sensors, or listed twice; a zone's
// nominal modulus outside [outer.lower_bound, outer.upper_bound] (the search starts there).
// Precondition: config.structure.kind is kMatrix.
MatrixModelData LoadMatrixModel(const Config& config);

// LoadMatrixModel's checks, channel selection and zone regrouping on a model already
// read or given in code; config.structure.manifest names it in messages.
MatrixModelData PrepareMatrixModel(const Config& config, MatrixModelData model);

// The measurements of `model` per config.data (step 2 above). Throws InputError naming
// the CSV file and the column of a channel it lacks (or the key model.channel_map when
// the map renamed it), the file when the data do not cover the time window, the truth's
// manifest when it lacks one of the model's channels or data.truth_moduli does not
// have one modulus per truth zone. given_truth (nullable): a model given in code as it
// was given (before PrepareMatrixModel), the synthetic truth when data.truth_manifest
// is empty (instead of the manifest's).
MatrixMeasurements LoadMatrixMeasurements(const Config& config, const MatrixModelData& model,
                                          const MatrixModelData* given_truth = nullptr);

// The CSV branch of LoadMatrixMeasurements on a record given in code (the Python
// module's data): `record` holds a column per channel of the model (model.channel_map
// names it), sampled from record.start_time on record.time_step, and is shifted by
// data.time_origin and resampled onto the config's grid as a CSV is. Throws InputError
// naming `name` and the column a channel lacks, or as ResampleMeasurements does.
MatrixMeasurements MatrixMeasurementsOfRecord(const Config& config, const MatrixModelData& model,
                                              ChannelSet record, const std::string& name);

// Throws InputError, naming the config, the bytes and what fits instead, when the
// coupled solves of `identify run` on `model` would hold stored fields above
// inner.max_field_bytes (kIterativeSolverFields fields of dofs x (steps + 1) doubles,
// the steps the config's time grid, onto which the data are resampled): a stored-field
// method named (conjugate_gradient, the relaxations); auto streams instead when they do
// not fit (ResolveCoupledSolverType), and is never refused here. `identify run` calls it
// between LoadMatrixModel and LoadMatrixMeasurements, before a synthetic truth is
// simulated; SolveCoupled would refuse every solve with the same reason.
void CheckMatrixModelFieldBytes(const Config& config, const MatrixModelData& model);

// The outputs H U of `truth` at zone_moduli [Pa] from rest, driven by `loads` (one row
// per load channel [N], sampled at t_j = j time_step) with the theta method: the
// noise-free data of that structure (sensor rows, model order). A truth with supports
// is held by them (their dofs at rest, docs/matrix_models.md section 11); with
// support_forces not null, it receives their reactions with the inertia of the free
// dofs, g^T (K U + M a) [N], as the bar's clamp reaction (one row per support, model
// order; no row without supports).
Matrix SimulateMatrixModel(const MatrixModelData& truth, const Vector& zone_moduli,
                           const Matrix& loads, double time_step, double theta,
                           Matrix* support_forces = nullptr);

// The standard deviations AddMatrixModelNoise draws at `snr`: RMS / snr over data's
// channels of the model's displacement sensors, of its strain sensors and of its loads
// (displacement_std, strain_std, force_std; all 0 when snr is infinite, a kind without
// channels 0).
NoiseLevels MatrixModelNoiseLevels(const MatrixModelData& model, const ChannelSet& data,
                                   double snr);

// Adds white Gaussian noise to every channel: standard deviation RMS / snr of the
// channels of the same quantity (MatrixModelNoiseLevels) (the displacement sensors together, the
// strain sensors together, the loads together), drawn by the project's StandardNormal
// (core/random.h) seeded with `seed`, the loads first, then the sensors in order, sample by
// sample, then each support's force (the loads' deviation) and displacement channel
// (the displacement sensors'). Nothing when snr is infinite. levels (nullable): the
// standard deviations drawn (displacement_std, strain_std, force_std; all 0 when snr is
// infinite).
void AddMatrixModelNoise(const MatrixModelData& model, double snr, std::uint64_t seed,
                         ChannelSet* data, NoiseLevels* levels = nullptr);

// The misfit levels that normalise least squares on a matrix model, the bar's convention
// (LeastSquaresMisfitLevels): per sensor kind, the noise of synthetic data at a finite
// data.snr (measurements.noise, *source "synthetic_snr"), else the estimate from the
// second differences of the measurements (DifferenceNoiseStd, s^2 averaged over the
// sensors of the kind, *source "data_differences"); a kind with a level 0 (noise-free
// data) takes the RMS of its channels in `used` instead (*source "channel_rms").
// force_std (s_f) weighs the supports' forces: 0 without supports (the loads are
// inputs); with supports the forces' level as the bar's clamp reaction f0 gets it: the
// synthetic noise of the loads, else s^2 averaged over the loads' and supports' force
// channels (the supports' displacement channels then join the displacement sensors, as
// the bar's u0 does), else the RMS of the loads' channels in `used` (of the supports'
// force channels without a load).
NoiseLevels MatrixLeastSquaresMisfitLevels(const Config& config, const MatrixModelData& model,
                                           const MatrixMeasurements& measurements,
                                           const ChannelSet& used, std::string* source);

// The noise levels the uncertainty of a matrix run draws (EstimateZoneUncertainty) and
// its zones' discrepancy target (IdentifyZoneModuli): the
// noise of synthetic data at a finite data.snr (measurements.noise, *source
// "synthetic_snr"), else per channel kind (displacement, strain, force) the estimate
// from the second differences of the measurements (DifferenceNoiseStd, s^2 averaged
// over the channels of the kind, *source "data_differences").
NoiseLevels MatrixNoiseLevels(const Config& config, const MatrixMeasurements& measurements,
                              std::string* source);

// The measurements as the CSV identify run reads back (WriteChannelCsv): every channel
// of the model, in its order, under its column (model.channel_map).
// Precondition: histories has the model's channels.
ChannelSet MatrixMeasurementTable(const Config& config, const MatrixModelData& model,
                                  const ChannelSet& histories);

// Step 3 above, into the one run type; the MCRE's supports with a measured displacement
// first tested against the data (ConfigForTheSupports: with mcre.clamp trusted and the
// data contradicting one, run.config treats them as measured when mcre.support_check is
// switch). With maps_and_uncertainty, run.model holds a copy
// of `model` for the writer (WriteIdentificationResults). Without, the moduli alone (no
// error map, model outputs or uncertainty: what a study needs of each run). Never throws for the
// optimiser or the inner solver: their failures are in run.failure (and run.outer).
// Progress: one info line per evaluation.
IdentificationRun RunMatrixIdentification(const Config& config, const MatrixModelData& model,
                                          const MatrixMeasurements& measurements,
                                          bool maps_and_uncertainty = true);

}  // namespace mcrewave
