#include "mcrewave/mcre/objective.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

#include "mcrewave/optim/valley_spacing.h"

namespace mcrewave {

bool McreOptions::IsValid(std::string* error) const {
  if (!weights.IsValid(error)) return false;
  if (!(std::isfinite(reference_modulus) && reference_modulus > 0.0)) {
    std::ostringstream why;
    why << "mcre.reference_modulus must be a finite positive number of Pa, got "
        << reference_modulus;
    if (error != nullptr) *error = why.str();
    return false;
  }
  if (!(std::isfinite(support_check_threshold) && support_check_threshold > 0.0)) {
    std::ostringstream why;
    why << "mcre.support_check_threshold must be a finite positive number, got "
        << support_check_threshold;
    if (error != nullptr) *error = why.str();
    return false;
  }
  if (!(std::isfinite(support_check_ramp_start) && support_check_ramp_start > 0.0 &&
        support_check_ramp_start <= support_check_threshold)) {
    std::ostringstream why;
    why << "mcre.support_check_ramp_start must be a finite positive number no larger than "
           "mcre.support_check_threshold ("
        << support_check_threshold << "), got " << support_check_ramp_start
        << " (equal to it: a hard switch)";
    if (error != nullptr) *error = why.str();
    return false;
  }
  std::ostringstream why;
  const std::size_t loads = unmeasured_loads.size();
  for (std::size_t l = 0; l < loads && why.tellp() == 0; ++l) {
    if (unmeasured_loads[l].empty()) {
      why << "mcre.unmeasured_loads: entry " << l + 1 << " is empty; expected a load channel name";
    }
    for (std::size_t other = 0; other < l && why.tellp() == 0; ++other) {
      if (unmeasured_loads[other] == unmeasured_loads[l]) {
        why << "mcre.unmeasured_loads names '" << unmeasured_loads[l] << "' twice";
      }
    }
  }
  if (why.tellp() == 0 && !unmeasured_load_interval.empty() &&
      unmeasured_load_interval.size() != 2 * loads) {
    why << "mcre.unmeasured_load_interval has " << unmeasured_load_interval.size()
        << " times; expected none or 2 per unmeasured load (start, end [s]), " << 2 * loads
        << " for the " << loads << " of mcre.unmeasured_loads";
  }
  for (std::size_t l = 0; 2 * l + 1 < unmeasured_load_interval.size() && why.tellp() == 0; ++l) {
    const double start = unmeasured_load_interval[2 * l], end = unmeasured_load_interval[2 * l + 1];
    if (!(std::isfinite(start) && std::isfinite(end) && start <= end)) {
      why << "mcre.unmeasured_load_interval: the interval of '" << unmeasured_loads[l] << "' is ["
          << start << ", " << end << "] s; expected finite times, start <= end";
    }
  }
  if (why.tellp() != 0) {
    if (error != nullptr) *error = why.str();
    return false;
  }
  return true;
}

std::vector<UnmeasuredLoad> UnmeasuredLoads(const McreOptions& mcre) {
  std::vector<UnmeasuredLoad> loads;
  for (std::size_t l = 0; l < mcre.unmeasured_loads.size(); ++l) {
    UnmeasuredLoad load;
    load.channel = mcre.unmeasured_loads[l];
    if (!mcre.unmeasured_load_interval.empty()) {
      load.start = mcre.unmeasured_load_interval[2 * l];
      load.end = mcre.unmeasured_load_interval[2 * l + 1];
    }
    loads.push_back(load);
  }
  return loads;
}

bool SearchOptions::IsValid(std::string* error) const {
  const std::pair<const char*, double> weights[] = {{"search.w_u", displacement_weight},
                                                    {"search.w_e", strain_weight},
                                                    {"search.w_u0", clamp_displacement_weight},
                                                    {"search.w_r", reaction_weight}};
  std::ostringstream why;
  for (const auto& [key, weight] : weights) {
    if (!(std::isfinite(weight) && weight > 0.0)) {
      why << key << " must be a finite positive number, got " << weight;
      if (error != nullptr) *error = why.str();
      return false;
    }
  }
  if (!(inner_tolerance > 0.0 && inner_tolerance < 1.0)) {
    why << "search.inner_tolerance must lie in (0, 1), got " << inner_tolerance;
  } else if (scan_points < 3 || scan_points > 100000) {
    why << "search.scan_points must lie in [3, 100000], got " << scan_points;
  } else if (!(samples_per_valley == 0.0 ||
               (samples_per_valley >= 1.0 && samples_per_valley <= 100.0))) {
    why << "search.samples_per_valley must be 0 (outer.scan_samples_per_valley) or lie in "
           "[1, 100], got "
        << samples_per_valley;
  } else if (window_points < 3 || window_points > 100) {
    why << "search.window_points must lie in [3, 100], got " << window_points;
  } else if (!(refine_window > 0.0 && refine_window <= 0.5)) {
    why << "search.refine_window must lie in (0, 0.5], got " << refine_window;
  } else if (algorithm != OuterAlgorithm::kBobyqa && algorithm != OuterAlgorithm::kSecant) {
    why << "search.algorithm must be bobyqa or secant, got " << OuterAlgorithmToString(algorithm);
  } else if (!(relative_tolerance == 0.0 ||
               (relative_tolerance > 0.0 && relative_tolerance <= 0.1))) {
    why << "search.relative_tolerance must be 0 (outer.relative_tolerance) or lie in (0, 0.1], "
           "got "
        << relative_tolerance;
  } else if (time_step_factor < 1 || time_step_factor > 64) {
    why << "search.time_step_factor must lie in [1, 64], got " << time_step_factor;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

SearchRefinement SearchRefinementOf(const SearchOptions& search) {
  SearchRefinement refinement;
  refinement.algorithm = search.algorithm;
  refinement.relative_tolerance = search.relative_tolerance;
  refinement.samples_per_valley = search.samples_per_valley;
  refinement.window_points = search.window_points;
  return refinement;
}

McreOptions SearchMcreOptions(const McreOptions& mcre, const SearchOptions& search) {
  McreOptions options = mcre;
  options.clamp = search.functional == SearchFunctional::kMeasured ? ClampModel::kMeasured
                                                                   : ClampModel::kPinned;
  options.weights.displacement_weight = search.displacement_weight;
  options.weights.strain_weight = search.strain_weight;
  options.weights.clamp_displacement_weight = search.clamp_displacement_weight;
  options.weights.reaction_weight = search.reaction_weight;
  return options;
}

bool SearchIsTheObjective(const McreOptions& mcre, const SearchOptions& search,
                          bool model_has_supports) {
  const McreWeights& weights = mcre.weights;
  if (weights.displacement_weight != search.displacement_weight ||
      weights.strain_weight != search.strain_weight) {
    return false;
  }
  if (!model_has_supports) return true;
  if (search.functional == SearchFunctional::kMeasured) return mcre.clamp == ClampModel::kMeasured;
  return mcre.clamp == ClampModel::kPinned &&
         weights.clamp_displacement_weight == search.clamp_displacement_weight &&
         weights.reaction_weight == search.reaction_weight;
}

McreObjective::McreObjective(ProblemFactory make_problem, const CoupledSolverOptions& inner,
                             double modulus_scale)
    : make_problem_(std::move(make_problem)),
      problem_(make_problem_()),
      inner_(inner),
      given_tolerance_(inner.tolerance),
      modulus_scale_(modulus_scale) {
  assert(problem_ != nullptr && inner.IsValid(nullptr) && modulus_scale > 0.0);
  rest_cost_ = problem_->RestCost();
}

McreObjective MatrixMcreObjective(const MatrixModelData& model, const ChannelSet& data,
                                  const McreOptions& mcre, double theta,
                                  const CoupledSolverOptions& inner, Factorization factorization,
                                  double modulus_scale, bool element_maps) {
  assert(mcre.IsValid(nullptr) && modulus_scale >= 0.0);
  return McreObjective(
      [&model, &data, mcre, theta, factorization,
       element_maps]() -> std::unique_ptr<StreamingCoupledProblem> {
        auto problem = std::make_unique<MatrixMcreProblem>(
            model, data, mcre.weights, mcre.reference_modulus, theta, factorization, mcre.clamp,
            UnmeasuredLoads(mcre));
        problem->set_element_maps(element_maps);
        return problem;
      },
      inner, modulus_scale > 0.0 ? modulus_scale : mcre.reference_modulus);
}

std::unique_ptr<ModulusObjective> McreObjective::CloneForScan(double inner_tolerance) const {
  CoupledSolverOptions inner = inner_;
  inner.tolerance = inner_tolerance;
  return std::make_unique<McreObjective>(make_problem_, inner, modulus_scale_);
}

void McreObjective::StartAfresh() {
  warm_start_.resize(0, 0);
  warm_start_modulus_ = 0.0;
  warm_start_reference_norm_ = 0.0;
  previous_start_.resize(0, 0);
  previous_start_modulus_ = 0.0;
  inner_.tolerance = given_tolerance_;
  problem_->ForgetTracePreconditioner();
}

double McreObjective::ValleySpacing() {
  Matrix traces;
  problem_->DataResponseTraces(&traces);
  return PredictedValleySpacing(traces, problem_->TraceWeights(), problem_->time_step());
}

void McreObjective::SetWarmStart(const Matrix& start, double reference_residual_norm) {
  assert((start.rows() == problem_->num_nodes() || start.rows() == problem_->num_traces()) &&
         start.cols() == problem_->num_steps() + 1);
  warm_start_ = start;
  warm_start_modulus_ = 0.0;
  warm_start_reference_norm_ = std::max(reference_residual_norm, 0.0);
  previous_start_.resize(0, 0);
  previous_start_modulus_ = 0.0;
}

const ObjectiveEvaluation& McreObjective::EvaluateModulus(double modulus, bool gradient_requested) {
  assert(modulus > 0.0 && std::isfinite(modulus));
  problem_->SetModuli(Vector::Constant(problem_->num_zones(), modulus));
  const Matrix* initial = warm_start_.size() > 0 ? &warm_start_ : nullptr;
  if (initial != nullptr && previous_start_.size() > 0 &&
      previous_start_modulus_ != warm_start_modulus_) {
    // t = (E - E1) / (E1 - E0);  W^(0) = W(E1) + t (W(E1) - W(E0)).
    const double t =
        (modulus - warm_start_modulus_) / (warm_start_modulus_ - previous_start_modulus_);
    if (std::abs(t) <= kMaxExtrapolation) {
      initial_ = warm_start_ + t * (warm_start_ - previous_start_);
      initial = &initial_;
    }
  }
  return Solve(modulus, gradient_requested, initial);
}

const ObjectiveEvaluation& McreObjective::EvaluateModuli(const Vector& zone_moduli,
                                                         bool gradient_requested) {
  assert(zone_moduli.size() == problem_->num_zones() && zone_moduli.allFinite() &&
         zone_moduli.minCoeff() > 0.0);
  if (zone_moduli.minCoeff() == zone_moduli.maxCoeff()) {
    return EvaluateModulus(zone_moduli[0], gradient_requested);
  }
  problem_->SetModuli(zone_moduli);
  // From the last usable solution: no line to extrapolate along in several dimensions.
  return Solve(-1.0, gradient_requested, warm_start_.size() > 0 ? &warm_start_ : nullptr);
}

const ObjectiveEvaluation& McreObjective::Solve(double modulus, bool gradient_requested,
                                                const Matrix* initial) {
  ObjectiveEvaluation record;
  record.modulus = modulus;
  record.moduli = problem_->moduli();
  record.gradient_requested = gradient_requested;
  record.inner = SolveCoupled(inner_, problem_.get(), initial, &solution_,
                              initial != nullptr ? warm_start_reference_norm_ : 0.0);
  record.usable = record.inner.IsSolutionUsable();
  if (record.usable && record.inner.at_round_off_floor) {
    // The floor this problem's sweeps reach: later solves accept within kFloorMargin of it.
    inner_.tolerance =
        std::min(kMaxFloorTolerance * given_tolerance_,
                 std::max(inner_.tolerance, kFloorMargin * record.inner.relative_residual));
  }
  if (record.usable) {
    record.cost = solution_.cost;
    record.cost_gradient = solution_.cost_gradient;
    record.cost_gradients = solution_.cost_gradients;
    // The last two usable solutions; one set by SetWarmStart or at unequal zone moduli
    // (modulus unknown: 0) is not extrapolated from.
    if (warm_start_.size() > 0 && warm_start_modulus_ > 0.0 && modulus > 0.0) {
      previous_start_.swap(warm_start_);
      previous_start_modulus_ = warm_start_modulus_;
    } else {
      previous_start_.resize(0, 0);
    }
    warm_start_ = solution_.WarmStart();
    warm_start_modulus_ = modulus > 0.0 ? modulus : 0.0;
    warm_start_reference_norm_ = 0.0;
    if (best_index_ < 0 || record.cost < evaluations_[best_index_].cost) {
      best_index_ = static_cast<int>(evaluations_.size());
      best_solution_ = solution_;
    }
  }
  spdlog::debug(
      "e^2({:.9g} Pa) = {:.9g} J s, de^2/dE = {:.6g} J s/Pa; inner {} (from {:.3g})",
      record.moduli.mean(), record.cost, record.cost_gradient, record.inner.BriefReport(),
      record.inner.residual_history.empty() ? -1.0 : record.inner.residual_history.front());
  evaluations_.push_back(std::move(record));
  return evaluations_.back();
}

bool McreObjective::Evaluate(const double* parameters, double* cost, double* gradient) {
  double modulus = 0.0;
  if (!TrialModulus(parameters[0], modulus_scale_, &modulus, &error_message_)) return false;
  const ObjectiveEvaluation& record = EvaluateModulus(modulus, gradient != nullptr);
  if (!record.usable) {
    std::ostringstream why;
    why << "the coupled solve at E = " << modulus
        << " Pa is not usable: " << record.inner.BriefReport() << " (" << record.inner.message
        << ")";
    error_message_ = why.str();
    return false;
  }
  // cost = e^2 / J_rest
  *cost = record.cost / cost_scale();
  if (gradient != nullptr) {
    // d cost / dx = (de^2/dE) (dE/dx) / J_rest, dE/dx = modulus_scale
    gradient[0] = record.cost_gradient * modulus_scale_ / cost_scale();
  }
  return true;
}

ZoneMcreObjective::ZoneMcreObjective(McreObjective* objective, const Vector& reference_moduli)
    : LogModuliObjective(reference_moduli), objective_(objective) {
  assert(reference_moduli.size() == objective->problem().num_zones());
}

ZoneMcreObjective::ZoneMcreObjective(McreObjective* objective, double modulus_scale)
    : ZoneMcreObjective(objective,
                        Vector::Constant(objective->problem().num_zones(), modulus_scale)) {}

double ZoneMcreObjective::cost_scale() const { return objective_->cost_scale(); }

bool ZoneMcreObjective::ModuliCost(const Vector& moduli, double* cost, Vector* gradient,
                                   std::string* why) {
  const ObjectiveEvaluation& record = objective_->EvaluateModuli(moduli, gradient != nullptr);
  if (!record.usable) {
    *why = "the coupled solve at the zone moduli of evaluation " + std::to_string(evaluations()) +
           " is not usable: " + record.inner.BriefReport() + " (" + record.inner.message + ")";
    return false;
  }
  *cost = record.cost;
  if (gradient != nullptr) *gradient = record.cost_gradients;
  inner_report_ = record.inner.BriefReport();
  return true;
}

void ZoneMcreObjective::OnEvaluated(const Vector& moduli, double cost, double gradient_norm) {
  spdlog::info(
      "zones evaluation {}: e^2 / J_rest = {:.10g}, |grad|_inf = {:.3g}, E in [{:.6g}, "
      "{:.6g}] GPa; inner {}",
      evaluations(), cost, gradient_norm, moduli.minCoeff() * 1e-9, moduli.maxCoeff() * 1e-9,
      inner_report_);
}

}  // namespace mcrewave
