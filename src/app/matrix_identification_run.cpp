#include "mcrewave/app/matrix_identification_run.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "mcrewave/core/random.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/data/resample.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/least_squares/output_error_modulus_objective.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/mcre/objective.h"

namespace mcrewave {
namespace {

// Whether the load channel `channel` is one of mcre.unmeasured_loads (no data of it).
bool IsUnmeasuredLoad(const Config& config, const std::string& channel) {
  const auto& unmeasured = config.mcre.unmeasured_loads;
  return std::find(unmeasured.begin(), unmeasured.end(), channel) != unmeasured.end();
}

// A channel of the model with its CSV column and kind.
struct ChannelColumn {
  std::string channel, column;
  ChannelKind kind;
};

// Every channel of the model, loads, sensors, then each support's force and
// displacement channels, with its CSV column.
std::vector<ChannelColumn> ChannelColumns(const Config& config, const MatrixModelData& model) {
  std::vector<ChannelColumn> channels;
  auto add = [&](const std::string& channel, ChannelKind kind) {
    channels.push_back({channel, config.structure.Column(channel), kind});
  };
  for (const MatrixModelLoad& load : model.loads) {
    // An unmeasured load has no column (MatrixMcreProblem gives it the datum 0).
    if (IsUnmeasuredLoad(config, load.channel)) continue;
    add(load.channel, ChannelKind::kForce);
  }
  for (const MatrixModelSensor& sensor : model.sensors) {
    add(sensor.channel,
        sensor.kind == SensorKind::kStrain ? ChannelKind::kStrain : ChannelKind::kDisplacement);
  }
  for (const MatrixModelSupport& support : model.supports) {
    add(support.force_channel, ChannelKind::kForce);
    if (!support.displacement_channel.empty()) {
      add(support.displacement_channel, ChannelKind::kDisplacement);
    }
  }
  return channels;
}

// A record of the model's channels (under their columns) on the config's grid: shifted
// by data.time_origin, resampled when sampled otherwise, the channels picked.
ChannelSet MatrixRecordOnGrid(const Config& config, const MatrixModelData& model, ChannelSet table,
                              const std::string& path) {
  const auto channels = ChannelColumns(config, model);
  // The record's clock shifted to the model's: t_model = t_record - data.time_origin.
  table.start_time -= config.data.time_origin;
  const int samples = config.time.NumSteps() + 1;
  if (table.time_step != config.time.step || table.start_time != 0.0 ||
      table.num_samples() != samples) {
    spdlog::info(
        "{}: resampling {} samples of {:.4g} s from t = {:.4g} s onto {} samples of "
        "{:.4g} s",
        path, table.num_samples(), table.time_step, table.start_time, samples, config.time.step);
    table = ResampleMeasurements(table, config.time.step, samples, path,
                                 config.data.at_rest_before_record);
  }
  ChannelSet set;
  set.time_step = config.time.step;
  for (const auto& [channel, column, kind] : channels) set.Add(channel, kind, table.Values(column));
  return set;
}

// Why `names` (a record's columns) lack the column of one of the model's `channels`
// ("" when they hold every one); `holder` names them in the message ("the header").
std::string MissingChannelColumn(const Config& config, const std::vector<ChannelColumn>& channels,
                                 const std::vector<std::string>& names, const std::string& holder) {
  for (const auto& [channel, column, kind] : channels) {
    if (std::find(names.begin(), names.end(), column) != names.end()) continue;
    return holder + " lacks the column '" + column + "' of the model's channel '" + channel + "'" +
           (column == channel ? std::string(" (model.channel_map can name another column)")
                              : " (model.channel_map of " + config.Name() + ")");
  }
  return "";
}

// The CSV of data.path on the config's grid: the model's channels (named as the model
// names them, of their kinds), in its order.
ChannelSet ReadMatrixMeasurementCsv(const Config& config, const MatrixModelData& model) {
  const std::string& path = config.data.path;
  const auto channels = ChannelColumns(config, model);
  // Every channel's column must be in the header (checked before any row is read).
  const HeaderCheck check_header = [&](const std::vector<std::string>& names,
                                       const std::string&) -> std::string {
    if (names.empty()) return "a header naming the columns: t and the model's channels";
    return MissingChannelColumn(config, channels, names, "the header");
  };
  return MatrixRecordOnGrid(config, model,
                            ReadChannelCsv(path, check_header, {}, config.data.time_column), path);
}

// Synthetic data: the truth's outputs at its moduli, with noise (its levels in *noise);
// the truth's moduli of the model's zones in *truth_moduli (empty when a zone name is
// not the truth's). given_truth (nullable): the model as given in code, before
// PrepareMatrixModel, the truth when data.truth_manifest is empty.
ChannelSet SyntheticMatrixMeasurements(const Config& config, const MatrixModelData& model,
                                       const MatrixModelData* given_truth, Vector* truth_moduli,
                                       NoiseLevels* noise) {
  const std::string manifest = config.data.truth_manifest.empty() ? config.structure.manifest
                                                                  : config.data.truth_manifest;
  // The truth's zones are its manifest's, also when the model regroups its elements.
  const bool own_model = manifest == config.structure.manifest;
  const MatrixModelData truth = own_model && given_truth != nullptr ? *given_truth
                                : own_model && !config.zones.RegroupsElements()
                                    ? model
                                    : ReadMatrixModel(manifest);
  const auto zones = static_cast<int>(truth.zones.size());
  Vector moduli(zones);
  if (!config.data.truth_moduli.empty()) {
    if (static_cast<int>(config.data.truth_moduli.size()) != zones) {
      throw InputError(config.Name() + ": data.truth_moduli has " +
                       std::to_string(config.data.truth_moduli.size()) +
                       " moduli; the truth's manifest " + manifest + " has " +
                       std::to_string(zones) + " zones");
    }
    for (int z = 0; z < zones; ++z) moduli[z] = config.data.truth_moduli[z];
  } else {
    for (int z = 0; z < zones; ++z) moduli[z] = truth.zones[z].nominal_modulus;
  }
  // The truth's channels in the model's order.
  std::vector<int> load_rows, sensor_rows;
  auto find = [&](const auto& list, const std::string& channel) {
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (list[i].channel == channel) return static_cast<int>(i);
    }
    throw InputError(manifest + ": the truth has no channel '" + channel +
                     "' of the model's manifest " + config.structure.manifest);
  };
  for (const MatrixModelLoad& load : model.loads) load_rows.push_back(find(truth.loads, load.channel));
  for (const MatrixModelSensor& sensor : model.sensors) {
    sensor_rows.push_back(find(truth.sensors, sensor.channel));
  }
  const int steps = config.time.NumSteps();
  // F_c(t_j) = F(t_j) of load:, on every load channel of the truth.
  Matrix truth_loads(static_cast<int>(truth.loads.size()), steps + 1);
  for (int j = 0; j <= steps; ++j) {
    truth_loads.col(j).setConstant(config.load.Value(j * config.time.step));
  }
  Matrix support_forces;
  const Matrix outputs = SimulateMatrixModel(truth, moduli, truth_loads, config.time.step,
                                             config.time.theta, &support_forces);
  // The model's supports from the truth's of the same force channel: the truth is held
  // by them, so their displacement is 0.
  std::vector<int> support_rows;
  for (const MatrixModelSupport& support : model.supports) {
    int found = -1;
    for (std::size_t s = 0; s < truth.supports.size(); ++s) {
      if (truth.supports[s].force_channel == support.force_channel) found = static_cast<int>(s);
    }
    if (found < 0) {
      throw InputError(manifest + ": the truth has no support of force channel '" +
                       support.force_channel + "' of the model's manifest " +
                       config.structure.manifest);
    }
    support_rows.push_back(found);
  }
  Matrix loads(static_cast<int>(load_rows.size()), steps + 1);
  Matrix sensors(static_cast<int>(sensor_rows.size()), steps + 1);
  for (std::size_t c = 0; c < load_rows.size(); ++c) {
    loads.row(static_cast<int>(c)) = truth_loads.row(load_rows[c]);
  }
  for (std::size_t k = 0; k < sensor_rows.size(); ++k) {
    sensors.row(static_cast<int>(k)) = outputs.row(sensor_rows[k]);
  }
  ChannelSet histories = MatrixChannelSet(model, config.time.step, loads, sensors);
  for (std::size_t s = 0; s < support_rows.size(); ++s) {
    const MatrixModelSupport& support = model.supports[s];
    histories.Add(support.force_channel, ChannelKind::kForce,
                  support_forces.row(support_rows[s]).transpose());
    if (!support.displacement_channel.empty()) {
      histories.Add(support.displacement_channel, ChannelKind::kDisplacement,
                    Vector::Zero(steps + 1));
    }
  }
  AddMatrixModelNoise(model, config.data.snr, config.data.seed, &histories, noise);

  truth_moduli->resize(static_cast<int>(model.zones.size()));
  for (std::size_t z = 0; z < model.zones.size(); ++z) {
    int found = -1;
    for (int t = 0; t < zones; ++t) {
      if (truth.zones[t].name == model.zones[z].name) found = t;
    }
    if (found < 0) {
      *truth_moduli = Vector();
      break;
    }
    (*truth_moduli)[static_cast<int>(z)] = moduli[found];
  }
  return histories;
}

double RootMeanSquareOfRows(const Matrix& rows) {
  return rows.size() > 0 ? std::sqrt(rows.squaredNorm() / static_cast<double>(rows.size())) : 0.0;
}

// e^2 and the zone and dof maps of a usable coupled solution at the problem's moduli:
// from its fields, or as a streaming solve summed them.
void CostAndMaps(MatrixMcreProblem* problem, const CoupledSolution& solution, double* cost,
                 Vector* zone_map, Vector* zone_gap, Vector* dof_map) {
  *cost = solution.cost;
  const bool fields = solution.has_fields();
  *zone_map = fields ? problem->ZoneErrorMap(solution.retrograde) : solution.zone_error_map;
  // The gap relative to the zone's own strain energy: the same sum over U,
  //   e_z^2 / ((E_z / E_z,nom) sum_j c_j h 1/2 U_j^T K_z U_j).
  const Vector energy =
      fields ? problem->ZoneErrorMap(solution.displacement) : solution.zone_strain_energy;
  *zone_gap = zone_map->cwiseQuotient(energy.cwiseMax(std::numeric_limits<double>::min()));
  *dof_map = fields ? problem->DofErrorMap(solution.retrograde) : solution.error_map;
}

// The coupled solve at `moduli`, then CostAndMaps; false with the reason in *failure
// when it is not usable.
bool SolveAt(const Vector& moduli, const CoupledSolverOptions& inner, MatrixMcreProblem* problem,
             CoupledSolution* solution, double* cost, Vector* zone_map, Vector* zone_gap,
             Vector* dof_map, std::string* failure) {
  problem->SetModuli(moduli);
  const CoupledSolverSummary summary = SolveCoupled(inner, problem, nullptr, solution);
  if (!summary.IsSolutionUsable() || !std::isfinite(solution->cost)) {
    *failure = "the coupled solve is not usable: " + summary.BriefReport();
    return false;
  }
  CostAndMaps(problem, *solution, cost, zone_map, zone_gap, dof_map);
  return true;
}

// The element map and sensitivities of a usable coupled solution of `problem` at its
// current moduli (mcre/element_error_map.h): from the stored fields, or from the sums of
// a streaming solve; empty when the model has no element blocks.
ErrorMap ElementMapOf(const MatrixModelData& model, const CoupledSolution& solution,
                      MatrixMcreProblem* problem) {
  if (model.elements.empty()) return ErrorMap();
  if (!solution.has_fields()) {
    ErrorMap map =
        AssembleElementErrorMap(model, solution.element_error_map, solution.gap_density,
                                static_cast<int>(solution.traces.cols()) - 1, problem->time_step());
    map.sensitivity = solution.element_sensitivity;
    return map;
  }
  ErrorMap map =
      ComputeElementErrorMap(model, problem->moduli(), solution.retrograde, problem->time_step());
  problem->ElementSensitivities(solution.displacement, solution.retrograde, &map.sensitivity);
  return map;
}

// Step 3 of RunMatrixIdentification: the error maps and the model's outputs at the
// identified moduli (from the last evaluation's solve when it was there, as it usually
// is), then the maps at the nominal moduli. Returns the coupled solution at the
// identified moduli, the objective's or one solved into *storage (null when there is
// none usable: a failure goes to run->failure).
const CoupledSolution* MapsAtIdentifiedAndNominal(
    const Config& config, const MatrixModelData& model, const McreObjective& objective,
    MatrixMcreProblem* problem, CoupledSolution* storage, IdentificationRun* run) {
  const CoupledSolution* identified = nullptr;
  std::string why;
  if (run->identified_moduli.size() > 0) {
    const std::vector<ZoneEvaluation>& history = run->zones.summary.history;
    if (!history.empty() && history.back().usable &&
        history.back().moduli == run->identified_moduli) {
      identified = &objective.last_solution();
      if (!model.elements.empty() && !identified->has_fields()) {
        // A streaming solve of the minimiser's, without the element map: gathered from
        // its traces, as its final pass would have.
        *storage = *identified;
        problem->StreamingElementMaps(storage->traces, storage);
        identified = storage;
      }
      CostAndMaps(problem, *identified, &run->zone_cost, &run->zone_map, &run->zone_gap,
                  &run->dof_map);
    } else if (SolveAt(run->identified_moduli, config.inner, problem, storage, &run->zone_cost,
                       &run->zone_map, &run->zone_gap, &run->dof_map, &why)) {
      identified = storage;
    } else if (run->failure.empty()) {
      run->failure = "at the identified moduli, " + why;
    }
    if (identified != nullptr) {
      run->element_map = ElementMapOf(model, *identified, problem);
    }
    if (!config.mcre.unmeasured_loads.empty() && identified != nullptr) {
      // The model's own response to every load, the unmeasured ones as identified
      // (ModelChannels: F = F~ - a G^T W / alpha), not the coupled solution's U, whose
      // constitutive gap K W is no load.
      const ChannelSet channels = problem->ModelChannels(*identified);
      run->model_loads.resize(static_cast<Eigen::Index>(model.loads.size()),
                              problem->num_steps() + 1);
      for (std::size_t c = 0; c < model.loads.size(); ++c) {
        run->model_loads.row(static_cast<Eigen::Index>(c)) =
            channels.Values(model.loads[c].channel).transpose();
      }
      run->model_outputs = SimulateMatrixModel(model, run->identified_moduli, run->model_loads,
                                               problem->time_step(), problem->theta());
    } else {
      run->model_outputs = problem->ModelOutputs();
    }
  }
  CoupledSolution nominal;
  if (SolveAt(run->nominal_moduli, config.inner, problem, &nominal, &run->nominal_cost,
              &run->nominal_zone_map, &run->nominal_zone_gap, &run->nominal_dof_map, &why)) {
    run->nominal_element_map = ElementMapOf(model, nominal, problem);
  } else if (run->failure.empty()) {
    run->failure = "at the nominal moduli, " + why;
  }
  return identified;
}

// After the zones: the identified moduli and why the run is not usable (no usable
// point, no tolerance met, a zone on a bound of [outer.lower_bound, outer.upper_bound]).
void TakeZoneOutcome(const MatrixModelData& model, IdentificationRun* out) {
  IdentificationRun& run = *out;
  const ZoneIdentificationSummary& zones = run.zones.summary;
  spdlog::info("zones: {}", zones.BriefReport());
  if (zones.moduli.size() == 0) {
    run.failure = "no usable evaluation: " + zones.message;
    return;
  }
  run.identified_moduli = zones.moduli;
  if (!zones.IsSolutionUsable()) {
    run.failure = "the optimiser stopped before a tolerance was met: " + zones.message;
  } else if (!zones.zones_on_bounds.empty()) {
    // A modulus on a bound is where the search stopped, not where the data point.
    const int z = zones.zones_on_bounds.front();
    run.failure = fmt::format(
        "zone '{}' ends on a bound of outer.lower_bound / outer.upper_bound ({:.6g} Pa): "
        "widen the bounds or check the data's units",
        model.zones[static_cast<std::size_t>(z)].name, run.identified_moduli[z]);
  }
}

// Whether every zone of `model` has the same nominal modulus, so that one E in every
// zone is the model at one modulus (the homogeneous stage applies).
bool SharesOneNominalModulus(const MatrixModelData& model) {
  return std::all_of(model.zones.begin(), model.zones.end(), [&](const MatrixModelZone& zone) {
    return zone.nominal_modulus == model.zones[0].nominal_modulus;
  });
}

// Whether the homogeneous stage's E* can start the zones: false, with run->failure set,
// when it is not usable or lies on a bound of the search, as the bar's E* fails.
bool TakeHomogeneousOutcome(const Config& config, IdentificationRun* run) {
  const IdentificationSummary& outer = run->outer;
  std::string why =
      outer.IsSolutionUsable() ? ModulusOnBoundMessage(outer.modulus, config.outer) : outer.message;
  if (why.empty()) return true;
  run->failure = "the homogeneous stage (one E in every zone): " + why;
  return false;
}

// Step 2a of RunMatrixIdentification: the homogeneous stage on run->data, with its cost
// curve and cold solve when `complete`; E* weighs both treatments of the supports when
// run->support_blend says so (IdentifyHomogeneousModulusOfSupports, `given` the config
// before the supports' test). False, with run->failure set, when E* is not usable or lies
// on a bound of the search.
bool IdentifyHomogeneousStage(const Config& given, const Config& config,
                              const MatrixModelData& model, bool complete, IdentificationRun* run) {
  spdlog::info("homogeneous stage: one E in every zone");
  run->homogeneous_ran = true;
  ModulusStage& stage = *run;
  // Its solution warm-starts the zones: no element map.
  stage = IdentifyHomogeneousModulusOfSupports(given, config, model, run->data,
                                               /*element_maps=*/false, &run->support_blend);
  if (!TakeHomogeneousOutcome(config, run)) return false;
  run->homogeneous_cost = stage.cost();
  // The cost curve e^2(E) feeds the uncertainty of one modulus (the bar's); the zones'
  // uncertainty does without it, so with several zones it is not computed.
  if (complete) {
    CompleteModulusStage(config, model, run->data, /*cost_curve=*/model.zones.size() == 1, &stage);
  }
  spdlog::info("homogeneous stage: E* = {:.9g} Pa, the zones' start", stage.identified_modulus());
  return true;
}

// Step 2a by least squares: one E in every zone by outer:'s scan and refinements on J
// (OutputErrorModulusObjective, the bar's least squares), J at E* into
// run->homogeneous_cost. False, with run->failure set, as TakeHomogeneousOutcome says.
bool IdentifyHomogeneousStageByLeastSquares(const Config& config, const MatrixModelData& model,
                                            IdentificationRun* run) {
  spdlog::info(
      "homogeneous stage: one E in every zone by least squares with {}/{} from {:.6g} Pa",
      OptimizerTypeToString(config.outer.optimizer),
      OuterAlgorithmToString(ResolveAlgorithm(config.outer.optimizer, config.outer.algorithm, 1)),
      config.outer.initial);
  OutputErrorModulusObjective objective(model, run->data, run->misfit_levels, config.time.theta,
                                        config.outer.initial);
  // dJ/dE = sum_z dJ/dE_z as the zones' stage gets its gradient (1 + Z sweeps or 2).
  objective.SetGradientMethod(config.zone_identification.least_squares_gradient);
  run->homogeneous_ran = true;
  ModulusStage& stage = *run;
  stage.outer = Identify(config.outer, &objective);
  spdlog::info("{}", stage.outer.BriefReport());
  stage.rest_cost = objective.rest_cost();
  stage.scan_cost_scale = stage.rest_cost;
  const bool usable = TakeHomogeneousOutcome(config, run);
  if (usable) run->homogeneous_cost = objective.Predict(stage.identified_modulus(), false).cost;
  stage.sweeps = objective.sweeps();
  if (!usable) return false;
  spdlog::info("homogeneous stage: E* = {:.9g} Pa, the zones' start", stage.identified_modulus());
  return true;
}

// Whether the homogeneous stage runs: the zones share one nominal modulus, and neither
// zone_identification.start_modulus nor start_moduli is given.
bool RunsTheHomogeneousStage(const Config& config, const MatrixModelData& model) {
  return config.zone_identification.start_modulus == 0.0 &&
         config.zone_identification.start_moduli.empty() && SharesOneNominalModulus(model);
}

// The zones' start: zone_identification.start_moduli, one per zone, or start_modulus in
// every zone when given, E* after the homogeneous stage, else the nominal moduli. Throws
// InputError when start_moduli does not hold one modulus per zone.
Vector ZoneStart(const Config& config, const IdentificationRun& run) {
  const std::vector<double>& starts = config.zone_identification.start_moduli;
  const auto zones = run.nominal_moduli.size();
  if (!starts.empty()) {
    if (static_cast<Eigen::Index>(starts.size()) != zones) {
      throw InputError(config.Name() + ": zone_identification.start_moduli has " +
                       std::to_string(starts.size()) + " moduli, the model has " +
                       std::to_string(zones) + " zones: give one per zone, in their order");
    }
    return Eigen::Map<const Vector>(starts.data(), zones);
  }
  const double start = config.zone_identification.start_modulus;
  if (start > 0.0) return Vector::Constant(zones, start);
  if (!run.homogeneous_ran) return run.nominal_moduli;
  return Vector::Constant(run.nominal_moduli.size(), run.identified_modulus());
}

// The pre-filter the data went through, its cut-off the one used.
PrefilterOptions UsedPrefilter(const Config& config, const IdentificationRun& run) {
  PrefilterOptions prefilter = config.prefilter;
  prefilter.cutoff_frequency = run.prefilter_cutoff;
  return prefilter;
}

// Step 2 with outer.functional: least_squares: every zone modulus by the output-error
// misfit J (docs/formulation.md section 8), then J and the model's outputs at the
// identified moduli and J at the nominal ones. run->data is the pre-filtered data.
void IdentifyMatrixZonesByLeastSquares(const Config& config, const MatrixModelData& model,
                                       const MatrixMeasurements& measurements,
                                       IdentificationRun* out) {
  IdentificationRun& run = *out;
  run.least_squares = true;
  run.misfit_levels =
      MatrixLeastSquaresMisfitLevels(config, model, measurements, run.data, &run.misfit_source);
  MatrixOutputErrorObjective objective(model, run.data, run.misfit_levels, config.time.theta);
  run.nominal_moduli = objective.reference_moduli();
  run.zone_rest_cost = objective.rest_cost();
  spdlog::info(
      "matrix model {}: {} dofs, {} zones, {} loads, {} sensors, {} steps of {:.4g} s; "
      "output-error least squares, misfit levels {:.4g} m, {:.4g} ({})",
      config.structure.manifest, model.dofs(), model.zones.size(), model.loads.size(),
      model.sensors.size(), run.data.num_steps(), run.data.time_step,
      run.misfit_levels.displacement_std, run.misfit_levels.strain_std, run.misfit_source);
  if (!model.supports.empty()) {
    // The bar's least squares keeps its clamp rigid whatever mcre.clamp says.
    spdlog::info(
        "{} supports held (least squares ignores mcre.clamp: {}), their forces outputs of "
        "misfit level {:.4g} N",
        model.supports.size(), ClampModelToString(config.mcre.clamp), run.misfit_levels.force_std);
  }
  // One E in every zone first, as the bar's least squares identifies its E.
  if (RunsTheHomogeneousStage(config, model) &&
      !IdentifyHomogeneousStageByLeastSquares(config, model, &run)) {
    return;
  }
  run.noise = MatrixNoiseLevels(config, measurements, &run.noise_source);
  run.zones.ran = true;
  run.zones.summary = IdentifyZoneModuliByLeastSquares(
      config.zone_identification, model, run.data, run.misfit_levels, config.time.theta, &objective,
      ZoneStart(config, run), config.outer.lower_bound, config.outer.upper_bound, run.noise,
      UsedPrefilter(config, run));
  TakeZoneOutcome(model, &run);
  if (run.identified_moduli.size() > 0) {
    run.zone_cost = objective.Cost(run.identified_moduli, nullptr);
    run.model_outputs = objective.outputs();
  }
  run.nominal_cost = objective.Cost(run.nominal_moduli, nullptr);
  if (!(std::isfinite(run.zone_cost) && std::isfinite(run.nominal_cost)) && run.failure.empty()) {
    run.failure = "the output-error misfit is not finite at the identified or nominal moduli";
  }
}

// Step 1 of RunMatrixIdentification: the pre-filter of run->data, the same on every
// channel (the structure is linear and time-invariant: the model driven by the filtered
// loads answers with the filtered outputs), its cut-off from the loads' spectra unless
// given (from the sensors' when there is no load) into run->prefilter_cutoff.
void PrefilterEveryChannel(const Config& config, const MatrixModelData& model,
                           IdentificationRun* run) {
  const double time_step = run->data.time_step;
  double cutoff = config.prefilter.cutoff_frequency;
  if (cutoff <= 0.0) {
    std::vector<std::string> source;
    for (const MatrixModelLoad& load : model.loads) {
      if (IsUnmeasuredLoad(config, load.channel)) continue;  // no data
      source.push_back(load.channel);
    }
    if (source.empty()) {
      for (const MatrixModelSensor& sensor : model.sensors) source.push_back(sensor.channel);
    }
    for (const std::string& channel : source) {
      cutoff = std::max(cutoff, EstimateCutoffFrequency(run->data.Values(channel), time_step));
    }
  }
  const ZeroPhaseLowPass filter(cutoff, 1.0 / time_step, config.prefilter.order);
  for (Channel& channel : run->data.channels) {
    channel.values = filter.Apply(channel.values, config.prefilter.at_rest_before_start);
  }
  run->prefilter_cutoff = cutoff;
  spdlog::info("pre-filter: zero-phase Butterworth, cut-off {:.6g} Hz", cutoff);
}

// A held truth's support forces as a support measures them, with the inertia of the
// free dofs, r_s = g_s^T (K U + M a) (docs/matrix_models.md section 10), as the bar's
// clamp reaction f0 = row_0(M a + K u) (model/simulation.h): least squares' prediction
// of the same held structure from the loads of `data`. The misfit levels only weigh its
// cost; M is positive definite (checked when the manifest is read), so is its free block.
Matrix HeldSupportForces(const MatrixModelData& truth, const ChannelSet& data,
                         const Vector& zone_moduli, double theta) {
  NoiseLevels unit_levels;
  unit_levels.displacement_std = unit_levels.strain_std = unit_levels.force_std = 1.0;
  MatrixOutputErrorObjective held(truth, data, unit_levels, theta);
  held.Cost(zone_moduli, nullptr);
  return held.support_forces();
}

}  // namespace

MatrixModelData LoadMatrixModel(const Config& config) {
  assert(config.structure.kind == ModelKind::kMatrix);
  return PrepareMatrixModel(config, ReadMatrixModel(config.structure.manifest));
}

MatrixModelData PrepareMatrixModel(const Config& config, MatrixModelData model) {
  for (const std::string& channel : config.mcre.unmeasured_loads) {
    const bool load = std::any_of(model.loads.begin(), model.loads.end(),
                                  [&](const MatrixModelLoad& it) { return it.channel == channel; });
    if (!load) {
      std::string names;
      for (const MatrixModelLoad& it : model.loads)
        names += (names.empty() ? "" : ", ") + it.channel;
      throw InputError(config.Name() + ": mcre.unmeasured_loads: '" + channel +
                       "' is not a load channel of the manifest " + config.structure.manifest +
                       " (its loads: " + names + ")");
    }
  }
  if (!config.data.channels.empty()) {
    // data.channels: the manifest's sensors the identification uses, in the manifest's
    // order (a sensor layout chosen among many, e.g. by `identify sensors`).
    std::vector<MatrixModelSensor> used;
    for (const std::string& channel : config.data.channels) {
      if (std::count(config.data.channels.begin(), config.data.channels.end(), channel) > 1) {
        throw InputError(config.Name() + ": data.channels: '" + channel + "' is listed twice");
      }
      const auto found =
          std::find_if(model.sensors.begin(), model.sensors.end(),
                       [&](const MatrixModelSensor& sensor) { return sensor.channel == channel; });
      if (found == model.sensors.end()) {
        throw InputError(config.Name() + ": data.channels: '" + channel +
                         "' is not a sensor of the manifest " + config.structure.manifest +
                         " (its loads and supports are always used)");
      }
    }
    for (MatrixModelSensor& sensor : model.sensors) {
      const auto& names = config.data.channels;
      if (std::find(names.begin(), names.end(), sensor.channel) != names.end()) {
        used.push_back(std::move(sensor));
      }
    }
    spdlog::info("{}: data.channels: {} of its {} sensors", config.structure.manifest, used.size(),
                 model.sensors.size());
    model.sensors = std::move(used);
  }
  if (config.zones.RegroupsElements()) {
    // model.zoning per_element or grid: the identification's zones regroup the manifest's
    // element blocks (model/matrix_model_elements.h).
    std::vector<std::string> names;
    const std::vector<int> element_zones =
        RegroupedElementZones(model, config.zones, config.structure.manifest, &names);
    spdlog::info("{}: model.zoning {}: {} zones of {} elements", config.structure.manifest,
                 ZoningToString(config.zones.zoning), names.size(), model.elements.size());
    if (!config.zones.free_zones.empty()) {
      // model.free_zones: those zones keep their own modulus (in the key's order, after
      // zone 0 "rest", every other zone tied).
      const std::vector<std::string>& free = config.zones.free_zones;
      std::vector<int> tied(names.size(), 0);
      for (std::size_t f = 0; f < free.size(); ++f) {
        const auto found = std::find(names.begin(), names.end(), free[f]);
        if (found == names.end()) {
          throw InputError(config.Name() + ": model.free_zones: '" + free[f] +
                           "' is not a zone of model.zoning " +
                           ZoningToString(config.zones.zoning) + " (e.g. '" + names.back() + "')");
        }
        if (std::count(free.begin(), free.end(), free[f]) > 1) {
          throw InputError(config.Name() + ": model.free_zones: '" + free[f] + "' is listed twice");
        }
        tied[static_cast<std::size_t>(found - names.begin())] = static_cast<int>(f) + 1;
      }
      if (free.size() >= names.size()) {
        throw InputError(config.Name() + ": model.free_zones lists every zone of model.zoning " +
                         ZoningToString(config.zones.zoning) +
                         ": leave it out to identify each zone freely");
      }
      std::vector<int> regrouped(element_zones.size());
      for (std::size_t e = 0; e < element_zones.size(); ++e) {
        regrouped[e] = tied[static_cast<std::size_t>(element_zones[e])];
      }
      std::vector<std::string> kept = {"rest"};
      kept.insert(kept.end(), free.begin(), free.end());
      spdlog::info("{}: model.free_zones: {} zones free, the other {} tied into 'rest'",
                   config.structure.manifest, free.size(), names.size() - free.size());
      model = RezonedMatrixModel(model, regrouped, kept);
    } else {
      model = RezonedMatrixModel(model, element_zones, names);
    }
  }
  for (const auto& entry : config.structure.channel_map) {
    const std::string& channel = entry.first;
    const bool known =
        std::any_of(model.loads.begin(), model.loads.end(),
                    [&](const MatrixModelLoad& load) { return load.channel == channel; }) ||
        std::any_of(model.sensors.begin(), model.sensors.end(),
                    [&](const MatrixModelSensor& sensor) { return sensor.channel == channel; }) ||
        std::any_of(
            model.supports.begin(), model.supports.end(), [&](const MatrixModelSupport& support) {
              return support.force_channel == channel || support.displacement_channel == channel;
            });
    if (!known) {
      throw InputError(config.Name() + ": model.channel_map: '" + channel +
                       "' is not a channel of the manifest " + config.structure.manifest);
    }
  }
  for (const MatrixModelZone& zone : model.zones) {
    if (!(zone.nominal_modulus > config.outer.lower_bound &&
          zone.nominal_modulus < config.outer.upper_bound)) {
      throw InputError(
          config.Name() + ": outer.lower_bound and outer.upper_bound [" +
          fmt::format("{:g}, {:g}", config.outer.lower_bound, config.outer.upper_bound) +
          "] Pa must hold the nominal modulus " + fmt::format("{:g}", zone.nominal_modulus) +
          " Pa of zone '" + zone.name + "' of " + config.structure.manifest +
          " (the search starts there)");
    }
  }
  return model;
}

void CheckMatrixModelFieldBytes(const Config& config, const MatrixModelData& model) {
  const double dofs = model.dofs();
  const double steps = config.time.NumSteps();
  const CoupledSolverType method =
      ResolveCoupledSolverType(config.inner, dofs, steps, /*streaming_available=*/true);
  const double bytes = IterativeSolverFieldBytes(dofs, steps);
  if (!HoldsIterativeSolverFields(method) ||
      bytes <= static_cast<double>(config.inner.max_field_bytes)) {
    return;
  }
  throw InputError(fmt::format(
      "{}: model.manifest {} ({} dofs) and {:g} steps (time.window / time.step) need {} bytes "
      "for inner.method '{}' ({} fields of dofs x (steps + 1) doubles), above "
      "inner.max_field_bytes = {}; use inner.method: streaming_conjugate_gradient (or auto), "
      "which stores no space-time field, raise inner.max_field_bytes, or use a coarser mesh "
      "(fewer dofs), a shorter window or a larger time step",
      config.Name(), config.structure.manifest, model.dofs(), steps, static_cast<long long>(bytes),
      CoupledSolverName(config.inner.type, method), kIterativeSolverFields,
      config.inner.max_field_bytes));
}

MatrixMeasurements LoadMatrixMeasurements(const Config& config, const MatrixModelData& model,
                                          const MatrixModelData* given_truth) {
  MatrixMeasurements measurements;
  if (config.data.source == DataSource::kCsv) {
    measurements.histories = ReadMatrixMeasurementCsv(config, model);
    measurements.source = config.data.path;
  } else {
    measurements.histories = SyntheticMatrixMeasurements(
        config, model, given_truth, &measurements.truth_moduli, &measurements.noise);
    measurements.source = "synthetic";
  }
  return measurements;
}

MatrixMeasurements MatrixMeasurementsOfRecord(const Config& config, const MatrixModelData& model,
                                              ChannelSet record, const std::string& name) {
  std::vector<std::string> names;
  for (const Channel& channel : record.channels) names.push_back(channel.name);
  const std::string missing =
      MissingChannelColumn(config, ChannelColumns(config, model), names, "the record");
  if (!missing.empty()) throw InputError(name + ": " + missing);
  MatrixMeasurements measurements;
  measurements.histories = MatrixRecordOnGrid(config, model, std::move(record), name);
  measurements.source = name;
  return measurements;
}

Matrix SimulateMatrixModel(const MatrixModelData& truth, const Vector& zone_moduli,
                           const Matrix& loads, double time_step, double theta,
                           Matrix* support_forces) {
  ChannelSet data = MatrixChannelSet(
      truth, time_step, loads, Matrix::Zero(static_cast<int>(truth.sensors.size()), loads.cols()));
  for (const MatrixModelSupport& support : truth.supports) {
    data.Add(support.force_channel, ChannelKind::kForce, Vector::Zero(loads.cols()));
  }
  // The weights and their reference modulus do not enter the direct sweep from W = 0;
  // the supports hold their dofs (the trusted treatment).
  MatrixMcreProblem simulation(truth, data, McreWeights(), truth.zones[0].nominal_modulus, theta,
                               Factorization::kAutomatic, ClampModel::kTrusted);
  simulation.SetModuli(zone_moduli);
  if (support_forces != nullptr) {
    *support_forces =
        truth.supports.empty() ? Matrix() : HeldSupportForces(truth, data, zone_moduli, theta);
  }
  return simulation.ModelOutputs();
}

NoiseLevels MatrixModelNoiseLevels(const MatrixModelData& model, const ChannelSet& data,
                                   double snr) {
  NoiseLevels levels;
  if (std::isinf(snr)) return levels;
  // The channels of each quantity, gathered as rows for their RMS.
  const auto samples = data.num_samples();
  const auto num_loads = static_cast<int>(model.loads.size());
  const auto num_sensors = static_cast<int>(model.sensors.size());
  int strain_count = 0;
  for (const MatrixModelSensor& sensor : model.sensors) {
    strain_count += sensor.kind == SensorKind::kStrain ? 1 : 0;
  }
  Matrix displacements(num_sensors - strain_count, samples), strains(strain_count, samples);
  for (int k = 0, u = 0, e = 0; k < num_sensors; ++k) {
    const MatrixModelSensor& sensor = model.sensors[static_cast<std::size_t>(k)];
    if (sensor.kind == SensorKind::kStrain) {
      strains.row(e++) = data.Values(sensor.channel).transpose();
    } else {
      displacements.row(u++) = data.Values(sensor.channel).transpose();
    }
  }
  Matrix loads(num_loads, samples);
  for (int c = 0; c < num_loads; ++c) {
    loads.row(c) = data.Values(model.loads[static_cast<std::size_t>(c)].channel).transpose();
  }
  levels.displacement_std = RootMeanSquareOfRows(displacements) / snr;
  levels.strain_std = RootMeanSquareOfRows(strains) / snr;
  levels.force_std = RootMeanSquareOfRows(loads) / snr;
  return levels;
}

void AddMatrixModelNoise(const MatrixModelData& model, double snr, std::uint64_t seed,
                         ChannelSet* data, NoiseLevels* levels) {
  const NoiseLevels drawn = MatrixModelNoiseLevels(model, *data, snr);
  if (levels != nullptr) *levels = drawn;
  if (std::isinf(snr)) return;
  const auto samples = data->num_samples();
  const auto num_loads = static_cast<int>(model.loads.size());
  const auto num_sensors = static_cast<int>(model.sensors.size());
  std::vector<Vector*> load_values, sensor_values;
  for (const MatrixModelLoad& load : model.loads)
    load_values.push_back(&data->Values(load.channel));
  for (const MatrixModelSensor& sensor : model.sensors) {
    sensor_values.push_back(&data->Values(sensor.channel));
  }
  const double std_u = drawn.displacement_std;
  const double std_e = drawn.strain_std;
  const double std_f = drawn.force_std;
  StandardNormal normal(seed);
  for (int c = 0; c < num_loads; ++c) {
    for (int j = 0; j < samples; ++j) (*load_values[c])[j] += std_f * normal();
  }
  for (int k = 0; k < num_sensors; ++k) {
    const double deviation = model.sensors[k].kind == SensorKind::kStrain ? std_e : std_u;
    for (int j = 0; j < samples; ++j) (*sensor_values[k])[j] += deviation * normal();
  }
  // Then the supports' channels, a force as the loads, a displacement as the sensors.
  for (const MatrixModelSupport& support : model.supports) {
    Vector& force = data->Values(support.force_channel);
    for (int j = 0; j < samples; ++j) force[j] += std_f * normal();
    if (support.displacement_channel.empty()) continue;
    Vector& displacement = data->Values(support.displacement_channel);
    for (int j = 0; j < samples; ++j) displacement[j] += std_u * normal();
  }
}

NoiseLevels MatrixNoiseLevels(const Config& config, const MatrixMeasurements& measurements,
                              std::string* source) {
  if (config.data.source == DataSource::kSynthetic && std::isfinite(config.data.snr)) {
    *source = "synthetic_snr";
    return measurements.noise;
  }
  // s^2 averaged over the channels of each kind
  double sums[3] = {0.0, 0.0, 0.0};
  int counts[3] = {0, 0, 0};
  for (const Channel& channel : measurements.histories.channels) {
    const int kind = channel.kind == ChannelKind::kStrain  ? 1
                     : channel.kind == ChannelKind::kForce ? 2
                                                           : 0;
    sums[kind] += std::pow(DifferenceNoiseStd(channel.values), 2);
    ++counts[kind];
  }
  NoiseLevels levels;
  double* stds[3] = {&levels.displacement_std, &levels.strain_std, &levels.force_std};
  for (int kind = 0; kind < 3; ++kind) {
    if (counts[kind] > 0) *stds[kind] = std::sqrt(sums[kind] / counts[kind]);
  }
  *source = "data_differences";
  return levels;
}

NoiseLevels MatrixLeastSquaresMisfitLevels(const Config& config, const MatrixModelData& model,
                                           const MatrixMeasurements& measurements,
                                           const ChannelSet& used, std::string* source) {
  NoiseLevels levels;
  const bool supports = !model.supports.empty();
  if (config.data.source == DataSource::kSynthetic && std::isfinite(config.data.snr)) {
    // std = RMS(signal) / SNR of the sensors of each kind, of the loads for the forces
    // (AddMatrixModelNoise)
    levels = measurements.noise;
    *source = "synthetic_snr";
  } else {
    // s^2 averaged over the channels of each kind (DifferenceNoiseStd): the sensors', and
    // with supports the loads' and supports' forces and the supports' displacements (the
    // bar's f0, fL and u0 with uL and its sensors: DifferenceNoiseLevels).
    double sums[3] = {0.0, 0.0, 0.0};
    int counts[3] = {0, 0, 0};
    auto add = [&](int kind, const std::string& channel) {
      sums[kind] += std::pow(DifferenceNoiseStd(measurements.histories.Values(channel)), 2);
      ++counts[kind];
    };
    for (const MatrixModelSensor& sensor : model.sensors) {
      add(sensor.kind == SensorKind::kStrain ? 1 : 0, sensor.channel);
    }
    if (supports) {
      for (const MatrixModelLoad& load : model.loads) add(2, load.channel);
      for (const MatrixModelSupport& support : model.supports) {
        add(2, support.force_channel);
        if (!support.displacement_channel.empty()) add(0, support.displacement_channel);
      }
    }
    if (counts[0] > 0) levels.displacement_std = std::sqrt(sums[0] / counts[0]);
    if (counts[1] > 0) levels.strain_std = std::sqrt(sums[1] / counts[1]);
    if (counts[2] > 0) levels.force_std = std::sqrt(sums[2] / counts[2]);
    *source = "data_differences";
  }
  // s_f weighs the supports' forces only (the loads are inputs).
  if (!supports) levels.force_std = 0.0;
  // Noise-free data have no level to normalise by: the RMS of the kind's channels in use
  // instead (only the ratio of the weights matters then); for the forces the loads' (the
  // bar's fL), or the supports' without a load.
  for (const int kind : {0, 1, 2}) {
    double& level = kind == 2   ? levels.force_std
                    : kind == 1 ? levels.strain_std
                                : levels.displacement_std;
    std::vector<std::string> channels;
    if (kind < 2) {
      for (const MatrixModelSensor& sensor : model.sensors) {
        if ((sensor.kind == SensorKind::kStrain) == (kind == 1)) channels.push_back(sensor.channel);
      }
    } else if (supports) {
      for (const MatrixModelLoad& load : model.loads) channels.push_back(load.channel);
      if (channels.empty()) {
        for (const MatrixModelSupport& support : model.supports) {
          channels.push_back(support.force_channel);
        }
      }
    }
    double sum = 0.0;
    for (const std::string& channel : channels) {
      sum += used.Values(channel).squaredNorm() / used.num_samples();
    }
    const double rms = channels.empty() ? 0.0 : std::sqrt(sum / channels.size());
    if (!(level > 0.0) && rms > 0.0) {
      level = rms;
      *source = "channel_rms";
    }
  }
  return levels;
}

ChannelSet MatrixMeasurementTable(const Config& config, const MatrixModelData& model,
                                  const ChannelSet& histories) {
  ChannelSet table;
  table.start_time = histories.start_time;
  table.time_step = histories.time_step;
  for (const auto& [channel, column, kind] : ChannelColumns(config, model)) {
    const Channel& source = histories.channels[static_cast<std::size_t>(histories.Find(channel))];
    table.Add(column, source.kind, source.values);
  }
  return table;
}

IdentificationRun RunMatrixIdentification(const Config& given, const MatrixModelData& model,
                                          const MatrixMeasurements& measurements,
                                          bool maps_and_uncertainty) {
  const auto start_time = std::chrono::steady_clock::now();
  IdentificationRun run;
  run.config = given;
  run.homogeneous_ran = false;
  const int dofs = model.dofs();
  const int steps = measurements.histories.num_steps();
  const double time_step = measurements.histories.time_step;
  run.inner_method = ResolveCoupledSolverType(given.inner, dofs, steps,
                                              /*streaming_available=*/true);
  run.data_source = measurements.source;
  run.truth_moduli = measurements.truth_moduli;
  run.reference_known = run.truth_moduli.size() > 0;
  if (maps_and_uncertainty) run.model = std::make_shared<const MatrixModelData>(model);
  run.data = measurements.histories;

  // 1. The pre-filter, the same on every channel.
  if (given.prefilter.enabled) PrefilterEveryChannel(given, model, &run);

  // 2. Every zone modulus at once, p_z = log(E_z / E_z,nom), from p = 0 (by least
  //    squares with outer.functional: least_squares, without error maps). The supports
  //    (if any) treated as mcre.clamp says (docs/matrix_models.md, "Supports"); held by
  //    least squares whatever it says, as the bar's least squares holds its clamp.
  if (given.outer.functional == OuterFunctional::kLeastSquares) {
    IdentifyMatrixZonesByLeastSquares(given, model, measurements, &run);
    run.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return run;
  }
  // The supports with a measured displacement tested on the raw data, their forces as
  // compared with (ConfigForTheSupports): every later step identifies with run.config.
  run.config =
      ConfigForTheSupports(given, model, measurements.histories, run.data, &run.support_checks,
                           &run.support_switched, &run.support_blend.weight);
  // Many zones on trusted supports whose displacements the data hold: the clamp measured,
  // the paper's formulation, as the bar's zones (zone_identification.measured_clamp,
  // docs/boundaries.md section 8). Every step of this run identifies the zones.
  const bool supports_displaced =
      !model.supports.empty() &&
      std::all_of(model.supports.begin(), model.supports.end(),
                  [](const MatrixModelSupport& s) { return !s.displacement_channel.empty(); });
  const Config zone_config =
      ConfigForTheZones(run.config, model.zones.size() > 1 && supports_displaced);
  if (zone_config.mcre.clamp != run.config.mcre.clamp) {
    run.config = zone_config;
    // The zones' treatment alone, whatever the test weighed.
    run.support_blend = SupportBlend();
    spdlog::info("{} zones: the supports measured (zone_identification.measured_clamp)",
                 model.zones.size());
  }
  run.zones.clamp = run.config.mcre.clamp;
  const Config& config = run.config;
  McreObjective mcre_objective =
      MatrixMcreObjective(model, run.data, config.mcre, config.time.theta, config.inner);
  auto& problem = static_cast<MatrixMcreProblem&>(mcre_objective.problem());
  // The minimiser's solves gather no element map; step 3 gathers it where it is read.
  problem.set_element_maps(false);
  run.nominal_moduli = problem.NominalModuli();
  run.zone_rest_cost = mcre_objective.rest_cost();
  const auto zones = static_cast<std::size_t>(model.zones.size());
  spdlog::info(
      "matrix model {}: {} dofs, {} zones, {} loads, {} sensors, {} steps of {:.4g} s; inner {}",
      config.structure.manifest, dofs, zones, model.loads.size(), model.sensors.size(), steps,
      time_step, CoupledSolverName(config.inner.type, run.inner_method));
  if (!model.supports.empty()) {
    spdlog::info("{} supports, treated as mcre.clamp: {}", model.supports.size(),
                 ClampModelToString(config.mcre.clamp));
  }
  if (RunsTheHomogeneousStage(config, model)) {
    // 2a. One E in every zone first, by the global scan and the refinements of the
    //     bar's identification (outer:, search:); the zones then start from E*, their
    //     first solve warm-started from its solution.
    if (!IdentifyHomogeneousStage(given, config, model, maps_and_uncertainty, &run)) {
      run.wall_time_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
      return run;
    }
    mcre_objective.SetWarmStart(run.solution.WarmStart());
  }
  // The discrepancy target's levels (zone_identification:), and the uncertainty's.
  run.noise = MatrixNoiseLevels(config, measurements, &run.noise_source);
  run.zones.ran = true;
  run.zones.summary = IdentifyZoneModuli(
      config.zone_identification, model, run.data, config.mcre, config.time.theta, config.inner,
      &mcre_objective, run.nominal_moduli, ZoneStart(config, run), config.outer.lower_bound,
      config.outer.upper_bound, run.noise, UsedPrefilter(config, run));
  TakeZoneOutcome(model, &run);
  if (!maps_and_uncertainty) {
    run.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return run;
  }

  // 3. The error maps and the model's outputs at the identified moduli, then the maps
  //    at the nominal moduli; 4. the uncertainty of the identified moduli.
  problem.set_element_maps(true);
  CoupledSolution storage;
  const CoupledSolution* identified =
      MapsAtIdentifiedAndNominal(config, model, mcre_objective, &problem, &storage, &run);
  if (identified != nullptr) {
    run.zone_uncertainty =
        EstimateZoneUncertainty(config.uncertainty, model, run.data, config.mcre, config.time.theta,
                                config.inner, run.identified_moduli, *identified, run.noise);
    spdlog::info("uncertainty: {}", run.zone_uncertainty.message);
  }
  run.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return run;
}

}  // namespace mcrewave
