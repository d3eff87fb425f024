#include "mcrewave/optim/regularization.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>


namespace mcrewave {
namespace {

// One minimisation at `weight` from `start`, recorded in *result.
BoundedMinimizerSummary MinimizeAt(const BoundedMinimizerOptions& options,
                                   const RegularizationOptions& regularization,
                                   FirstOrderObjective* data, const std::vector<double>& lower,
                                   const std::vector<double>& upper,
                                   const std::vector<double>& start, double weight,
                                   double target_misfit, RegularizedMinimization* result,
                                   RegularizedPoint* point) {
  RegularizedObjective objective(data, regularization.kind, weight, regularization.tv_smoothing,
                                 regularization.neighbours);
  BoundedMinimizerSummary summary = MinimizeWithinBounds(options, &objective, lower, upper, start);
  result->evaluations += summary.evaluations;
  *point = RegularizedPoint();
  point->weight = weight;
  point->evaluations = summary.evaluations;
  point->termination = summary.termination;
  if (!summary.x.empty() && weight == 0.0) {
    // Without a penalty the minimiser's cost is the data cost at its minimiser.
    point->misfit = summary.cost;
    point->roughness =
        JumpPenalty(regularization.kind, 1.0, regularization.tv_smoothing, summary.x.data(),
                    static_cast<int>(summary.x.size()), nullptr, &regularization.neighbours);
  } else if (!summary.x.empty()) {
    // The parts at the best point: evaluate once more without the gradient (the
    // objective's last evaluation need not be the best one).
    double cost = 0.0;
    RegularizedObjective parts(data, regularization.kind, weight, regularization.tv_smoothing,
                               regularization.neighbours);
    if (parts.Evaluate(summary.x.data(), &cost, nullptr)) {
      point->misfit = parts.last_data_cost();
      point->roughness =
          JumpPenalty(regularization.kind, 1.0, regularization.tv_smoothing, summary.x.data(),
                      static_cast<int>(summary.x.size()), nullptr, &regularization.neighbours);
      ++result->evaluations;
    } else {
      summary.termination = TerminationType::kFailure;
      summary.message = "the data cost at the minimiser failed: " + data->error_message();
      point->termination = summary.termination;
    }
  }
  point->meets_target =
      target_misfit >= 0.0 && summary.IsSolutionUsable() && point->misfit <= target_misfit;
  if (summary.IsSolutionUsable()) {
    spdlog::info("regularisation weight {:.3g}: misfit {:.6g}{}, roughness {:.6g}; {}", weight,
                 point->misfit,
                 target_misfit >= 0.0 ? fmt::format(" (target {:.6g})", target_misfit) : "",
                 point->roughness, summary.BriefReport());
  } else {
    spdlog::info("regularisation weight {:.3g}: {}", weight, summary.BriefReport());
  }
  result->path.push_back(*point);
  return summary;
}

}  // namespace

bool RegularizationOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!std::isfinite(weight)) {
    why << "zone_identification.regularization_weight must be a finite number (< 0: automatic), "
           "got "
        << weight;
  } else if (!(tv_smoothing > 0.0 && tv_smoothing < 1.0)) {
    why << "zone_identification.tv_smoothing must lie in (0, 1), got " << tv_smoothing;
  } else if (!(min_weight > 0.0 && max_weight > min_weight && std::isfinite(max_weight))) {
    why << "zone_identification.min_weight and zone_identification.max_weight must satisfy 0 < "
           "min_weight < "
           "max_weight, got "
        << min_weight << " and " << max_weight;
  } else if (!(grid_factor > 1.0 && grid_factor <= 1e6)) {
    why << "zone_identification.grid_factor must lie in (1, 1e6], got " << grid_factor;
  } else if (refinement_steps < 0 || refinement_steps > 30) {
    why << "zone_identification.refinement_steps must lie in [0, 30], got " << refinement_steps;
  } else if (!(weight_tolerance > 0.0 && weight_tolerance <= 100.0)) {
    why << "zone_identification.weight_tolerance must lie in (0, 100], got " << weight_tolerance;
  } else if (!(discrepancy_factor > 0.0 && std::isfinite(discrepancy_factor))) {
    why << "zone_identification.discrepancy_factor must be a positive number, got "
        << discrepancy_factor;
  } else if (std::any_of(neighbours.begin(), neighbours.end(), [](const ZonePair& pair) {
               return pair.first < 0 || pair.second < 0 || pair.first == pair.second ||
                      !(pair.weight > 0.0 && std::isfinite(pair.weight));
             })) {
    why << "the zones' neighbour pairs must join two distinct zones with a positive weight";
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

double JumpPenalty(RegularizationKind kind, double weight, double tv_smoothing, const double* p,
                   int n, double* gradient, const std::vector<ZonePair>* neighbours) {
  if (kind == RegularizationKind::kNone || weight == 0.0) return 0.0;
  const bool chain = neighbours == nullptr || neighbours->empty();
  const int pairs = chain ? std::max(n - 1, 0) : static_cast<int>(neighbours->size());
  double penalty = 0.0;
  for (int k = 0; k < pairs; ++k) {
    // The chain's pair k is (k, k + 1) of weight 1 (a product by 1 is exact: the chain's
    // bits whichever way it is given).
    const int a = chain ? k : (*neighbours)[k].first;
    const int b = chain ? k + 1 : (*neighbours)[k].second;
    const double pair_weight = chain ? 1.0 : (*neighbours)[k].weight;
    assert(a >= 0 && a < n && b >= 0 && b < n && a != b);
    const double d = p[b] - p[a];
    double phi = 0.0;
    double dphi = 0.0;  // phi'(d)
    if (kind == RegularizationKind::kTikhonov) {
      phi = d * d;
      dphi = 2.0 * d;
    } else {
      const double root = std::sqrt(d * d + tv_smoothing * tv_smoothing);
      phi = root - tv_smoothing;
      dphi = d / root;
    }
    penalty += pair_weight * phi;
    if (gradient != nullptr) {
      // d w phi(p_b - p_a) / d p_b = w phi',  / d p_a = -w phi'
      gradient[b] += weight * (pair_weight * dphi);
      gradient[a] -= weight * (pair_weight * dphi);
    }
  }
  return weight * penalty;
}

RegularizedObjective::RegularizedObjective(FirstOrderObjective* data, RegularizationKind kind,
                                           double weight, double tv_smoothing,
                                           std::vector<ZonePair> neighbours)
    : data_(data),
      kind_(kind),
      weight_(weight),
      tv_smoothing_(tv_smoothing),
      neighbours_(std::move(neighbours)) {}

bool RegularizedObjective::Evaluate(const double* x, double* cost, double* gradient) {
  double data_cost = 0.0;
  if (!data_->Evaluate(x, &data_cost, gradient)) return false;
  const double penalty =
      JumpPenalty(kind_, weight_, tv_smoothing_, x, num_parameters(), gradient, &neighbours_);
  last_data_cost_ = data_cost;
  last_penalty_ = penalty;
  *cost = data_cost + penalty;
  return true;
}

int LCurveCorner(const std::vector<double>& misfits, const std::vector<double>& roughness) {
  assert(misfits.size() == roughness.size());
  const int n = static_cast<int>(misfits.size());
  if (n < 3) return -1;
  // (ln misfit, ln roughness), each scaled to [0, 1] over the grid.
  std::vector<double> x(n), y(n);
  for (int k = 0; k < n; ++k) {
    if (!(misfits[k] > 0.0 && roughness[k] > 0.0)) return -1;
    x[k] = std::log(misfits[k]);
    y[k] = std::log(roughness[k]);
  }
  const auto [x_low, x_high] = std::minmax_element(x.begin(), x.end());
  const auto [y_low, y_high] = std::minmax_element(y.begin(), y.end());
  const double x_range = *x_high - *x_low, y_range = *y_high - *y_low;
  if (!(x_range > 0.0 && y_range > 0.0)) return -1;
  const double x0 = *x_low, y0 = *y_low;
  for (int k = 0; k < n; ++k) {
    x[k] = (x[k] - x0) / x_range;
    y[k] = (y[k] - y0) / y_range;
  }
  // The distance below the chord from the first point to the last (positive on the
  // origin's side, where an L bends).
  const double dx = x[n - 1] - x[0], dy = y[n - 1] - y[0];
  const double length = std::hypot(dx, dy);
  if (!(length > 0.0)) return -1;
  int corner = -1;
  double largest = kLCurveMinimumBend;
  for (int k = 1; k + 1 < n; ++k) {
    const double below = (dx * (y[k] - y[0]) - dy * (x[k] - x[0])) / length;
    if (below > largest) {
      largest = below;
      corner = k;
    }
  }
  return corner;
}

namespace {

// The automatic weight of MinimizeRegularized, one member per stage: the descent of
// the weight grid (Descend), the choice when no weight of the grid met the target
// (ChooseWithoutHit), and the regula falsi between the last miss and the hit
// (Refine). The members share the grid and the current hit and miss.
class WeightSearch {
 public:
  WeightSearch(const BoundedMinimizerOptions& options, const RegularizationOptions& regularization,
               FirstOrderObjective* data, const std::vector<double>& lower,
               const std::vector<double>& upper, double target_misfit, double target_std_dev,
               RegularizedMinimization* result)
      : options_(options),
        regularization_(regularization),
        data_(data),
        lower_(lower),
        upper_(upper),
        target_misfit_(target_misfit),
        target_std_dev_(target_std_dev),
        target_(target_misfit),
        l_curve_(regularization.weight_rule == WeightRule::kLCurve),
        result_(*result) {}

  // The search from `initial`; fills *result.
  void Run(const std::vector<double>& initial) {
    result_.target_misfit = target_misfit_;
    if (!Descend(initial)) return;
    result_.weight_choice = choice_;
    if (hit_weight_ < 0.0) ChooseWithoutHit();
    if (missed_ > 0.0) Refine();
    result_.minimizer = std::move(hit_);
    result_.weight = hit_weight_;
    result_.x = result_.minimizer.x;
    result_.misfit = hit_misfit_;
  }

 private:
  // The grid's k-th minimisation becomes the one kept.
  void Keep(std::size_t k) {
    hit_ = grid_[k];
    hit_weight_ = grid_weights_[k];
    hit_misfit_ = grid_misfits_[k];
  }

  // Descends the grid, warm-started, to the first weight that meets the target. The
  // discrepancy principle keeps it (and refines it below). The L-curve keeps the
  // largest weight only when its misfit is within kLCurveTopShare of the target (data
  // that the nearly homogeneous profile explains better than the noise would ask for
  // no contrast, where the corner would still lie at a lighter weight); below it, the
  // corner of the points down to the first weight that meets the target (lighter ones
  // only fit the noise), or that weight; the corner of the whole grid when none does.
  // False when the first minimisation failed: *result is then final.
  bool Descend(const std::vector<double>& initial) {
    std::vector<double> start = initial;
    // c0, the data cost at the start: the grid's unit.
    double start_cost = 0.0;
    if (!data_->Evaluate(initial.data(), &start_cost, nullptr) || !(start_cost > 0.0)) {
      start_cost = 1.0;  // a failure shows in the first minimisation
    }
    ++result_.evaluations;
    for (double weight = regularization_.max_weight * start_cost;
         weight >= regularization_.min_weight * start_cost * (1.0 - 1e-12);
         weight /= regularization_.grid_factor) {
      BoundedMinimizerSummary summary =
          MinimizeAt(options_, regularization_, data_, lower_, upper_, start, weight,
                     target_misfit_, &result_, &point_);
      if (!summary.IsSolutionUsable() && !grid_.empty()) {
        // Below a weight that converged, a minimisation that did not (out of
        // evaluations among zones that drift to their bounds: the noise fitted) ends the
        // descent; the weight is chosen among the converged ones, as when the target is
        // missed.
        spdlog::warn(
            "the minimisation at the regularisation weight {:.3g} failed ({}): the descent "
            "stops at {:.3g}",
            weight, summary.message, grid_weights_.back());
        break;
      }
      if (!summary.IsSolutionUsable()) {
        result_.minimizer = std::move(summary);
        result_.weight = weight;
        result_.weight_choice = WeightRuleToString(regularization_.weight_rule);
        result_.x = result_.minimizer.x;
        result_.misfit = point_.misfit;
        return false;  // a failed minimisation ends the search: its message says why
      }
      start = summary.x;
      grid_.push_back(std::move(summary));
      grid_weights_.push_back(weight);
      grid_misfits_.push_back(point_.misfit);
      grid_roughness_.push_back(point_.roughness);
      if (point_.meets_target &&
          (!l_curve_ || (grid_.size() == 1 && point_.misfit <= kLCurveTopShare * target_misfit_))) {
        Keep(grid_.size() - 1);
        break;
      }
      if (l_curve_ && point_.meets_target && grid_.size() > 1) {
        // The L-curve below the largest weight: lighter weights than this one only fit
        // the noise (its flat arm); the corner of the points so far, or this weight.
        const int corner = LCurveCorner(grid_misfits_, grid_roughness_);
        Keep(corner >= 0 ? static_cast<std::size_t>(corner) : grid_.size() - 1);
        missed_ = -1.0;  // no refinement
        spdlog::info("the weight {:.3g} meets the noise's level {:.6g}: the weight is {} {:.3g}",
                     weight, target_misfit_, corner >= 0 ? "the L-curve's corner above it," : "it,",
                     hit_weight_);
        choice_ = corner >= 0 ? "l_curve" : "discrepancy";
        break;
      }
      missed_ = weight;
      missed_misfit_ = point_.misfit;
    }
    return true;
  }

  // No weight of the grid met the target: the grid's last, lightest weight gives the
  // misfit floor (the first minimisation returned if it failed, and the loop runs at
  // least once for options that are valid, max > min weight).
  void ChooseWithoutHit() {
    assert(!grid_.empty());
    const double last_weight = grid_weights_.back();
    const double last_misfit = grid_misfits_.back();
    result_.misfit_floor = last_misfit;
    // The floor raised by its margin: the target of the rule below and of the merges.
    result_.floor_target = FloorTarget(last_misfit);
    // No weight reaches the noise's level (model error, or the noise underestimated):
    // the noise level is not to be trusted, and the L-curve needs none (the L-curve
    // rule's own choice then, the discrepancy principle's fallback, with a warning).
    const int corner = LCurveCorner(grid_misfits_, grid_roughness_);
    if (corner >= 0) {
      if (l_curve_ || target_misfit_ < 0.0) {
        spdlog::info("the weight is the L-curve's corner, {:.3g} (misfit {:.6g})",
                     grid_weights_[corner], grid_misfits_[corner]);
      } else {
        spdlog::warn(
            "no regularisation weight down to {:.3g} brings the misfit {:.6g} to the noise's "
            "level {:.6g}: the weight is the L-curve's corner, {:.3g} (misfit {:.6g})",
            last_weight, last_misfit, target_misfit_, grid_weights_[corner], grid_misfits_[corner]);
      }
      result_.weight_choice = "l_curve";
      Keep(static_cast<std::size_t>(corner));
      missed_ = -1.0;  // no target to refine against
      return;
    }
    // Without a corner (fewer than 3 weights, or a straight curve) the principle is
    // applied to the floor itself, raised by its margin.
    target_ = result_.floor_target;
    spdlog::warn(
        "{} down to {:.3g}: the target becomes the misfit floor {:.6g} + {:.3g} %, {:.6g}",
        l_curve_ || target_misfit_ < 0.0
            ? std::string("the L-curve has no corner")
            : fmt::format("no regularisation weight brings the misfit to the noise's level {:.6g}",
                          target_misfit_),
        last_weight, last_misfit, 100.0 * (target_ / last_misfit - 1.0), target_);
    result_.weight_choice = "misfit_floor";
    for (std::size_t k = 0; k < grid_.size(); ++k) {
      if (grid_misfits_[k] <= target_) {
        Keep(k);
        missed_ = k > 0 ? grid_weights_[k - 1] : -1.0;
        missed_misfit_ = k > 0 ? grid_misfits_[k - 1] : -1.0;
        break;
      }
    }
  }

  // The misfit floor F raised by regularization_.floor_margin's margin (the top of
  // optim/regularization.h).
  double FloorTarget(double floor) const {
    const bool spread_known = target_misfit_ > 0.0 && target_std_dev_ > 0.0;
    if (regularization_.floor_margin == FloorMargin::kNoiseFit && spread_known) {
      // sigma^2 = s^2 / (2 m): a chi-square of N degrees of freedom has mean N sigma^2
      // and variance 2 N sigma^4.
      const double sigma_squared = target_std_dev_ * target_std_dev_ / (2.0 * target_misfit_);
      const auto n = static_cast<double>(lower_.size());
      // F + (n + 2 sqrt(2 n)) sigma^2: the noise n free parameters fit, plus two of its
      // standard deviations.
      return floor + (n + 2.0 * std::sqrt(2.0 * n)) * sigma_squared;
    }
    if (regularization_.floor_margin == FloorMargin::kNoiseFit) {
      spdlog::warn(
          "zone_identification.floor_margin noise_fit needs the spread of the target's noise "
          "draws, which is not known (zone_identification.noise_samples >= 2 gives it): the "
          "margin is ten_percent's");
    }
    return (1.0 + kMisfitFloorMargin) * floor;
  }

  // Regula falsi (Illinois) between the weight that missed (larger) and the hit on
  // f(s) = ln(misfit / target), s = ln lambda, nearly linear where the misfit follows
  // a power of lambda: stops once the chord's root lies within a factor
  // 1 + weight_tolerance of the hit (the weight, not the misfit: near the noise's level
  // the misfit can vary by 10 % over 4 decades of lambda, where the zones change the
  // most), or after refinement_steps.
  void Refine() {
    const auto log_ratio = [&](double misfit) { return std::log(misfit / target_); };
    double hit_log = std::log(hit_weight_), missed_log = std::log(missed_);
    double hit_f = target_ > 0.0 && hit_misfit_ > 0.0 ? log_ratio(hit_misfit_) : 0.0;
    double missed_f = target_ > 0.0 ? log_ratio(missed_misfit_) : 0.0;
    int last_side = 0;  // +1: the last step replaced the missed end, -1: the hit
    for (int step = 0; step < regularization_.refinement_steps; ++step) {
      // The root of the chord; the midpoint when the chord is not usable (a zero
      // misfit at the hit, or a misfit that did not grow with lambda).
      double s = 0.5 * (hit_log + missed_log);
      if (target_ > 0.0 && hit_misfit_ > 0.0 && missed_f > hit_f) {
        s = hit_log - hit_f * (missed_log - hit_log) / (missed_f - hit_f);
      }
      if (s - hit_log <= std::log1p(regularization_.weight_tolerance)) break;
      const double weight = std::exp(s);
      if (!(weight < missed_)) break;
      BoundedMinimizerSummary summary = MinimizeAt(options_, regularization_, data_, lower_, upper_,
                                                   hit_.x, weight, target_, &result_, &point_);
      if (!summary.IsSolutionUsable() || !(point_.misfit > 0.0)) break;  // keep the hit
      const double f = log_ratio(point_.misfit);
      if (point_.meets_target) {
        hit_ = std::move(summary);
        hit_weight_ = weight;
        hit_misfit_ = point_.misfit;
        hit_log = s;
        hit_f = f;
        // Illinois: an end kept twice has its value halved, so that the chord moves it.
        if (last_side == -1) missed_f *= 0.5;
        last_side = -1;
      } else {
        missed_ = weight;
        missed_log = s;
        missed_f = f;
        if (last_side == +1) hit_f *= 0.5;
        last_side = +1;
      }
    }
  }

  const BoundedMinimizerOptions& options_;
  const RegularizationOptions& regularization_;
  FirstOrderObjective* data_;
  const std::vector<double>& lower_;
  const std::vector<double>& upper_;
  const double target_misfit_;   // the caller's target
  const double target_std_dev_;  // its draws' standard deviation (<= 0: unknown)
  double target_;               // the refinement's: the caller's, or the misfit floor's
  const bool l_curve_;
  RegularizedMinimization& result_;
  RegularizedPoint point_;
  double missed_ = -1.0;  // the last weight that missed the target
  double missed_misfit_ = -1.0;
  BoundedMinimizerSummary hit_;
  double hit_weight_ = -1.0;
  double hit_misfit_ = -1.0;
  std::string choice_ = "discrepancy";  // of a weight kept in the descent
  // The grid's minimisations, for the L-curve and the misfit-floor rule.
  std::vector<BoundedMinimizerSummary> grid_;
  std::vector<double> grid_weights_, grid_misfits_, grid_roughness_;
};

}  // namespace

RegularizedMinimization MinimizeRegularized(
    const BoundedMinimizerOptions& options, const RegularizationOptions& regularization,
    FirstOrderObjective* data, const std::vector<double>& lower, const std::vector<double>& upper,
    const std::vector<double>& initial, double target_misfit, double target_std_dev) {
  RegularizedMinimization result;
  const bool automatic =
      regularization.kind != RegularizationKind::kNone && regularization.weight < 0.0;
  if (!automatic) {
    RegularizedPoint point;
    const double weight =
        regularization.kind == RegularizationKind::kNone ? 0.0 : regularization.weight;
    result.weight_choice = regularization.kind == RegularizationKind::kNone ? "none" : "fixed";
    result.minimizer = MinimizeAt(options, regularization, data, lower, upper, initial, weight,
                                  target_misfit, &result, &point);
    result.weight = weight;
    result.target_misfit = target_misfit;
    result.x = result.minimizer.x;
    result.misfit = point.misfit;
    return result;
  }
  WeightSearch search(options, regularization, data, lower, upper, target_misfit, target_std_dev,
                      &result);
  search.Run(initial);
  return result;
}

namespace {

// The data cost over groups of zones: zone z takes its group's parameter,
//   p_z = q_{g(z)},  d cost / d q_g = sum_{z in g} d cost / d p_z.
class GroupedObjective : public FirstOrderObjective {
 public:
  // zones must outlive this objective.
  GroupedObjective(FirstOrderObjective* zones, std::vector<int> group_of, int groups)
      : zones_(zones),
        group_of_(std::move(group_of)),
        groups_(groups),
        zone_parameters_(group_of_.size()),
        zone_gradient_(group_of_.size()) {}
  int num_parameters() const override { return groups_; }
  bool Evaluate(const double* q, double* cost, double* gradient) override {
    for (std::size_t z = 0; z < group_of_.size(); ++z) zone_parameters_[z] = q[group_of_[z]];
    if (!zones_->Evaluate(zone_parameters_.data(), cost,
                          gradient != nullptr ? zone_gradient_.data() : nullptr)) {
      return false;
    }
    if (gradient != nullptr) {
      std::fill(gradient, gradient + groups_, 0.0);
      for (std::size_t z = 0; z < group_of_.size(); ++z) {
        gradient[group_of_[z]] += zone_gradient_[z];
      }
    }
    return true;
  }
  std::string error_message() const override { return zones_->error_message(); }

 private:
  FirstOrderObjective* zones_;
  std::vector<int> group_of_;
  int groups_;
  std::vector<double> zone_parameters_;
  std::vector<double> zone_gradient_;
};

}  // namespace

ZoneMerge MergeNeighbouringZones(const BoundedMinimizerOptions& options, FirstOrderObjective* data,
                                 const std::vector<double>& lower, const std::vector<double>& upper,
                                 const std::vector<double>& x, double target_misfit) {
  assert(target_misfit >= 0.0 && x.size() == lower.size() && x.size() == upper.size());
  const int zones = static_cast<int>(x.size());
  ZoneMerge merge;
  merge.group_of.resize(zones);
  for (int z = 0; z < zones; ++z) merge.group_of[z] = z;
  merge.groups = zones;
  // The current groups' log E, and the boundaries already tried on them.
  std::vector<double> value = x;
  std::vector<bool> refused(zones, false);  // refused[b]: removing boundary b (after group b)
  for (;;) {
    // The untried boundary with the smallest |jump|; the first along the bar on a tie.
    int boundary = -1;
    for (int b = 0; b + 1 < merge.groups; ++b) {
      if (refused[b]) continue;
      if (boundary < 0 ||
          std::abs(value[b + 1] - value[b]) < std::abs(value[boundary + 1] - value[boundary])) {
        boundary = b;
      }
    }
    if (boundary < 0) break;
    // The groups with the boundary removed: group boundary + 1 joins group boundary,
    // started from its zones' mean log E; the others from their values.
    std::vector<int> old_members(merge.groups, 0);
    for (int g : merge.group_of) ++old_members[g];
    std::vector<int> group_of = merge.group_of;
    for (int& g : group_of) {
      if (g > boundary) --g;
    }
    const int groups = merge.groups - 1;
    std::vector<double> start(groups);
    for (int g = 0; g < groups; ++g) start[g] = g < boundary ? value[g] : value[g + 1];
    start[boundary] = (old_members[boundary] * value[boundary] +
                       old_members[boundary + 1] * value[boundary + 1]) /
                      (old_members[boundary] + old_members[boundary + 1]);
    std::vector<double> group_lower(groups, -std::numeric_limits<double>::infinity());
    std::vector<double> group_upper(groups, std::numeric_limits<double>::infinity());
    for (int z = 0; z < zones; ++z) {
      group_lower[group_of[z]] = std::max(group_lower[group_of[z]], lower[z]);
      group_upper[group_of[z]] = std::min(group_upper[group_of[z]], upper[z]);
    }
    GroupedObjective grouped(data, group_of, groups);
    const BoundedMinimizerSummary refit =
        MinimizeWithinBounds(options, &grouped, group_lower, group_upper, start);
    ++merge.refits;
    merge.evaluations += refit.evaluations;
    const bool kept = refit.IsSolutionUsable() && refit.cost <= target_misfit;
    spdlog::info("zones: merging {} zones into {} groups: misfit {:.6g} against target {:.6g}, {}",
                 zones, groups, refit.cost, target_misfit, kept ? "kept" : "refused");
    if (!kept) {
      refused[boundary] = true;
      continue;
    }
    ++merge.merges;
    merge.group_of = std::move(group_of);
    merge.groups = groups;
    merge.misfit = refit.cost;
    value = refit.x;
    std::fill(refused.begin(), refused.end(), false);
  }
  if (merge.merges > 0) {
    merge.x.resize(zones);
    for (int z = 0; z < zones; ++z) merge.x[z] = value[merge.group_of[z]];
  }
  return merge;
}

}  // namespace mcrewave
