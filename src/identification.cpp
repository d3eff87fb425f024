#include "mcrewave/identification.h"

#include <spdlog/spdlog.h>

#include <array>
#include <cmath>
#include <exception>
#include <sstream>
#include <utility>

#include "identification_internal.h"

namespace mcrewave {
namespace {

constexpr std::array<std::pair<OptimizerType, const char*>, 2> kOptimizerTypes{{
    {OptimizerType::kNlopt, "nlopt"},
    {OptimizerType::kCeres, "ceres"},
}};

constexpr std::array<std::pair<OuterAlgorithm, const char*>, 7> kOuterAlgorithms{{
    {OuterAlgorithm::kDefault, "default"},
    {OuterAlgorithm::kBobyqa, "bobyqa"},
    {OuterAlgorithm::kCobyla, "cobyla"},
    {OuterAlgorithm::kSbplx, "sbplx"},
    {OuterAlgorithm::kMma, "mma"},
    {OuterAlgorithm::kLbfgs, "lbfgs"},
    {OuterAlgorithm::kBfgs, "bfgs"},
}};

template <typename Enum, std::size_t N>
const char* ToName(const std::array<std::pair<Enum, const char*>, N>& table, Enum value) {
  for (const auto& [v, name] : table) {
    if (v == value) return name;
  }
  return "unknown";
}

template <typename Enum, std::size_t N>
bool FromName(const std::array<std::pair<Enum, const char*>, N>& table, const std::string& name,
              Enum* value) {
  for (const auto& [v, n] : table) {
    if (name == n) {
      *value = v;
      return true;
    }
  }
  return false;
}

// "a, b or c": the algorithms the optimiser offers, for messages.
std::string AvailableAlgorithms(OptimizerType optimizer) {
  std::vector<std::string> names;
  for (const auto& [algorithm, name] : kOuterAlgorithms) {
    if (IsAlgorithmAvailable(optimizer, algorithm)) names.push_back(name);
  }
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + names[i];
  }
  return text;
}

}  // namespace

const char* OptimizerTypeToString(OptimizerType type) { return ToName(kOptimizerTypes, type); }
bool StringToOptimizerType(const std::string& name, OptimizerType* type) {
  return FromName(kOptimizerTypes, name, type);
}
const char* OuterAlgorithmToString(OuterAlgorithm algorithm) {
  return ToName(kOuterAlgorithms, algorithm);
}
bool StringToOuterAlgorithm(const std::string& name, OuterAlgorithm* algorithm) {
  return FromName(kOuterAlgorithms, name, algorithm);
}

bool IsAlgorithmAvailable(OptimizerType optimizer, OuterAlgorithm algorithm) {
  switch (algorithm) {
    case OuterAlgorithm::kDefault:
    case OuterAlgorithm::kLbfgs:
      return true;
    case OuterAlgorithm::kBobyqa:
    case OuterAlgorithm::kCobyla:
    case OuterAlgorithm::kSbplx:
    case OuterAlgorithm::kMma:
      return optimizer == OptimizerType::kNlopt;
    case OuterAlgorithm::kBfgs:
      return optimizer == OptimizerType::kCeres;
  }
  return false;
}

OuterAlgorithm ResolveAlgorithm(OptimizerType optimizer, OuterAlgorithm algorithm) {
  if (algorithm != OuterAlgorithm::kDefault) return algorithm;
  return optimizer == OptimizerType::kNlopt ? OuterAlgorithm::kBobyqa : OuterAlgorithm::kLbfgs;
}

bool UsesGradient(OptimizerType optimizer, OuterAlgorithm algorithm) {
  switch (ResolveAlgorithm(optimizer, algorithm)) {
    case OuterAlgorithm::kMma:
    case OuterAlgorithm::kLbfgs:
    case OuterAlgorithm::kBfgs:
      return true;
    default:
      return false;
  }
}

bool IdentificationOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(std::isfinite(lower_bound) && lower_bound > 0.0)) {
    why << "outer.lower_bound must be a finite positive modulus in Pa, got " << lower_bound;
  } else if (!(std::isfinite(upper_bound) && upper_bound > lower_bound)) {
    why << "outer.upper_bound (" << upper_bound << " Pa) must be finite and above "
        << "outer.lower_bound (" << lower_bound << " Pa)";
  } else if (!(initial > lower_bound && initial < upper_bound)) {
    why << "outer.initial (" << initial << " Pa) must lie strictly between outer.lower_bound ("
        << lower_bound << " Pa) and outer.upper_bound (" << upper_bound << " Pa)";
  } else if (!(relative_tolerance > 0.0 && relative_tolerance < 0.1)) {
    why << "outer.relative_tolerance must lie in (0, 0.1), got " << relative_tolerance;
  } else if (max_evaluations < 2) {
    why << "outer.max_evaluations must be at least 2, got " << max_evaluations;
  } else if (!(max_time > 0.0)) {
    why << "outer.max_time must be a positive number of seconds, got " << max_time;
  } else if (!IsAlgorithmAvailable(optimizer, algorithm)) {
    why << "outer.algorithm '" << OuterAlgorithmToString(algorithm)
        << "' is not available with outer.optimizer '" << OptimizerTypeToString(optimizer)
        << "'; choose " << AvailableAlgorithms(optimizer);
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

std::string IdentificationSummary::BriefReport() const {
  std::ostringstream out;
  out << OptimizerTypeToString(optimizer) << "/" << OuterAlgorithmToString(algorithm) << ": "
      << TerminationTypeToString(termination) << ", E = " << modulus << " Pa after " << evaluations
      << " evaluations (" << gradient_evaluations << " with gradient), " << wall_time_s << " s";
  return out.str();
}

std::string IdentificationSummary::FullReport() const {
  std::ostringstream out;
  out << "Outer loop (identification of E)\n"
      << "  optimizer              " << OptimizerTypeToString(optimizer) << "\n"
      << "  algorithm              " << OuterAlgorithmToString(algorithm) << "\n"
      << "  termination            " << TerminationTypeToString(termination) << "\n"
      << "  message                " << message << "\n"
      << "  optimizer message      " << optimizer_message << "\n"
      << "  initial modulus        " << initial_modulus << " Pa\n"
      << "  identified modulus     " << modulus << " Pa\n"
      << "  scaled cost            " << cost << "\n"
      << "  evaluations            " << evaluations << "\n"
      << "  with gradient          " << gradient_evaluations << "\n";
  if (iterations >= 0) out << "  iterations             " << iterations << "\n";
  out << "  wall time              " << wall_time_s << " s\n";
  return out.str();
}

namespace internal {

GuardedObjective::GuardedObjective(const IdentificationOptions& options,
                                   ModulusObjective* objective)
    : options_(options), objective_(objective), start_(std::chrono::steady_clock::now()) {}

double GuardedObjective::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool GuardedObjective::Evaluate(double x, double* cost, double* gradient) {
  if (stop_ != StopReason::kNone) return false;
  if (evaluations_ >= options_.max_evaluations) {
    stop_ = StopReason::kEvaluationLimit;
    stop_message_ = "outer.max_evaluations (" + std::to_string(options_.max_evaluations) +
                    ") reached before convergence";
    return false;
  }
  if (ElapsedSeconds() >= options_.max_time) {
    std::ostringstream why;
    why << "outer.max_time (" << options_.max_time << " s) reached before convergence";
    stop_ = StopReason::kTimeLimit;
    stop_message_ = why.str();
    return false;
  }
  ++evaluations_;
  if (gradient != nullptr) ++gradient_evaluations_;
  const double modulus = x * objective_->modulus_scale();
  bool usable = false;
  try {
    usable = objective_->Evaluate(&x, cost, gradient);
    if (usable && !std::isfinite(*cost)) {
      usable = false;
      stop_message_ = "the objective returned a non-finite cost";
    } else if (!usable) {
      stop_message_ = objective_->error_message();
    }
  } catch (const std::exception& error) {
    stop_message_ = std::string("the objective threw: ") + error.what();
  } catch (...) {
    stop_message_ = "the objective threw an exception that is not a std::exception";
  }
  if (!usable) {
    stop_ = StopReason::kFailure;
    spdlog::info("{} evaluation {}: E = {:.9g} Pa failed: {}",
                 OptimizerTypeToString(options_.optimizer), evaluations_, modulus, stop_message_);
    return false;
  }
  if (!has_best_ || *cost < best_cost_) {
    has_best_ = true;
    best_x_ = x;
    best_cost_ = *cost;
    best_has_gradient_ = gradient != nullptr;
    best_gradient_ = gradient != nullptr ? gradient[0] : 0.0;
  }
  if (gradient != nullptr) {
    spdlog::info(
        "{} evaluation {}: E = {:.9g} Pa, cost {:.9g}, gradient {:.3e}; best E = {:.9g} Pa",
        OptimizerTypeToString(options_.optimizer), evaluations_, modulus, *cost, gradient[0],
        best_x_ * objective_->modulus_scale());
  } else {
    spdlog::info("{} evaluation {}: E = {:.9g} Pa, cost {:.9g}; best E = {:.9g} Pa",
                 OptimizerTypeToString(options_.optimizer), evaluations_, modulus, *cost,
                 best_x_ * objective_->modulus_scale());
  }
  return true;
}

void GuardedObjective::ReportStop(IdentificationSummary* summary) const {
  summary->termination =
      stop_ == StopReason::kFailure ? TerminationType::kFailure : TerminationType::kNoConvergence;
  summary->message = stop_message_;
}

void GuardedObjective::FillSummary(IdentificationSummary* summary) const {
  summary->evaluations = evaluations_;
  summary->gradient_evaluations = gradient_evaluations_;
  if (has_best_) {
    summary->modulus = best_x_ * objective_->modulus_scale();
    summary->cost = best_cost_;
    summary->gradient = best_has_gradient_ ? best_gradient_ : 0.0;
  }
  summary->wall_time_s = ElapsedSeconds();
}

}  // namespace internal

IdentificationSummary Identify(const IdentificationOptions& options, ModulusObjective* objective) {
  IdentificationSummary summary;
  summary.optimizer = options.optimizer;
  summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm);
  summary.initial_modulus = options.initial;
  std::string why;
  if (!options.IsValid(&why)) {
    summary.message = "invalid options: " + why;
    return summary;
  }
  internal::GuardedObjective guarded(options, objective);
  if (options.optimizer == OptimizerType::kNlopt) {
    internal::MinimizeWithNlopt(options, &guarded, &summary);
  } else {
    internal::MinimizeWithCeres(options, &guarded, &summary);
  }
  guarded.FillSummary(&summary);
  if (!guarded.has_best() && summary.termination == TerminationType::kConvergence) {
    summary.termination = TerminationType::kFailure;
    summary.message = "no usable evaluation of the objective";
  }
  return summary;
}

}  // namespace mcrewave
