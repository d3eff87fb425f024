#include "mcrewave/app/results.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcrewave/app/zones_csv.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"
#include "mcrewave/core/version.h"
#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave {
namespace {

// The meaning of the uncertainty figure, written beside it.
constexpr const char* kUncertaintyMeaning =
    "first-order standard deviation of the identified E under fresh white measurement noise of "
    "the levels below: std over the noise draws of -dg/k, dg the change of de^2/dE at E caused "
    "by one draw, k the slope of de^2/dE over E +- 5 %; indicative only when it is not small "
    "against that 5 %";

// The shortest decimal text that reads back as exactly `value` ("null" for NaN,
// ".inf" for infinities, YAML spelling).
std::string Format(double value) { return FormatNumber(value, kYamlRoundTrip); }
// A CSV value of the bar's results: every digit a double needs (%.17g).
std::string CsvNumber(double value) { return FormatNumber(value, kSeventeenDigits); }

std::string Quoted(const std::string& text) {
  YAML::Emitter emitter;
  emitter << YAML::DoubleQuoted << text;
  return emitter.c_str();
}

// YAML lines "key: value  # comment", the comments aligned per block.
class YamlWriter {
 public:
  void Line(int indent, const std::string& key, const std::string& value,
            const std::string& comment = "") {
    lines_.push_back(
        {std::string(2 * indent, ' ') + key + ":" + (value.empty() ? "" : " " + value), comment});
  }
  void Number(int indent, const std::string& key, double value, const std::string& comment = "") {
    Line(indent, key, Format(value), comment);
  }
  void Integer(int indent, const std::string& key, long value, const std::string& comment = "") {
    Line(indent, key, std::to_string(value), comment);
  }
  void Text(int indent, const std::string& key, const std::string& value,
            const std::string& comment = "") {
    Line(indent, key, Quoted(value), comment);
  }
  void Raw(const std::string& text) { lines_.push_back({text, ""}); }

  std::string str() const {
    // Comments aligned after the longest commented line of at most kAlignLimit
    // characters; longer lines keep theirs two spaces after the text.
    constexpr std::size_t kAlignLimit = 60;
    std::size_t width = 0;
    for (const auto& [text, comment] : lines_) {
      if (!comment.empty() && text.size() <= kAlignLimit) width = std::max(width, text.size());
    }
    std::string out;
    for (const auto& [text, comment] : lines_) {
      out += text;
      if (!comment.empty()) {
        out += std::string(text.size() < width ? width - text.size() + 2 : 2, ' ') + "# " + comment;
      }
      out += "\n";
    }
    return out;
  }

 private:
  std::vector<std::pair<std::string, std::string>> lines_;
};

// ---------------------------------------------------------------------------
// CSV files.

std::string EvaluationsCsv(const ModulusStage& run) {
  std::string csv =
      "evaluation,modulus,cost,cost_gradient,gradient_requested,usable,inner_iterations,sweeps,"
      "relative_residual\n";
  for (std::size_t i = 0; i < run.evaluations.size(); ++i) {
    const ObjectiveEvaluation& e = run.evaluations[i];
    csv += std::to_string(i + 1) + ',' + CsvNumber(e.modulus) + ',' +
           CsvNumber(e.usable ? e.cost : NAN) + ',' + CsvNumber(e.usable ? e.cost_gradient : NAN) +
           ',' + (e.gradient_requested ? "1," : "0,") + (e.usable ? "1," : "0,") +
           std::to_string(e.inner.iterations) + ',' + std::to_string(e.inner.sweeps) + ',' +
           FormatNumber(e.inner.relative_residual, kSixDigits) + '\n';
  }
  return csv;
}

std::string CostCurveCsv(const std::vector<CostCurvePoint>& curve) {
  std::string csv = "modulus,cost,cost_gradient,usable\n";
  for (const CostCurvePoint& point : curve) {
    csv += CsvNumber(point.modulus) + ',' + CsvNumber(point.usable ? point.cost : NAN) + ',' +
           CsvNumber(point.usable ? point.cost_gradient : NAN) + (point.usable ? ",1\n" : ",0\n");
  }
  return csv;
}

// Measured and model channels at both ends (run.model_channels: F_L = fL~ - W_L / alpha,
// at x = 0 the clamp's load or reaction); a model column the run has not (an end
// displacement not in use, after a streaming solve) is left empty.
std::string EndsCsv(const IdentificationRun& run) {
  const ChannelSet& data = run.data;
  std::string csv =
      "t,u0_measured,u0_model,uL_measured,uL_model,f0_measured,f0_model,fL_measured,fL_model\n";
  const BarEnds measured = BarEndChannels(data);
  const Vector* measured_columns[] = {&measured.u0, &measured.uL, &measured.f0, &measured.fL};
  const Vector* model_columns[4] = {};
  const char* names[] = {"u0", "uL", "f0", "fL"};
  for (int c = 0; c < 4; ++c) {
    const int found = run.model_channels.Find(names[c]);
    if (found >= 0) {
      model_columns[c] = &run.model_channels.channels[static_cast<std::size_t>(found)].values;
    }
  }
  for (int j = 0; j < data.num_samples(); ++j) {
    csv += CsvNumber(data.Time(j));
    for (int c = 0; c < 4; ++c) {
      csv += ',' + CsvNumber((*measured_columns[c])[j]) + ',';
      if (model_columns[c] != nullptr) csv += CsvNumber((*model_columns[c])[j]);
    }
    csv += '\n';
  }
  return csv;
}

// The relative residual per iteration of the solve from W = 0 at the identified
// E; for the direct solvers (no iteration history) their one final residual.
std::vector<double> InnerResidualHistory(const ModulusStage& run) {
  const CoupledSolverSummary& inner = run.cold_solve;
  if (!inner.residual_history.empty()) return inner.residual_history;
  if (inner.relative_residual >= 0.0) return {inner.relative_residual};
  return {};
}

std::string InnerResidualCsv(const ModulusStage& run) {
  std::string csv = "iteration,relative_residual\n";
  const std::vector<double> history = InnerResidualHistory(run);
  for (std::size_t i = 0; i < history.size(); ++i) {
    csv += std::to_string(i + 1) + ',' + CsvNumber(history[i]) + '\n';
  }
  return csv;
}

// The global scan: cost = scaled cost x J_rest and its gradient d cost/dE at each scan
// modulus (solved at outer.scan_tolerance); usable 0 where the sample's solve failed.
// cost_scale: J_rest of the functional scanned (e^2's, or the search functional's);
// modulus_scale: its E_scale (outer.initial).
std::string ScanCsv(const IdentificationSummary& outer, double cost_scale, double modulus_scale) {
  std::string csv = "modulus,cost,cost_gradient,usable\n";
  // de^2/dE = (d cost/dx) J_rest / E_scale.
  const double gradient_scale = cost_scale / modulus_scale;
  for (std::size_t i = 0; i < outer.scan_moduli.size(); ++i) {
    const bool usable = std::isfinite(outer.scan_costs[i]);
    csv += CsvNumber(outer.scan_moduli[i]) + ',' +
           CsvNumber(usable ? outer.scan_costs[i] * cost_scale : 0.0) + ',' +
           CsvNumber(usable ? outer.scan_gradients[i] * gradient_scale : 0.0) +
           (usable ? ",1\n" : ",0\n");
  }
  return csv;
}

// Every valley of the scan: its bracket, the estimate, and the refined minimum
// (e^2 in J s; refined 0 and modulus/cost empty when it was not refined).
std::string ValleysCsv(const IdentificationSummary& outer, double cost_scale) {
  std::string csv =
      "valley,lower_modulus,upper_modulus,estimated_modulus,estimated_cost,refined,modulus,cost,"
      "evaluations\n";
  int index = 0;
  for (const ScanValley& valley : outer.valleys) {
    csv += std::to_string(++index) + ',' + CsvNumber(valley.lower_modulus) + ',' +
           CsvNumber(valley.upper_modulus) + ',' + CsvNumber(valley.estimated_modulus) + ',' +
           CsvNumber(valley.estimated_cost * cost_scale) + (valley.refined ? ",1," : ",0,");
    if (valley.refined) {
      csv += CsvNumber(valley.modulus) + ',' + CsvNumber(valley.cost * cost_scale) + ',' +
             std::to_string(valley.evaluations) + '\n';
    } else {
      csv += ",,0\n";
    }
  }
  return csv;
}

// ---------------------------------------------------------------------------
// Figures.

// The gnuplot plot items of scan.csv and valleys.csv (E in GPa), each ending in ", ".
// search: the scan is of the search functional, drawn on the right axis.
std::string ScanPlots(const std::string& folder, bool search) {
  const std::string axes = search ? " axes x1y2" : "";
  const std::string of = search ? " of e^2_{search} (right axis)" : "";
  return GnuplotString(folder + "/scan.csv") + " skip 1 using ($1/1e9):($4 > 0 ? $2 : 1/0)" + axes +
         " with linespoints pt 5 ps 0.6 lc rgb '#2ca02c' title 'global scan" + of + "', " +
         GnuplotString(folder + "/valleys.csv") + " skip 1 using ($4/1e9):5" + axes +
         " with points pt 9 ps 1.6 lc rgb '#ff7f0e' title 'valleys seen (estimate)', " +
         GnuplotString(folder + "/valleys.csv") + " skip 1 using ($6 > 0 ? $7/1e9 : 1/0):8" + axes +
         " with points pt 4 ps 2 lw 2 lc rgb '#1f77b4' title 'valleys refined', ";
}

std::string CostCurveScript(const ModulusStage& run, const Config& config,
                            const std::string& folder) {
  const double identified = run.identified_modulus() / 1e9;
  const std::string curve = GnuplotString(folder + "/cost_curve.csv");
  const std::string evaluations = GnuplotString(folder + "/evaluations.csv");
  std::ostringstream script;
  script
      << GnuplotPngTerminal() << "set terminal pngcairo size 1000,1000\n"
      << "set multiplot layout 2,1 title 'MCRE cost curve e^2(E); identified E = " << identified
      << " GPa (dashed)'\n"
      << "set xlabel 'E [GPa]'\nset ylabel 'e^2 [J s]'\nset format y '%.5g'\nset key top center\n"
      << "set arrow 1 from " << identified << ", graph 0 to " << identified
      << ", graph 1 nohead dashtype 2 lc rgb '#555555'\n";
  // Top: the global scan over the bounds with the refinement (or, without a scan,
  // everything computed); bottom: the window E* +- 5 % where the uncertainty's k
  // is fitted.
  const double low = identified * (1.0 - kCurvatureWindow);
  const double high = identified * (1.0 + kCurvatureWindow);
  const IdentificationSummary& outer = run.outer;
  const bool scanned = !outer.scan_moduli.empty();
  // The scan's samples and the valleys it saw (estimates; refined minima), on both
  // panels: the bottom one shows the valleys near E* that the top one's scale hides.
  const std::string scan_plot = scanned ? ScanPlots(folder, outer.scan_of_search) : std::string();
  if (outer.scan_of_search) {
    script << "set y2label 'e^2_{search} [J s] (search: functional)'\nset y2tics\n"
           << "set format y2 '%.5g'\nset ytics nomirror\n";
  }
  for (int panel = 0; panel < 2; ++panel) {
    if (panel == 0 && scanned) {
      // Bounds over a decade or more: log E, as the scan is spaced.
      if (outer.scan_moduli.back() >= 10.0 * outer.scan_moduli.front())
        script << "set logscale x\n";
      script << "set title 'global scan over the bounds (inner tolerance "
             << config.outer.scan_tolerance << "), its valleys and the local refinements'\n";
    } else if (panel == 0) {
      script << "set title 'over the optimiser evaluations'\n";
    } else {
      script << "unset logscale x\nset title 'within 5 % of the identified E'\nset xrange [" << low
             << ":" << high << "]\n";
    }
    script << "plot " << scan_plot;
    // Without a cost curve (a structure of several zones), the scan and the evaluations.
    if (!run.cost_curve.empty()) {
      script << curve
             << " skip 1 using ($1/1e9):($4 > 0 ? $2 : 1/0) with linespoints pt 7 ps 0.5 lw 2 lc "
                "rgb '#8b00c9' title 'e^2(E), cost curve', ";
    }
    script << evaluations
           << " skip 1 using ($2/1e9):($6 > 0 ? $3 : 1/0) with points pt 6 ps 1.5 lc rgb 'red' "
              "title 'optimiser evaluations'\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

std::string EndsScript(const IdentificationRun& run, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/ends.csv");
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1200,900\nset multiplot layout 2,2 "
         << "title 'Measured and model end quantities at the identified modulus'\n"
         << "set xlabel 't [ms]'\n";
  struct Panel {
    const char* title;
    const char* unit;
    int measured;  // column of the measured value
    double scale;
  };
  const Panel panels[] = {{"u_0 (x = 0)", "u [um]", 2, 1e6},
                          {"u_L (x = L)", "u [um]", 4, 1e6},
                          {"f_0 (x = 0, clamp reaction)", "f [N]", 6, 1.0},
                          {"f_L (x = L, load)", "f [N]", 8, 1.0}};
  for (const Panel& panel : panels) {
    script << "set title '" << panel.title << "'\nset ylabel '" << panel.unit << "'\n"
           << "plot " << csv << " skip 1 using ($1*1e3):($" << panel.measured << "*" << panel.scale
           << ") with lines lc rgb '#aaaaaa' title '"
           << (run.config.prefilter.enabled ? "measured, pre-filtered" : "measured") << "', " << csv
           << " skip 1 using ($1*1e3):($" << panel.measured + 1 << "*" << panel.scale
           << ") with lines lw 2 lc rgb '#1f4e9c' title 'model'\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

// summary.yaml's comment on inner.method: why auto chose the solver that ran on `dofs`
// dofs and `steps` steps ("" when the config named it).
std::string InnerMethodComment(CoupledSolverType method, const Config& config, double dofs,
                               double steps) {
  if (config.inner.type != CoupledSolverType::kAuto) return "";
  const double bytes = IterativeSolverFieldBytes(dofs, steps);
  std::ostringstream comment;
  comment << "inner.method auto: the stored fields, " << static_cast<long long>(bytes) << " bytes, "
          << (method == CoupledSolverType::kStreamingConjugateGradient ? "exceed" : "fit")
          << " inner.max_field_bytes";
  return comment.str();
}

std::string InnerResidualScript(const ModulusStage& run, const Config& config,
                                const std::string& folder) {
  // The method's name with spaces for underscores (gnuplot's subscripts).
  std::string method = CoupledSolverTypeToString(run.inner_method);
  if (config.inner.type == CoupledSolverType::kAuto) method = "auto: " + method;
  std::replace(method.begin(), method.end(), '_', ' ');
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set title 'Inner solver (" << method
         << "): relative residual ||c - A W||_P / ||c||_P from W = 0 at the identified "
            "modulus'\n"
            "set xlabel 'iteration (sweep pair)'\nset ylabel 'relative residual'\n"
            "set logscale y\nset format y '10^{%T}'\n"
         << "plot " << GnuplotString(folder + "/inner_residual.csv")
         << " skip 1 using 1:2 with linespoints pt 7 ps 0.6 lw 2 title 'relative residual', "
         << config.inner.tolerance << " with lines dashtype 2 lc rgb '#555555' "
         << "title 'inner.tolerance'\n";
  return script.str();
}

// The sensitivity map's two peaks (error_map.h), prefixed by `prefix` ("" or
// "nominal_"): the element where e^2 falls fastest as its modulus is lowered, and where
// it falls fastest as it is raised. Nothing when the map has no sensitivity.
// With the noise's std of every element's sensitivity (`noise_std`, empty when not
// known), each peak's value in those stds.
void SensitivityPeaksYaml(const ErrorMap& map, const std::string& prefix, const Vector& noise_std,
                          YamlWriter* yaml) {
  if (map.sensitivity.size() == 0) return;
  const bool known = noise_std.size() == map.sensitivity.size();
  const int softening = map.SofteningPeakElement(), stiffening = map.StiffeningPeakElement();
  yaml->Integer(1, prefix + "softening_peak_element", softening,
                "largest de^2/d ln E_el: e^2 falls fastest as its modulus is lowered");
  yaml->Number(1, prefix + "softening_peak_position", map.position[softening], "[m]");
  if (known) {
    // s_el / std(s_el): the peak in the noise's standard deviations.
    yaml->Number(1, prefix + "softening_peak_noise_ratio",
                 map.sensitivity[softening] / noise_std[softening],
                 "its value over its std under the noise, E held (docs/boundaries.md "
                 "section 11)");
  }
  yaml->Integer(1, prefix + "stiffening_peak_element", stiffening,
                "smallest de^2/d ln E_el: e^2 falls fastest as its modulus is raised");
  yaml->Number(1, prefix + "stiffening_peak_position", map.position[stiffening], "[m]");
  if (known) {
    yaml->Number(1, prefix + "stiffening_peak_noise_ratio",
                 map.sensitivity[stiffening] / noise_std[stiffening], "the same");
  }
}

}  // namespace

std::string ErrorMapCsv(const IdentificationRun& run) {
  const ErrorMap& map = run.error_map;
  const Vector fractions = map.Fractions();
  const bool sensitivity = map.sensitivity.size() == map.share.size();
  const Vector& noise_std = run.uncertainty.sensitivity_std;
  const bool known = sensitivity && noise_std.size() == map.share.size();
  std::string csv = "element,x,share,fraction";
  csv += sensitivity ? ",sensitivity" : "";
  csv += known ? ",sensitivity_noise_std\n" : "\n";
  for (Eigen::Index e = 0; e < map.share.size(); ++e) {
    csv += std::to_string(e) + "," + Format(map.position[e]) + "," + Format(map.share[e]) + "," +
           Format(fractions[e]);
    if (sensitivity) csv += "," + Format(map.sensitivity[e]);
    if (known) csv += "," + Format(noise_std[e]);
    csv += "\n";
  }
  return csv;
}

// gnuplot's nonuniform matrix: first row the count and the x of each column, then
// one row per time: t, then the densities.
std::string SpaceTimeDataOf(const ErrorMap& map) {
  std::string text = std::to_string(map.density_position.size());
  for (Eigen::Index c = 0; c < map.density_position.size(); ++c) {
    text += " " + Format(map.density_position[c]);
  }
  text += "\n";
  for (Eigen::Index i = 0; i < map.times.size(); ++i) {
    text += Format(map.times[i]);
    for (Eigen::Index e = 0; e < map.density.cols(); ++e) text += " " + Format(map.density(i, e));
    text += "\n";
  }
  return text;
}

std::string ErrorMapSpaceTimeData(const IdentificationRun& run) {
  return SpaceTimeDataOf(run.error_map);
}

std::string ErrorMapScript(const IdentificationRun& run, const std::string& folder) {
  // The sensitivity and the space-time panels when the map has them.
  const bool space_time = run.error_map.density.size() > 0;
  const bool sensitivity = run.error_map.sensitivity.size() > 0;
  const int panels = 1 + (space_time ? 1 : 0) + (sensitivity ? 1 : 0);
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1100," << 450 * panels
         << "\nset multiplot layout " << panels
         << ",1 title 'MCRE error map at the identified E = " << run.identified_modulus() / 1e9
         << " GPa'\n"
         << "set xlabel 'x [m]'\nset ylabel 'share of the constitutive gap'\nset grid\n"
         << "set xrange [0:" << run.config.model.length << "]\n"
         << "set title 'e_{el}^2 / sum e_{el}^2 per element'\n"
         << "plot " << GnuplotString(folder + "/error_map.csv")
         << " skip 1 using 2:4 with boxes fill solid 0.6 lc rgb '#1f4e9c' notitle\n";
  if (sensitivity) {
    script
        << "set title 'sensitivity de^2/d ln E_{el} per element: > 0 where a softer element "
           "lowers e^2'\n"
        << "set ylabel 'de^2/d ln E_{el} [J s]'\n"
        << "plot " << GnuplotString(folder + "/error_map.csv")
        << " skip 1 using 2:5 with boxes fill solid 0.6 lc rgb '#b2182b' title 'de^2/d ln E_{el}'";
    if (run.uncertainty.sensitivity_std.size() == run.error_map.sensitivity.size()) {
      // +- 3 std of the noise's part, E held.
      script << ", '' skip 1 using 2:(3*$6) with lines lc rgb '#333333' dashtype 2 "
                "title '+- 3 std of the noise', '' skip 1 using 2:(-3*$6) with lines lc rgb "
                "'#333333' dashtype 2 notitle";
    }
    script << "\n";
  }
  if (!space_time) {
    script << "unset multiplot\n";
    return script.str();
  }
  script << "set title 'gap energy density 1/2 W^T K_{el} W / h_e [J/m] over x and t'\n"
         << "set ylabel 't [ms]'\nunset grid\nset palette rgb 21,22,23\n"
         << "set cblabel 'J/m'\nset yrange [0:" << run.config.time.window * 1e3 << "]\n"
         << "set datafile separator whitespace\n"
         << "plot " << GnuplotString(folder + "/error_map_spacetime.dat")
         << " matrix nonuniform using 1:($2*1e3):3 with image notitle\n"
         << "unset multiplot\n";
  return script.str();
}

// Every file an identification's results may hold (the MCRE, least-squares and
// matrix writers), summary.yaml first.
constexpr const char* kResultFileNames[] = {
    "summary.yaml",  "evaluations.csv", "cost_curve.csv",          "ends.csv",
    "scan.csv",      "valleys.csv",     "inner_residual.csv",      "error_map.csv",
    "fit.csv",       "zones.csv",       "error_map_spacetime.dat", "error_map_dofs.csv",
    "moduli.csv",    "ends.png",        "cost_curve.png",          "error_map.png",
    "fit.png",       "zones.png",       "inner_residual.png",      "moduli.png"};

// A results folder being filled: every file written atomically, its path kept.
class ResultsFolder {
 public:
  // Creates the folder and removes an earlier run's result files from it, its
  // summary.yaml first: the folder then holds this run's files only, and says it is
  // complete (summary.yaml) only once they are all written. Throws
  // std::runtime_error when the folder cannot be created or a file removed.
  explicit ResultsFolder(const std::string& folder) : folder_(folder) {
    std::error_code error;
    std::filesystem::create_directories(folder, error);
    if (error) throw std::runtime_error("cannot create folder " + folder + ": " + error.message());
    for (const char* name : kResultFileNames) {
      const std::string path = folder + "/" + name;
      std::filesystem::remove(path, error);
      if (error) throw std::runtime_error("cannot remove " + path + ": " + error.message());
    }
  }
  void Write(const std::string& name, const std::string& content) {
    const std::string path = folder_ + "/" + name;
    WriteFileAtomically(path, content);
    written_.push_back(path);
  }
  // Draws each (name, gnuplot script) into name.png; without gnuplot, or when a
  // figure fails, warns and goes on without it.
  void Draw(const std::vector<std::pair<std::string, std::string>>& drawings) {
    bool gnuplot_missing = false;
    const std::vector<std::string> why = DrawGnuplotFigures(folder_, drawings, &gnuplot_missing);
    if (gnuplot_missing) {
      spdlog::warn("gnuplot not found on the PATH: figures skipped (the CSV files are written)");
      return;
    }
    for (std::size_t i = 0; i < drawings.size(); ++i) {
      if (!why[i].empty()) {
        spdlog::warn("figure {}.png skipped: {}", drawings[i].first, why[i]);
        continue;
      }
      written_.push_back(folder_ + "/" + drawings[i].first + ".png");
    }
  }
  void Add(const std::vector<std::string>& paths) {
    written_.insert(written_.end(), paths.begin(), paths.end());
  }
  const std::vector<std::string>& written() const { return written_; }

 private:
  std::string folder_;
  std::vector<std::string> written_;
};

// The closing config: block of a summary, every key that applies to the model's
// kind, as resolved.
void ConfigYaml(const Config& config, YamlWriter* yaml) {
  yaml->Line(0, "config", "", "as resolved (every key that applies to model.kind)");
  std::istringstream text(AppliedConfigToYaml(config));
  for (std::string line; std::getline(text, line);) yaml->Raw("  " + line);
}

namespace {

// The prefilter: block of a summary: whether the measurements were low-passed, at which
// cut-off [Hz] and where it came from.
void PrefilterYaml(const Config& config, double prefilter_cutoff, YamlWriter* yaml) {
  yaml->Line(0, "prefilter", "", "zero-phase low-pass of the measurements (prefilter.*)");
  yaml->Line(1, "enabled", config.prefilter.enabled ? "true" : "false");
  yaml->Number(1, "cutoff_frequency", config.prefilter.enabled ? prefilter_cutoff : NAN,
               "[Hz] cut-off used (null: off)");
  yaml->Text(1, "cutoff_source",
             !config.prefilter.enabled                 ? "off"
             : config.prefilter.cutoff_frequency > 0.0 ? "config"
                                                       : "derived_from_load",
             "config: prefilter.cutoff_frequency; derived_from_load: EstimateCutoffFrequency");
}

}  // namespace

// The optimizer:, scan: and prefilter: blocks of a summary, for a cost named
// `cost` (e^2 or J) in `unit` (J s or s) whose scale is cost_scale; the scan's costs
// are scaled by scan_cost_scale (the search functional's, outer.scan_of_search).
void OptimizerScanAndPrefilterYaml(const IdentificationSummary& outer, double cost_scale,
                                   double scan_cost_scale, const Config& config,
                                   double prefilter_cutoff, const std::string& cost,
                                   const std::string& unit, YamlWriter* yaml) {
  yaml->Line(0, "optimizer", "");
  yaml->Text(1, "name", OptimizerTypeToString(outer.optimizer));
  yaml->Text(1, "algorithm", OuterAlgorithmToString(outer.algorithm));
  yaml->Text(1, "termination", TerminationTypeToString(outer.termination));
  yaml->Text(1, "message", outer.message);
  yaml->Text(1, "optimizer_message", outer.optimizer_message, "the optimiser's own words");
  yaml->Number(1, "initial_modulus", outer.initial_modulus, "[Pa]");
  yaml->Integer(1, "evaluations", outer.evaluations, "of the local refinements (scan apart)");
  yaml->Integer(1, "gradient_evaluations", outer.gradient_evaluations,
                "of which with the gradient");
  yaml->Integer(1, "iterations", outer.iterations, "Ceres iterations (-1: NLopt)");
  yaml->Number(1, "scaled_cost", outer.cost, cost + " / cost_scale at the identified modulus");
  yaml->Number(1, "cost_scale", cost_scale,
               "[" + unit + "] " + cost + " of the structure left at rest, the scale of the cost");
  yaml->Number(1, "wall_time_s", outer.wall_time_s, "[s] scan and refinements");

  const std::string scanned = outer.scan_of_search ? cost + "_search" : cost;
  yaml->Line(0, "scan", "",
             "global scan of " + scanned + " and d" + scanned +
                 "/dE over the bounds (outer.scan_*" +
                 (outer.scan_of_search ? ", search.scan_points)" : ")"));
  yaml->Text(1, "functional", outer.scan_of_search ? "search_pinned" : "same",
             "search_pinned: the search: functional, e^2_search (the pinned clamp); same: " + cost +
                 " itself");
  yaml->Number(
      1, "search_modulus", outer.search_modulus > 0.0 ? outer.search_modulus : NAN,
      "[Pa] e^2_search's minimiser, near which " + cost + " was refined (null: one stage)");
  yaml->Integer(1, "points", static_cast<long>(outer.scan_moduli.size()), "0: no scan");
  yaml->Number(1, "predicted_valley_spacing", outer.predicted_valley_spacing,
               "mean spacing of the valleys of " + scanned + " in ln E (0: not predicted)");
  yaml->Line(1, "resolution_limited", outer.scan_resolution_limited ? "true" : "false",
             "true: more samples wanted than outer.scan_max_points");
  yaml->Integer(1, "local_minima", outer.local_minima,
                "valleys of " + scanned + " seen (valleys.csv)");
  yaml->Integer(1, "failed_points", outer.scan_failures, "samples without a usable cost");
  yaml->Number(1, "second_modulus", outer.second_modulus > 0.0 ? outer.second_modulus : NAN,
               "[Pa] the second-lowest valley (null: fewer than two)");
  yaml->Number(1, "scaled_cost_gap", outer.cost_gap,
               scanned + " / its cost scale, of the second-lowest valley minus the lowest");
  yaml->Number(1, "cost_gap", outer.cost_gap * scan_cost_scale,
               "[" + unit + "] the same gap of " + scanned);
  yaml->Integer(1, "refinements", outer.refinements,
                "valleys refined (within outer.refine_margin of the lowest)");
  yaml->Line(1, "valleys", "",
             "every valley: estimate [Pa], refined minimiser [Pa] or null, " + scanned + " [" +
                 unit + "]");
  for (const ScanValley& valley : outer.valleys) {
    yaml->Raw("    - {estimate: " + Format(valley.estimated_modulus) +
              ", modulus: " + Format(valley.refined ? valley.modulus : NAN) + ", cost: " +
              Format((valley.refined ? valley.cost : valley.estimated_cost) * scan_cost_scale) +
              ", refined: " + (valley.refined ? "true" : "false") + "}");
  }
  yaml->Integer(1, "sweeps", outer.scan_sweeps, "sweeps of the scan");
  yaml->Number(1, "wall_time_s", outer.scan_wall_time_s, "[s] of the scan");

  PrefilterYaml(config, prefilter_cutoff, yaml);
}

namespace {

// The uncertainty: block of an identification's summary: the modulus' standard
// deviation, its curvature, and the noise it was drawn with, estimated and left.
void UncertaintyYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const ModulusUncertainty& uncertainty = run.uncertainty;
  yaml->Line(0, "uncertainty", "");
  yaml->Number(1, "modulus_std_dev", uncertainty.available ? uncertainty.std_dev : NAN,
               "[Pa] null when not available (see message)");
  yaml->Number(1, "relative_std_dev", uncertainty.available ? uncertainty.relative_std_dev : NAN,
               "modulus_std_dev / identified_modulus");
  yaml->Text(1, "meaning", kUncertaintyMeaning);
  yaml->Text(1, "message", uncertainty.message);
  yaml->Number(1, "curvature", uncertainty.curvature,
               "[J s/Pa^2] k, least-squares slope of de^2/dE over E +- 5 %");
  yaml->Integer(1, "curvature_points", uncertainty.curvature_points, "cost-curve points of k");
  yaml->Integer(1, "samples", uncertainty.samples, "noise draws");
  yaml->Number(1, "noise_std_displacement", run.noise.displacement_std, "[m] drawn on u0 and uL");
  yaml->Number(1, "noise_std_force", run.noise.force_std, "[N] drawn on f0 and fL");
  yaml->Text(1, "noise_source", run.noise_source,
             "synthetic_snr: the data's own noise; data_differences: estimated from the data");
  yaml->Number(1, "estimated_noise_std_displacement", run.estimated_noise.displacement_std,
               "[m] from the second differences of the data (MAD)");
  yaml->Number(1, "estimated_noise_std_force", run.estimated_noise.force_std,
               "[N] from the second differences of the data (MAD)");
  yaml->Number(1, "misfit_rms_displacement", run.misfit.displacement_std,
               "[m] RMS of U - u~ at both ends, at the optimum");
  yaml->Number(1, "misfit_rms_force", run.misfit.force_std,
               "[N] RMS of F - f~ = -W / alpha at both ends (a trusted clamp: r(U) - f0~ at "
               "x = 0; a pinned one: -W_0 / alpha_0), at the optimum");
  yaml->Integer(1, "sweeps", uncertainty.sweeps, "of the noise solves");
}

// The inner: block of an identification's summary: the coupled solves of the
// optimiser, their iterations, sweeps and time, and the solve at the optimum, on a
// structure of `dofs` dofs over `steps` steps.
void InnerSolvesYaml(const ModulusStage& run, const Config& config, double dofs, double steps,
                     YamlWriter* yaml) {
  long inner_iterations = 0;
  int max_inner_iterations = 0;
  double inner_time = 0.0;
  for (const ObjectiveEvaluation& evaluation : run.evaluations) {
    inner_iterations += std::max(0, evaluation.inner.iterations);
    max_inner_iterations = std::max(max_inner_iterations, evaluation.inner.iterations);
    inner_time += std::max(0.0, evaluation.inner.wall_time_s);
  }
  const CoupledSolverSummary& best_inner = run.evaluations[run.best_index].inner;
  yaml->Line(0, "inner", "");
  yaml->Text(1, "method", CoupledSolverTypeToString(run.inner_method),
             InnerMethodComment(run.inner_method, config, dofs, steps));
  yaml->Integer(1, "solves", static_cast<long>(run.evaluations.size()),
                "coupled solves of the optimiser");
  yaml->Integer(1, "iterations", inner_iterations, "sweep pairs over those solves");
  yaml->Integer(1, "max_iterations_one_solve", max_inner_iterations);
  yaml->Integer(1, "sweeps", run.sweeps - run.search_sweeps, "of those solves");
  yaml->Integer(1, "search_sweeps", run.search_sweeps,
                "of the search functional's own solves (its valleys' refinement; 0: one stage)");
  yaml->Number(1, "wall_time_s", inner_time, "[s] in those solves");
  yaml->Integer(1, "iterations_at_optimum", best_inner.iterations,
                "of the solve at the identified modulus");
  yaml->Number(1, "relative_residual_at_optimum", best_inner.relative_residual);
  yaml->Integer(1, "iterations_from_zero_at_optimum", run.cold_solve.iterations,
                "of a solve from W = 0 at the identified modulus (inner_residual.csv)");
  // The spectrum of I - G that sets the CG's iterations (docs/formulation.md section 4).
  auto estimate = [](double a) { return a > 0.0 ? a : NAN; };
  yaml->Number(1, "spectrum_min_from_zero", estimate(run.cold_solve.spectrum_min),
               "least eigenvalue of I - G (preconditioned: of M^-1 (I - L)), that solve's Ritz "
               "estimate (null: not estimated, another solver or no step)");
  yaml->Number(1, "spectrum_max_from_zero", estimate(run.cold_solve.spectrum_max),
               "largest: CG needs about sqrt(max / min) iterations a decade of residual");
}

// The cost_curve: section's points and range, as the MCRE and least squares write it.
void CostCurveYaml(const std::vector<CostCurvePoint>& curve, YamlWriter* yaml) {
  yaml->Line(0, "cost_curve", "");
  yaml->Integer(1, "points", static_cast<long>(curve.size()));
  yaml->Number(1, "lowest_modulus", curve.empty() ? NAN : curve.front().modulus, "[Pa]");
  yaml->Number(1, "highest_modulus", curve.empty() ? NAN : curve.back().modulus, "[Pa]");
}

// Measured and predicted channels of the least-squares fit at the identified E:
// uL (x = L) and f0 (the clamp reaction), then each interior sensor; a model column
// is empty when its channel is no output of the fit under that name (uL when
// data.channels leaves it out).
std::string FitCsv(const IdentificationRun& run) {
  const ChannelSet& data = run.data;
  const OutputErrorFit& fit = run.fit;
  const std::vector<MatrixModelSensor>& model_sensors = run.model->sensors;
  // The row of the fit's outputs of each channel, by name (-1: none).
  auto output_row = [&](const std::string& name) {
    for (std::size_t k = 0; k < model_sensors.size(); ++k) {
      if (model_sensors[k].channel == name) return static_cast<Eigen::Index>(k);
    }
    return Eigen::Index{-1};
  };
  std::string csv = "t,uL_measured,uL_model,f0_measured,f0_model";
  const std::vector<BarSensor> sensors = BarSensors(data);
  std::vector<Eigen::Index> sensor_rows;
  for (const BarSensor& sensor : sensors) {
    const std::string& name = data.channels[static_cast<std::size_t>(sensor.index)].name;
    csv += "," + name + "_measured," + name + "_model";
    sensor_rows.push_back(output_row(name));
  }
  csv += "\n";
  const Eigen::Index uL_row = output_row("uL");
  const BarEnds measured = BarEndChannels(data);
  const std::vector<const Vector*> sensor_values = BarSensorValues(data);
  for (int j = 0; j < data.num_samples(); ++j) {
    csv += CsvNumber(data.Time(j)) + ',' + CsvNumber(measured.uL[j]) + ',';
    if (uL_row >= 0) csv += CsvNumber(fit.outputs(uL_row, j));
    csv += ',' + CsvNumber(measured.f0[j]) + ',' + CsvNumber(fit.support_forces(0, j));
    for (std::size_t k = 0; k < sensor_values.size(); ++k) {
      csv += ',' + CsvNumber((*sensor_values[k])[j]) + ',';
      if (sensor_rows[k] >= 0) csv += CsvNumber(fit.outputs(sensor_rows[k], j));
    }
    csv += "\n";
  }
  return csv;
}

std::string LeastSquaresCostCurveScript(const IdentificationRun& run, const std::string& folder) {
  const double identified = run.identified_modulus() / 1e9;
  const bool scanned = !run.outer.scan_moduli.empty();
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1000,1000\n"
         << "set multiplot layout 2,1 title 'Output-error least squares J(E); identified E = "
         << identified << " GPa (dashed)'\n"
         << "set xlabel 'E [GPa]'\nset ylabel 'J [s]'\nset format y '%.5g'\nset key top center\n"
         << "set arrow 1 from " << identified << ", graph 0 to " << identified
         << ", graph 1 nohead dashtype 2 lc rgb '#555555'\n";
  const std::string curve = GnuplotString(folder + "/cost_curve.csv") +
                            " skip 1 using ($1/1e9):($4 > 0 ? $2 : 1/0) with linespoints pt 7 "
                            "ps 0.5 lw 2 lc rgb '#8b00c9' title 'J(E), cost curve'";
  if (scanned) {
    if (run.outer.scan_moduli.back() >= 10.0 * run.outer.scan_moduli.front())
      script << "set logscale x\n";
    script << "set title 'global scan over the bounds, its valleys and the local refinements'\n"
           << "plot " << ScanPlots(folder, false) << curve << "\nunset logscale x\n";
  }
  script << "set title 'within 5 % of the identified E'\nset xrange ["
         << identified * (1.0 - kCurvatureWindow) << ":" << identified * (1.0 + kCurvatureWindow)
         << "]\nplot " << (scanned ? ScanPlots(folder, false) : std::string()) << curve
         << "\nunset multiplot\n";
  return script.str();
}

std::string FitScript(const IdentificationRun& run, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/fit.csv");
  const char* measured = run.config.prefilter.enabled ? "measured, pre-filtered" : "measured";
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1200,500\nset multiplot layout 1,2 "
         << "title 'Least-squares fit at the identified modulus: the clamped model driven by the "
            "measured f_L'\n"
         << "set xlabel 't [ms]'\n"
         << "set title 'u_L (x = L)'\nset ylabel 'u [um]'\nplot " << csv
         << " skip 1 using ($1*1e3):($2*1e6) with lines lc rgb '#aaaaaa' title '" << measured
         << "', " << csv
         << " skip 1 using ($1*1e3):($3*1e6) with lines lw 2 lc rgb '#1f4e9c' title 'model'\n"
         << "set title 'f_0 (x = 0, clamp reaction)'\nset ylabel 'f [N]'\nplot " << csv
         << " skip 1 using ($1*1e3):4 with lines lc rgb '#aaaaaa' title '" << measured << "', "
         << csv << " skip 1 using ($1*1e3):5 with lines lw 2 lc rgb '#1f4e9c' title 'model'\n"
         << "unset multiplot\n";
  return script.str();
}

// The first lines of a summary.yaml: what the run identified, the config's path and the
// version.
void SummaryHeaderYaml(const Config& config, const std::string& title, YamlWriter* yaml) {
  yaml->Raw("# mcrewave identify run: " + title);
  if (!config.source_path.empty()) yaml->Raw("# config: " + config.source_path);
  yaml->Text(0, "version", kVersion, "mcrewave version");
}

// The zones: block's uncertainty: of the bar's zone moduli (BarZoneUncertainty).
void BarZoneUncertaintyYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const ZoneUncertainty& uncertainty = run.zone_uncertainty;
  const Vector& moduli = run.zones.summary.moduli;
  yaml->Line(1, "uncertainty", "", "first order, from the noise drawn (uncertainty:)");
  yaml->Text(2, "message", uncertainty.message);
  yaml->Line(2, "zones", "", "std_dev [Pa] null when not available");
  for (Eigen::Index z = 0; z < moduli.size(); ++z) {
    const double std_dev = uncertainty.available ? uncertainty.std_dev[z] : NAN;
    yaml->Raw("      - {index: " + std::to_string(z) + ", std_dev: " + Format(std_dev) +
              ", relative_std_dev: " + Format(std_dev / moduli[z]) + "}");
  }
  yaml->Integer(2, "samples", uncertainty.samples, "noise draws");
  yaml->Integer(2, "sweeps", uncertainty.sweeps, "of the curvature's and the noise's solves");
}

// The bar's reference_modulus and relative_error: E of synthetic data against the
// identified E (null for CSV data).
void ReferenceYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const double reference = run.reference_known ? run.config.model.modulus : NAN;
  yaml->Number(0, "reference_modulus", reference,
               "[Pa] E the synthetic data were made with (null: unknown, CSV data)");
  yaml->Number(0, "relative_error",
               run.reference_known ? (run.identified_modulus() - reference) / reference : NAN,
               "(identified - reference) / reference (null when unknown)");
}

// The supports: block: each test of a trusted support against the data
// (ConfigForTheSupports) and whether the run switched to the measured treatment; nothing
// when no support was tested.
void SupportChecksYaml(const IdentificationRun& run, YamlWriter* yaml) {
  if (run.support_checks.empty()) return;
  yaml->Line(0, "supports", "",
             "the trusted supports tested against the data (mcre.support_check, "
             "docs/boundaries.md)");
  yaml->Line(1, "switched", run.support_switched ? "true" : "false",
             "treated as measured because the data contradict them (the config below)");
  const SupportBlend& blend = run.support_blend;
  yaml->Number(1, "measured_weight", blend.weight,
               "the paper's formulation's weight a in E* (0: trusted, 1: measured)");
  if (blend.trusted_modulus > 0.0 && blend.measured_modulus > 0.0) {
    yaml->Number(1, "trusted_modulus", blend.trusted_modulus,
                 "[Pa] E of the trusted treatment; E* = (1 - a) this + a the next");
    yaml->Number(1, "measured_modulus", blend.measured_modulus,
                 "[Pa] E of the paper's treatment (docs/boundaries.md section 10)");
  }
  yaml->Line(1, "tests", "");
  for (const SupportCheck& check : run.support_checks) {
    yaml->Raw("    - support: " + Quoted(check.support));
    yaml->Text(3, "displacement_channel", check.displacement_channel);
    yaml->Text(3, "force_channel", check.force_channel);
    yaml->Number(3, "statistic", check.statistic,
                 "t = -<u~, z> / (s_u ||z||): standard normal on a rigid support");
    yaml->Number(3, "threshold", check.threshold, "t above it contradicts the support");
    yaml->Line(3, "contradicted", check.contradicted ? "true" : "false");
    yaml->Number(3, "compliance", check.compliance, "[m/N] c = -<u~, z> / <z, z>");
    yaml->Number(3, "compliance_std", check.compliance_std, "[m/N] s_u / ||z||");
    yaml->Number(3, "support_stiffness", check.SupportStiffness(), "[N/m] 1 / c");
    yaml->Number(3, "displacement_std", check.displacement_std,
                 "[m] s_u, from the second differences of the raw displacement");
  }
}

// The coarse_mesh: block of a run from a coarse mesh (model.coarse_elements,
// docs/multilevel.md); nothing on one mesh.
void CoarseMeshYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const CoarseMeshStage& stage = run.coarse_mesh;
  if (!stage.ran) return;
  yaml->Line(0, "coarse_mesh", "",
             "E first identified on a coarser bar, then refined up to model.elements; the cost "
             "curve, the uncertainty, the zones and the solve from zero are the coarse mesh's");
  yaml->Integer(1, "elements", stage.coarse_elements, "model.coarse_elements");
  yaml->Number(1, "modulus", stage.coarse_modulus, "[Pa] E* on the coarse mesh");
  yaml->Number(1, "wall_time_s", stage.coarse_wall_time_s,
               "[s] the coarse run: identification, cost curve, maps and uncertainty");
  yaml->Number(1, "curvature", stage.curvature,
               "[J s/Pa^2] its cost curve's d^2e^2/dE^2, the refinement's first step");
  yaml->Text(1, "refinement", stage.refinement.message, "the secant on model.elements");
  yaml->Integer(1, "refinement_evaluations", stage.refinement.evaluations,
                "on every mesh above the coarse one");
  yaml->Integer(1, "refinement_sweeps", stage.sweeps, "of those evaluations");
  yaml->Number(1, "refinement_wall_time_s", stage.refinement.wall_time_s, "[s]");
}

// The end of the bar's summary.yaml: its zones: block when it has zones, then the
// resolved config.
void ZonesAndConfigYaml(const IdentificationRun& run, YamlWriter* yaml) {
  if (run.zones.ran) {
    for (const std::string& line : ZonesYamlLines(run.zones)) yaml->Raw(line);
    if (!run.least_squares) BarZoneUncertaintyYaml(run, yaml);
  }
  ConfigYaml(run.config, yaml);
}

std::string LeastSquaresSummaryYaml(const IdentificationRun& run) {
  const IdentificationSummary& outer = run.outer;
  const double identified = run.identified_modulus();
  YamlWriter yaml;
  SummaryHeaderYaml(run.config, "the modulus E identified by output-error least squares J(E)",
                    &yaml);
  yaml.Text(0, "functional", OuterFunctionalToString(run.config.outer.functional),
            "outer.functional");
  yaml.Number(0, "identified_modulus", identified, "[Pa] E minimising J");
  ReferenceYaml(run, &yaml);
  yaml.Number(0, "cost", run.fit.cost,
              "[s] J = 1/2 sum_k c_k h (misfit / noise level)^2 at the identified modulus");
  yaml.Integer(0, "evaluations", outer.scan_evaluations + outer.evaluations,
               "J evaluations of the identification: the scan's and the refinements'");
  yaml.Integer(0, "sweeps", run.sweeps, "simulations and sensitivity sweeps, curve included");
  yaml.Number(0, "wall_time_s", run.wall_time_s, "[s] identification and cost curve");

  yaml.Line(0, "uncertainty", "");
  yaml.Number(1, "modulus_std_bound", run.modulus_std_bound,
              "[Pa] 1 / sqrt(I): Cramer-Rao bound with the measured load taken as exact");
  yaml.Number(1, "relative_std_bound", run.modulus_std_bound / identified,
              "modulus_std_bound / identified_modulus; the load's noise is not counted");
  yaml.Number(1, "fisher_information", run.fit.fisher_information,
              "[1/Pa^2] sum_k c_k sum (dy/dE)^2 / s^2 at the identified modulus");
  yaml.Number(1, "curvature", run.curvature,
              "[s/Pa^2] d^2J/dE^2 observed, least-squares slope of dJ/dE over E +- 5 %");
  yaml.Number(1, "noise_std_displacement", run.misfit_levels.displacement_std,
              "[m] s_u, the normalisation of the displacement misfit");
  yaml.Number(1, "noise_std_force", run.misfit_levels.force_std, "[N] s_f, of the force misfit");
  yaml.Number(1, "noise_std_strain", run.misfit_levels.strain_std, "[-] s_e, of the strain misfit");
  yaml.Text(1, "noise_source", run.misfit_source,
            "synthetic_snr: the data's own noise; data_differences: estimated from the data; "
            "channel_rms: noise-free data, the channels' RMS");

  OptimizerScanAndPrefilterYaml(outer, run.rest_cost, run.rest_cost, run.config,
                                run.prefilter_cutoff, "J", "s", &yaml);

  CostCurveYaml(run.cost_curve, &yaml);
  ZonesAndConfigYaml(run, &yaml);
  return yaml.str();
}

std::vector<std::string> WriteLeastSquaresResults(const IdentificationRun& run,
                                                  const std::string& folder, bool figures) {
  ResultsFolder results(folder);
  results.Write("cost_curve.csv", CostCurveCsv(run.cost_curve));
  results.Write("fit.csv", FitCsv(run));
  if (!run.outer.scan_moduli.empty()) {
    results.Write("scan.csv", ScanCsv(run.outer, run.rest_cost, run.config.outer.initial));
    results.Write("valleys.csv", ValleysCsv(run.outer, run.rest_cost));
  }
  if (figures) {
    results.Draw({{"cost_curve", LeastSquaresCostCurveScript(run, folder)},
                  {"fit", FitScript(run, folder)}});
  }
  results.Add(WriteZoneResults(run.zones, run.config.model, folder, figures));
  // The summary last: its presence says the folder is complete.
  results.Write("summary.yaml", LeastSquaresSummaryYaml(run));
  return results.written();
}

}  // namespace

namespace {
// A structure given by matrices (model.kind: matrix): its summary and files (results.h).
std::string MatrixSummaryYaml(const IdentificationRun& run);
std::vector<std::string> WriteMatrixIdentificationResults(const IdentificationRun& run,
                                                          const std::string& folder, bool figures);
}  // namespace

std::string SummaryYaml(const IdentificationRun& run) {
  if (run.config.structure.kind == ModelKind::kMatrix) return MatrixSummaryYaml(run);
  if (run.least_squares) return LeastSquaresSummaryYaml(run);
  const IdentificationSummary& outer = run.outer;
  const double identified = run.identified_modulus();
  YamlWriter yaml;
  SummaryHeaderYaml(run.config, "the modulus E identified by minimising the MCRE cost e^2(E)",
                    &yaml);
  yaml.Number(0, "identified_modulus", identified,
              run.support_blend.Blends()
                  ? "[Pa] E weighing two treatments' minimisers of e^2 (supports:)"
                  : "[Pa] E minimising e^2");
  ReferenceYaml(run, &yaml);
  yaml.Number(0, "cost", run.cost(), "[J s] e^2 at the identified modulus");
  yaml.Integer(0, "evaluations", outer.scan_evaluations + outer.evaluations,
               "evaluations of the identification: the scans' and the refinements' (the search "
               "functional's included)");
  yaml.Integer(0, "sweeps", outer.scan_sweeps + run.sweeps,
               "direct + retrograde sweeps of those evaluations");
  yaml.Number(0, "wall_time_s", run.wall_time_s,
              "[s] identification, cost curve and uncertainty (not the data)");
  SupportChecksYaml(run, &yaml);
  CoarseMeshYaml(run, &yaml);

  if (run.error_map.share.size() > 0) {
    const int peak = run.error_map.PeakElement();
    yaml.Line(0, "error_map", "", "the constitutive gap by element at the identified E");
    yaml.Integer(1, "peak_element", peak, "element of the largest share");
    yaml.Number(1, "peak_position", run.error_map.position[peak], "[m] its midpoint");
    yaml.Number(1, "peak_fraction", run.error_map.Fractions()[peak],
                "its share of the constitutive gap");
    SensitivityPeaksYaml(run.error_map, "", run.uncertainty.sensitivity_std, &yaml);
  }

  UncertaintyYaml(run, &yaml);

  OptimizerScanAndPrefilterYaml(outer, run.rest_cost, run.scan_cost_scale, run.config,
                                run.prefilter_cutoff, "e^2", "J s", &yaml);

  InnerSolvesYaml(run, run.config, run.config.model.elements + 1.0, run.data.num_steps(), &yaml);

  yaml.Line(0, "weights", "");
  yaml.Number(1, "alpha", run.alpha, "[m/N] force weight w_f L / (S E0)");
  yaml.Number(1, "beta", run.beta, "[N/m] displacement weight w_u S E0 / L");

  CostCurveYaml(run.cost_curve, &yaml);
  yaml.Integer(1, "sweeps", run.cost_curve_sweeps);
  yaml.Integer(0, "total_sweeps",
               run.outer.scan_sweeps + run.sweeps + run.cost_curve_sweeps + run.uncertainty.sweeps,
               "scan, optimiser, cost curve and uncertainty");

  ZonesAndConfigYaml(run, &yaml);
  return yaml.str();
}

std::vector<std::string> WriteIdentificationResults(const IdentificationRun& run,
                                                    const std::string& folder, bool figures) {
  assert(run.IsUsable());
  if (run.config.structure.kind == ModelKind::kMatrix) {
    return WriteMatrixIdentificationResults(run, folder, figures);
  }
  if (run.least_squares) return WriteLeastSquaresResults(run, folder, figures);
  ResultsFolder results(folder);
  results.Write("evaluations.csv", EvaluationsCsv(run));
  results.Write("cost_curve.csv", CostCurveCsv(run.cost_curve));
  results.Write("ends.csv", EndsCsv(run));
  results.Write("inner_residual.csv", InnerResidualCsv(run));
  if (!run.outer.scan_moduli.empty()) {
    results.Write("scan.csv", ScanCsv(run.outer, run.scan_cost_scale, run.config.outer.initial));
    results.Write("valleys.csv", ValleysCsv(run.outer, run.scan_cost_scale));
  }
  if (run.error_map.share.size() > 0) {
    results.Write("error_map.csv", ErrorMapCsv(run));
    if (run.error_map.density.size() > 0) {
      results.Write("error_map_spacetime.dat", ErrorMapSpaceTimeData(run));
    }
  }
  if (figures) {
    std::vector<std::pair<std::string, std::string>> drawings = {
        {"cost_curve", CostCurveScript(run, run.config, folder)},
        {"ends", EndsScript(run, folder)},
    };
    if (run.error_map.share.size() > 0)
      drawings.emplace_back("error_map", ErrorMapScript(run, folder));
    if (!InnerResidualHistory(run).empty()) {
      drawings.emplace_back("inner_residual", InnerResidualScript(run, run.config, folder));
    }
    results.Draw(drawings);
  }
  results.Add(WriteZoneResults(run.zones, run.config.model, folder, figures));
  // The summary last: its presence says the folder is complete.
  results.Write("summary.yaml", SummaryYaml(run));
  return results.written();
}

namespace {

// Least squares has no error map: its columns are left empty.
std::string MatrixZonesCsv(const IdentificationRun& run) {
  std::vector<ZoneRow> rows(static_cast<std::size_t>(run.nominal_moduli.size()));
  for (int z = 0; z < run.nominal_moduli.size(); ++z) {
    ZoneRow& row = rows[static_cast<std::size_t>(z)];
    row.name = run.model->zones[static_cast<std::size_t>(z)].name;
    row.nominal_modulus = run.nominal_moduli[z];
    row.modulus = run.identified_moduli[z];
    if (run.truth_moduli.size() > 0) row.truth_modulus = run.truth_moduli[z];
  }
  if (run.least_squares) return ZonesCsv(rows);
  const Vector nominal_share = GapFractions(run.nominal_zone_map),
               share = GapFractions(run.zone_map);
  for (int z = 0; z < run.nominal_moduli.size(); ++z) {
    ZoneRow& row = rows[static_cast<std::size_t>(z)];
    row.error_share_nominal = nominal_share[z];
    row.error_share_identified = share[z];
    row.relative_gap_nominal = run.nominal_zone_gap[z];
    row.relative_gap_identified = run.zone_gap[z];
  }
  return ZonesCsv(rows);
}

// t, each load as used, each sensor as used and as the identified model gives it.
std::string MatrixFitCsv(const IdentificationRun& run) {
  // With unmeasured loads every load's column is the history the model was driven by
  // (the identified force where it was not measured), named <load>_model.
  const bool driven = run.model_loads.size() > 0;
  std::string csv = "t";
  for (const MatrixModelLoad& load : run.model->loads) {
    csv += "," + load.channel + (driven ? "_model" : "");
  }
  for (const MatrixModelSensor& sensor : run.model->sensors) {
    csv += "," + sensor.channel + "_measured," + sensor.channel + "_model";
  }
  csv += "\n";
  std::vector<const Vector*> loads, sensors;
  if (!driven) {
    for (const MatrixModelLoad& load : run.model->loads) {
      loads.push_back(&run.data.Values(load.channel));
    }
  }
  for (const MatrixModelSensor& sensor : run.model->sensors) {
    sensors.push_back(&run.data.Values(sensor.channel));
  }
  for (int j = 0; j <= run.data.num_steps(); ++j) {
    csv += Format(j * run.data.time_step);
    for (const Vector* load : loads) csv += "," + Format((*load)[j]);
    for (Eigen::Index c = 0; driven && c < run.model_loads.rows(); ++c) {
      csv += "," + Format(run.model_loads(c, j));
    }
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      csv +=
          "," + Format((*sensors[k])[j]) + "," + Format(run.model_outputs(static_cast<int>(k), j));
    }
    csv += "\n";
  }
  return csv;
}

std::string MatrixDofMapCsv(const IdentificationRun& run) {
  std::string csv = "dof,nominal_j_s,identified_j_s\n";
  for (int i = 0; i < run.model->dofs(); ++i) {
    csv += std::to_string(i) + "," + Format(run.nominal_dof_map[i]) + "," +
           Format(run.dof_map[i]) + "\n";
  }
  return csv;
}

// error_map.csv of a matrix model with element blocks: the bar's columns (element, its
// position's coordinates x, y, z as it has them, share [J s] and fraction at the
// identified moduli), then the same at the nominal moduli, then the element's zone (its
// index in the manifest, as zones.csv's column zone), then the sensitivity
// de^2/d ln E_el [J s] at the identified and at the nominal moduli, and, when the
// uncertainty is known, the sensitivity's noise std at the identified moduli.
std::string MatrixElementMapCsv(const IdentificationRun& run, const MatrixModelData& model) {
  const Vector fractions = run.element_map.Fractions();
  const Vector nominal_fractions = run.nominal_element_map.Fractions();
  const Eigen::Index dimension = model.elements.front().position.size();
  std::string csv = "element";
  for (Eigen::Index i = 0; i < dimension; ++i) csv += std::string(",") + "xyz"[i];
  const auto elements = static_cast<Eigen::Index>(model.elements.size());
  const bool sensitivities = run.element_map.sensitivity.size() == elements &&
                             run.nominal_element_map.sensitivity.size() == elements;
  const Vector& noise_std = run.zone_uncertainty.sensitivity_std;
  const bool known = sensitivities && noise_std.size() == elements;
  csv += ",share,fraction,nominal_share,nominal_fraction,zone";
  csv += sensitivities ? ",sensitivity,nominal_sensitivity" : "";
  csv += known ? ",sensitivity_noise_std\n" : "\n";
  for (std::size_t el = 0; el < model.elements.size(); ++el) {
    const MatrixModelElement& element = model.elements[el];
    const auto e = static_cast<Eigen::Index>(el);
    csv += std::to_string(el);
    for (Eigen::Index i = 0; i < dimension; ++i) csv += "," + Format(element.position[i]);
    csv += "," + Format(run.element_map.share[e]) + "," + Format(fractions[e]) + "," +
           Format(run.nominal_element_map.share[e]) + "," + Format(nominal_fractions[e]) + "," +
           std::to_string(element.zone);
    if (sensitivities) {
      csv += "," + Format(run.element_map.sensitivity[e]) + "," +
             Format(run.nominal_element_map.sensitivity[e]);
    }
    if (known) csv += "," + Format(noise_std[e]);
    csv += "\n";
  }
  return csv;
}

std::string MatrixEvaluationsCsv(const IdentificationRun& run) {
  std::string csv = "evaluation";
  for (const MatrixModelZone& zone : run.model->zones) csv += "," + zone.name + "_pa";
  csv += ",scaled_cost,usable,gradient_norm\n";
  for (std::size_t i = 0; i < run.zones.summary.history.size(); ++i) {
    const ZoneEvaluation& e = run.zones.summary.history[i];
    csv += std::to_string(i + 1);
    for (int z = 0; z < e.moduli.size(); ++z) csv += "," + Format(e.moduli[z]);
    csv += "," + Format(e.cost) + "," + (e.usable ? "1" : "0") + "," + Format(e.gradient_norm) +
           "\n";
  }
  return csv;
}

std::string MatrixZonesScript(const IdentificationRun& run, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/zones.csv");
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1200,500\n"
         << "set termoption noenhanced\nset datafile separator ','\n"
            "set multiplot layout 1,2 title "
         << GnuplotString("Zones of " + run.config.structure.manifest) << "\n"
         << "set style data histograms\nset style histogram clustered gap 1\n"
            "set style fill solid 0.8 border -1\nset xtics rotate by -30\n"
            "set key top right\nset yrange [0:*]\nset offsets 0, 0, graph 0.25, 0\n"
            "set title 'Zone moduli'\nset ylabel 'E [GPa]'\nplot "
         << csv << " skip 1 using ($5*1e-9):xtic(2) title 'nominal' lc rgb '#aaaaaa', '' skip 1 "
         << "using ($6*1e-9) title 'identified' lc rgb '#d62728'";
  if (run.truth_moduli.size() > 0) {
    script << ", '' skip 1 using ($8*1e-9) title 'truth' lc rgb '#000000'";
  }
  if (run.least_squares) {
    // No error map by least squares: the right panel says so.
    script << "\nunset xtics\nunset ytics\nunset ylabel\nset border 0\nset title 'no error map: "
              "output-error "
              "least squares'\nplot [0:1] [0:1] NaN notitle\nunset multiplot\n";
    return script.str();
  }
  script << "\nset title 'MCRE error map: constitutive gap / strain energy of the zone'\n"
            "set ylabel 'relative gap'\nplot "
         << csv << " skip 1 using 12:xtic(2) title 'at the nominal moduli' lc rgb '#fdae61', '' "
         << "skip 1 using 13 title 'at the identified moduli' lc rgb '#2c7bb6'\n"
            "unset multiplot\n";
  return script.str();
}

// The first sensors (at most 6 panels), measured and model, in um or microstrain.
std::string MatrixFitScript(const IdentificationRun& run, const std::string& folder,
                            bool prefiltered, const std::vector<SensorKind>& kinds) {
  const std::string csv = GnuplotString(folder + "/fit.csv");
  const int panels = std::min<int>(6, static_cast<int>(run.model->sensors.size()));
  const int loads = static_cast<int>(run.model->loads.size());
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1000," << 220 * std::max(panels, 1)
         << "\nset termoption noenhanced\nset datafile separator ','\nset multiplot layout "
         << std::max(panels, 1)
         << ",1 title 'Sensors: " << (prefiltered ? "measured, pre-filtered" : "measured")
         << " (grey) and the identified model driven by the "
         << (run.model_loads.size() > 0 ? "measured and the identified loads" : "measured loads")
         << " (blue)'\n"
            "set xlabel 't [ms]'\n";
  for (int k = 0; k < panels; ++k) {
    const bool strain = kinds[static_cast<std::size_t>(k)] == SensorKind::kStrain;
    const int column = 2 + loads + 2 * k;
    script << "set title " << GnuplotString(run.model->sensors[static_cast<std::size_t>(k)].channel)
           << "\nset ylabel '" << (strain ? "strain [1e-6]" : "u [um]") << "'\nplot " << csv
           << " skip 1 using ($1*1e3):($" << column << "*1e6) with lines lc rgb '#aaaaaa' notitle, "
           << csv << " skip 1 using ($1*1e3):($" << column + 1
           << "*1e6) with lines lw 2 lc rgb '#1f4e9c' notitle\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

// The model: and data: blocks of a matrix run's summary.yaml.
void MatrixModelAndDataYaml(const IdentificationRun& run, const Config& config, YamlWriter* yaml) {
  yaml->Line(0, "model", "");
  yaml->Text(1, "kind", ModelKindToString(config.structure.kind));
  yaml->Text(1, "manifest", run.config.structure.manifest);
  yaml->Integer(1, "dofs", run.model->dofs());
  yaml->Integer(1, "zones", static_cast<long>(run.model->zones.size()));
  yaml->Integer(1, "loads", static_cast<long>(run.model->loads.size()));
  yaml->Integer(1, "sensors", static_cast<long>(run.model->sensors.size()));
  yaml->Integer(1, "supports", static_cast<int>(run.model->supports.size()));
  yaml->Line(0, "data", "");
  yaml->Text(1, "source", run.data_source);
  yaml->Integer(1, "steps", run.data.num_steps());
  yaml->Number(1, "time_step", run.data.time_step, "[s]");
}

// The uncertainty: block of a matrix run's summary.yaml (EstimateZoneUncertainty).
void MatrixUncertaintyYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const ZoneUncertainty& uncertainty = run.zone_uncertainty;
  yaml->Line(0, "uncertainty", "", "first order, from the noise drawn (uncertainty:)");
  yaml->Text(1, "message", uncertainty.message);
  yaml->Line(1, "zones", "", "std_dev [Pa] null when not available");
  for (std::size_t z = 0; z < run.model->zones.size(); ++z) {
    const auto index = static_cast<Eigen::Index>(z);
    const double std_dev = uncertainty.available ? uncertainty.std_dev[index] : NAN;
    yaml->Raw("    - {name: " + Quoted(run.model->zones[z].name) + ", std_dev: " + Format(std_dev) +
              ", relative_std_dev: " + Format(std_dev / run.identified_moduli[index]) + "}");
  }
  yaml->Integer(1, "samples", uncertainty.samples, "noise draws");
  yaml->Number(1, "noise_std_displacement", run.noise.displacement_std, "[m]");
  yaml->Number(1, "noise_std_strain", run.noise.strain_std, "[-]");
  yaml->Number(1, "noise_std_force", run.noise.force_std, "[N]");
  yaml->Text(1, "noise_source", run.noise_source,
             "synthetic_snr: the data's own noise; data_differences: estimated from the data");
  yaml->Integer(1, "sweeps", uncertainty.sweeps, "of the curvature's and the noise's solves");
}

// The error_map: block of a matrix run with an element map (error_map.csv): the element
// of the largest share at the identified and at the nominal moduli.
void MatrixElementMapYaml(const IdentificationRun& run, YamlWriter* yaml) {
  if (run.element_map.share.size() == 0 || run.nominal_element_map.share.size() == 0) return;
  const int peak = run.element_map.PeakElement();
  const int nominal_peak = run.nominal_element_map.PeakElement();
  yaml->Line(0, "error_map", "", "the constitutive gap by element (error_map.csv)");
  yaml->Integer(1, "peak_element", peak, "element of the largest share at the identified moduli");
  yaml->Number(1, "peak_fraction", run.element_map.Fractions()[peak],
               "its share of the constitutive gap");
  yaml->Integer(1, "nominal_peak_element", nominal_peak, "the same at the nominal moduli");
  yaml->Number(1, "nominal_peak_fraction", run.nominal_element_map.Fractions()[nominal_peak]);
  SensitivityPeaksYaml(run.element_map, "", run.zone_uncertainty.sensitivity_std, yaml);
  SensitivityPeaksYaml(run.nominal_element_map, "nominal_", Vector(), yaml);
}

// The zones: block of a matrix run, in the layout of the bar's (ZonesYamlLines): the
// zones' minimiser, its costs (e^2 [J s], or J [s] by least squares) and every zone's
// modulus, with its share of the constitutive gap at the nominal and the identified
// moduli by the MCRE.
void MatrixZonesYaml(const IdentificationRun& run, YamlWriter* yaml) {
  const std::string cost = run.least_squares ? "J" : "e^2";
  const std::string unit = run.least_squares ? "[s] " : "[J s] ";
  yaml->Line(0, "zones", "",
             run.homogeneous_ran ? "identification of every zone modulus from the homogeneous E*"
                                 : "identification of every zone modulus from the nominal moduli");
  yaml->Line(1, "functional", run.least_squares ? "least_squares" : "mcre", "outer.functional");
  if (!run.least_squares && !run.model->supports.empty()) {
    yaml->Line(1, "clamp", ClampModelToString(run.zones.clamp),
               "the supports' treatment of the zones (zone_identification.measured_clamp)");
  }
  yaml->Integer(1, "count", static_cast<long>(run.model->zones.size()));
  const ZoneIdentificationSummary& zones = run.zones.summary;
  const BoundedMinimizerSummary& minimizer = zones.regularized.minimizer;
  yaml->Line(1, "termination", TerminationTypeToString(zones.termination));
  yaml->Text(1, "message", zones.message);
  yaml->Number(1, "homogeneous_modulus", run.homogeneous_ran ? run.identified_modulus() : NAN,
               "[Pa] E*, the start (null: the zones' nominal moduli differ, they start there)");
  yaml->Number(1, "cost", run.zone_cost, unit + cost + " at the zone moduli");
  yaml->Number(1, "homogeneous_cost", run.homogeneous_ran ? run.homogeneous_cost : NAN,
               unit + cost + " at E* in every zone");
  yaml->Number(1, "nominal_cost", run.nominal_cost, unit + cost + " at the nominal moduli");
  yaml->Number(1, "cost_scale", run.zone_rest_cost,
               run.least_squares ? "[s] J_rest, J with every prediction 0"
                                 : "[J s] J_rest, e^2 of the structure left at rest "
                                   "(0 <= e^2 <= J_rest)");
  // The penalty and merging of zone_identification:, as the bar's zones: block says them.
  yaml->Number(1, "regularization_weight", zones.regularized.weight,
               "lambda of the jump penalty on log E between consecutive zones");
  yaml->Text(1, "weight_choice", zones.regularized.weight_choice);
  yaml->Number(1, "target_misfit", zones.regularized.target_misfit,
               cost + " / J_rest the noise explains (discrepancy principle; -1: not used)");
  yaml->Number(1, "floor_target", zones.regularized.floor_target,
               cost +
                   " / J_rest, the misfit floor + zone_identification.floor_margin when no "
                   "weight met the target (-1: met)");
  yaml->Integer(1, "weights_tried", static_cast<long>(zones.regularized.path.size()));
  yaml->Integer(1, "groups", zones.merge.groups,
                "zones left distinct by merging (-1: zone_identification.merge_zones off)");
  yaml->Integer(1, "merges", zones.merge.merges);
  yaml->Line(1, "optimizer", OptimizerTypeToString(minimizer.optimizer));
  yaml->Line(1, "algorithm", OuterAlgorithmToString(minimizer.algorithm));
  yaml->Text(1, "optimizer_message", minimizer.optimizer_message, "the optimiser's own words");
  yaml->Integer(1, "evaluations", zones.evaluations,
                "of every minimisation (zone_evaluations.csv) and the costs at its minimiser");
  yaml->Integer(1, "gradient_evaluations", minimizer.gradient_evaluations,
                "of the minimisation kept");
  yaml->Number(1, "scaled_cost", minimizer.cost,
               cost + " / cost_scale (+ the penalty) at the zone moduli");
  yaml->Integer(1, "sweeps", zones.sweeps);
  yaml->Line(1, "moduli", "",
             run.least_squares
                 ? "per zone (zones.csv): index, name, nominal, identified and truth modulus [Pa]"
                 : "per zone (zones.csv): index, name, nominal, identified and truth modulus "
                   "[Pa], share of the gap and gap / strain energy at the nominal and "
                   "identified moduli");
  const Vector nominal_share = GapFractions(run.nominal_zone_map),
               share = GapFractions(run.zone_map);
  for (int z = 0; z < run.nominal_moduli.size(); ++z) {
    const bool truth = run.truth_moduli.size() > 0;
    std::string entry = "    - {index: " + std::to_string(z) +
                        ", name: " + Quoted(run.model->zones[static_cast<std::size_t>(z)].name) +
                        ", nominal: " + Format(run.nominal_moduli[z]) +
                        ", modulus: " + Format(run.identified_moduli[z]) +
                        ", truth: " + Format(truth ? run.truth_moduli[z] : NAN) +
                        ", relative_error: " +
                        Format(truth ? run.identified_moduli[z] / run.truth_moduli[z] - 1.0 : NAN);
    if (!run.least_squares) {
      entry += ", error_share_nominal: " + Format(nominal_share[z]) +
               ", error_share_identified: " + Format(share[z]) +
               ", relative_gap_nominal: " + Format(run.nominal_zone_gap[z]) +
               ", relative_gap_identified: " + Format(run.zone_gap[z]);
    }
    yaml->Raw(entry + "}");
  }
}

// summary.yaml of a matrix run by least squares: the bar's least-squares layout (J [s]
// for e^2, the misfit levels, no error map and no inner solver) with the model, the data
// and the zones: block.
std::string MatrixLeastSquaresSummaryYaml(const IdentificationRun& run, const Config& config) {
  const ModulusStage& stage = run;
  YamlWriter yaml;
  SummaryHeaderYaml(config,
                    "the zone moduli of a structure given by matrices, by output-error least "
                    "squares",
                    &yaml);
  yaml.Text(0, "functional", "least_squares", "outer.functional (docs/formulation.md section 8)");
  MatrixModelAndDataYaml(run, config, &yaml);
  if (run.homogeneous_ran) {
    yaml.Number(0, "identified_modulus", stage.identified_modulus(),
                "[Pa] one E in every zone minimising J, the zones' start");
    yaml.Number(0, "cost", run.homogeneous_cost,
                "[s] J = 1/2 sum_k c_k h (misfit / noise level)^2 at the identified modulus");
    yaml.Integer(0, "evaluations", stage.outer.scan_evaluations + stage.outer.evaluations,
                 "J evaluations of the homogeneous stage: the scan's and the refinements'");
    yaml.Integer(0, "sweeps", stage.outer.scan_sweeps + stage.sweeps,
                 "simulations and sensitivity sweeps of those evaluations");
  }
  yaml.Number(0, "wall_time_s", run.wall_time_s, "[s] identification and fit");
  yaml.Line(0, "misfit_levels", "", "each sensor kind's misfit divided by its level");
  yaml.Number(1, "displacement", run.misfit_levels.displacement_std, "[m] s_u (0: no such sensor)");
  yaml.Number(1, "strain", run.misfit_levels.strain_std, "[-] s_e (0: no such sensor)");
  if (static_cast<int>(run.model->supports.size()) > 0) {
    yaml.Number(1, "force", run.misfit_levels.force_std, "[N] s_f of the supports' forces");
  }
  yaml.Text(1, "source", run.misfit_source);
  if (run.homogeneous_ran) {
    OptimizerScanAndPrefilterYaml(stage.outer, stage.rest_cost, stage.rest_cost, config,
                                  run.prefilter_cutoff, "J", "s", &yaml);
  } else {
    PrefilterYaml(config, run.prefilter_cutoff, &yaml);
  }
  MatrixZonesYaml(run, &yaml);
  ConfigYaml(config, &yaml);
  return yaml.str();
}

std::string MatrixSummaryYaml(const IdentificationRun& run) {
  const Config& config = run.config;
  if (run.least_squares) return MatrixLeastSquaresSummaryYaml(run, config);
  const ModulusStage& stage = run;
  YamlWriter yaml;
  SummaryHeaderYaml(config, "the zone moduli of a structure given by matrices, by the MCRE", &yaml);
  MatrixModelAndDataYaml(run, config, &yaml);
  SupportChecksYaml(run, &yaml);
  if (run.homogeneous_ran) {
    // The bar's headline keys, of the homogeneous stage.
    yaml.Number(0, "identified_modulus", stage.identified_modulus(),
                "[Pa] one E in every zone minimising e^2, the zones' start");
    yaml.Number(0, "cost", run.homogeneous_cost, "[J s] e^2 at the identified modulus");
    yaml.Integer(0, "evaluations", stage.outer.scan_evaluations + stage.outer.evaluations,
                 "evaluations of the homogeneous stage: the scans' and the refinements' (the "
                 "search functional's included)");
    yaml.Integer(0, "sweeps", stage.outer.scan_sweeps + stage.sweeps,
                 "direct + retrograde sweeps of those evaluations");
  }
  yaml.Number(0, "wall_time_s", run.wall_time_s, "[s] identification, error maps and uncertainty");
  MatrixElementMapYaml(run, &yaml);
  MatrixUncertaintyYaml(run, &yaml);
  if (run.homogeneous_ran) {
    OptimizerScanAndPrefilterYaml(stage.outer, stage.rest_cost, stage.scan_cost_scale, config,
                                  run.prefilter_cutoff, "e^2", "J s", &yaml);
    InnerSolvesYaml(stage, config, run.model->dofs(), run.data.num_steps(), &yaml);
    if (!stage.cost_curve.empty()) {
      CostCurveYaml(stage.cost_curve, &yaml);
      yaml.Integer(1, "sweeps", stage.cost_curve_sweeps);
    }
  } else {
    PrefilterYaml(config, run.prefilter_cutoff, &yaml);
    yaml.Line(0, "inner", "");
    yaml.Text(
        1, "method", CoupledSolverTypeToString(run.inner_method),
        InnerMethodComment(run.inner_method, config, run.model->dofs(), run.data.num_steps()));
  }
  MatrixZonesYaml(run, &yaml);
  ConfigYaml(config, &yaml);
  return yaml.str();
}

std::vector<std::string> WriteMatrixIdentificationResults(const IdentificationRun& run,
                                                          const std::string& folder, bool figures) {
  const Config& config = run.config;
  const MatrixModelData& model = *run.model;
  ResultsFolder results(folder);
  results.Write("zones.csv", MatrixZonesCsv(run));
  results.Write("zone_evaluations.csv", MatrixEvaluationsCsv(run));
  const ModulusStage& stage = run;
  if (run.homogeneous_ran) {
    if (!stage.outer.scan_moduli.empty()) {
      results.Write("scan.csv", ScanCsv(stage.outer, stage.scan_cost_scale, config.outer.initial));
      results.Write("valleys.csv", ValleysCsv(stage.outer, stage.scan_cost_scale));
    }
    // The MCRE's evaluations and solves (least squares keeps none, as the bar's).
    if (!run.least_squares) {
      results.Write("evaluations.csv", EvaluationsCsv(stage));
      if (!stage.cost_curve.empty()) {
        results.Write("cost_curve.csv", CostCurveCsv(stage.cost_curve));
      }
      results.Write("inner_residual.csv", InnerResidualCsv(stage));
    }
  }
  results.Write("fit.csv", MatrixFitCsv(run));
  if (!run.least_squares) results.Write("error_map_dofs.csv", MatrixDofMapCsv(run));
  if (run.element_map.share.size() > 0 && run.nominal_element_map.share.size() > 0) {
    results.Write("error_map.csv", MatrixElementMapCsv(run, model));
    results.Write("error_map_spacetime.dat", SpaceTimeDataOf(run.element_map));
  }
  if (figures) {
    std::vector<SensorKind> kinds;
    for (const MatrixModelSensor& sensor : model.sensors) kinds.push_back(sensor.kind);
    std::vector<std::pair<std::string, std::string>> drawings = {
        {"zones", MatrixZonesScript(run, folder)},
        {"fit", MatrixFitScript(run, folder, config.prefilter.enabled, kinds)}};
    if (run.homogeneous_ran && !run.least_squares) {
      drawings.emplace_back("cost_curve", CostCurveScript(stage, config, folder));
      if (!InnerResidualHistory(stage).empty()) {
        drawings.emplace_back("inner_residual", InnerResidualScript(stage, config, folder));
      }
    }
    results.Draw(drawings);
  }
  // The summary last: its presence says the folder is complete.
  results.Write("summary.yaml", MatrixSummaryYaml(run));
  return results.written();
}

}  // namespace
}  // namespace mcrewave
