#include "mcrewave/identification/zone_identification.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <utility>
#include <vector>

#include "mcrewave/core/format.h"
#include "mcrewave/core/random.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"

namespace mcrewave {

bool ZoneIdentificationOptions::IsValid(std::string* error) const {
  if (!minimizer.IsValid(error) || !regularization.IsValid(error)) return false;
  if (noise_samples < 1 || noise_samples > 1000) {
    if (error != nullptr) {
      *error = "zone_identification.noise_samples must be an integer in [1, 1000], got " +
               std::to_string(noise_samples);
    }
    return false;
  }
  if (regularization.floor_margin == FloorMargin::kNoiseFit && noise_samples < 2) {
    if (error != nullptr) {
      *error =
          "zone_identification.floor_margin noise_fit takes the noise's spread from its draws: "
          "set zone_identification.noise_samples to 2 or more (4 by default), or floor_margin "
          "to ten_percent";
    }
    return false;
  }
  if (!(start_modulus >= 0.0 && std::isfinite(start_modulus))) {
    if (error != nullptr) {
      *error =
          "zone_identification.start_modulus must be 0 (the homogeneous stage's E*) or a "
          "modulus [Pa], got " +
          std::to_string(start_modulus);
    }
    return false;
  }
  for (const double start : start_moduli) {
    if (!(start > 0.0 && std::isfinite(start))) {
      if (error != nullptr) {
        *error = "zone_identification.start_moduli must hold positive moduli [Pa], got " +
                 FormatNumber(start, kSixDigits);
      }
      return false;
    }
  }
  if (!start_moduli.empty() && start_modulus != 0.0) {
    if (error != nullptr) {
      *error =
          "zone_identification.start_moduli and start_modulus are both given: keep one (a "
          "modulus per zone, or one for every zone)";
    }
    return false;
  }
  return true;
}

std::string ZoneIdentificationSummary::BriefReport() const {
  std::ostringstream out;
  out << TerminationTypeToString(termination) << ": " << moduli.size() << " zones, "
      << (least_squares ? "J " : "e^2 ") << cost << (least_squares ? " s" : " J s")
      << " (homogeneous " << homogeneous_cost << "), weight " << regularized.weight << " ("
      << regularized.weight_choice << ")";
  if (merge.groups >= 0) out << ", " << merge.groups << " groups after merging";
  out << ", " << evaluations << " evaluations, " << wall_time_s << " s";
  return out.str();
}

std::string ZoneIdentificationSummary::FullReport() const {
  std::ostringstream out;
  out << "Zone identification\n"
      << "  termination:        " << TerminationTypeToString(termination) << "\n"
      << "  message:            " << message << "\n"
      << "  homogeneous E*:     " << homogeneous_modulus << " Pa (-1: the zones started apart)\n"
      << (least_squares ? "  J:                  " : "  e^2:                ") << cost
      << (least_squares ? " s" : " J s") << " (at the start: " << homogeneous_cost << ")\n"
      << "  weight:             " << regularized.weight << " (" << regularized.weight_choice
      << ", target misfit " << regularized.target_misfit << ", noise "
      << (least_squares ? "J" : "e^2") << " / J_rest " << noise_cost << ")\n";
  if (merge.groups >= 0) {
    out << "  merging:            " << merge.groups << " groups, " << merge.merges
        << " merges kept of " << merge.refits << " refits (" << merge.evaluations
        << " evaluations)\n";
  }
  out << "  evaluations:        " << evaluations << ", sweeps " << sweeps << "\n"
      << "  wall time:          " << wall_time_s << " s\n";
  for (Eigen::Index z = 0; z < moduli.size(); ++z) {
    out << "  zone " << z;
    if (static_cast<std::size_t>(z) < zone_start.size()) {
      out << " [" << zone_start[z] << ", " << zone_end[z] << "] m";
    }
    out << ": " << moduli[z] << " Pa (" << moduli[z] / start_moduli[z] << " of its start)\n";
  }
  out << regularized.minimizer.FullReport();
  return out.str();
}

namespace {

// `drawn` (a copy of the data) with every channel replaced by white noise at `noise`'s
// levels, then pre-filtered as `prefilter` says.
ChannelSet DrawNoiseAlone(const PrefilterOptions& prefilter, const NoiseLevels& noise,
                          StandardNormal* normal, ChannelSet* drawn) {
  DrawWhiteNoise(noise, normal, drawn);
  return prefilter.enabled ? PrefilterMeasurements(*drawn, prefilter) : *drawn;
}

// Records every evaluation of a zone objective into `history` and logs a line for each
// one that is not usable, naming the cost and why (the objective logs the usable ones).
class RecordingObjective : public FirstOrderObjective {
 public:
  RecordingObjective(LogModuliObjective* objective, const char* cost_name,
                     std::vector<ZoneEvaluation>* history)
      : objective_(objective), cost_name_(cost_name), history_(history) {}
  int num_parameters() const override { return objective_->num_parameters(); }
  bool Evaluate(const double* p, double* cost, double* gradient) override {
    ZoneEvaluation record;
    record.moduli = objective_->Moduli(p);
    record.usable = objective_->Evaluate(p, cost, gradient);
    record.cost = record.usable ? *cost : std::nan("");
    if (record.usable && gradient != nullptr) {
      record.gradient_norm = Eigen::Map<const Vector>(gradient, num_parameters()).norm();
    }
    history_->push_back(record);
    if (record.usable) return true;
    std::string moduli;
    for (int z = 0; z < record.moduli.size(); ++z) {
      moduli += (z == 0 ? "" : ", ") + fmt::format("{:.6g}", record.moduli[z] * 1e-9);
    }
    spdlog::info("evaluation {}: E = [{}] GPa, {} not usable ({})", history_->size(), moduli,
                 cost_name_, objective_->error_message());
    return false;
  }
  std::string error_message() const override { return objective_->error_message(); }

 private:
  LogModuliObjective* objective_;
  const char* cost_name_;
  std::vector<ZoneEvaluation>* history_;
};

}  // namespace

std::vector<ZonePair> ZoneNeighbours(const MatrixModelData& model) {
  // Every (a, b), a < b, once per dof that both zones' stiffness touches.
  std::vector<std::vector<int>> zones_of_dof(static_cast<std::size_t>(model.dofs()));
  for (std::size_t z = 0; z < model.zones.size(); ++z) {
    const SparseMatrix& stiffness = model.zones[z].stiffness;
    for (int column = 0; column < stiffness.outerSize(); ++column) {
      for (SparseMatrix::InnerIterator entry(stiffness, column); entry; ++entry) {
        if (entry.value() != 0.0) {
          zones_of_dof[static_cast<std::size_t>(column)].push_back(static_cast<int>(z));
          break;
        }
      }
    }
  }
  std::vector<std::pair<int, int>> shared;
  for (const std::vector<int>& zones : zones_of_dof) {
    for (std::size_t i = 0; i < zones.size(); ++i) {
      for (std::size_t j = i + 1; j < zones.size(); ++j) shared.emplace_back(zones[i], zones[j]);
    }
  }
  std::sort(shared.begin(), shared.end());
  std::vector<ZonePair> pairs;
  std::vector<int> counts;
  for (std::size_t k = 0; k < shared.size(); ++k) {
    if (k == 0 || shared[k] != shared[k - 1]) {
      pairs.push_back(ZonePair{shared[k].first, shared[k].second, 1.0});
      counts.push_back(0);
    }
    ++counts.back();
  }
  const int most = counts.empty() ? 1 : *std::max_element(counts.begin(), counts.end());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    pairs[k].weight = static_cast<double>(counts[k]) / most;
  }
  return pairs;
}

namespace {

// A start of e^2 / J_rest at most this is a minimum already: the admissible fields meet
// the data to a relative gap of 1e-10, round-off (noise-free data of the model at the
// start; BoundedMinimizerOptions::matched_cost).
constexpr double kMatchedRelativeCost = 1e-20;

// The steps both functionals share, on zone_objective (a function of p_z =
// log(E_z / E_z,ref), its cost scaled by summary->cost_scale, which the caller has set)
// from summary->start_moduli: the discrepancy target from expected_noise_cost() (the
// scaled cost of noise alone; negative: not usable) when the weight rule or the merging
// needs it, the regularised minimisation, the merging, and the moduli, cost and zones on
// a bound. When the target's noise cost is not usable the summary says so and nothing is
// minimised.
template <typename NoiseCost>
void MinimizeOverZones(const ZoneIdentificationOptions& options, const MatrixModelData& model,
                       LogModuliObjective* zone_objective, double lower_bound, double upper_bound,
                       NoiseCost&& expected_noise_cost, ZoneIdentificationSummary* summary) {
  const Vector& reference = zone_objective->reference_moduli();
  const int zones = static_cast<int>(reference.size());
  std::vector<double> lower(zones), upper(zones), initial(zones);
  for (int z = 0; z < zones; ++z) {
    lower[z] = std::log(lower_bound / reference[z]);
    upper[z] = std::log(upper_bound / reference[z]);
    initial[z] = std::log(summary->start_moduli[z] / reference[z]);
  }
  RecordingObjective recorder(zone_objective, summary->least_squares ? "J" : "e^2",
                              &summary->history);

  double target = -1.0;
  const bool automatic = options.regularization.kind != RegularizationKind::kNone &&
                         options.regularization.weight < 0.0;
  if (automatic || options.merge_zones) {
    summary->noise_cost = expected_noise_cost(&summary->noise_cost_std_dev);
    if (summary->noise_cost < 0.0) {
      summary->termination = TerminationType::kFailure;
      summary->message = summary->least_squares
                             ? "a noise simulation of the discrepancy target is not finite"
                             : "a noise solve of the discrepancy target is not usable";
      return;
    }
    target = options.regularization.discrepancy_factor * summary->noise_cost;
    spdlog::info(
        "zones: discrepancy target {} / J_rest = {:.6g} (noise alone, {} draws, standard "
        "deviation {:.3g})",
        summary->least_squares ? "J" : "e^2", target, options.noise_samples,
        summary->noise_cost_std_dev);
  }
  BoundedMinimizerOptions minimizer = options.minimizer;
  if (!summary->least_squares) minimizer.matched_cost = kMatchedRelativeCost;
  RegularizationOptions regularization = options.regularization;
  if (options.neighbours == ZoneNeighbourhood::kSharedNodes) {
    regularization.neighbours = ZoneNeighbours(model);
  }
  summary->regularized =
      MinimizeRegularized(minimizer, regularization, &recorder, lower, upper, initial, target,
                          options.regularization.discrepancy_factor * summary->noise_cost_std_dev);
  const RegularizedMinimization& result = summary->regularized;
  summary->termination = result.minimizer.termination;
  summary->message = result.minimizer.message;
  if (options.merge_zones && result.IsSolutionUsable()) {
    // The merges' target: the discrepancy target or, when no weight of the grid met it
    // (a draw whose noise cost lies above the mean the target is), the misfit floor's,
    // as the weight's own fallback.
    summary->merge = MergeNeighbouringZones(options.minimizer, &recorder, lower, upper, result.x,
                                            result.AttainableTarget());
    spdlog::info("zones: {} merge(s) kept in {} refits: {} groups", summary->merge.merges,
                 summary->merge.refits, summary->merge.groups);
  }
  const bool merged = !summary->merge.x.empty();
  const std::vector<double>& x = merged ? summary->merge.x : result.x;
  if (!x.empty()) {
    summary->moduli = zone_objective->Moduli(x.data());
    summary->cost = (merged ? summary->merge.misfit : result.misfit) * summary->cost_scale;
    for (int z = 0; z < zones; ++z) {
      if (std::abs(x[z] - lower[z]) < 1e-6 || std::abs(x[z] - upper[z]) < 1e-6) {
        summary->zones_on_bounds.push_back(z);
      }
    }
    if (!summary->zones_on_bounds.empty()) {
      spdlog::warn("zones: {} zone(s) on a bound of [outer.lower_bound, outer.upper_bound]",
                   summary->zones_on_bounds.size());
    }
  }
}

}  // namespace

void SetBarZoneExtents(const BarModel& model, ZoneIdentificationSummary* summary) {
  const int zones = model.num_zones();
  summary->zone_start.assign(zones, model.properties().length);
  summary->zone_end.assign(zones, 0.0);
  for (int e = 0; e < model.num_elements(); ++e) {
    const int z = model.element_zone(e);
    summary->zone_start[z] = std::min(summary->zone_start[z], model.node_position(e));
    summary->zone_end[z] = std::max(summary->zone_end[z], model.node_position(e + 1));
  }
}

namespace {

// The mean of the draws' costs / cost_scale; their sample standard deviation / cost_scale
// into *std_dev (when given; -1 with fewer than 2 draws).
double MeanOfDraws(const std::vector<double>& costs, double cost_scale, double* std_dev) {
  const auto n = static_cast<double>(costs.size());
  double mean = 0.0;
  for (double cost : costs) mean += cost;
  mean /= n;
  if (std_dev != nullptr && costs.size() >= 2) {
    // s = sqrt(sum_k (c_k - mean)^2 / (n - 1)), the unbiased variance's root
    double squares = 0.0;
    for (double cost : costs) squares += (cost - mean) * (cost - mean);
    *std_dev = std::sqrt(squares / (n - 1.0)) / cost_scale;
  }
  return mean / cost_scale;
}

}  // namespace

double ExpectedNoiseCost(const MatrixModelData& model, const ChannelSet& data,
                         const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
                         const Vector& moduli, const NoiseLevels& noise,
                         const PrefilterOptions& prefilter, int samples, std::uint64_t seed,
                         double cost_scale, double* std_dev) {
  if (std_dev != nullptr) *std_dev = -1.0;
  StandardNormal normal(seed);
  ChannelSet drawn = data;
  std::vector<double> costs;
  for (int sample = 0; sample < samples; ++sample) {
    const ChannelSet noise_data = DrawNoiseAlone(prefilter, noise, &normal, &drawn);
    McreObjective objective = MatrixMcreObjective(model, noise_data, mcre, theta, inner,
                                                  Factorization::kAutomatic, moduli[0]);
    const ObjectiveEvaluation& record = objective.EvaluateModuli(moduli, false);
    if (!record.usable) return -1.0;
    costs.push_back(record.cost);
  }
  return MeanOfDraws(costs, cost_scale, std_dev);
}

double ExpectedLeastSquaresNoiseCost(const MatrixModelData& model, const ChannelSet& data,
                                     const NoiseLevels& misfit_levels, double theta,
                                     const Vector& moduli, const NoiseLevels& noise,
                                     const PrefilterOptions& prefilter, int samples,
                                     std::uint64_t seed, double cost_scale, double* std_dev) {
  if (std_dev != nullptr) *std_dev = -1.0;
  StandardNormal normal(seed);
  ChannelSet drawn = data;
  std::vector<double> costs;
  for (int sample = 0; sample < samples; ++sample) {
    const ChannelSet noise_data = DrawNoiseAlone(prefilter, noise, &normal, &drawn);
    MatrixOutputErrorObjective objective(model, noise_data, misfit_levels, theta,
                                         Factorization::kAutomatic, moduli[0]);
    costs.push_back(objective.Cost(moduli, nullptr));
    if (!std::isfinite(costs.back())) return -1.0;
  }
  return MeanOfDraws(costs, cost_scale, std_dev);
}

namespace {

// The frame both functionals' identifications share: the summary's start (functional,
// start moduli, noise levels), then `identify` (the objective, the cost scale and
// MinimizeOverZones into the summary), its exception a failure of the summary, and the
// wall time.
template <typename Identify>
ZoneIdentificationSummary IdentifyZones(const Vector& start_moduli, const NoiseLevels& noise,
                                        bool least_squares, Identify&& identify) {
  const auto start = std::chrono::steady_clock::now();
  ZoneIdentificationSummary summary;
  summary.least_squares = least_squares;
  summary.start_moduli = start_moduli;
  if (start_moduli.size() > 0 && (start_moduli.array() == start_moduli[0]).all()) {
    summary.homogeneous_modulus = start_moduli[0];
  }
  summary.noise = noise;
  try {
    identify(&summary);
  } catch (const std::exception& error) {
    summary.termination = TerminationType::kFailure;
    summary.message = std::string(least_squares ? "the least-squares zone identification failed: "
                                                : "the zone identification failed: ") +
                      error.what();
  }
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

// IdentifyZoneModuli's steps on `objective` into *summary (its start set).
void IdentifyOnMcreObjective(const ZoneIdentificationOptions& options, const MatrixModelData& model,
                             const ChannelSet& data, const McreOptions& mcre, double theta,
                             const CoupledSolverOptions& inner, McreObjective* objective,
                             const Vector& reference_moduli, double lower_bound, double upper_bound,
                             const PrefilterOptions& prefilter,
                             ZoneIdentificationSummary* summary) {
  const std::size_t first = objective->evaluations().size();
  const long sweeps_before = objective->sweeps();
  summary->cost_scale = objective->cost_scale();
  ZoneMcreObjective zone_objective(objective, reference_moduli);
  MinimizeOverZones(
      options, model, &zone_objective, lower_bound, upper_bound,
      [&](double* std_dev) {
        return ExpectedNoiseCost(model, data, mcre, theta, inner, summary->start_moduli,
                                 summary->noise, prefilter, options.noise_samples,
                                 options.noise_seed, summary->cost_scale, std_dev);
      },
      summary);
  if (objective->evaluations().size() > first && objective->evaluations()[first].usable) {
    summary->homogeneous_cost = objective->evaluations()[first].cost;
  }
  summary->evaluations = zone_objective.evaluations();
  summary->sweeps = objective->sweeps() - sweeps_before;
}

// From this many zones on, least squares by forward sensitivities says that the adjoint
// is cheaper (1 + Z sweeps an evaluation against 2).
constexpr int kManyZones = 16;

// IdentifyZoneModuliByLeastSquares's steps on `objective` into *summary (its start set),
// its gradient by options.least_squares_gradient.
void IdentifyOnOutputError(const ZoneIdentificationOptions& options, const MatrixModelData& model,
                           const ChannelSet& data, const NoiseLevels& misfit_levels, double theta,
                           MatrixOutputErrorObjective* objective, double lower_bound,
                           double upper_bound, const PrefilterOptions& prefilter,
                           ZoneIdentificationSummary* summary) {
  objective->SetGradientMethod(options.least_squares_gradient);
  const int zones = objective->num_parameters();
  if (options.least_squares_gradient == LeastSquaresGradient::kForwardSensitivities &&
      zones >= kManyZones) {
    spdlog::info(
        "least squares on {} zones: the gradient by forward sensitivities costs {} sweeps an "
        "evaluation; zone_identification.least_squares_gradient: adjoint costs 2",
        zones, 1 + zones);
  }
  const int evaluations_before = objective->evaluations();
  const long sweeps_before = objective->sweeps();
  summary->cost_scale = objective->cost_scale();
  summary->homogeneous_cost = objective->Cost(summary->start_moduli, nullptr);
  MinimizeOverZones(
      options, model, objective, lower_bound, upper_bound,
      [&](double* std_dev) {
        return ExpectedLeastSquaresNoiseCost(
            model, data, misfit_levels, theta, summary->start_moduli, summary->noise, prefilter,
            options.noise_samples, options.noise_seed, summary->cost_scale, std_dev);
      },
      summary);
  summary->evaluations = objective->evaluations() - evaluations_before;
  summary->sweeps = objective->sweeps() - sweeps_before;
}

}  // namespace

ZoneIdentificationSummary IdentifyZoneModuli(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
    double homogeneous_modulus, double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter, const Matrix* warm_start) {
  const Vector start = Vector::Constant(static_cast<int>(model.zones.size()), homogeneous_modulus);
  return IdentifyZones(start, noise, false, [&](ZoneIdentificationSummary* summary) {
    McreObjective objective = MatrixMcreObjective(model, data, mcre, theta, inner,
                                                  Factorization::kAutomatic, homogeneous_modulus);
    const StreamingCoupledProblem& problem = objective.problem();
    if (warm_start != nullptr && warm_start->cols() == problem.num_steps() + 1 &&
        (warm_start->rows() == problem.num_nodes() || warm_start->rows() == problem.num_traces())) {
      objective.SetWarmStart(*warm_start);
    }
    IdentifyOnMcreObjective(options, model, data, mcre, theta, inner, &objective, start,
                            lower_bound, upper_bound, prefilter, summary);
  });
}

ZoneIdentificationSummary IdentifyZoneModuli(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const McreOptions& mcre, double theta, const CoupledSolverOptions& inner,
    McreObjective* objective, const Vector& reference_moduli, const Vector& start_moduli,
    double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter) {
  return IdentifyZones(start_moduli, noise, false, [&](ZoneIdentificationSummary* summary) {
    IdentifyOnMcreObjective(options, model, data, mcre, theta, inner, objective, reference_moduli,
                            lower_bound, upper_bound, prefilter, summary);
  });
}

ZoneIdentificationSummary IdentifyZoneModuliByLeastSquares(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const NoiseLevels& misfit_levels, double theta, double homogeneous_modulus, double lower_bound,
    double upper_bound, const NoiseLevels& noise, const PrefilterOptions& prefilter) {
  const Vector start = Vector::Constant(static_cast<int>(model.zones.size()), homogeneous_modulus);
  return IdentifyZones(start, noise, true, [&](ZoneIdentificationSummary* summary) {
    MatrixOutputErrorObjective objective(model, data, misfit_levels, theta,
                                         Factorization::kAutomatic, homogeneous_modulus);
    IdentifyOnOutputError(options, model, data, misfit_levels, theta, &objective, lower_bound,
                          upper_bound, prefilter, summary);
  });
}

ZoneIdentificationSummary IdentifyZoneModuliByLeastSquares(
    const ZoneIdentificationOptions& options, const MatrixModelData& model, const ChannelSet& data,
    const NoiseLevels& misfit_levels, double theta, MatrixOutputErrorObjective* objective,
    const Vector& start_moduli, double lower_bound, double upper_bound, const NoiseLevels& noise,
    const PrefilterOptions& prefilter) {
  return IdentifyZones(start_moduli, noise, true, [&](ZoneIdentificationSummary* summary) {
    IdentifyOnOutputError(options, model, data, misfit_levels, theta, objective, lower_bound,
                          upper_bound, prefilter, summary);
  });
}

}  // namespace mcrewave
