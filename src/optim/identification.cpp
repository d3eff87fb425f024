#include "mcrewave/optim/identification.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "core/enum_names.h"
#include "optim/identification_internal.h"

namespace mcrewave {
namespace {

using internal::FromName;
using internal::ToName;

constexpr std::array<std::pair<OptimizerType, const char*>, 2> kOptimizerTypes{{
    {OptimizerType::kNlopt, "nlopt"},
    {OptimizerType::kCeres, "ceres"},
}};

constexpr std::array<std::pair<OuterAlgorithm, const char*>, 8> kOuterAlgorithms{{
    {OuterAlgorithm::kDefault, "default"},
    {OuterAlgorithm::kBobyqa, "bobyqa"},
    {OuterAlgorithm::kCobyla, "cobyla"},
    {OuterAlgorithm::kSbplx, "sbplx"},
    {OuterAlgorithm::kMma, "mma"},
    {OuterAlgorithm::kLbfgs, "lbfgs"},
    {OuterAlgorithm::kBfgs, "bfgs"},
    {OuterAlgorithm::kBrent, "brent"},
}};

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
    case OuterAlgorithm::kBrent:
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
  } else if (scan_points > 0 && max_evaluations < scan_points + 2) {
    why << "outer.max_evaluations (" << max_evaluations << ") must exceed outer.scan_points ("
        << scan_points << ") by at least 2: the scan's evaluations count in it";
  } else if (!(max_time > 0.0)) {
    why << "outer.max_time must be a positive number of seconds, got " << max_time;
  } else if (!(scan_points == 0 || (scan_points >= 3 && scan_points <= 100000))) {
    why << "outer.scan_points must be 0 (no scan) or in [3, 100000], got " << scan_points;
  } else if (!(scan_tolerance > 0.0 && scan_tolerance < 1.0)) {
    why << "outer.scan_tolerance must lie in (0, 1), got " << scan_tolerance;
  } else if (!(scan_threads >= 1 && scan_threads <= 64)) {
    why << "outer.scan_threads must lie in [1, 64], got " << scan_threads;
  } else if (!(refine_candidates >= 1 && refine_candidates <= 100)) {
    why << "outer.refine_candidates must lie in [1, 100], got " << refine_candidates;
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
  if (!scan_moduli.empty()) {
    out << "; scan of " << scan_moduli.size() << " points saw " << local_minima
        << " local minima, scaled cost gap " << cost_gap;
  }
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
  if (!scan_moduli.empty()) {
    out << "  scan points            " << scan_moduli.size() << " over [" << scan_moduli.front()
        << ", " << scan_moduli.back() << "] Pa\n"
        << "  scan local minima      " << local_minima << "\n"
        << "  second minimum         " << second_modulus << " Pa\n"
        << "  scaled cost gap        " << cost_gap << "\n"
        << "  refinements            " << refinements << "\n"
        << "  scan sweeps            " << scan_sweeps << "\n"
        << "  scan wall time         " << scan_wall_time_s << " s\n";
  }
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
    } else if (usable && gradient != nullptr && !std::isfinite(*gradient)) {
      usable = false;
      stop_message_ = "the objective returned a non-finite gradient";
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
        "{} evaluation {}: E = {:.9g} Pa, cost e^2/J_rest {:.9g}, gradient {:.3e}; best E = {:.9g} "
        "Pa",
        OptimizerTypeToString(options_.optimizer), evaluations_, modulus, *cost, gradient[0],
        best_x_ * objective_->modulus_scale());
  } else {
    spdlog::info("{} evaluation {}: E = {:.9g} Pa, cost e^2/J_rest {:.9g}; best E = {:.9g} Pa",
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

namespace {

// One local search from options.initial within options' bounds.
IdentificationSummary MinimizeLocally(const IdentificationOptions& options,
                                      ModulusObjective* objective) {
  IdentificationSummary summary;
  summary.optimizer = options.optimizer;
  summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm);
  summary.initial_modulus = options.initial;
  internal::GuardedObjective guarded(options, objective);
  if (summary.algorithm == OuterAlgorithm::kBrent) {
    internal::MinimizeWithBrent(options, &guarded, &summary);
  } else if (options.optimizer == OptimizerType::kNlopt) {
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

// Scaled cost at x, NaN when the evaluation fails or throws (why written to
// *failure).
double ScanCost(ModulusObjective* objective, double x, std::string* failure) {
  double cost = std::numeric_limits<double>::quiet_NaN();
  try {
    if (!objective->Evaluate(&x, &cost, nullptr)) {
      *failure = objective->error_message();
      cost = std::numeric_limits<double>::quiet_NaN();
    } else if (!std::isfinite(cost)) {
      *failure = "the objective returned a non-finite cost";
      cost = std::numeric_limits<double>::quiet_NaN();
    }
  } catch (const std::exception& error) {
    *failure = std::string("the objective threw: ") + error.what();
    cost = std::numeric_limits<double>::quiet_NaN();
  } catch (...) {
    *failure = "the objective threw an exception that is not a std::exception";
    cost = std::numeric_limits<double>::quiet_NaN();
  }
  return cost;
}

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Scan points are split into this many contiguous chunks (fewer when there are
// fewer points), whatever the thread count, so that every cost is the same bits
// on 1 or 64 threads.
constexpr int kScanChunks = 8;

// The scaled costs at xs. The points form min(kScanChunks, P) contiguous chunks,
// chunk c = [c P / C, (c + 1) P / C); each chunk is evaluated in order by a fresh
// copy of the objective (CloneForScan), warm-started point to point from its own
// first point only, so a cost depends on its chunk and never on which thread ran
// it. Chunk c runs on thread c mod scan_threads. Without copies (CloneForScan
// gives none) every point is evaluated in order on `objective`. Samples not
// reached within options.max_time of `start` stay NaN. *first_failure: why the
// lowest failed sample failed; *sweeps: the inner sweeps the scan ran.
std::vector<double> ScanCosts(const IdentificationOptions& options, ModulusObjective* objective,
                              const std::vector<double>& xs, Clock::time_point start,
                              std::string* first_failure, long* sweeps) {
  const int points = static_cast<int>(xs.size());
  std::vector<double> costs(xs.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::string> failures(xs.size());
  auto scan_cost = [&](ModulusObjective* evaluated, int i) {
    if (SecondsSince(start) >= options.max_time) {
      failures[i] = "outer.max_time reached during the scan";
      return;
    }
    costs[i] = ScanCost(evaluated, xs[i], &failures[i]);
  };
  const int chunks = std::min(kScanChunks, points);
  const int threads = std::min(options.scan_threads, chunks);
  std::vector<long> thread_sweeps(threads, 0);
  std::vector<char> cloned(threads, 1);
  auto run_chunks = [&](int thread) {
    for (int c = thread; c < chunks; c += threads) {
      std::unique_ptr<ModulusObjective> copy = objective->CloneForScan(options.scan_tolerance);
      if (copy == nullptr) {
        cloned[thread] = 0;
        return;
      }
      for (int i = c * points / chunks; i < (c + 1) * points / chunks; ++i) {
        scan_cost(copy.get(), i);
      }
      thread_sweeps[thread] += copy->sweeps();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(run_chunks, t);
  run_chunks(0);
  for (std::thread& thread : pool) thread.join();
  *sweeps = 0;
  for (const long count : thread_sweeps) *sweeps += count;
  if (std::find(cloned.begin(), cloned.end(), 0) != cloned.end()) {
    // CloneForScan gives no copy (it gives one always or never): every point on `objective`.
    const long sweeps_before = objective->sweeps();
    for (int i = 0; i < points; ++i) scan_cost(objective, i);
    *sweeps = objective->sweeps() - sweeps_before;
  }
  for (const std::string& failure : failures) {
    if (!failure.empty()) {
      *first_failure = failure;
      break;
    }
  }
  return costs;
}

// Indices of the sampled local minima of costs, lowest cost first: usable
// samples below each neighbour (an end needs only its one neighbour). A failed
// (NaN) neighbour is no evidence of a minimum: a sample beside one is not listed.
std::vector<int> SampledMinima(const std::vector<double>& costs) {
  const int n = static_cast<int>(costs.size());
  std::vector<int> minima;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(costs[i])) continue;
    // Comparisons with NaN are false: a failed neighbour fails the test.
    const bool below_left = i == 0 || costs[i] < costs[i - 1];
    const bool below_right = i == n - 1 || costs[i] <= costs[i + 1];
    if (below_left && below_right) minima.push_back(i);
  }
  std::stable_sort(minima.begin(), minima.end(), [&](int a, int b) { return costs[a] < costs[b]; });
  return minima;
}

}  // namespace

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
  if (options.scan_points == 0) return MinimizeLocally(options, objective);

  const Clock::time_point start = Clock::now();
  const double scale = objective->modulus_scale();
  const double x_lower = options.lower_bound / scale;
  const double x_upper = options.upper_bound / scale;
  const int points = options.scan_points;
  std::vector<double> xs(points);
  for (int i = 0; i < points; ++i) {
    // x_i = x_lo (x_hi / x_lo)^(i / (P - 1)): evenly spaced in log E, so that
    // bounds over decades still get samples near every modulus.
    xs[i] = x_lower * std::pow(x_upper / x_lower, i / (points - 1.0));
  }
  std::string scan_failure;
  long scan_sweeps = 0;
  const std::vector<double> costs =
      ScanCosts(options, objective, xs, start, &scan_failure, &scan_sweeps);
  const std::vector<int> minima = SampledMinima(costs);
  const double scan_wall_time_s = SecondsSince(start);
  const int scan_failures = static_cast<int>(
      std::count_if(costs.begin(), costs.end(), [](double cost) { return !std::isfinite(cost); }));
  if (scan_failures > 0) {
    spdlog::warn("scan: {} of {} samples have no usable cost (first: {})", scan_failures, points,
                 scan_failure);
  }
  spdlog::info("scan of {} moduli over [{:.6g}, {:.6g}] Pa: {} sampled local minima, {:.3g} s",
               points, options.lower_bound, options.upper_bound, minima.size(), scan_wall_time_s);

  // Local refinements of the lowest sampled minima, each within the bracket of
  // its neighbouring scan points and with what the scan and the earlier
  // refinements left of max_evaluations and max_time.
  std::vector<IdentificationSummary> refined;
  std::string limit_message;
  // A refinement that failed leaves its valley unknown: no result is reported
  // over it, whatever the other refinements found.
  std::string refinement_failure;
  int evaluations_used = points;
  // Which limit stopped the search, in the user's terms.
  auto limit_reached = [&](const std::string& when) {
    std::ostringstream why;
    if (evaluations_used + 2 > options.max_evaluations) {
      why << "outer.max_evaluations (" << options.max_evaluations << ", the scan's " << points
          << " included) reached " << when;
    } else {
      why << "outer.max_time (" << options.max_time << " s) reached " << when;
    }
    return why.str();
  };
  const int candidates = std::min<int>(options.refine_candidates, static_cast<int>(minima.size()));
  for (int k = 0; k < candidates && limit_message.empty(); ++k) {
    const int i = minima[k];
    IdentificationOptions local = options;
    local.max_evaluations = options.max_evaluations - evaluations_used;
    local.max_time = options.max_time - SecondsSince(start);
    if (local.max_evaluations < 2 || !(local.max_time > 0.0)) {
      limit_message =
          limit_reached("before sampled minimum " + std::to_string(k + 1) + " was refined");
      break;
    }
    local.lower_bound = xs[std::max(i - 1, 0)] * scale;
    local.upper_bound = xs[std::min(i + 1, points - 1)] * scale;
    // Start at the sample, moved strictly inside the bracket at an end of the scan.
    const double width = local.upper_bound - local.lower_bound;
    local.initial = std::clamp(xs[i] * scale, local.lower_bound + 1e-3 * width,
                               local.upper_bound - 1e-3 * width);
    spdlog::info("refining sampled minimum {} at E = {:.6g} Pa within [{:.6g}, {:.6g}] Pa", k + 1,
                 xs[i] * scale, local.lower_bound, local.upper_bound);
    refined.push_back(MinimizeLocally(local, objective));
    evaluations_used += refined.back().evaluations;
    if (refined.back().termination == TerminationType::kNoConvergence) {
      limit_message = limit_reached("before convergence");
    }
    if (refined.back().termination == TerminationType::kFailure && refinement_failure.empty()) {
      std::ostringstream why;
      why << "the refinement of sampled minimum " << k + 1 << " (E = " << xs[i] * scale
          << " Pa) failed: " << refined.back().message;
      refinement_failure = why.str();
    }
  }

  // The usable refinement of least cost; the first refinement's failure if none is.
  int best = -1;
  for (int k = 0; k < static_cast<int>(refined.size()); ++k) {
    if (refined[k].IsSolutionUsable() && (best < 0 || refined[k].cost < refined[best].cost)) {
      best = k;
    }
  }
  if (best >= 0) {
    summary = refined[best];
  } else if (!refined.empty()) {
    summary = refined.front();
  } else if (scan_failures == points) {
    summary.termination = TerminationType::kFailure;
    summary.message = "no usable evaluation in the scan of the bounds: " + scan_failure;
  } else if (limit_message.empty()) {
    summary.termination = TerminationType::kFailure;
    summary.message = "the scan saw no minimum between usable samples (" +
                      std::to_string(scan_failures) + " of " + std::to_string(points) +
                      " samples failed; first: " + scan_failure + ")";
  }
  if (!refinement_failure.empty()) {
    summary.termination = TerminationType::kFailure;
    summary.message = refinement_failure;
  }
  if (SecondsSince(start) >= options.max_time && limit_message.empty() && refined.empty()) {
    limit_message = "outer.max_time reached during the scan of the bounds";
  }
  if (!limit_message.empty()) {
    // A limit reached is not convergence, whatever an earlier refinement found.
    summary.termination = TerminationType::kNoConvergence;
    summary.message = limit_message;
  }
  summary.initial_modulus = options.initial;
  summary.evaluations = 0;
  summary.gradient_evaluations = 0;
  for (const IdentificationSummary& local : refined) {
    summary.evaluations += local.evaluations;
    summary.gradient_evaluations += local.gradient_evaluations;
  }
  summary.refinements = static_cast<int>(refined.size());
  for (const double x : xs) summary.scan_moduli.push_back(x * scale);
  summary.scan_costs = costs;
  summary.scan_evaluations = points;
  summary.scan_sweeps = scan_sweeps;
  summary.scan_failures = scan_failures;
  summary.local_minima = static_cast<int>(minima.size());
  // The second valley: its refined cost when refined, else its sampled cost.
  if (minima.size() >= 2 && best >= 0) {
    double second_cost = std::numeric_limits<double>::infinity();
    for (int k = 0; k < static_cast<int>(minima.size()); ++k) {
      const bool was_refined = k < static_cast<int>(refined.size());
      if (k == best || (was_refined && !refined[k].IsSolutionUsable())) continue;
      const double cost = was_refined ? refined[k].cost : costs[minima[k]];
      const double modulus = was_refined ? refined[k].modulus : xs[minima[k]] * scale;
      if (cost < second_cost) {
        second_cost = cost;
        summary.second_modulus = modulus;
      }
    }
    if (std::isfinite(second_cost)) summary.cost_gap = second_cost - summary.cost;
  }
  summary.scan_wall_time_s = scan_wall_time_s;
  summary.wall_time_s = SecondsSince(start);
  return summary;
}

}  // namespace mcrewave
