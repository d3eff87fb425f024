// Regularisation of the identification of many zone moduli, and the automatic choice
// of its weight (docs/zones_and_sensors.md, "Regularisation and its weight").
//
// With parameters p_z = log(E_z / E_scale) (one per zone, in order along the bar) the
// penalty on the jumps of log E between neighbouring zones is
//   R(p) = lambda sum_{z=0}^{Z-2} phi(p_{z+1} - p_z),
//   phi(d) = d^2                            (tikhonov)
//   phi(d) = sqrt(d^2 + eps^2) - eps        (total_variation, smoothed by eps)
// added to the scaled data cost e^2 / J_rest. Tikhonov favours smooth profiles, the
// total variation piecewise-constant ones (a jump costs its size, not its square).
//
// The weight lambda: fixed (weight >= 0) or chosen (weight < 0, the default) by
// weight_rule from the target misfit (the discrepancy target: the scaled e^2 the noise
// alone explains, identification/zone_identification.h). The grid
// lambda_k = c0 max_weight / grid_factor^k down to c0 min_weight is descended from its
// largest weight, each minimisation warm-started from the previous one, to the first
// weight that meets the target (or a minimisation that fails, or the grid's end). The
// weights are relative to c0, the data cost at the start: the scaled e^2 of nearly
// consistent data is 1e-6 or less, where an absolute weight of 1 would freeze every
// zone. Then:
//   l_curve (the default): the grid's largest weight when its misfit lies under
//     kLCurveTopShare of the target; else the corner of the points descended
//     (LCurveCorner); without a corner, the weight that met the target;
//   discrepancy: regula falsi (Illinois) on ln(misfit / target) against ln lambda
//     between the weight that met the target and the last that missed, until the chord's
//     root lies within a factor 1 + weight_tolerance of the lambda kept or
//     refinement_steps are spent.
// When no weight meets the target (model error, or the noise underestimated), the
// weight is the corner of the grid's L-curve (weight_choice "l_curve", a warning), or
// without a corner the largest lambda whose misfit stays within a margin of the misfit
// floor F, the misfit at the grid's lightest lambda (weight_choice "misfit_floor"; the
// regula falsi then refines it as for the discrepancy principle, on F + margin), the
// margin by floor_margin:
//   ten_percent (the default): kMisfitFloorMargin F;
//   noise_fit: what n free parameters fit of the noise, n sigma^2, plus two of its
//     standard deviations sqrt(2 n) sigma^2: (n + 2 sqrt(2 n)) sigma^2, where
//     sigma^2 = s^2 / (2 m) is the noise cost per degree of freedom of a chi-square whose
//     mean m and standard deviation s the target's draws give (m = target_misfit,
//     s = target_std_dev). The linear least-squares fit of n parameters to N samples of
//     white noise lowers the misfit's expectation from N sigma^2 to (N - n) sigma^2, so a
//     penalty that raises the misfit above the floor by less cannot be told from noise
//     fitting (docs/zones_and_sensors.md, "Regularisation and its weight").
#pragma once

#include <string>
#include <vector>

#include "mcrewave/optim/bounded_minimizer.h"

namespace mcrewave {

// Two zones whose jump of log E the penalty counts, and the weight of their interface.
struct ZonePair {
  int first = 0;
  int second = 0;
  double weight = 1.0;
};

// The `zone_identification.*` options.
struct RegularizationOptions {
  RegularizationKind kind = RegularizationKind::kTikhonov;
  // lambda; < 0: chosen by weight_rule.
  double weight = -1.0;
  // The L-curve by default (why: docs/zones_and_sensors.md, "Regularisation and its
  // weight"). The discrepancy target still decides whether the data ask for any
  // contrast at all.
  WeightRule weight_rule = WeightRule::kLCurve;
  // eps of the smoothed total variation, in log E (1e-3: jumps above 0.1 % of E count
  // by their size).
  double tv_smoothing = 1e-3;
  // The grid of weights, relative to the data cost c0 at the start. Below 1e-4 c0 the
  // zones are as free as unregularised (docs/zones_and_sensors.md, "Measured on the
  // paper's bar").
  double max_weight = 1.0;
  double min_weight = 1e-4;
  // The ratio of neighbouring grid weights: about 2 + (decades / 2) minimisations to
  // the first weight that meets the target.
  double grid_factor = 100.0;
  // The refinement after the grid (rule discrepancy): at most refinement_steps regula
  // falsi steps, stopped once the chord's root lies within a factor 1 + weight_tolerance
  // of the lambda kept.
  int refinement_steps = 4;
  double weight_tolerance = 0.25;
  // tau of the target misfit tau * (expected e^2 of the noise).
  double discrepancy_factor = 1.0;
  // The margin over the misfit floor when the target is missed and the L-curve has no
  // corner (see the top of this file).
  FloorMargin floor_margin = FloorMargin::kTenPercent;
  // Not a config key: the zones whose jumps the penalty counts, set from the structure
  // (ZoneNeighbours, identification/zone_identification.h). Empty: the chain (z, z + 1)
  // of weight 1, the zones in order along a bar.
  std::vector<ZonePair> neighbours;

  // Messages name the zone_identification.* keys.
  bool IsValid(std::string* error) const;
};

// lambda sum_(a,b) w_ab phi(p_b - p_a) over the pairs `neighbours` of n parameters (null
// or empty: the chain lambda sum_z phi(p_{z+1} - p_z)); when gradient is not null the
// penalty's gradient is ADDED to gradient[0..n).
double JumpPenalty(RegularizationKind kind, double weight, double tv_smoothing, const double* p,
                   int n, double* gradient, const std::vector<ZonePair>* neighbours = nullptr);

// The data objective plus the penalty. Keeps the two parts of its last usable
// evaluation apart.
class RegularizedObjective : public FirstOrderObjective {
 public:
  // data must outlive this objective; neighbours as JumpPenalty's (empty: the chain).
  RegularizedObjective(FirstOrderObjective* data, RegularizationKind kind, double weight,
                       double tv_smoothing, std::vector<ZonePair> neighbours = {});
  int num_parameters() const override { return data_->num_parameters(); }
  bool Evaluate(const double* x, double* cost, double* gradient) override;
  std::string error_message() const override { return data_->error_message(); }

  double weight() const { return weight_; }
  void set_weight(double weight) { weight_ = weight; }
  // The data cost and penalty of the last usable evaluation.
  double last_data_cost() const { return last_data_cost_; }
  double last_penalty() const { return last_penalty_; }

 private:
  FirstOrderObjective* data_;
  RegularizationKind kind_;
  double weight_;
  double tv_smoothing_;
  std::vector<ZonePair> neighbours_;
  double last_data_cost_ = 0.0;
  double last_penalty_ = 0.0;
};

// One regularised minimisation of the weight search.
struct RegularizedPoint {
  double weight = 0.0;
  double misfit = 0.0;     // data cost at the minimiser
  double roughness = 0.0;  // sum_z phi(p_{z+1} - p_z) (the penalty / weight)
  bool meets_target = false;
  int evaluations = 0;
  TerminationType termination = TerminationType::kFailure;
};

// The margin over the misfit floor of the last fallback (see the top of this file).
constexpr double kMisfitFloorMargin = 0.1;

// The L-curve rule keeps the grid's largest weight when its misfit is at most this
// share of the discrepancy target (below 1: one draw's e^2 differs from the mean the
// target is; docs/zones_and_sensors.md, "Regularisation and its weight").
constexpr double kLCurveTopShare = 0.8;
// The least bend of an L-curve corner: its distance below the chord, in the grid's
// (ln misfit, ln roughness) scaled to [0, 1].
constexpr double kLCurveMinimumBend = 0.01;

// The corner of the L-curve through the grid's points (ln misfit_k, ln roughness_k),
// in the grid's order (lambda decreasing): each axis scaled to [0, 1] over the grid,
// the interior point farthest below the chord from the first point to the last, when
// that distance exceeds kLCurveMinimumBend. Returns its index, or -1 (fewer than 3
// points, a value <= 0, a flat axis, or no bend).
int LCurveCorner(const std::vector<double>& misfits, const std::vector<double>& roughness);

struct RegularizedMinimization {
  double weight = -1.0;  // lambda of the result
  // "fixed", "none" (no regularisation), "discrepancy", "l_curve" (the target missed:
  // the grid's L-curve corner), or "misfit_floor" (the target missed and no corner:
  // the principle applied to the misfit floor + kMisfitFloorMargin).
  std::string weight_choice = "fixed";
  double target_misfit = -1.0;         // the discrepancy target (-1: not used)
  double misfit_floor = -1.0;  // the grid's lightest weight's misfit when the target was missed
  // The misfit floor + its margin (floor_margin) when the target was missed, the target
  // of weight_choice "misfit_floor" and of MergeNeighbouringZones; -1 when it was met.
  double floor_target = -1.0;
  std::vector<RegularizedPoint> path;  // every minimisation, in order
  BoundedMinimizerSummary minimizer;   // the minimisation at `weight`
  std::vector<double> x;               // its minimiser
  double misfit = -1.0;                // its data cost
  int evaluations = 0;                 // of every minimisation
  bool IsSolutionUsable() const { return minimizer.IsSolutionUsable(); }
  // The misfit the data can be held to: target_misfit, or when no weight of the grid
  // met it, the misfit floor raised by its margin (the target of weight_choice
  // "misfit_floor", and of MergeNeighbouringZones).
  double AttainableTarget() const { return floor_target >= 0.0 ? floor_target : target_misfit; }
};

// Minimises data cost + R within the bounds: at the fixed weight, or with the weight
// regularization.weight_rule chooses for target_misfit (scaled like the data cost).
// options.max_evaluations and max_time hold for each minimisation. target_std_dev: the
// standard deviation of the draws whose mean target_misfit is (scaled alike; <= 0:
// unknown), which regularization.floor_margin noise_fit needs (without it, ten_percent
// with a warning). Preconditions: both options valid; target_misfit >= 0 when
// regularization.weight < 0 and kind is not kNone.
RegularizedMinimization MinimizeRegularized(
    const BoundedMinimizerOptions& options, const RegularizationOptions& regularization,
    FirstOrderObjective* data, const std::vector<double>& lower, const std::vector<double>& upper,
    const std::vector<double>& initial, double target_misfit, double target_std_dev = -1.0);

// Merging of neighbouring zones after the regularised minimisation, a debiasing refit
// (docs/zones_and_sensors.md, "Merging neighbouring zones"): from the regularised
// minimiser x, each zone its own group, the boundary with the smallest |jump of log E|
// between two neighbouring groups is removed, every group refitted on the data cost
// alone (no penalty, one parameter per group, started from the groups' mean log E), and
// the merge kept when the refit's misfit stays at or below the target; else the next
// smallest jump is tried. It stops when no boundary can be removed. The result is the
// last kept refit: the fewest groups, in this order, whose unpenalised fit explains the
// data within the noise.
struct ZoneMerge {
  std::vector<int> group_of;  // per zone, its group (numbered along the bar)
  int groups = -1;            // groups at the end (-1: not run)
  int merges = 0;             // merges kept
  int refits = 0;             // refits tried (kept or not)
  int evaluations = 0;        // of every refit
  std::vector<double> x;      // per zone, its group's log E of the last kept refit
                              // (empty: no merge kept, the regularised x stands)
  double misfit = -1.0;       // data cost at x
};

// Preconditions: options valid; lower, upper and x with data->num_parameters()
// entries, lower < upper; target_misfit >= 0 (scaled like the data cost).
ZoneMerge MergeNeighbouringZones(const BoundedMinimizerOptions& options, FirstOrderObjective* data,
                                 const std::vector<double>& lower, const std::vector<double>& upper,
                                 const std::vector<double>& x, double target_misfit);

}  // namespace mcrewave
