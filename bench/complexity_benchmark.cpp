// The complexity study of the paper's Table 1 and Fig. 5: the multiply-accumulates
// (MACs) and the time every coupled solver spends on the paper's case (bar of
// 1 m, h = 0.36 us, 1750 steps, theta = 1/2, default weights w_u = 0.01, w_f = 1,
// noisy data at SNR 10, trial modulus 0.9 E_ref, tolerance 1e-8) against the number
// n of degrees of freedom (nodes), and the paper's Table 1 formulas at the same n.
//
// MACs: the Riccati and shooting solvers count theirs as they run
// (summary.multiply_accumulates); the sweep-based solvers are counted from their
// sweeps, inner products and field updates (operation_counts.h, loop structure of
// iterative_coupled_solvers.cpp); the all-at-once solver (Eigen's supernodal
// SparseLU) is timed, not counted, and only up to n = 50 (17 s there).
//
// Runs whose cost at 1750 steps would exceed a budget of kMacBudget MACs are made
// at two shorter step counts m1 and 2 m1 and extrapolated linearly to 1750 steps
// (cost = a + b m: a per-window part such as the final dense solve of single
// shooting, and a per-step part); the CSV says which. Multiple shooting, whose
// segments depend on the window, runs at full length only (n <= 200).
//
// Also scans single shooting, multiple shooting and Riccati over growing windows
// (20 elements) to show where single shooting breaks down.
//
// Usage: complexity_benchmark OUTPUT_DIR [max_dofs]   (writes methods.csv,
//        paper_table1.csv, exponents.csv, shooting_breakdown.csv; prints the
//        ratios at n = 101 and the fitted exponents)

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/operation_counts.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"

namespace mcrewave {
namespace {

namespace counts = operation_counts;

constexpr int kPaperSteps = 1750;
constexpr int kPaperDofs = 101;
// Largest MAC count of one measured run at full length; above it, two shorter runs.
constexpr double kMacBudget = 1.5e10;
// Fewest steps of the shorter run of a method with a per-window cost (single shooting).
constexpr int kMinimumShortSteps = 50;
// Runs shorter than this are repeated and averaged (timer resolution, cache warm-up).
constexpr double kMinimumTimedSeconds = 0.3;
const std::vector<int> kDofs = {10, 20, 50, 101, 200, 500, 1000};
// The all-at-once sparse LU takes about 17 s at n = 50 and grows like n^2.3.
constexpr int kMaxAllAtOnceDofs = 50;
// Multiple shooting: a 4n-column march and a 6n x 4n QR per segment.
constexpr int kMaxMultipleShootingDofs = 200;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct MethodSpec {
  std::string name;  // CSV and plot label
  CoupledSolverType type;
};

const std::vector<MethodSpec> kMethods = {
    {"relaxation_fixed_omega", CoupledSolverType::kRelaxation},
    {"adaptive_relaxation", CoupledSolverType::kAdaptiveRelaxation},
    {"conjugate_gradient", CoupledSolverType::kConjugateGradient},
    {"all_at_once", CoupledSolverType::kAllAtOnce},
    {"riccati", CoupledSolverType::kRiccati},
    {"single_shooting", CoupledSolverType::kSingleShooting},
    {"multiple_shooting", CoupledSolverType::kMultipleShooting},
};

// The paper's case with n nodes: its data over 1750 steps.
struct PaperCase {
  explicit PaperCase(int dofs) : bar(Bar(dofs)), model(bar) {
    DataOptions data_options;
    data_options.snr = 10.0;
    data_options.seed = 5;
    data = MakeSyntheticMeasurements(bar, LoadOptions(), TimeOptions(), data_options);
  }
  static BarProperties Bar(int dofs) {
    BarProperties properties;
    properties.elements = dofs - 1;
    return properties;
  }
  BarProperties bar;
  BarModel model;
  ChannelSet data;
};

// The first `steps` steps of a measurement set.
ChannelSet Truncate(const ChannelSet& data, int steps) {
  ChannelSet head = data;
  head.Values("u0") = data.Values("u0").head(steps + 1);
  head.Values("uL") = data.Values("uL").head(steps + 1);
  head.Values("f0") = data.Values("f0").head(steps + 1);
  head.Values("fL") = data.Values("fL").head(steps + 1);
  return head;
}

// MACs of a sweep-based solve, from its summary: sweeps, inner products <.,.>_P
// and n (m + 1) updates of whole fields, as iterative_coupled_solvers.cpp does them
// from a zero start: 3 start-up sweeps (c = T(0) and the round-off floor's
// W_u = Retrograde(0)) and 2 inner products; then per iteration
//   relaxation:          1 inner product, 1 field update, 2 sweeps;
//   adaptive, Lanczos:   2 inner products, 3 field updates, 2 sweeps per step;
//   conjugate gradients: 2 inner products, 3 field updates, 2 sweeps, and on
//                        convergence 2 sweeps and 1 inner product of verification.
double SweepSolverMacs(const CoupledSolverSummary& summary, int n, int m) {
  constexpr int kBandwidth = 1;
  const double direct = counts::DirectSweep(n, kBandwidth, m);
  const double retrograde = counts::RetrogradeSweep(n, kBandwidth, m);
  const double inner_product = counts::InnerProduct(n, kBandwidth, m);
  const double field = static_cast<double>(n) * (m + 1.0);
  // Every sweep pair is direct + retrograde; the floor's W_u is one extra retrograde.
  const double retrograde_sweeps = (summary.sweeps + 1) / 2;
  const double direct_sweeps = summary.sweeps - retrograde_sweeps;
  const double k = summary.iterations;
  double inner_products = 2.0, field_updates = 0.0;
  switch (summary.type) {
    case CoupledSolverType::kRelaxation:
      inner_products += k + 1.0;
      field_updates += k;
      break;
    case CoupledSolverType::kAdaptiveRelaxation: {
      const double restart_sweeps = 2.0 * summary.safeguard_restarts;
      const double lanczos_steps = (summary.sweeps - 3.0 - 2.0 * k - restart_sweeps) / 2.0;
      inner_products += 1.0 + 2.0 * lanczos_steps + k + 1.0;
      field_updates += 1.0 + 3.0 * lanczos_steps + k;
      break;
    }
    case CoupledSolverType::kConjugateGradient:
      inner_products += 2.0 * k + 1.0;
      field_updates += 3.0 * k;
      break;
    default:
      return kNaN;
  }
  return direct_sweeps * direct + retrograde_sweeps * retrograde + inner_products * inner_product +
         field_updates * field;
}

struct RunResult {
  CoupledSolverSummary summary;
  double macs = kNaN;
  double seconds = kNaN;
};

RunResult RunOnce(const CoupledSolverOptions& options, const BarModel& model,
                  const ChannelSet& data, double reference_modulus) {
  const MatrixModelData matrices = BarRunModel(model, data, {});
  MatrixMcreProblem problem(matrices, data, McreWeights(), reference_modulus, 0.5);
  problem.SetModulus(0.9 * reference_modulus);
  RunResult result;
  int repeats = 0;
  double total = 0.0;
  using Clock = std::chrono::steady_clock;
  while (repeats == 0 || (total < kMinimumTimedSeconds && repeats < 20)) {
    CoupledSolution solution;
    const auto start = Clock::now();
    result.summary = SolveCoupled(options, &problem, nullptr, &solution);
    total += std::chrono::duration<double>(Clock::now() - start).count();
    ++repeats;
  }
  result.seconds = total / repeats;
  const int n = model.num_nodes(), m = data.num_steps();
  switch (options.type) {
    case CoupledSolverType::kRelaxation:
    case CoupledSolverType::kAdaptiveRelaxation:
    case CoupledSolverType::kConjugateGradient:
      result.macs = SweepSolverMacs(result.summary, n, m);
      break;
    case CoupledSolverType::kAllAtOnce:
      break;
    default:
      result.macs = result.summary.multiply_accumulates;
  }
  return result;
}

// Estimated MACs per step and per window of the dense methods (section 2 and 3 of
// docs/riccati_shooting.md), to plan their runs only.
double PlannedMacs(CoupledSolverType type, int n, int steps) {
  const double nn = n;
  switch (type) {
    case CoupledSolverType::kRiccati:
      return steps * (6.4 * nn * nn * nn + 120.0 * nn * nn);
    case CoupledSolverType::kSingleShooting:
      return steps * 90.0 * nn * nn + 22.0 * nn * nn * nn;
    default:
      return 0.0;
  }
}

struct Measurement {
  std::string method;
  int dofs = 0;
  int first_steps = 0, second_steps = 0;  // second_steps > 0: extrapolated from two runs
  double macs = kNaN, seconds = kNaN;     // at 1750 steps
  CoupledSolverSummary summary;           // of the run at the most steps
  std::string note;
};

// Solves with `options` at 1750 steps, or at m1 and 2 m1 steps and extrapolates.
Measurement Measure(const MethodSpec& method, const CoupledSolverOptions& options,
                    const PaperCase& paper) {
  Measurement measurement;
  measurement.method = method.name;
  measurement.dofs = paper.model.num_nodes();
  const int n = measurement.dofs;
  const double full = PlannedMacs(method.type, n, kPaperSteps);
  if (full <= kMacBudget) {
    const RunResult run = RunOnce(options, paper.model, paper.data, paper.bar.modulus);
    measurement.first_steps = kPaperSteps;
    measurement.macs = run.macs;
    measurement.seconds = run.seconds;
    measurement.summary = run.summary;
    return measurement;
  }
  // Two runs of m1 and 2 m1 steps within the budget: 3 m1 per-step costs.
  const double per_step = PlannedMacs(method.type, n, 1) - PlannedMacs(method.type, n, 0);
  const double per_window = PlannedMacs(method.type, n, 0);
  // At least kMinimumShortSteps steps when a per-window part exists, so that the
  // per-step part of the time stands out of the timing noise.
  const int minimum = per_window > 0.0 ? kMinimumShortSteps : 4;
  const int m1 =
      std::max(minimum, static_cast<int>((kMacBudget - 2.0 * per_window) / (3.0 * per_step)));
  const RunResult first =
      RunOnce(options, paper.model, Truncate(paper.data, m1), paper.bar.modulus);
  const RunResult second =
      RunOnce(options, paper.model, Truncate(paper.data, 2 * m1), paper.bar.modulus);
  // cost(m) = a + b m through the two runs, evaluated at m = 1750.
  auto extrapolate = [&](double at_m1, double at_m2) {
    const double slope = (at_m2 - at_m1) / m1;
    return at_m1 + slope * (kPaperSteps - m1);
  };
  measurement.first_steps = m1;
  measurement.second_steps = 2 * m1;
  measurement.macs = extrapolate(first.macs, second.macs);
  measurement.seconds = extrapolate(first.seconds, second.seconds);
  measurement.summary = second.summary;
  return measurement;
}

// The paper's Table 1 (MACs), m steps, n dofs, k relaxation iterations.
double PaperRiccati(double n, double m) {
  return m * (std::pow(n, 4) + 16 * std::pow(n, 3) + 68 * n * n + 86 * n + 15) + std::pow(n, 4) +
         98.0 / 3.0 * std::pow(n, 3) + 121 * n * n + 132 * n + 25;
}
double PaperShooting(double n, double m) {
  return m * (320 * std::pow(n, 3) + 160 * n * n + 42 * n + 5) + 256 * std::pow(n, 4) +
         128 * std::pow(n, 3) + 56 * n * n + 2 * n + 12;
}
double PaperRelaxation(double n, double m, double k) {
  return k * (42 * n * n * m + 7 * n * m - 24 * n * n + 1);
}

// Least-squares slope of log y against log x over the points with x >= x_min.
double FittedExponent(const std::vector<std::pair<double, double>>& points, double x_min) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (const auto& [x, y] : points) {
    if (x < x_min || !(y > 0.0) || !std::isfinite(y)) continue;
    const double lx = std::log(x), ly = std::log(y);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    ++count;
  }
  if (count < 2) return kNaN;
  return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

std::string Number(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}

// Single shooting, multiple shooting and Riccati over growing windows on 20 elements
// at the paper's Courant number (c h / h_e = 0.57), SNR 5, trial modulus 0.9 E_ref,
// default tolerance 1e-8.
std::string ShootingBreakdownScan() {
  struct Window {
    double w_u, theta;
    int steps;
  };
  const std::vector<Window> windows = {
      {0.01, 0.5, 200}, {0.01, 0.5, 800}, {0.01, 0.5, 1600}, {0.01, 0.5, 3200}, {0.01, 0.5, 6400},
      {1.0, 0.5, 200},  {1.0, 0.5, 400},  {1.0, 0.5, 800},   {1.0, 0.5, 1600},  {1.0, 0.5, 3200},
      {1.0, 0.75, 20},  {1.0, 0.75, 40},  {1.0, 0.75, 200}};
  std::ostringstream csv;
  csv << "w_u,theta,steps,window_over_paper,method,termination,condition_number,segments,"
         "relative_residual\n";
  std::printf("\nSingle shooting against the window (20 elements):\n");
  std::printf("%-5s %-5s %6s %7s | %-17s %-13s %10s %5s %10s\n", "w_u", "theta", "steps", "T/T_p",
              "method", "termination", "condition", "segs", "residual");
  for (const Window& window : windows) {
    constexpr int kElements = 20;
    BarProperties bar;
    bar.elements = kElements;
    TimeOptions time;
    time.step = 0.36e-6 * 100.0 / kElements;
    time.window = time.step * window.steps;
    time.theta = window.theta;
    LoadOptions load;
    load.duration = 1e-4 * time.window / 0.63e-3;
    DataOptions data_options;
    data_options.snr = 5.0;
    data_options.seed = 7;
    data_options.truth_refinement = 2;
    const BarModel model(bar);
    const ChannelSet data = MakeSyntheticMeasurements(bar, load, time, data_options);
    McreWeights weights;
    weights.displacement_weight = window.w_u;
    const MatrixModelData matrices = BarRunModel(model, data, {});
    MatrixMcreProblem problem(matrices, data, weights, bar.modulus, window.theta);
    problem.SetModulus(0.9 * bar.modulus);
    for (CoupledSolverType type :
         {CoupledSolverType::kSingleShooting, CoupledSolverType::kMultipleShooting,
          CoupledSolverType::kRiccati}) {
      CoupledSolverOptions options;
      options.type = type;
      CoupledSolution solution;
      const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &solution);
      const double ratio = time.window / 0.63e-3;
      std::printf("%-5g %-5g %6d %7.2f | %-17s %-13s %10.3g %5d %10.3g\n", window.w_u, window.theta,
                  window.steps, ratio, CoupledSolverTypeToString(type),
                  TerminationTypeToString(summary.termination), summary.shooting_condition_number,
                  summary.shooting_segments, summary.relative_residual);
      csv << window.w_u << ',' << window.theta << ',' << window.steps << ',' << Number(ratio) << ','
          << CoupledSolverTypeToString(type) << ',' << TerminationTypeToString(summary.termination)
          << ',' << Number(summary.shooting_condition_number) << ',' << summary.shooting_segments
          << ',' << Number(summary.relative_residual) << '\n';
    }
  }
  return csv.str();
}

// methods.csv: one row per measurement that ran.
std::string MethodsCsv(const std::vector<Measurement>& measurements) {
  std::ostringstream methods_csv;
  methods_csv << "method,dofs,steps_run,second_steps_run,macs_at_1750,seconds_at_1750,"
                 "iterations,sweeps,termination,relative_residual,segments,condition_number,"
                 "note\n";
  for (const Measurement& m : measurements) {
    if (m.first_steps == 0) continue;
    methods_csv << m.method << ',' << m.dofs << ',' << m.first_steps << ',' << m.second_steps << ','
                << Number(m.macs) << ',' << Number(m.seconds) << ',' << m.summary.iterations << ','
                << m.summary.sweeps << ',' << TerminationTypeToString(m.summary.termination) << ','
                << Number(m.summary.relative_residual) << ',' << m.summary.shooting_segments << ','
                << Number(m.summary.shooting_condition_number) << ",\"" << m.note << "\"\n";
  }
  return methods_csv.str();
}

// Fitted growth exponents in n, over n >= 50 (asymptotic) and over all n, printed
// with the paper's Table 1's; returns exponents.csv.
std::string FittedExponentsCsv(const std::vector<Measurement>& measurements) {
  std::map<std::string, std::vector<std::pair<double, double>>> macs_points, seconds_points;
  for (const Measurement& m : measurements) {
    if (m.first_steps == 0) continue;
    macs_points[m.method].push_back({m.dofs, m.macs});
    seconds_points[m.method].push_back({m.dofs, m.seconds});
  }
  std::ostringstream exponents_csv;
  exponents_csv << "method,points,macs_exponent_n_ge_50,seconds_exponent_n_ge_50,"
                   "macs_exponent_all,seconds_exponent_all\n";
  std::printf("\nFitted exponents p in cost ~ n^p (n >= 50; all n):\n");
  for (const MethodSpec& method : kMethods) {
    const auto& macs = macs_points[method.name];
    const auto& seconds = seconds_points[method.name];
    const double macs50 = FittedExponent(macs, 50), seconds50 = FittedExponent(seconds, 50);
    const double macs_all = FittedExponent(macs, 0), seconds_all = FittedExponent(seconds, 0);
    std::printf("  %-22s MACs %5.2f (%5.2f)   seconds %5.2f (%5.2f)   [%zu points]\n",
                method.name.c_str(), macs50, macs_all, seconds50, seconds_all, seconds.size());
    exponents_csv << method.name << ',' << seconds.size() << ',' << Number(macs50) << ','
                  << Number(seconds50) << ',' << Number(macs_all) << ',' << Number(seconds_all)
                  << '\n';
  }
  std::printf("  paper Table 1: Riccati %.2f, shooting %.2f, relaxation %.2f (at fixed k)\n",
              FittedExponent({{50, PaperRiccati(50, 1750)}, {1000, PaperRiccati(1000, 1750)}}, 0),
              FittedExponent({{50, PaperShooting(50, 1750)}, {1000, PaperShooting(1000, 1750)}}, 0),
              FittedExponent(
                  {{50, PaperRelaxation(50, 1750, 1)}, {1000, PaperRelaxation(1000, 1750, 1)}}, 0));
  return exponents_csv.str();
}

// The ratios to conjugate gradients at the paper's size n = 101, and the paper's
// Table 1 ratios beside ours, on stdout.
void PrintRatiosAtPaperSize(const std::vector<Measurement>& measurements) {
  std::map<std::pair<std::string, int>, const Measurement*> by_key;
  for (const Measurement& m : measurements) by_key[{m.method, m.dofs}] = &m;
  auto at_paper = [&](const std::string& name) -> const Measurement* {
    auto it = by_key.find({name, kPaperDofs});
    return it == by_key.end() || it->second->first_steps == 0 ? nullptr : it->second;
  };
  const Measurement* krylov = at_paper("conjugate_gradient");
  if (krylov != nullptr) {
    std::printf(
        "\nRatios to conjugate gradients (Krylov) at n = %d, 1750 steps "
        "(CG: %d iterations, %.3g MACs, %.3g s):\n",
        kPaperDofs, krylov->summary.iterations, krylov->macs, krylov->seconds);
    for (const MethodSpec& method : kMethods) {
      const Measurement* m = at_paper(method.name);
      if (m == nullptr) continue;
      std::printf("  %-22s MACs x %8.3g   seconds x %8.3g\n", method.name.c_str(),
                  m->macs / krylov->macs, m->seconds / krylov->seconds);
    }
    const Measurement* relaxation = at_paper("relaxation_fixed_omega");
    if (relaxation != nullptr) {
      const double k = relaxation->summary.iterations;
      const double paper_relaxation = PaperRelaxation(kPaperDofs, kPaperSteps, k);
      std::printf(
          "  paper's Table 1 at n = %d, k = %.0f: Riccati / relaxation %.3g, "
          "shooting / relaxation %.3g\n",
          kPaperDofs, k, PaperRiccati(kPaperDofs, kPaperSteps) / paper_relaxation,
          PaperShooting(kPaperDofs, kPaperSteps) / paper_relaxation);
      std::printf(
          "  ours at n = %d: Riccati / relaxation %.3g, single shooting / relaxation "
          "%.3g (MACs)\n",
          kPaperDofs, at_paper("riccati") ? at_paper("riccati")->macs / relaxation->macs : kNaN,
          at_paper("single_shooting") ? at_paper("single_shooting")->macs / relaxation->macs
                                      : kNaN);
    }
  }
}

// One method at n = dofs on the paper's case: measured, or not run beyond its budget;
// the fixed-omega relaxation (0.9 times the omega of an adaptive solve run first) sets
// relaxation_iterations.
Measurement MeasureMethodAt(const MethodSpec& method, const PaperCase& paper, int dofs,
                            int* relaxation_iterations) {
  CoupledSolverOptions options;
  options.type = method.type;
  options.max_iterations = 20000;
  Measurement measurement;
  measurement.method = method.name;
  measurement.dofs = dofs;
  const long all_at_once_unknowns = 5L * dofs * (kPaperSteps + 1);
  if (method.type == CoupledSolverType::kRelaxation) {
    // The paper's method with a fixed omega: 0.9 times the adaptive choice, from
    // an adaptive solve run first.
    CoupledSolverOptions adaptive = options;
    adaptive.type = CoupledSolverType::kAdaptiveRelaxation;
    const double adaptive_omega = RunOnce(adaptive, paper.model, paper.data, paper.bar.modulus)
                                      .summary.relaxation_coefficient;
    options.relaxation_coefficient = 0.9 * adaptive_omega;
    measurement = Measure(method, options, paper);
    *relaxation_iterations = measurement.summary.iterations;
    measurement.note = "omega = 0.9 x adaptive = " + Number(0.9 * adaptive_omega);
  } else if (method.type == CoupledSolverType::kAllAtOnce &&
             (all_at_once_unknowns > options.max_all_at_once_unknowns ||
              dofs > kMaxAllAtOnceDofs)) {
    measurement.note = "not run: " + std::to_string(all_at_once_unknowns) +
                       " unknowns, beyond the time budget of the sparse LU";
  } else if (method.type == CoupledSolverType::kMultipleShooting &&
             dofs > kMaxMultipleShootingDofs) {
    measurement.note = "not run: 4n-column march and 4n x 4n QR per segment beyond budget";
  } else {
    options.max_dense_solver_bytes = 8L << 30;
    options.max_all_at_once_bytes = 8L << 30;
    measurement = Measure(method, options, paper);
  }
  if (measurement.second_steps > 0) {
    measurement.note = "extrapolated from " + std::to_string(measurement.first_steps) + " and " +
                       std::to_string(measurement.second_steps) + " steps";
  }
  if (method.type == CoupledSolverType::kAllAtOnce) {
    measurement.note += measurement.note.empty() ? "" : "; ";
    measurement.note += "MACs not counted (Eigen SparseLU)";
  }
  return measurement;
}

// One measurement's line of the table on stdout.
void PrintMeasurement(const MethodSpec& method, int dofs, const Measurement& measurement) {
  const bool ran = measurement.first_steps > 0;
  std::printf("%-22s %5d %11s %10.3g %10.3g %6d %7ld %-14s %s\n", method.name.c_str(), dofs,
              ran ? (measurement.second_steps > 0 ? (std::to_string(measurement.first_steps) + "+" +
                                                     std::to_string(measurement.second_steps))
                                                        .c_str()
                                                  : "1750")
                  : "-",
              measurement.macs, measurement.seconds, measurement.summary.iterations,
              measurement.summary.sweeps,
              ran ? TerminationTypeToString(measurement.summary.termination) : "not_run",
              measurement.note.c_str());
  std::fflush(stdout);
}

int Run(const std::string& output_dir, int max_dofs) {
  std::vector<Measurement> measurements;
  std::ostringstream table1;
  table1 << "dofs,steps,relaxation_iterations,paper_riccati_macs,paper_shooting_macs,"
            "paper_relaxation_macs\n";
  std::printf("%-22s %5s %11s %10s %10s %6s %7s %-14s\n", "method", "n", "steps", "MACs", "seconds",
              "iter", "sweeps", "termination");
  for (int dofs : kDofs) {
    if (dofs > max_dofs) break;
    const PaperCase paper(dofs);
    int relaxation_iterations = -1;
    for (const MethodSpec& method : kMethods) {
      const Measurement measurement = MeasureMethodAt(method, paper, dofs, &relaxation_iterations);
      PrintMeasurement(method, dofs, measurement);
      measurements.push_back(measurement);
    }
    table1 << dofs << ',' << kPaperSteps << ',' << relaxation_iterations << ','
           << Number(PaperRiccati(dofs, kPaperSteps)) << ','
           << Number(PaperShooting(dofs, kPaperSteps)) << ','
           << Number(PaperRelaxation(dofs, kPaperSteps, relaxation_iterations)) << '\n';
  }
  const std::string methods_csv = MethodsCsv(measurements);
  const std::string exponents_csv = FittedExponentsCsv(measurements);
  PrintRatiosAtPaperSize(measurements);

  const std::string breakdown = ShootingBreakdownScan();
  WriteFileAtomically(output_dir + "/methods.csv", methods_csv);
  WriteFileAtomically(output_dir + "/paper_table1.csv", table1.str());
  WriteFileAtomically(output_dir + "/exponents.csv", exponents_csv);
  WriteFileAtomically(output_dir + "/shooting_breakdown.csv", breakdown);
  return 0;
}

}  // namespace
}  // namespace mcrewave

static int BenchmarkMain(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR [max_dofs]\n", argv[0]);
    return 2;
  }
  const int max_dofs = argc > 2 ? std::atoi(argv[2]) : 1000;
  return mcrewave::Run(argv[1], max_dofs);
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
