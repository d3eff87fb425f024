#include "mcrewave/optim/identification.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cassert>
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
#include "mcrewave/core/interrupt.h"
#include "optim/identification_internal.h"

namespace mcrewave {

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
  } else if (!(scan_samples_per_valley == 0.0 ||
               (scan_samples_per_valley >= 1.0 && scan_samples_per_valley <= 100.0))) {
    why << "outer.scan_samples_per_valley must be 0 (the scan_points grid alone) or in [1, 100], "
        << "got " << scan_samples_per_valley;
  } else if (!(scan_max_points >= std::max(scan_points, 3) && scan_max_points <= 100000)) {
    why << "outer.scan_max_points must lie in [outer.scan_points (" << scan_points
        << "), 100000], got " << scan_max_points;
  } else if (!(scan_tolerance > 0.0 && scan_tolerance < 1.0)) {
    why << "outer.scan_tolerance must lie in (0, 1), got " << scan_tolerance;
  } else if (!(scan_threads >= 1 && scan_threads <= 64)) {
    why << "outer.scan_threads must lie in [1, 64], got " << scan_threads;
  } else if (!(refine_margin >= 0.0 && refine_margin <= 10.0)) {
    why << "outer.refine_margin must lie in [0, 10], got " << refine_margin;
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
  if (search_modulus > 0.0) out << "; search functional's E = " << search_modulus << " Pa";
  if (!scan_moduli.empty()) {
    out << "; scan " << (scan_of_search ? "of the search functional " : "") << "of "
        << scan_moduli.size() << " points saw " << local_minima << " valleys (" << refinements
        << " refined)";
    if (std::isnan(cost_gap)) {
      out << ", no second valley";
    } else {
      out << ", scaled cost gap to the second " << cost_gap;
    }
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
  if (search_modulus > 0.0) {
    out << "  search modulus         " << search_modulus << " Pa (the search functional's)\n"
        << "  scan of the search     " << (scan_of_search ? "yes" : "no (the objective's own)")
        << "\n";
  }
  if (!scan_moduli.empty()) {
    out << "  scan points            " << scan_moduli.size() << " over [" << scan_moduli.front()
        << ", " << scan_moduli.back() << "] Pa\n"
        << "  predicted valley step  " << predicted_valley_spacing << " in ln E\n"
        << "  resolution limited     " << (scan_resolution_limited ? "yes" : "no") << "\n"
        << "  valleys                " << local_minima << "\n";
    if (std::isnan(cost_gap)) {
      out << "  second minimum         none (no second valley)\n";
    } else {
      out << "  second minimum         " << second_modulus << " Pa\n"
          << "  scaled cost gap        " << cost_gap << "\n";
    }
    out << "  refinements            " << refinements << "\n"
        << "  scan sweeps            " << scan_sweeps << "\n"
        << "  scan wall time         " << scan_wall_time_s << " s\n";
  }
  for (const ScanValley& valley : valleys) {
    out << "    valley in [" << valley.lower_modulus << ", " << valley.upper_modulus
        << "] Pa: estimate " << valley.estimated_modulus << " Pa, cost " << valley.estimated_cost;
    if (valley.refined) {
      out << "; refined " << valley.modulus << " Pa, cost " << valley.cost << " ("
          << TerminationTypeToString(valley.termination) << ", " << valley.evaluations
          << " evaluations)";
    }
    out << "\n";
  }
  if (iterations >= 0) out << "  iterations             " << iterations << "\n";
  out << "  wall time              " << wall_time_s << " s\n";
  return out.str();
}

namespace {

// The progress line of one evaluation of the local search at E = modulus [Pa] (cost null:
// it failed).
void LogEvaluation(const char* optimizer, const internal::GuardedObjective& guard, double modulus,
                   const double* cost, const double* gradient, double scale) {
  if (cost == nullptr) {
    spdlog::info("{} evaluation {}: E = {:.9g} Pa failed: {}", optimizer, guard.evaluations(),
                 modulus, guard.stop_message());
  } else if (gradient != nullptr) {
    spdlog::info(
        "{} evaluation {}: E = {:.9g} Pa, cost e^2/J_rest {:.9g}, gradient {:.3e}; best E = {:.9g} "
        "Pa",
        optimizer, guard.evaluations(), modulus, *cost, gradient[0], guard.best_x()[0] * scale);
  } else {
    spdlog::info("{} evaluation {}: E = {:.9g} Pa, cost e^2/J_rest {:.9g}; best E = {:.9g} Pa",
                 optimizer, guard.evaluations(), modulus, *cost, guard.best_x()[0] * scale);
  }
}

// One local search from options.initial within options' bounds. curvature: an
// estimate of d^2 cost / dx^2 near the start (0: unknown), for the step scale of
// Ceres and of NLopt's gradient methods.
IdentificationSummary MinimizeLocally(const IdentificationOptions& options,
                                      ModulusObjective* objective, double curvature = 0.0) {
  IdentificationSummary summary;
  summary.optimizer = options.optimizer;
  summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm, 1);
  summary.initial_modulus = options.initial;
  const double scale = objective->modulus_scale();
  internal::GuardedObjective guarded(objective,
                                     {options.max_evaluations, options.max_time, "outer"});
  guarded.set_observer([&options, scale](const internal::GuardedObjective& guard, const double* x,
                                         const double* cost, const double* gradient) {
    LogEvaluation(OptimizerTypeToString(options.optimizer), guard, x[0] * scale, cost, gradient,
                  scale);
  });
  if (summary.algorithm == OuterAlgorithm::kBrent) {
    internal::MinimizeWithBrent(options, &guarded, scale, &summary);
  } else if (summary.algorithm == OuterAlgorithm::kSecant) {
    internal::MinimizeWithSecant(options, &guarded, scale, curvature, &summary);
  } else if (options.optimizer == OptimizerType::kNlopt) {
    internal::MinimizeWithNlopt(options, &guarded, scale, curvature, &summary);
  } else {
    internal::MinimizeWithCeres(options, &guarded, scale, curvature, &summary);
  }
  summary.evaluations = guarded.evaluations();
  summary.gradient_evaluations = guarded.gradient_evaluations();
  if (guarded.has_best()) {
    summary.modulus = guarded.best_x()[0] * scale;
    summary.cost = guarded.best_cost();
    summary.gradient = guarded.best_gradient().empty() ? 0.0 : guarded.best_gradient()[0];
  }
  summary.wall_time_s = guarded.ElapsedSeconds();
  if (!guarded.has_best() && summary.termination == TerminationType::kConvergence) {
    summary.termination = TerminationType::kFailure;
    summary.message = "no usable evaluation of the objective";
  }
  return summary;
}

// Scaled cost and gradient at x into *cost, *gradient; both NaN when the
// evaluation fails, throws or gives a non-finite value (why written to *failure).
void ScanSample(ModulusObjective* objective, double x, double* cost, double* gradient,
                std::string* failure) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  *cost = kNaN;
  *gradient = kNaN;
  try {
    if (!objective->Evaluate(&x, cost, gradient)) {
      *failure = objective->error_message();
    } else if (!std::isfinite(*cost) || !std::isfinite(*gradient)) {
      *failure = "the objective returned a non-finite cost or gradient";
    } else {
      return;
    }
  } catch (const std::exception& error) {
    *failure = std::string("the objective threw: ") + error.what();
  } catch (...) {
    *failure = "the objective threw an exception that is not a std::exception";
  }
  *cost = kNaN;
  *gradient = kNaN;
}

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Scan points are split into this many contiguous chunks (fewer when there are
// fewer points), whatever the thread count, so that every sample is the same bits
// on 1 or 64 threads.
constexpr int kScanChunks = 8;

// The scaled costs and gradients at xs. The points form min(kScanChunks, P)
// contiguous chunks, chunk c = [c P / C, (c + 1) P / C); each chunk is evaluated in
// order by a copy of the objective (CloneForScan, one per thread, StartAfresh
// before each chunk but its first: a copy's fields are made once), warm-started
// point to point from its own first point only, so a sample depends on its chunk and
// never on which thread ran it. Chunk c runs on thread c mod scan_threads. Without copies
// (CloneForScan gives none) every point is evaluated in order on `objective`.
// Samples not reached within options.max_time of `start` stay NaN.
// *first_failure: why the lowest failed sample failed; *sweeps: the inner sweeps
// the scan ran.
void ScanSamples(const IdentificationOptions& options, ModulusObjective* objective,
                 const std::vector<double>& xs, Clock::time_point start, std::vector<double>* costs,
                 std::vector<double>* gradients, std::string* first_failure, long* sweeps) {
  const int points = static_cast<int>(xs.size());
  costs->assign(xs.size(), std::numeric_limits<double>::quiet_NaN());
  gradients->assign(xs.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::string> failures(xs.size());
  auto sample = [&](ModulusObjective* evaluated, int i) {
    if (SecondsSince(start) >= options.max_time) {
      failures[i] = "outer.max_time reached during the scan";
      return;
    }
    if (InterruptRequested()) {
      failures[i] = kInterruptedMessage;
      return;
    }
    ScanSample(evaluated, xs[i], &(*costs)[i], &(*gradients)[i], &failures[i]);
  };
  const int chunks = std::min(kScanChunks, points);
  const int threads = std::min(options.scan_threads, chunks);
  std::vector<long> thread_sweeps(threads, 0);
  std::vector<char> cloned(threads, 1);
  auto run_chunks = [&](int thread) {
    std::unique_ptr<ModulusObjective> copy;
    for (int c = thread; c < chunks; c += threads) {
      if (copy == nullptr) {
        copy = objective->CloneForScan(options.scan_tolerance);
        if (copy == nullptr) {
          cloned[thread] = 0;
          return;
        }
      } else {
        copy->StartAfresh();
      }
      for (int i = c * points / chunks; i < (c + 1) * points / chunks; ++i) {
        sample(copy.get(), i);
      }
    }
    if (copy != nullptr) thread_sweeps[thread] = copy->sweeps();
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
    for (int i = 0; i < points; ++i) sample(objective, i);
    *sweeps = objective->sweeps() - sweeps_before;
  }
  for (const std::string& failure : failures) {
    if (!failure.empty()) {
      *first_failure = failure;
      break;
    }
  }
}

// A valley of the scan: bracket [xs[left], xs[left + 1]], the estimate of its
// minimum (x, scaled cost) and the curvature d^2 cost / dx^2 there.
struct ValleyEstimate {
  int left = 0;
  double x = 0.0;
  double cost = 0.0;
  double curvature = 0.0;
};

// The local minimum inside (0, 1) of the cubic Hermite interpolant on [x0, x1] of
// costs c0, c1 and gradients g0, g1 (d cost / dx), if it has one. With w = x1 - x0,
// d0 = w g0, d1 = w g1 and t in [0, 1]:
//   p(t) = a t^3 + b t^2 + d0 t + c0,  a = 2 (c0 - c1) + d0 + d1,
//   b = 3 (c1 - c0) - 2 d0 - d1,  p'(t) = 3 a t^2 + 2 b t + d0,
// and a minimum is a root of p' with p''(t) = 6 a t + 2 b > 0.
bool HermiteMinimum(double x0, double x1, double c0, double c1, double g0, double g1,
                    ValleyEstimate* valley) {
  const double w = x1 - x0;
  const double d0 = w * g0, d1 = w * g1;
  const double a = 2.0 * (c0 - c1) + d0 + d1;
  const double b = 3.0 * (c1 - c0) - 2.0 * d0 - d1;
  // Roots of 3 a t^2 + 2 b t + d0, written without cancellation.
  double roots[2];
  int count = 0;
  const double qa = 3.0 * a, qb = 2.0 * b;
  if (std::abs(qa) <= 1e-14 * (std::abs(qb) + std::abs(d0))) {
    if (qb != 0.0) roots[count++] = -d0 / qb;
  } else {
    const double discriminant = qb * qb - 4.0 * qa * d0;
    if (discriminant >= 0.0) {
      const double q = -0.5 * (qb + std::copysign(std::sqrt(discriminant), qb));
      if (q != 0.0) roots[count++] = q / qa;
      roots[count++] = q != 0.0 ? d0 / q : -qb / (2.0 * qa);
    }
  }
  for (int r = 0; r < count; ++r) {
    const double t = roots[r];
    const double second = 6.0 * a * t + 2.0 * b;
    if (t > 0.0 && t < 1.0 && second > 0.0) {
      valley->x = x0 + t * w;
      valley->cost = ((a * t + b) * t + d0) * t + c0;
      valley->curvature = second / (w * w);
      return true;
    }
  }
  // A sign change with the root on an end: the minimum is that end.
  if (g0 < 0.0 && g1 >= 0.0) {
    const bool at_right = c1 <= c0;
    valley->x = at_right ? x1 : x0;
    valley->cost = at_right ? c1 : c0;
    valley->curvature = (g1 - g0) / w;
    return true;
  }
  return false;
}

// The valleys of the scan (xs ascending, costs and gradients NaN where failed),
// lowest estimated cost first: the interior minima of the Hermite interpolant of
// every interval between usable samples, and a bound whose gradient points
// outward.
std::vector<ValleyEstimate> FindValleys(const std::vector<double>& xs,
                                        const std::vector<double>& costs,
                                        const std::vector<double>& gradients) {
  const int n = static_cast<int>(xs.size());
  std::vector<ValleyEstimate> valleys;
  auto usable = [&](int i) { return std::isfinite(costs[i]) && std::isfinite(gradients[i]); };
  if (n >= 2 && usable(0) && gradients[0] >= 0.0 && usable(1)) {
    // Rising from the lower bound: a valley at the bound.
    valleys.push_back({0, xs[0], costs[0], (gradients[1] - gradients[0]) / (xs[1] - xs[0])});
  }
  for (int i = 0; i + 1 < n; ++i) {
    if (!usable(i) || !usable(i + 1)) continue;
    ValleyEstimate valley;
    valley.left = i;
    if (HermiteMinimum(xs[i], xs[i + 1], costs[i], costs[i + 1], gradients[i], gradients[i + 1],
                       &valley)) {
      valleys.push_back(valley);
    }
  }
  if (n >= 2 && usable(n - 1) && gradients[n - 1] <= 0.0 && usable(n - 2)) {
    // Falling to the upper bound: a valley at the bound.
    valleys.push_back({n - 2, xs[n - 1], costs[n - 1],
                       (gradients[n - 1] - gradients[n - 2]) / (xs[n - 1] - xs[n - 2])});
  }
  std::stable_sort(
      valleys.begin(), valleys.end(),
      [](const ValleyEstimate& a, const ValleyEstimate& b) { return a.cost < b.cost; });
  return valleys;
}

// The scan's moduli (scaled), evenly spaced in log E over [x_lower, x_upper]:
// max(scan_points, scan_samples_per_valley per predicted spacing), at most
// scan_max_points (*limited then true).
std::vector<double> ScanGrid(const IdentificationOptions& options, double x_lower, double x_upper,
                             double valley_spacing, bool* limited) {
  const double log_range = std::log(x_upper / x_lower);
  int points = options.scan_points;
  *limited = false;
  if (options.scan_samples_per_valley > 0.0 && valley_spacing > 0.0) {
    // Samples per valley spacing over the log range, both ends included.
    const double wanted =
        std::ceil(log_range / valley_spacing * options.scan_samples_per_valley) + 1;
    if (wanted > options.scan_max_points) {
      *limited = true;
      points = options.scan_max_points;
    } else {
      points = std::max(points, static_cast<int>(wanted));
    }
  }
  std::vector<double> xs(points);
  for (int i = 0; i < points; ++i) {
    // x_i = x_lo (x_hi / x_lo)^(i / (P - 1)): evenly spaced in log E, so that
    // bounds over decades still get samples near every modulus.
    xs[i] = x_lower * std::pow(x_upper / x_lower, i / (points - 1.0));
  }
  return xs;
}

// The scan of the bounds [options.lower_bound, options.upper_bound]: its samples,
// the valleys between them and what failed.
struct BoundsScan {
  std::vector<double> xs;                // scaled moduli, ascending
  std::vector<double> costs, gradients;  // scaled, NaN where failed
  std::vector<ValleyEstimate> valleys;   // lowest estimated cost first
  double valley_spacing = 0.0;           // predicted, in ln E (0: none)
  bool limited = false;                  // capped at outer.scan_max_points
  std::string scan_failure;              // why the lowest failed sample failed
  long scan_sweeps = 0;                  // inner sweeps the scan ran
  int scan_failures = 0;                 // samples without a usable cost
  double scan_wall_time_s = 0.0;         // from `start` to the valleys found
};

// Samples the bounds on ScanGrid's grid (ScanSamples) and finds their valleys
// (FindValleys), warning about a grid capped at scan_max_points, a scan that
// leaves fewer than 2 evaluations and failed samples.
BoundsScan ScanBounds(const IdentificationOptions& options, ModulusObjective* objective,
                      double scale, Clock::time_point start) {
  BoundsScan scan;
  const double x_lower = options.lower_bound / scale;
  const double x_upper = options.upper_bound / scale;
  if (options.scan_samples_per_valley > 0.0) {
    try {
      scan.valley_spacing = objective->ValleySpacing();
    } catch (const std::exception& error) {
      spdlog::warn("scan: no predicted valley spacing ({}): scan_points alone", error.what());
    }
  }
  scan.xs = ScanGrid(options, x_lower, x_upper, scan.valley_spacing, &scan.limited);
  const int points = static_cast<int>(scan.xs.size());
  if (scan.limited) {
    spdlog::warn(
        "scan: the predicted valley spacing {:.3g} in ln E asks for more than "
        "outer.scan_max_points ({}) samples: valleys narrower than the scan's step may be "
        "missed",
        scan.valley_spacing, options.scan_max_points);
  }
  if (points + 2 > options.max_evaluations) {
    spdlog::warn(
        "scan: {} samples leave fewer than 2 of outer.max_evaluations ({}) to the refinements: "
        "raise outer.max_evaluations",
        points, options.max_evaluations);
  }
  ScanSamples(options, objective, scan.xs, start, &scan.costs, &scan.gradients, &scan.scan_failure,
              &scan.scan_sweeps);
  scan.valleys = FindValleys(scan.xs, scan.costs, scan.gradients);
  scan.scan_wall_time_s = SecondsSince(start);
  scan.scan_failures = static_cast<int>(std::count_if(
      scan.costs.begin(), scan.costs.end(), [](double cost) { return !std::isfinite(cost); }));
  if (scan.scan_failures > 0) {
    spdlog::warn("scan: {} of {} samples have no usable cost (first: {})", scan.scan_failures,
                 points, scan.scan_failure);
  }
  spdlog::info(
      "scan of {} moduli over [{:.6g}, {:.6g}] Pa (predicted valley spacing {:.3g} in ln E): {} "
      "valleys, {:.3g} s",
      points, options.lower_bound, options.upper_bound, scan.valley_spacing, scan.valleys.size(),
      scan.scan_wall_time_s);
  return scan;
}

// The refinements of the scan's valleys and what stopped them.
struct ValleyRefinements {
  std::vector<IdentificationSummary> refined;  // in the order the valleys were refined
  std::vector<ScanValley> reported;            // one per valley of the scan
  std::string limit_message;  // which limit stopped the search, in the user's terms
  // A refinement that failed leaves its valley unknown: no result is reported
  // over it, whatever the other refinements found.
  std::string refinement_failure;
};

// Which limit stopped the search `when`, in the user's terms: max_evaluations if
// fewer than 2 of them are left after evaluations_used (the scan's `points`
// included), else max_time.
std::string LimitReached(const IdentificationOptions& options, int evaluations_used, int points,
                         const std::string& when) {
  std::ostringstream why;
  if (evaluations_used + 2 > options.max_evaluations) {
    why << "outer.max_evaluations (" << options.max_evaluations << ", the scan's " << points
        << " included) reached " << when;
  } else {
    why << "outer.max_time (" << options.max_time << " s) reached " << when;
  }
  return why.str();
}

// A refinement (MinimizeLocally) of valley k of the scan within the samples
// [first, last], started at its estimate moved strictly inside, with what
// *evaluations_used and `start` left of max_evaluations and max_time; adds its
// evaluations to *evaluations_used.
IdentificationSummary RefineValley(const IdentificationOptions& options,
                                   ModulusObjective* objective, const BoundsScan& scan,
                                   double scale, int k, int first, int last,
                                   Clock::time_point start, int* evaluations_used) {
  const ValleyEstimate& valley = scan.valleys[k];
  IdentificationOptions local = options;
  local.max_evaluations = options.max_evaluations - *evaluations_used;
  local.max_time = options.max_time - SecondsSince(start);
  local.lower_bound = scan.xs[first] * scale;
  local.upper_bound = scan.xs[last] * scale;
  // Start at the estimate, moved strictly inside the bracket.
  const double width = local.upper_bound - local.lower_bound;
  local.initial = std::clamp(valley.x * scale, local.lower_bound + 1e-3 * width,
                             local.upper_bound - 1e-3 * width);
  spdlog::info("refining valley {} (estimate E = {:.9g} Pa) within [{:.6g}, {:.6g}] Pa", k + 1,
               valley.x * scale, local.lower_bound, local.upper_bound);
  IdentificationSummary result = MinimizeLocally(local, objective, valley.curvature);
  *evaluations_used += result.evaluations;
  return result;
}

// Local refinements of the valleys within refine_margin of the lowest estimate
// (at most refine_candidates, the lowest always), each within its bracket and
// with what the scan and the earlier refinements left of max_evaluations and
// max_time, none once a limit is reached; a refinement ending on an inner edge of
// its bracket is redone once over the neighbouring intervals. Every valley is
// reported, refined or not.
ValleyRefinements RefineValleys(const IdentificationOptions& options, ModulusObjective* objective,
                                const BoundsScan& scan, double scale, Clock::time_point start) {
  const std::vector<ValleyEstimate>& valleys = scan.valleys;
  const int points = static_cast<int>(scan.xs.size());
  ValleyRefinements out;
  out.reported.resize(valleys.size());
  int evaluations_used = points;
  const double lowest = valleys.empty() ? 0.0 : valleys.front().cost;
  const double threshold = lowest + options.refine_margin * std::abs(lowest);
  for (int k = 0; k < static_cast<int>(valleys.size()); ++k) {
    const ValleyEstimate& valley = valleys[k];
    ScanValley& report = out.reported[k];
    report.lower_modulus = scan.xs[valley.left] * scale;
    report.upper_modulus = scan.xs[valley.left + 1] * scale;
    report.estimated_modulus = valley.x * scale;
    report.estimated_cost = valley.cost;
    const bool wanted = k == 0 || (valley.cost <= threshold && k < options.refine_candidates);
    if (!wanted || !out.limit_message.empty()) continue;
    if (options.max_evaluations - evaluations_used < 2 || SecondsSince(start) >= options.max_time) {
      out.limit_message = LimitReached(options, evaluations_used, points,
                                       "before valley " + std::to_string(k + 1) + " was refined");
      continue;
    }
    IdentificationSummary result = RefineValley(options, objective, scan, scale, k, valley.left,
                                                valley.left + 1, start, &evaluations_used);
    // Ended on an inner edge of its bracket (the scan's gradient, at its loose
    // tolerance, misplaced the sign change): once more over the neighbouring intervals.
    const double tolerance = 4.0 * options.relative_tolerance * result.modulus;
    const bool on_left = valley.left > 0 && result.modulus - report.lower_modulus <= tolerance;
    const bool on_right =
        valley.left + 2 < points && report.upper_modulus - result.modulus <= tolerance;
    if (result.IsSolutionUsable() && (on_left || on_right) &&
        options.max_evaluations - evaluations_used >= 2) {
      const int evaluations_before = result.evaluations;
      result = RefineValley(options, objective, scan, scale, k, std::max(valley.left - 1, 0),
                            std::min(valley.left + 2, points - 1), start, &evaluations_used);
      result.evaluations += evaluations_before;
    }
    report.refined = true;
    report.termination = result.termination;
    report.modulus = result.modulus;
    report.cost = result.cost;
    report.evaluations = result.evaluations;
    if (result.termination == TerminationType::kNoConvergence) {
      out.limit_message = LimitReached(options, evaluations_used, points, "before convergence");
    }
    if (result.termination == TerminationType::kFailure && out.refinement_failure.empty()) {
      std::ostringstream why;
      why << "the refinement of valley " << k + 1 << " (E = " << report.estimated_modulus
          << " Pa) failed: " << result.message;
      out.refinement_failure = why.str();
    }
    out.refined.push_back(std::move(result));
  }
  return out;
}

// The index of the usable refinement of least cost (the first of equal costs),
// -1 if none is usable.
int BestRefinement(const std::vector<IdentificationSummary>& refined) {
  int best = -1;
  for (int k = 0; k < static_cast<int>(refined.size()); ++k) {
    if (refined[k].IsSolutionUsable() && (best < 0 || refined[k].cost < refined[best].cost)) {
      best = k;
    }
  }
  return best;
}

// Sets *summary to the outcome of the scan and its refinements: refinement `best`,
// else the first refinement's, else the scan's failure; then a failed
// refinement's failure, and a limit reached (the scan's max_time included) as no
// convergence, whatever an earlier refinement found.
void SetOutcome(const IdentificationOptions& options, const BoundsScan& scan,
                const ValleyRefinements& refinements, int best, Clock::time_point start,
                IdentificationSummary* summary) {
  const std::vector<IdentificationSummary>& refined = refinements.refined;
  const int points = static_cast<int>(scan.xs.size());
  std::string limit_message = refinements.limit_message;
  if (best >= 0) {
    *summary = refined[best];
  } else if (!refined.empty()) {
    *summary = refined.front();
  } else if (scan.scan_failures == points) {
    summary->termination = TerminationType::kFailure;
    summary->message = "no usable evaluation in the scan of the bounds: " + scan.scan_failure;
  } else if (limit_message.empty()) {
    summary->termination = TerminationType::kFailure;
    summary->message = "the scan saw no minimum between usable samples (" +
                       std::to_string(scan.scan_failures) + " of " + std::to_string(points) +
                       " samples failed; first: " + scan.scan_failure + ")";
  }
  if (!refinements.refinement_failure.empty()) {
    summary->termination = TerminationType::kFailure;
    summary->message = refinements.refinement_failure;
  }
  if (SecondsSince(start) >= options.max_time && limit_message.empty() && refined.empty()) {
    limit_message = "outer.max_time reached during the scan of the bounds";
  }
  if (!limit_message.empty()) {
    // A limit reached is not convergence, whatever an earlier refinement found.
    summary->termination = TerminationType::kNoConvergence;
    summary->message = limit_message;
  }
}

// Sets summary->second_modulus and cost_gap from the valleys other than the
// result's: the lowest refined cost of a converged refinement, or the
// estimated cost of a valley not refined. Unchanged if there is none.
void SetSecondValley(const std::vector<ScanValley>& reported, IdentificationSummary* summary) {
  double second_cost = std::numeric_limits<double>::infinity();
  for (const ScanValley& valley : reported) {
    if (valley.refined && valley.modulus == summary->modulus) continue;
    if (valley.refined && valley.termination != TerminationType::kConvergence) continue;
    const double cost = valley.refined ? valley.cost : valley.estimated_cost;
    if (cost < second_cost) {
      second_cost = cost;
      summary->second_modulus = valley.refined ? valley.modulus : valley.estimated_modulus;
    }
  }
  if (std::isfinite(second_cost)) summary->cost_gap = second_cost - summary->cost;
}

}  // namespace

bool EndsOnAnInnerEdge(const IdentificationOptions& window, const IdentificationOptions& bounds,
                       double modulus) {
  const double tolerance = 4.0 * bounds.relative_tolerance * modulus;
  const bool on_lower =
      window.lower_bound > bounds.lower_bound && modulus - window.lower_bound <= tolerance;
  const bool on_upper =
      window.upper_bound < bounds.upper_bound && window.upper_bound - modulus <= tolerance;
  return on_lower || on_upper;
}

IdentificationSummary RefineFrom(const IdentificationOptions& options, ModulusObjective* objective,
                                 double curvature) {
  IdentificationOptions local = options;
  local.scan_points = 0;
  std::string why;
  if (!local.IsValid(&why)) {
    IdentificationSummary summary;
    summary.optimizer = options.optimizer;
    summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm, 1);
    summary.initial_modulus = options.initial;
    summary.message = "invalid options: " + why;
    return summary;
  }
  return MinimizeLocally(local, objective, curvature);
}

IdentificationSummary Identify(const IdentificationOptions& options, ModulusObjective* objective) {
  IdentificationSummary summary;
  summary.optimizer = options.optimizer;
  summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm, 1);
  summary.initial_modulus = options.initial;
  std::string why;
  if (!options.IsValid(&why)) {
    summary.message = "invalid options: " + why;
    return summary;
  }
  if (options.scan_points == 0) return MinimizeLocally(options, objective);

  const Clock::time_point start = Clock::now();
  const double scale = objective->modulus_scale();
  const BoundsScan scan = ScanBounds(options, objective, scale, start);
  ValleyRefinements refinements = RefineValleys(options, objective, scan, scale, start);
  const std::vector<IdentificationSummary>& refined = refinements.refined;
  const int best = BestRefinement(refined);
  SetOutcome(options, scan, refinements, best, start, &summary);
  summary.initial_modulus = options.initial;
  summary.evaluations = 0;
  summary.gradient_evaluations = 0;
  for (const IdentificationSummary& local : refined) {
    summary.evaluations += local.evaluations;
    summary.gradient_evaluations += local.gradient_evaluations;
  }
  summary.refinements = static_cast<int>(refined.size());
  for (const double x : scan.xs) summary.scan_moduli.push_back(x * scale);
  summary.scan_costs = scan.costs;
  summary.scan_gradients = scan.gradients;
  summary.scan_evaluations = static_cast<int>(scan.xs.size());
  summary.scan_sweeps = scan.scan_sweeps;
  summary.scan_failures = scan.scan_failures;
  summary.predicted_valley_spacing = scan.valley_spacing;
  summary.scan_resolution_limited = scan.limited;
  summary.local_minima = static_cast<int>(scan.valleys.size());
  // The second valley: its refined cost when refined, else its estimated cost.
  if (best >= 0) SetSecondValley(refinements.reported, &summary);
  summary.valleys = std::move(refinements.reported);
  summary.scan_wall_time_s = scan.scan_wall_time_s;
  summary.wall_time_s = SecondsSince(start);
  return summary;
}

namespace {

// What the two-stage identification's result takes from its global search (stage 1)
// and its window scan (stage 2).
struct TwoStageRecord {
  Clock::time_point start;
  IdentificationSummary found;  // the global search's
  int search_evaluations = 0;   // the search's scan and refinements
  int window_evaluations = 0;   // stage 2's window scan
  long window_sweeps = 0;
  double window_wall_time_s = 0.0;

  // `result` with the search's count, and the search's scan fields unless the
  // objective's own scan (stage 3) replaced them (scan_of_search false). The scan
  // counts add the search's (scan and refinements) and stage 2's window scan.
  IdentificationSummary With(IdentificationSummary result, bool scan_of_search) const {
    if (scan_of_search) {
      result.scan_evaluations = 0;
      result.scan_sweeps = 0;
      result.scan_wall_time_s = 0.0;
      result.scan_moduli = found.scan_moduli;
      result.scan_costs = found.scan_costs;
      result.scan_gradients = found.scan_gradients;
      result.scan_failures = found.scan_failures;
      result.predicted_valley_spacing = found.predicted_valley_spacing;
      result.scan_resolution_limited = found.scan_resolution_limited;
      result.valleys = found.valleys;
      result.local_minima = found.local_minima;
      result.cost_gap = found.cost_gap;
      result.second_modulus = found.second_modulus;
      result.refinements = found.refinements;
    }
    result.scan_evaluations += search_evaluations + window_evaluations;
    result.scan_sweeps += found.scan_sweeps + window_sweeps;
    result.scan_wall_time_s += found.wall_time_s + window_wall_time_s;
    result.search_modulus = found.modulus;
    result.scan_of_search = scan_of_search;
    result.wall_time_s = SecondsSince(start);
    return result;
  }

  // The result when the objective is not minimised: `termination` and `message`, the
  // options' optimiser and start.
  IdentificationSummary NotRun(const IdentificationOptions& options, TerminationType termination,
                               const std::string& message,
                               const IdentificationSummary* refined = nullptr) const {
    IdentificationSummary not_run;
    not_run.optimizer = options.optimizer;
    not_run.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm, 1);
    not_run.initial_modulus = options.initial;
    IdentificationSummary result = With(refined != nullptr ? *refined : not_run, true);
    result.termination = termination;
    result.message = message;
    return result;
  }
};

// Stage 2's options: a scan of window_points over the search's modulus +- refine_window
// (within the bounds), started at that modulus, with the evaluations and the time the
// search left.
IdentificationOptions WindowOptions(const IdentificationOptions& options,
                                    const TwoStageRecord& record, double refine_window,
                                    int window_points) {
  IdentificationOptions local = options;
  local.scan_points = window_points;
  local.lower_bound = std::max(options.lower_bound, record.found.modulus * (1.0 - refine_window));
  local.upper_bound = std::min(options.upper_bound, record.found.modulus * (1.0 + refine_window));
  const double width = local.upper_bound - local.lower_bound;
  local.initial = std::clamp(record.found.modulus, local.lower_bound + 1e-3 * width,
                             local.upper_bound - 1e-3 * width);
  local.max_evaluations = options.max_evaluations - record.search_evaluations;
  local.max_time = options.max_time - SecondsSince(record.start);
  return local;
}

}  // namespace

IdentificationSummary IdentifyInTwoStages(const IdentificationOptions& options,
                                          ModulusObjective* search, int search_scan_points,
                                          double refine_window, ModulusObjective* objective,
                                          const SearchRefinement& refinement) {
  assert(options.scan_points > 0 && search_scan_points >= 3 && refine_window > 0.0 &&
         refine_window <= 0.5 && refinement.window_points >= 3);
  TwoStageRecord record;
  record.start = Clock::now();
  // 1. The global search, its valleys refined as `refinement` says whatever the optimiser.
  IdentificationOptions global = options;
  global.scan_points = search_scan_points;
  if (refinement.samples_per_valley > 0.0) {
    global.scan_samples_per_valley = refinement.samples_per_valley;
  }
  global.optimizer = OptimizerType::kNlopt;
  global.algorithm = refinement.algorithm;
  if (refinement.relative_tolerance > 0.0) {
    global.relative_tolerance = refinement.relative_tolerance;
  }
  record.found = Identify(global, search);
  const IdentificationSummary& found = record.found;
  record.search_evaluations = found.scan_evaluations + found.evaluations;
  if (!found.IsSolutionUsable()) {
    return record.NotRun(options, found.termination, "the global search: " + found.message);
  }
  // 2. The objective near the search's minimiser, with what the search left: a scan of
  // the window (cost and gradient, as the global scan's), its valleys refined.
  const IdentificationOptions local =
      WindowOptions(options, record, refine_window, refinement.window_points);
  if (local.max_evaluations < local.scan_points + 2 || !(local.max_time > 0.0)) {
    return record.NotRun(options, TerminationType::kNoConvergence,
                         local.max_evaluations < local.scan_points + 2
                             ? "outer.max_evaluations (" + std::to_string(options.max_evaluations) +
                                   ") reached by the global search (" +
                                   std::to_string(record.search_evaluations) + " evaluations)"
                             : "outer.max_time reached by the global search");
  }
  spdlog::info("refining the objective near the search's E = {:.9g} Pa within [{:.6g}, {:.6g}] Pa",
               found.modulus, local.lower_bound, local.upper_bound);
  IdentificationSummary refined = Identify(local, objective);
  record.window_evaluations = refined.scan_evaluations;
  record.window_sweeps = refined.scan_sweeps;
  record.window_wall_time_s = refined.scan_wall_time_s;
  if (!refined.IsSolutionUsable() || !EndsOnAnInnerEdge(local, options, refined.modulus)) {
    return record.With(refined, true);
  }

  // 3. Its minimum lies beyond the window: the objective's own global search.
  spdlog::warn(
      "the objective's minimum lies beyond {:.3g} % of the search's E = {:.9g} Pa "
      "(search.refine_window): scanning the objective itself",
      100.0 * refine_window, found.modulus);
  IdentificationOptions own = options;
  own.max_evaluations = local.max_evaluations - refined.evaluations - record.window_evaluations;
  own.max_time = options.max_time - SecondsSince(record.start);
  if (own.max_evaluations < own.scan_points + 2 || !(own.max_time > 0.0)) {
    return record.NotRun(
        options, TerminationType::kNoConvergence,
        "outer.max_evaluations or outer.max_time reached before the objective's own scan, which "
        "the refinement on an edge of search.refine_window asked for",
        &refined);
  }
  IdentificationSummary scanned = Identify(own, objective);
  scanned.evaluations += refined.evaluations;
  scanned.gradient_evaluations += refined.gradient_evaluations;
  return record.With(scanned, false);
}

}  // namespace mcrewave
