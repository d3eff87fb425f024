#include "mcrewave/app/identification_run.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/zone_identification_run.h"
#include "mcrewave/core/format.h"
#include "mcrewave/data/noise.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/data/resample.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/model/simulation.h"

namespace mcrewave {
namespace {

// The measurements an identification compares with: the channels of
// data.channels (LoadMeasurements checked they exist), then the pre-filter
// (its cut-off into *cutoff, 0 when off); *ends: the end displacements in use.
ChannelSet IdentificationData(const Config& config, const ChannelSet& data,
                              EndDisplacementChannels* ends, double* cutoff) {
  ChannelSet selected = PrefilterMeasurements(
      SelectChannels(data, config.data.channels, "data.channels", "the data", &ends->u0, &ends->uL),
      config.prefilter, cutoff);
  if (config.prefilter.enabled) {
    spdlog::info("pre-filter: zero-phase Butterworth of order {} (x2), cut-off {:.6g} Hz{}",
                 config.prefilter.order, *cutoff,
                 config.prefilter.cutoff_frequency > 0.0 ? "" : " (derived from the load)");
  }
  return selected;
}

// RMS over every strain channel (e@X) of the set; 0 without any.
double StrainRms(const ChannelSet& set) {
  double squares = 0.0;
  Eigen::Index samples = 0;
  for (const BarSensor& sensor : BarSensors(set)) {
    if (sensor.kind != SensorKind::kStrain) continue;
    const Vector& values = set.channels[static_cast<std::size_t>(sensor.index)].values;
    squares += values.squaredNorm();
    samples += values.size();
  }
  return samples > 0 ? std::sqrt(squares / static_cast<double>(samples)) : 0.0;
}

// Relative agreement asked of a CSV's time grid with the config's.
constexpr double kGridTolerance = 1e-6;

// The moduli of the cost curve, ascending: `points` moduli evenly spaced over
// the window E* +- kCurvatureWindow E*; when the optimiser's evaluations reach
// farther, half of them over the span of the evaluations instead and the other
// half over the window, so the curve shows both the optimiser's path and the
// neighbourhood of E*. Clipped to the bounds.
std::vector<double> CostCurveModuli(const Config& config, const ModulusStage& run) {
  const double center = run.identified_modulus();
  const double lower = config.outer.lower_bound;
  const double upper = config.outer.upper_bound;
  const double window_low = std::max(lower, center * (1.0 - kCurvatureWindow));
  const double window_high = std::min(upper, center * (1.0 + kCurvatureWindow));
  double span_low = window_low;
  double span_high = window_high;
  for (const ObjectiveEvaluation& evaluation : run.evaluations) {
    span_low = std::min(span_low, evaluation.modulus);
    span_high = std::max(span_high, evaluation.modulus);
  }
  const int points = config.output.curve_points;
  const bool wider = span_low < window_low || span_high > window_high;
  const int span_points = wider ? points / 2 : 0;
  std::vector<double> moduli;
  for (int i = 0; i < span_points; ++i) {
    moduli.push_back(span_low + (span_high - span_low) * i / (span_points - 1.0));
  }
  const int window_points = points - span_points;
  for (int i = 0; i < window_points; ++i) {
    moduli.push_back(window_low + (window_high - window_low) * i / (window_points - 1.0));
  }
  std::sort(moduli.begin(), moduli.end());
  return moduli;
}

// The cost curve at CostCurveModuli, each solve warm-started from the previous
// point's (the first from the solution at E*).
std::vector<CostCurvePoint> ComputeCostCurve(const Config& config, const MatrixModelData& model,
                                             const ChannelSet& data, const ModulusStage& run,
                                             long* sweeps) {
  const double center = run.identified_modulus();
  const std::vector<double> moduli = CostCurveModuli(config, run);
  spdlog::info("cost curve: {} points over [{:.6g}, {:.6g}] Pa", moduli.size(), moduli.front(),
               moduli.back());

  McreObjective objective = MatrixMcreObjective(model, data, config.mcre, config.time.theta,
                                                config.inner, Factorization::kAutomatic, center);
  if (run.solution.WarmStart().size() > 0) objective.SetWarmStart(run.solution.WarmStart());
  std::vector<CostCurvePoint> curve;
  for (const double modulus : moduli) {
    const ObjectiveEvaluation& evaluation = objective.EvaluateModulus(modulus);
    CostCurvePoint point;
    point.modulus = modulus;
    point.usable = evaluation.usable;
    point.cost = evaluation.cost;
    point.cost_gradient = evaluation.cost_gradient;
    if (!point.usable) {
      spdlog::warn("cost curve: the coupled solve at E = {:.6g} Pa is not usable ({})", modulus,
                   evaluation.inner.BriefReport());
    }
    curve.push_back(point);
  }
  *sweeps = objective.sweeps();
  return curve;
}

std::string Number(double value) { return FormatNumber(value, kSixDigits); }

// Solves `objective` at `modulus` [Pa] and makes that solve the stage's E*: its
// evaluation the stage's last and best, its solution the stage's, its sweeps counted. A
// solve that is not usable fails the stage: "<what> is not usable: " and the solver's
// message.
void SolveStageAt(double modulus, const std::string& what, McreObjective* objective,
                  ModulusStage* stage) {
  const long sweeps_before = objective->sweeps();
  const ObjectiveEvaluation& solve = objective->EvaluateModulus(modulus);
  stage->outer.modulus = modulus;
  if (!solve.usable) {
    stage->outer.termination = TerminationType::kFailure;
    stage->outer.message = what + " is not usable: " + solve.inner.message;
  }
  stage->evaluations.push_back(solve);
  stage->sweeps += objective->sweeps() - sweeps_before;
  stage->best_index = static_cast<int>(stage->evaluations.size()) - 1;
  stage->solution = objective->last_solution();
}

}  // namespace

ChannelSet SyntheticMeasurements(const Config& config) {
  ChannelSet data = MakeSyntheticMeasurements(config.model, config.load, config.time, config.data);
  // The end channels first, then the interior ones (the first non-finite one is named).
  std::vector<std::pair<std::string, const Vector*>> channels = {{"u0", &data.Values("u0")},
                                                                 {"uL", &data.Values("uL")},
                                                                 {"f0", &data.Values("f0")},
                                                                 {"fL", &data.Values("fL")}};
  for (const BarSensor& sensor : BarSensors(data)) {
    const Channel& channel = data.channels[static_cast<std::size_t>(sensor.index)];
    channels.push_back({channel.name, &channel.values});
  }
  for (const auto& [name, values] : channels) {
    if (!values->allFinite()) {
      throw InputError(config.Name() + ": the synthetic channel '" + name +
                       "' is not finite: load.amplitude (" + Number(config.load.amplitude) +
                       " N) or the noise of data.snr (" + Number(config.data.snr) +
                       ") lies beyond double range");
    }
  }
  return data;
}

ChannelSet LoadMeasurements(const Config& config) {
  bool use_u0 = true, use_uL = true;
  if (config.data.source == DataSource::kSynthetic) {
    ChannelSet data = SyntheticMeasurements(config);
    SelectChannels(data, config.data.channels, "data.channels", "the synthetic data (data.sensors)",
                   &use_u0, &use_uL);
    return data;
  }
  return BarMeasurementsOfRecord(config, ReadMeasurementCsv(config.data.path), config.data.path);
}

ChannelSet BarMeasurementsOfRecord(const Config& config, ChannelSet data, const std::string& name) {
  bool use_u0 = true, use_uL = true;
  // Dead channels and outliers are looked for in the file's own samples, so that the
  // line named is the file's (resampling would spread a spike over its neighbours).
  CheckMeasurementChannels(data, name);
  const std::string config_name = config.Name();
  const int expected_samples = config.time.NumSteps() + 1;
  if (std::abs(data.time_step - config.time.step) > kGridTolerance * config.time.step ||
      std::abs(data.start_time) > kGridTolerance * config.time.step) {
    // Another rate or origin: band-limited resampling onto the model's grid (resample.h).
    spdlog::info("{}: resampling {} samples of {:.6g} s onto {} samples of time.step {:.6g} s",
                 name, data.num_samples(), data.time_step, expected_samples, config.time.step);
    data = ResampleMeasurements(data, config.time.step, expected_samples, name);
  }
  SelectChannels(data, config.data.channels, "data.channels", name, &use_u0, &use_uL);
  for (const BarSensor& sensor : BarSensors(data)) {
    if (sensor.position > config.model.length) {
      throw InputError(name + ":1: column '" +
                       data.channels[static_cast<std::size_t>(sensor.index)].name +
                       "': the sensor lies outside the bar [0, " + Number(config.model.length) +
                       "] m (model.length of " + config_name + ")");
    }
  }
  if (data.num_samples() > expected_samples) {
    // A record longer than the window on the model's grid: its first samples are the
    // window's, as resampling would take them from data on another grid.
    spdlog::info("{}: using the first {} of its {} samples (time.window {:.6g} s)", name,
                 expected_samples, data.num_samples(), config.time.window);
    KeepFirstSamples(expected_samples, &data);
  }
  if (data.num_samples() < expected_samples) {
    throw InputError(
        name + ": " + std::to_string(data.num_samples()) +
        " samples, fewer than time.window / time.step + 1 = " + std::to_string(expected_samples) +
        " in " + config_name + " (time.window " + Number(config.time.window) + " s)");
  }
  return data;
}

int SearchTimeStepFactor(const ChannelSet& data, const MatrixModelData& model, double theta,
                         const SearchOptions& search, double* force_frequency) {
  const double h = data.time_step;
  // The forces the model is driven by or tested against: its loads' and its supports'
  // measured forces (the same channels whichever road the bar takes).
  std::vector<std::string> forces;
  for (const MatrixModelLoad& load : model.loads) forces.push_back(load.channel);
  for (const MatrixModelSupport& support : model.supports) forces.push_back(support.force_channel);
  double largest = 0.0;  // the largest rms frequency of a force channel [Hz]
  for (const std::string& channel : forces) {
    const int index = data.Find(channel);
    if (index < 0) continue;
    const Vector& x = data.channels[index].values;
    const double energy = x.squaredNorm();
    if (x.size() < 2 || !(energy > 0.0)) continue;
    // f_rms = (1 / (2 pi h)) (sum_j (x_j+1 - x_j)^2 / sum_j x_j^2)^1/2
    const double differences = (x.tail(x.size() - 1) - x.head(x.size() - 1)).squaredNorm();
    largest = std::max(largest, std::sqrt(differences / energy) / (2.0 * M_PI * h));
  }
  if (force_frequency != nullptr) *force_frequency = largest;
  if (theta != 0.5 || !(largest > 0.0) || !std::isfinite(largest)) return 1;
  // (omega k h)^2 / 6 <= refine_window / 10.
  const double allowed = std::sqrt(0.6 * search.refine_window) / (2.0 * M_PI * largest * h);
  const int by_band =
      allowed >= search.time_step_factor ? search.time_step_factor : static_cast<int>(allowed);
  return std::max(1, std::min(by_band, data.num_steps() / kSearchMinimumSteps));
}

ChannelSet SearchData(const ChannelSet& data, int factor) {
  assert(factor >= 1 && data.num_steps() / factor >= 1);
  if (factor == 1) return data;
  return ResampleMeasurements(data, factor * data.time_step, data.num_steps() / factor + 1,
                              "the search functional's data (search.time_step_factor)");
}

McreIdentification IdentifyWithMcre(const Config& config, const MatrixModelData& model,
                                    const ChannelSet& data, bool element_maps) {
  McreIdentification result;
  result.objective = std::make_unique<McreObjective>(
      MatrixMcreObjective(model, data, config.mcre, config.time.theta, config.inner,
                          Factorization::kAutomatic, config.outer.initial, element_maps));
  result.scan_cost_scale = result.objective->cost_scale();
  if (!IdentifiesInTwoStages(config, model)) {
    IdentificationOptions outer = config.outer;
    // The search functional is e^2 itself: its scan, on e^2, in one stage.
    if (ScansTheSearchFunctional(config)) outer.scan_points = config.search.scan_points;
    result.outer = Identify(outer, result.objective.get());
    return result;
  }
  CoupledSolverOptions search_inner = config.inner;
  search_inner.tolerance = config.search.inner_tolerance;
  // The search's data must outlive `search` only: its minimiser places e^2's window.
  double force_frequency = 0.0;
  const int factor =
      SearchTimeStepFactor(data, model, config.time.theta, config.search, &force_frequency);
  spdlog::info(
      "search functional on {} steps of {:.6g} s ({} times the data's; the forces' rms "
      "frequency {:.4g} Hz)",
      data.num_steps() / factor, factor * data.time_step, factor, force_frequency);
  const ChannelSet search_data = SearchData(data, factor);
  McreObjective search = MatrixMcreObjective(
      model, search_data, SearchMcreOptions(config.mcre, config.search), config.time.theta,
      search_inner, Factorization::kAutomatic, config.outer.initial, element_maps);
  result.outer = IdentifyInTwoStages(config.outer, &search, config.search.scan_points,
                                     config.search.refine_window, result.objective.get(),
                                     SearchRefinementOf(config.search));
  result.search_sweeps = search.sweeps();
  if (result.outer.scan_of_search) result.scan_cost_scale = search.cost_scale();
  return result;
}

bool IdentifiesInTwoStages(const Config& config, const MatrixModelData& model) {
  return ScansTheSearchFunctional(config) &&
         !SearchIsTheObjective(config.mcre, config.search, !model.supports.empty());
}

ModulusStage IdentifyHomogeneousModulus(const Config& config, const MatrixModelData& model,
                                        const ChannelSet& data, bool element_maps) {
  ModulusStage stage;
  stage.inner_method = ResolveCoupledSolverType(config.inner, model.dofs(), data.num_steps(),
                                                /*streaming_available=*/true);
  spdlog::info(
      "identifying E with {}/{} from {:.6g} Pa in [{:.6g}, {:.6g}] Pa; inner {}; global scan on {}",
      OptimizerTypeToString(config.outer.optimizer),
      OuterAlgorithmToString(ResolveAlgorithm(config.outer.optimizer, config.outer.algorithm, 1)),
      config.outer.initial, config.outer.lower_bound, config.outer.upper_bound,
      CoupledSolverName(config.inner.type, stage.inner_method),
      config.outer.scan_points == 0          ? "none (outer.scan_points 0)"
      : IdentifiesInTwoStages(config, model) ? "the pinned search functional (search:)"
      : ScansTheSearchFunctional(config)
          ? "mcre:'s e^2, the search functional itself on this model (search.scan_points)"
          : "mcre:'s e^2");
  McreIdentification identification = IdentifyWithMcre(config, model, data, element_maps);
  McreObjective& objective = *identification.objective;
  stage.rest_cost = objective.rest_cost();
  stage.scan_cost_scale = identification.scan_cost_scale;
  stage.outer = identification.outer;
  stage.evaluations = objective.evaluations();
  stage.search_sweeps = identification.search_sweeps;
  stage.sweeps = objective.sweeps() + stage.search_sweeps;
  spdlog::info("{}", stage.outer.BriefReport());
  if (!stage.IsUsable()) return stage;
  // Every field reported belongs to the identified E: the objective's best evaluation is
  // at E* unless another evaluation went lower; then E* is solved once more
  // (warm-started).
  stage.best_index = objective.best_index();
  stage.solution = objective.best_solution();
  if (stage.evaluations[stage.best_index].modulus != stage.identified_modulus()) {
    SolveStageAt(stage.identified_modulus(), "the coupled solve at the identified E", &objective,
                 &stage);
  }
  return stage;
}

McreObjective CompleteModulusStage(const Config& config, const MatrixModelData& model,
                                   const ChannelSet& data, bool cost_curve, ModulusStage* stage) {
  // The cost curve around E*.
  if (cost_curve) {
    stage->cost_curve = ComputeCostCurve(config, model, data, *stage, &stage->cost_curve_sweeps);
  }
  // The inner solver's convergence at E* from W = 0.
  McreObjective cold =
      MatrixMcreObjective(model, data, config.mcre, config.time.theta, config.inner,
                          Factorization::kAutomatic, stage->identified_modulus());
  stage->cold_solve = cold.EvaluateModulus(stage->identified_modulus()).inner;
  return cold;
}

Config MeasuredSupportConfig(const Config& config) {
  Config measured = config;
  const McreWeights paper;
  measured.mcre.clamp = ClampModel::kMeasured;
  measured.mcre.weights.displacement_weight = paper.displacement_weight;
  measured.mcre.weights.strain_weight = paper.strain_weight;
  // The scan on the same formulation at heavier weights, which has one valley where
  // e^2's own may have two (docs/boundaries.md section 9); e^2 refined near its minimum.
  measured.search.functional = SearchFunctional::kMeasured;
  measured.search.displacement_weight = 1.0;
  measured.search.strain_weight = 1.0;
  return measured;
}

Config ConfigForTheZones(const Config& config, bool supports_displaced) {
  return config.zone_identification.measured_clamp && config.mcre.clamp == ClampModel::kTrusted &&
                 supports_displaced
             ? MeasuredSupportConfig(config)
             : config;
}

Config ConfigForTheSupports(const Config& config, const MatrixModelData& model,
                            const ChannelSet& raw, const ChannelSet& data,
                            std::vector<SupportCheck>* checks, bool* switched, double* weight,
                            bool log) {
  checks->clear();
  *switched = false;
  *weight = 0.0;
  if (config.mcre.clamp != ClampModel::kTrusted ||
      config.mcre.support_check == SupportCheckAction::kOff) {
    return config;
  }
  *checks = CheckSupports(model, raw, data, config.mcre.support_check_threshold);
  if (log) {
    for (const SupportCheck& check : *checks) {
      if (check.contradicted) {
        spdlog::warn("{}", check.BriefReport());
      } else {
        spdlog::info("{}", check.BriefReport());
      }
    }
  }
  const double a = SupportSwitchWeight(*checks, config.mcre.support_check_ramp_start,
                                       config.mcre.support_check_threshold);
  if (a == 0.0) return config;
  if (config.mcre.support_check == SupportCheckAction::kWarn) {
    if (log && AnySupportContradicted(*checks)) {
      spdlog::warn(
          "the supports stay trusted (mcre.support_check: warn): E may be biased; "
          "mcre.support_check: switch or mcre.clamp: measured treats them as measured");
    }
    return config;
  }
  *weight = a;
  *switched = a >= 0.5;
  if (log) {
    if (a == 1.0) {
      spdlog::warn(
          "the supports are treated as measured, with the paper's weights and scan "
          "(mcre.support_check: switch; mcre.support_check: warn keeps them trusted)");
    } else {
      spdlog::warn(
          "t lies between mcre.support_check_ramp_start and mcre.support_check_threshold: E "
          "is identified both ways and weighs the paper's formulation's by {:.3g}; the fields "
          "are the {} treatment's (mcre.support_check: warn keeps the supports trusted)",
          a, *switched ? "measured" : "trusted");
    }
  }
  return *switched ? MeasuredSupportConfig(config) : config;
}

ModulusStage IdentifyHomogeneousModulusOfSupports(const Config& given, const Config& config,
                                                  const MatrixModelData& model,
                                                  const ChannelSet& data, bool element_maps,
                                                  SupportBlend* blend) {
  ModulusStage stage = IdentifyHomogeneousModulus(config, model, data, element_maps);
  const bool measured = config.mcre.clamp != given.mcre.clamp;
  if (!blend->Blends() || !stage.IsUsable()) return stage;
  const Config other = measured ? given : MeasuredSupportConfig(given);
  spdlog::info("E with the {} treatment of the supports too (weight {:.3g})",
               measured ? "trusted" : "measured", measured ? 1.0 - blend->weight : blend->weight);
  const ModulusStage other_stage =
      IdentifyHomogeneousModulus(other, model, data, /*element_maps=*/false);
  stage.sweeps += other_stage.sweeps;
  if (!other_stage.IsUsable()) {
    spdlog::warn("the {} treatment's identification failed ({}): E* is the {} one's alone",
                 measured ? "trusted" : "measured", other_stage.outer.message,
                 measured ? "measured" : "trusted");
    blend->weight = measured ? 1.0 : 0.0;
    return stage;
  }
  blend->trusted_modulus = measured ? other_stage.identified_modulus() : stage.identified_modulus();
  blend->measured_modulus =
      measured ? stage.identified_modulus() : other_stage.identified_modulus();
  const double modulus = blend->Modulus();
  spdlog::info("E* = {:.6g} Pa: {:.6g} Pa trusted, {:.6g} Pa measured, weights {:.3g} and {:.3g}",
               modulus, blend->trusted_modulus, blend->measured_modulus, 1.0 - blend->weight,
               blend->weight);
  // Every field reported belongs to E*: config's solve there, from its own E*'s solution.
  McreObjective objective =
      MatrixMcreObjective(model, data, config.mcre, config.time.theta, config.inner,
                          Factorization::kAutomatic, config.outer.initial, element_maps);
  if (stage.solution.WarmStart().size() > 0) objective.SetWarmStart(stage.solution.WarmStart());
  SolveStageAt(modulus, "the coupled solve at the weighted E*", &objective, &stage);
  return stage;
}

IdentificationRun IdentifyModulus(const Config& given, const ChannelSet& data) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  IdentificationRun run;
  run.reference_known = given.data.source == DataSource::kSynthetic;
  run.data = IdentificationData(given, data, &run.ends, &run.prefilter_cutoff);

  run.model = std::make_shared<const MatrixModelData>(
      BarRunModel(BarModel(given.model), run.data, run.ends));
  const MatrixModelData& matrices = *run.model;
  // The supports tested on the data as given, before the pre-filter, their forces
  // pre-filtered.
  run.config = ConfigForTheSupports(given, matrices, data, run.data, &run.support_checks,
                                    &run.support_switched, &run.support_blend.weight);
  const Config& config = run.config;
  static_cast<ModulusStage&>(run) = IdentifyHomogeneousModulusOfSupports(
      given, config, matrices, run.data, /*element_maps=*/true, &run.support_blend);
  // The bar's weights from k* = E0 S / L (mcre/matrix_mcre_problem.h): alpha = w_f / k*
  // of its loads, beta = w_u k* of its end displacement, for the summary.
  const double stiffness_scale = config.mcre.reference_modulus * matrices.stiffness_length;
  run.alpha = config.mcre.weights.force_weight / stiffness_scale;
  run.beta = config.mcre.weights.displacement_weight * stiffness_scale;
  run.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

namespace {

// The error map, the model's channels and the RMS misfits at the identified E*, from
// run->solution, with `problem` (run->config's, on run->model and run->data).
void ReportAtIdentifiedModulus(const Config& config, MatrixMcreProblem* problem,
                               IdentificationRun* run) {
  // The error map of the constitutive gap at the homogeneous E* (error_map.h).
  run->error_map = BarErrorMap(config, *run, problem);
  const int peak = run->error_map.PeakElement();
  spdlog::info("error map: largest share {:.3g} of the constitutive gap at x = {:.4g} m",
               run->error_map.Fractions()[peak], run->error_map.position[peak]);
  if (run->error_map.sensitivity.size() > 0) {
    spdlog::info(
        "sensitivity map: e^2 falls fastest as E is lowered at x = {:.4g} m, "
        "as it is raised at x = {:.4g} m",
        run->error_map.position[run->error_map.SofteningPeakElement()],
        run->error_map.position[run->error_map.StiffeningPeakElement()]);
  }
  // The model's channels and the RMS misfits at E*; an end displacement the run does
  // not use is no channel of the problem: from the stored field.
  run->model_channels = problem->ModelChannels(run->solution);
  if (run->solution.has_fields()) {
    const auto last = run->solution.displacement.rows() - 1;
    for (const auto& [name, row] : {std::pair<const char*, Eigen::Index>{"u0", 0}, {"uL", last}}) {
      if (run->model_channels.Find(name) < 0) {
        run->model_channels.Add(name, ChannelKind::kDisplacement,
                                run->solution.displacement.row(row).transpose());
      }
    }
  }
  run->misfit = EndMisfitLevels(run->data, run->model_channels);
}

// RunIdentification by the MCRE on the mesh of config.model.
IdentificationRun RunOnOneMesh(const Config& given, const ChannelSet& data) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  IdentificationRun run = IdentifyModulus(given, data);
  if (!run.IsUsable()) return run;
  // Every step identifies with the config of the homogeneous stage (ConfigForTheSupports).
  const Config config = run.config;
  const MatrixModelData& matrices = *run.model;

  // The cost curve around E* and the inner solver's convergence there from W = 0.
  McreObjective cold = CompleteModulusStage(config, matrices, run.data, /*cost_curve=*/true, &run);
  ReportAtIdentifiedModulus(config, &dynamic_cast<MatrixMcreProblem&>(cold.problem()), &run);
  // The uncertainty figure: noise levels known for synthetic data with noise,
  // estimated from the data's second differences otherwise.
  run.estimated_noise = DifferenceNoiseLevels(data);
  run.noise = MeasurementNoiseLevels(config, data, &run.noise_source);
  int curvature_points = 0;
  const double curvature = CostGradientSlope(run.cost_curve, run.identified_modulus(),
                                             kCurvatureWindow, &curvature_points);
  run.uncertainty = EstimateModulusUncertainty(
      config.uncertainty, matrices, run.data, config.mcre, config.time.theta, config.inner,
      run.identified_modulus(), run.solution, run.noise, curvature, curvature_points);
  if (run.uncertainty.available) {
    spdlog::info("uncertainty: std(E) = {:.4g} Pa ({:.3g} %) over {} noise draws",
                 run.uncertainty.std_dev, 100.0 * run.uncertainty.relative_std_dev,
                 run.uncertainty.samples);
  } else {
    spdlog::warn("uncertainty not available: {}", run.uncertainty.message);
  }
  // Every zone's modulus from E* when the identification has zones
  // (zone_identification_run.h).
  run.zones =
      RunZoneIdentification(config, IdentificationZoneLayout(config), run, TruthZones(config));
  if (run.zones.ran && run.zones.summary.moduli.size() > 0) {
    run.zone_uncertainty = BarZoneUncertainty(config, run);
    spdlog::info("zones: uncertainty {}", run.zone_uncertainty.message);
  }
  run.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

// One treatment's E refined on one mesh of the ladder: the secant from the previous
// mesh's E* within E* (1 -+ search.refine_window), its first step Newton's with
// `curvature` [J s/Pa^2] (0: unknown), `warm_start` (empty: none) the previous mesh's
// traces or W, `reference_residual_norm` (0: none) the ||c||_P of the solve that gave it
// (SolveCoupled's); streaming solves gather the element maps when `element_maps`.
struct MeshRefinement {
  std::unique_ptr<McreObjective> objective;
  IdentificationSummary summary;
  // Why the refined E* cannot be taken: not converged, or on an edge of the window
  // inside the bounds; "" otherwise.
  std::string problem;
};

MeshRefinement RefineOnMesh(const Config& config, const MatrixModelData& model,
                            const ChannelSet& data, double start_modulus, double curvature,
                            const Matrix& warm_start, double reference_residual_norm,
                            bool element_maps, int max_evaluations, double max_time) {
  MeshRefinement level;
  level.objective = std::make_unique<McreObjective>(
      MatrixMcreObjective(model, data, config.mcre, config.time.theta, config.inner,
                          Factorization::kAutomatic, start_modulus, element_maps));
  if (warm_start.size() > 0) level.objective->SetWarmStart(warm_start, reference_residual_norm);
  IdentificationOptions options = config.outer;
  const double window = config.search.refine_window;
  options.optimizer = OptimizerType::kNlopt;
  options.algorithm = OuterAlgorithm::kSecant;
  options.initial = start_modulus;
  options.lower_bound = std::max(config.outer.lower_bound, start_modulus * (1.0 - window));
  options.upper_bound = std::min(config.outer.upper_bound, start_modulus * (1.0 + window));
  options.max_evaluations = max_evaluations;
  options.max_time = max_time;
  spdlog::info("refining E ({} supports) on {} elements from {:.9g} Pa within [{:.6g}, {:.6g}] Pa",
               ClampModelToString(config.mcre.clamp), config.model.elements, start_modulus,
               options.lower_bound, options.upper_bound);
  if (!(max_time > 0.0) || max_evaluations < 2) {
    level.summary.termination = TerminationType::kNoConvergence;
    level.summary.message = "outer.max_time or outer.max_evaluations reached on a coarser mesh";
    level.problem = "the refinement on " + std::to_string(config.model.elements) +
                    " elements: " + level.summary.message;
    return level;
  }
  // d^2 cost / dx^2 = (d^2e^2/dE^2) E_scale^2 / J_scale (objective.h's scaling).
  const double scaled_curvature =
      curvature * start_modulus * start_modulus / level.objective->cost_scale();
  level.summary = RefineFrom(options, level.objective.get(), scaled_curvature);
  spdlog::info("refinement on {} elements: {}", config.model.elements, level.summary.BriefReport());
  if (!level.summary.IsSolutionUsable() || level.objective->best_index() < 0) {
    level.problem = "the refinement on " + std::to_string(config.model.elements) +
                    " elements: " + level.summary.message;
  } else if (EndsOnAnInnerEdge(options, config.outer, level.summary.modulus)) {
    level.problem = "the refinement on " + std::to_string(config.model.elements) +
                    " elements ended on an edge of E* (1 -+ search.refine_window) of the coarser "
                    "mesh's E*: raise model.coarse_elements, or set it to 0 to identify on "
                    "model.elements alone";
  }
  return level;
}

// The inner tolerance of the refinements above the coarse mesh, relative to
// outer.relative_tolerance (docs/multilevel.md gives what it moves E by).
constexpr double kLadderInnerToleranceFactor = 100.0;

// The meshes the refinement climbs from the coarse mesh: 10, 100, ... times
// model.coarse_elements below model.elements, then model.elements. Each mesh's E* lies
// within the discretisation's shift, O(h^2), of the next's, so each refinement starts
// next to its minimum.
std::vector<int> MeshLadder(int coarse_elements, int elements) {
  std::vector<int> meshes;
  for (long n = 10L * coarse_elements; n < elements; n *= 10) meshes.push_back(static_cast<int>(n));
  meshes.push_back(elements);
  return meshes;
}

// The next mesh's warm start from a solution on `model` at `modulus` [Pa]. For a
// streaming solver the traces H U, which do not depend on the mesh: a streaming solve's
// own, or those of the stored displacement, read by `previous`'s problem (the objective
// that solved it; null: one made on `model`). For a stored-field solver W, each sample
// interpolated linearly from the bar's uniform nodes onto the next mesh's `next_nodes`
// (empty when the solution stored no field).
Matrix WarmStartForTheNextMesh(const Config& config, const MatrixModelData& model,
                               const ChannelSet& data, double modulus,
                               const CoupledSolution& solution, McreObjective* previous,
                               bool next_streams, int next_nodes) {
  if (!next_streams) {
    if (!solution.has_fields()) return Matrix();
    const Matrix& coarse = solution.retrograde;
    const Eigen::Index intervals = coarse.rows() - 1;
    Matrix fine(next_nodes, coarse.cols());
    for (int i = 0; i < next_nodes; ++i) {
      // x_i / h_coarse for the fine node i of next_nodes - 1 equal elements.
      const double position = static_cast<double>(i) * intervals / (next_nodes - 1.0);
      const Eigen::Index left =
          std::min<Eigen::Index>(static_cast<Eigen::Index>(position), intervals - 1);
      const double t = position - static_cast<double>(left);
      fine.row(i) = (1.0 - t) * coarse.row(left) + t * coarse.row(left + 1);
    }
    return fine;
  }
  if (!solution.has_fields()) return solution.traces;
  std::unique_ptr<McreObjective> made;
  if (previous == nullptr) {
    made = std::make_unique<McreObjective>(MatrixMcreObjective(model, data, config.mcre,
                                                               config.time.theta, config.inner,
                                                               Factorization::kAutomatic, modulus));
    previous = made.get();
  }
  // H holds the trusted reaction's row g^T K(E): at the solution's modulus.
  previous->problem().SetModulus(modulus);
  return dynamic_cast<const MatrixMcreProblem&>(previous->problem())
      .ObservedTraces(solution.displacement);
}

// One treatment's E climbed up the ladder from `coarse_modulus` on `coarse_model` (the
// coarse run's, of coarse_elements elements; its solution `coarse_solution`): the last
// mesh's refinement, or the first that failed. The curvature of each refinement's first
// step is the previous mesh's last secant slope when positive, else `curvature`.
// *evaluations and *sweeps add up the climb's.
MeshRefinement ClimbTheLadder(const Config& config, const ChannelSet& data,
                              const EndDisplacementChannels& ends,
                              std::shared_ptr<const MatrixModelData> coarse_model,
                              int coarse_elements, double coarse_modulus, double curvature,
                              const CoupledSolution& coarse_solution, int max_evaluations,
                              double max_time, int* evaluations, long* sweeps,
                              std::shared_ptr<const MatrixModelData>* fine_model) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  Config previous = config;
  previous.model.elements = coarse_elements;
  std::shared_ptr<const MatrixModelData> previous_model = std::move(coarse_model);
  double modulus = coarse_modulus;
  const CoupledSolution* solution = &coarse_solution;
  // ||c||_P of the solve that gave `solution` on a mesh of the ladder (0: the coarse run's,
  // not kept). ||c||_P converges with the mesh: the next mesh's streaming solve measures
  // its residuals against it instead of paying the data start's four sweeps.
  double reference_residual_norm = 0.0;
  MeshRefinement level;
  for (const int elements : MeshLadder(coarse_elements, config.model.elements)) {
    Config mesh = config;
    mesh.model.elements = elements;
    // Each refinement starts within the discretisation's shift of its minimum, where the
    // gradient's error from an inexact inner solve moves E by far less than the outer
    // tolerance (docs/multilevel.md): its solves stop at kLadderInnerToleranceFactor times
    // outer.relative_tolerance, and so stay above the sweeps' round-off floor of the
    // finest meshes.
    mesh.inner.tolerance = std::max(config.inner.tolerance,
                                    kLadderInnerToleranceFactor * config.outer.relative_tolerance);
    auto model =
        std::make_shared<const MatrixModelData>(BarRunModel(BarModel(mesh.model), data, ends));
    const bool streams =
        ResolveCoupledSolverType(mesh.inner, model->dofs(), data.num_steps(), true) ==
        CoupledSolverType::kStreamingConjugateGradient;
    const Matrix warm_start =
        solution->WarmStart().size() > 0
            ? WarmStartForTheNextMesh(previous, *previous_model, data, modulus, *solution,
                                      level.objective.get(), streams, model->dofs())
            : Matrix();
    MeshRefinement next = RefineOnMesh(
        mesh, *model, data, modulus, curvature, warm_start, reference_residual_norm,
        /*element_maps=*/elements == config.model.elements, max_evaluations - *evaluations,
        max_time - std::chrono::duration<double>(Clock::now() - start).count());
    *evaluations += next.summary.evaluations;
    *sweeps += next.objective->sweeps();
    level = std::move(next);
    if (!level.problem.empty()) return level;
    // The secant's last slope, de^2/dE between its last two evaluations.
    const std::vector<ObjectiveEvaluation>& done = level.objective->evaluations();
    if (done.size() >= 2) {
      const ObjectiveEvaluation& a = done[done.size() - 2];
      const ObjectiveEvaluation& b = done.back();
      const double slope = (b.cost_gradient - a.cost_gradient) / (b.modulus - a.modulus);
      if (slope > 0.0 && std::isfinite(slope)) curvature = slope;
    }
    modulus = level.summary.modulus;
    solution = &level.objective->best_solution();
    reference_residual_norm =
        level.objective->evaluations()[level.objective->best_index()].inner.reference_residual_norm;
    previous = mesh;
    previous_model = model;
    *fine_model = model;
  }
  return level;
}

// RunIdentification from a coarse mesh up the ladder (UsesCoarseMesh; docs/multilevel.md).
IdentificationRun RunFromACoarseMesh(const Config& given, const ChannelSet& data) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const int fine_elements = given.model.elements;
  // 1. Everything on the coarse mesh.
  Config coarse = given;
  coarse.model.elements = given.model.coarse_elements;
  spdlog::info("coarse mesh: E first on {} elements, then refined up to {} (model.coarse_elements)",
               coarse.model.elements, fine_elements);
  IdentificationRun run = RunOnOneMesh(coarse, data);
  CoarseMeshStage& stage = run.coarse_mesh;
  stage.ran = true;
  stage.coarse_elements = coarse.model.elements;
  stage.coarse_wall_time_s = run.wall_time_s;
  if (!UnreportableMessage(run).empty()) {
    if (!run.IsUsable()) {
      run.outer.message = "on the coarse mesh (model.coarse_elements " +
                          std::to_string(stage.coarse_elements) + "): " + run.outer.message;
    }
    return run;
  }
  stage.coarse_modulus = run.identified_modulus();
  int curvature_points = 0;
  stage.curvature =
      CostGradientSlope(run.cost_curve, stage.coarse_modulus, kCurvatureWindow, &curvature_points);

  // 2. E refined up the ladder of meshes, with the config of the coarse run's supports
  // (ConfigForTheSupports) and what the coarse identification left.
  Config config = run.config;
  config.model.elements = fine_elements;
  config.inner = given.inner;
  const int max_evaluations =
      config.outer.max_evaluations - static_cast<int>(run.TotalEvaluations());
  const double max_time = config.outer.max_time - run.outer.wall_time_s;
  const SupportBlend coarse_blend = run.support_blend;
  const bool measured = config.mcre.clamp != given.mcre.clamp;
  const double own_start = !coarse_blend.Blends() ? stage.coarse_modulus
                           : measured             ? coarse_blend.measured_modulus
                                                  : coarse_blend.trusted_modulus;
  int evaluations = 0;
  std::shared_ptr<const MatrixModelData> model;
  const auto refinement_start = Clock::now();
  MeshRefinement fine = ClimbTheLadder(config, run.data, run.ends, run.model, stage.coarse_elements,
                                       own_start, stage.curvature, run.solution, max_evaluations,
                                       max_time, &evaluations, &stage.sweeps, &model);
  double modulus = fine.summary.modulus;
  if (fine.problem.empty() && coarse_blend.Blends()) {
    // Both treatments weigh in E* (docs/boundaries.md section 10): the other's E climbs
    // too, from its coarse E, without a coarse solution or curvature of its own.
    Config other = measured ? given : MeasuredSupportConfig(given);
    other.model.elements = fine_elements;
    std::shared_ptr<const MatrixModelData> other_model;
    const MeshRefinement other_fine = ClimbTheLadder(
        other, run.data, run.ends, run.model, stage.coarse_elements,
        measured ? coarse_blend.trusted_modulus : coarse_blend.measured_modulus, 0.0,
        CoupledSolution(), max_evaluations - evaluations,
        max_time - std::chrono::duration<double>(Clock::now() - refinement_start).count(),
        &evaluations, &stage.sweeps, &other_model);
    if (!other_fine.problem.empty()) {
      fine.problem = other_fine.problem;
    } else {
      run.support_blend.trusted_modulus = measured ? other_fine.summary.modulus : modulus;
      run.support_blend.measured_modulus = measured ? modulus : other_fine.summary.modulus;
      modulus = run.support_blend.Modulus();
    }
  }
  stage.refinement = fine.summary;
  stage.refinement.evaluations = evaluations;
  stage.refinement.wall_time_s =
      std::chrono::duration<double>(Clock::now() - refinement_start).count();

  // The run is the fine mesh's from here: E*, its solution, maps and channels.
  run.config = config;
  run.inner_method =
      ResolveCoupledSolverType(config.inner, fine_elements + 1.0, run.data.num_steps(), true);
  run.sweeps += stage.sweeps;
  run.outer.evaluations += evaluations;
  run.outer.gradient_evaluations += evaluations;
  run.outer.wall_time_s += stage.refinement.wall_time_s;
  if (!fine.problem.empty()) {
    run.outer.termination =
        fine.summary.IsSolutionUsable() ? TerminationType::kFailure : fine.summary.termination;
    run.outer.message = fine.problem;
    return run;
  }
  run.model = model;
  McreObjective& objective = *fine.objective;
  const std::size_t first = run.evaluations.size();
  run.evaluations.insert(run.evaluations.end(), objective.evaluations().begin(),
                         objective.evaluations().end());
  run.best_index = static_cast<int>(first) + objective.best_index();
  run.solution = objective.best_solution();
  run.outer.modulus = modulus;
  run.outer.cost = fine.summary.cost;
  run.outer.gradient = fine.summary.gradient;
  run.rest_cost = objective.rest_cost();
  if (run.evaluations[run.best_index].modulus != run.identified_modulus()) {
    SolveStageAt(run.identified_modulus(), "the coupled solve at the refined E", &objective, &run);
  }
  ReportAtIdentifiedModulus(config, &dynamic_cast<MatrixMcreProblem&>(objective.problem()), &run);
  run.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

}  // namespace

bool UsesCoarseMesh(const Config& config) {
  const CoupledSolverType inner = config.inner.type;
  return config.structure.kind == ModelKind::kBar &&
         config.outer.functional == OuterFunctional::kMcre && config.model.coarse_elements > 0 &&
         config.model.elements > config.model.coarse_elements &&
         (inner == CoupledSolverType::kAuto || inner == CoupledSolverType::kConjugateGradient ||
          inner == CoupledSolverType::kStreamingConjugateGradient);
}

IdentificationRun RunIdentification(const Config& given, const ChannelSet& data) {
  if (given.outer.functional == OuterFunctional::kLeastSquares) {
    return RunLeastSquares(given, data);
  }
  return UsesCoarseMesh(given) ? RunFromACoarseMesh(given, data) : RunOnOneMesh(given, data);
}

ZoneUncertainty BarZoneUncertainty(const Config& config, const IdentificationRun& run) {
  const ZoneIdentificationSummary& zones = run.zones.summary;
  const BarModel bar(config.model, run.zones.layout.ElementZones(config.model));
  const MatrixModelData model = BarRunModel(bar, run.data, run.ends);
  McreObjective objective =
      MatrixMcreObjective(model, run.data, config.mcre, config.time.theta, config.inner,
                          Factorization::kAutomatic, zones.homogeneous_modulus);
  // E*'s solution, on the same mesh, steps and channels: its shape is the zoned problem's.
  objective.SetWarmStart(run.solution.WarmStart());
  if (!objective.EvaluateModuli(zones.moduli, false).usable) {
    ZoneUncertainty unavailable;
    unavailable.message = "the coupled solve at the zone moduli is not usable";
    return unavailable;
  }
  return EstimateZoneUncertainty(config.uncertainty, model, run.data, config.mcre,
                                 config.time.theta, config.inner, zones.moduli,
                                 objective.last_solution(), run.noise);
}

ErrorMap BarErrorMap(const Config& config, const IdentificationRun& run,
                     MatrixMcreProblem* problem) {
  const BarModel model(config.model);
  // The shares, the picture and the sensitivities on the exported bar's elements, which
  // are the bar's: from the stored fields, or as the streaming solver summed and sampled
  // them while the fields passed. Its picture is the gap energy of an element [J], the
  // bar's per length [J/m].
  if (run.solution.has_fields()) {
    const ErrorMap elements =
        ComputeElementErrorMap(*run.model, Vector::Constant(1, run.identified_modulus()),
                               run.solution.retrograde, config.time.step);
    ErrorMap map =
        AssembleErrorMap(model, elements.share, elements.density / model.element_length(),
                         SpaceTimeStride(run.data.num_steps()), config.time.step);
    problem->SetModuli(Vector::Constant(1, run.identified_modulus()));
    problem->ElementSensitivities(run.solution.displacement, run.solution.retrograde,
                                  &map.sensitivity);
    return map;
  }
  ErrorMap map = AssembleErrorMap(model, run.solution.element_error_map,
                                  run.solution.gap_density / model.element_length(),
                                  SpaceTimeStride(run.data.num_steps()), config.time.step);
  map.sensitivity = run.solution.element_sensitivity;
  return map;
}

NoiseLevels MeasurementNoiseLevels(const Config& config, const ChannelSet& data,
                                   std::string* source) {
  if (!(config.data.source == DataSource::kSynthetic && std::isfinite(config.data.snr))) {
    *source = "data_differences";
    return DifferenceNoiseLevels(data);
  }
  NoiseLevels noise;
  const ChannelSet truth = SimulateTruth(config.model, config.load, config.time, config.data);
  // std = RMS(signal) / SNR (noise.h)
  noise.displacement_std = RootMeanSquare(truth.Values("uL")) / config.data.snr;
  noise.force_std = RootMeanSquare(truth.Values("fL")) / config.data.snr;
  // Strains: RMS over every strain channel / SNR (noise.h).
  noise.strain_std = StrainRms(truth) / config.data.snr;
  *source = "synthetic_snr";
  return noise;
}

NoiseLevels LeastSquaresMisfitLevels(const Config& config, const ChannelSet& data,
                                     const ChannelSet& used, std::string* source) {
  NoiseLevels levels = MeasurementNoiseLevels(config, data, source);
  // Noise-free data have no level to normalise by: the RMS of the channels instead
  // (only the ratio of the weights matters then, as in the comparator study).
  for (auto [level, rms] :
       {std::pair<double*, double>{&levels.displacement_std, RootMeanSquare(used.Values("uL"))},
        {&levels.force_std, RootMeanSquare(used.Values("fL"))},
        {&levels.strain_std, StrainRms(used)}}) {
    if (!(*level > 0.0) && rms > 0.0) {
      *level = rms;
      *source = "channel_rms";
    }
  }
  return levels;
}

IdentificationRun RunLeastSquares(const Config& config, const ChannelSet& data) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  IdentificationRun run;
  run.config = config;
  run.least_squares = true;
  run.reference_known = config.data.source == DataSource::kSynthetic;
  run.data = IdentificationData(config, data, &run.ends, &run.prefilter_cutoff);
  run.misfit_levels = LeastSquaresMisfitLevels(config, data, run.data, &run.misfit_source);
  run.estimated_noise = DifferenceNoiseLevels(data);
  run.model = std::make_shared<const MatrixModelData>(
      BarRunModel(BarModel(config.model), run.data, run.ends));
  OutputErrorModulusObjective objective(*run.model, run.data, run.misfit_levels, config.time.theta,
                                        config.outer.initial);
  // dJ/dE = sum_z dJ/dE_z as the zones' stage gets its gradient (1 + Z sweeps or 2).
  objective.SetGradientMethod(config.zone_identification.least_squares_gradient);
  run.rest_cost = objective.rest_cost();
  spdlog::info(
      "identifying E by output-error least squares with {}/{} from {:.6g} Pa in [{:.6g}, "
      "{:.6g}] Pa; misfit levels {:.4g} m, {:.4g} N ({})",
      OptimizerTypeToString(config.outer.optimizer),
      OuterAlgorithmToString(ResolveAlgorithm(config.outer.optimizer, config.outer.algorithm, 1)),
      config.outer.initial, config.outer.lower_bound, config.outer.upper_bound,
      run.misfit_levels.displacement_std, run.misfit_levels.force_std, run.misfit_source);
  run.outer = Identify(config.outer, &objective);
  spdlog::info("{}", run.outer.BriefReport());
  if (run.IsUsable()) {
    const double identified = run.identified_modulus();
    run.fit = objective.Predict(identified, true);
    // J(E) on output.curve_points moduli evenly spaced over E* +- 5 %.
    const int points = std::max(config.output.curve_points, 3);
    for (int i = 0; i < points; ++i) {
      const double modulus =
          identified * (1.0 - kCurvatureWindow + 2.0 * kCurvatureWindow * i / (points - 1.0));
      const OutputErrorFit& prediction = objective.Predict(modulus, true);
      CostCurvePoint point;
      point.modulus = modulus;
      point.cost = prediction.cost;
      point.cost_gradient = prediction.cost_gradient;
      point.usable = std::isfinite(prediction.cost) && std::isfinite(prediction.cost_gradient);
      run.cost_curve.push_back(point);
    }
    int curvature_points = 0;
    run.curvature =
        CostGradientSlope(run.cost_curve, identified, kCurvatureWindow, &curvature_points);
    // The Cramer-Rao bound 1 / sqrt(I), I the Fisher information at E* (OutputErrorFit).
    if (run.fit.fisher_information > 0.0) {
      run.modulus_std_bound = 1.0 / std::sqrt(run.fit.fisher_information);
    }
  }
  run.sweeps = objective.sweeps() + run.outer.scan_sweeps;
  if (run.IsUsable()) {
    run.zones = RunLeastSquaresZoneIdentification(config, IdentificationZoneLayout(config), run,
                                                  TruthZones(config));
  }
  run.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

std::string ModulusOnBoundMessage(double modulus, const IdentificationOptions& outer) {
  const std::pair<double, const char*> bounds[] = {{outer.lower_bound, "outer.lower_bound"},
                                                   {outer.upper_bound, "outer.upper_bound"}};
  for (const auto& [bound, key] : bounds) {
    if (std::abs(modulus - bound) <= kOnBoundTolerance * bound) {
      return "E = " + FormatNumber(modulus, kSixDigits) + " Pa lies on " + key + " (" +
             FormatNumber(bound, kSixDigits) +
             " Pa): e^2 has no minimum inside the bounds; widen them, or check the units of the "
             "data (SI: m and N)";
    }
  }
  return "";
}

std::string UnreportableMessage(const IdentificationRun& run) {
  if (!run.failure.empty()) return run.failure;
  if (!run.IsUsable()) return run.outer.message;
  if (run.config.structure.kind == ModelKind::kMatrix) return "";
  const std::string on_bound = ModulusOnBoundMessage(run.identified_modulus(), run.config.outer);
  if (!on_bound.empty() || run.least_squares) return on_bound;
  return ImplausibleMisfitMessage(run);
}

std::string ImplausibleMisfitMessage(const IdentificationRun& run) {
  const ChannelSet& data = run.data;
  // RMS over both ends: sqrt((|a|^2 + |b|^2) / (2 samples)).
  auto both_ends_rms = [&](const Vector& a, const Vector& b) {
    return std::sqrt((a.squaredNorm() + b.squaredNorm()) / (2.0 * data.num_samples()));
  };
  struct QuantityType {
    const char* name;
    const char* unit;
    double misfit;
    double measured;
  };
  const QuantityType types[] = {
      {"displacements", "m", run.misfit.displacement_std,
       both_ends_rms(data.Values("u0"), data.Values("uL"))},
      {"forces", "N", run.misfit.force_std, both_ends_rms(data.Values("f0"), data.Values("fL"))}};
  for (const QuantityType& type : types) {
    if (!(type.misfit <= kImplausibleMisfitFactor * type.measured)) {
      constexpr NumberFormat kFourDigits{NumberFormat::Notation::kSignificant, 4};
      constexpr NumberFormat kThreeDigits{NumberFormat::Notation::kSignificant, 3};
      return "at E = " + FormatNumber(run.identified_modulus(), kSixDigits) +
             " Pa the model misses the measured end " + type.name + " by an RMS of " +
             FormatNumber(type.misfit, kFourDigits) + " " + type.unit + ", " +
             FormatNumber(type.misfit / type.measured, kThreeDigits) + " times their own RMS (" +
             FormatNumber(type.measured, kFourDigits) + " " + type.unit +
             "): it explains nothing of them; check the units of the data (SI: m and N) and the "
             "model's geometry and density";
    }
  }
  return "";
}

}  // namespace mcrewave
