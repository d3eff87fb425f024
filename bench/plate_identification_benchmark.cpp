// The plate example of docs/matrix_models.md identified by the MCRE: both zone moduli
// (matrix and inclusion) of a model mesh from data of a finer truth mesh (no inverse
// crime), at SNR inf, 20 and 10 over noise seeds; the identification time of each run;
// and the MCRE error map over the model's mesh at the homogeneous nominal model, where
// the inclusion is what is wrong.
//
// Case: an impact of 1 kN over 20 us (half sine) on the free edge x = L (channel F,
// measured: it takes noise too), transverse (the example's load_F.mtx, -y) or axial
// (+x, built from nodes.csv), 200 steps of 1 us (about 2.5 transits of the plate's
// length by the longitudinal wave), trapezoidal rule; the truth: matrix 200 GPa,
// inclusion 140 GPa (30 % softer). The five sensors of the example (uy_tip, uy_mid,
// ux_tip and the gauges exx_root, exx_mid). Noise of identify's synthetic data
// (AddMatrixModelNoise, app/matrix_identification_run.h), per quantity type: std = RMS
// over the displacement channels / SNR, over the strain channels / SNR, and RMS(F) /
// SNR for the load.
//
// Identification: ZoneMcreObjective (p_z = log(E_z / 200 GPa)) minimised by NLopt
// L-BFGS within [100, 400] GPa from the nominal 200 GPa in both zones, CG inner solves
// to 1e-8 warm-started, the default weights (w_u = 0.01, w_f = 1, w_e = 0.01).
//
// Usage: plate_identification_benchmark OUTPUT_DIR [--seeds=20] [--threads=2]
//            [--load=transverse|axial] [--model=FOLDER] [--truth=FOLDER]
//   (model and truth: folders of make_plate_example.py; default configs/plate/coarse
//   and configs/plate/fine; scripts/plate_study.sh runs the study of results/plate).
//   Writes OUTPUT_DIR/runs.csv (one row per identification), summary.md (statistics
//   per SNR and the goals), error_map.csv and error_map.png (the element map of
//   the model's element blocks), moduli.png.
// Runs are independent and each is seeded: the numbers do not depend on threads.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"

namespace {

using namespace mcrewave;

const std::string kPlate = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/";
constexpr double kTimeStep = 1e-6;        // h [s]
constexpr int kSteps = 200;               // m
constexpr double kImpactDuration = 2e-5;  // [s]
constexpr double kImpactAmplitude = 1e3;  // [N]
constexpr double kNominal = 2e11;         // [Pa], E0 of the weights and the start

Vector TruthModuli() { return (Vector(2) << 2e11, 1.4e11).finished(); }

// The measured load F and the fine plate's outputs at the truth, noise-free.
// (The fine and the coarse plate name their channels alike.)
ChannelSet FineTruth(const MatrixModelData& fine) {
  Matrix loads = Matrix::Zero(1, kSteps + 1);
  for (int j = 0; j <= kSteps; ++j) {
    const double t = j * kTimeStep;
    if (t < kImpactDuration) loads(0, j) = kImpactAmplitude * std::sin(M_PI * t / kImpactDuration);
  }
  return MatrixChannelSet(fine, kTimeStep, loads,
                          SimulateMatrixModel(fine, TruthModuli(), loads, kTimeStep, 0.5));
}

struct Run {
  double snr = 0.0;
  std::uint64_t seed = 0;  // 0 at SNR inf
  bool converged = false;
  std::string message;
  Vector moduli = Vector::Constant(2, std::numeric_limits<double>::quiet_NaN());
  int evaluations = 0;
  double wall_time_s = 0.0;
};

void Identify(const MatrixModelData& coarse, const ChannelSet& truth, Run* run) {
  const auto start = std::chrono::steady_clock::now();
  ChannelSet data = truth;
  AddMatrixModelNoise(coarse, run->snr, run->seed, &data);
  McreOptions mcre;
  mcre.weights = McreWeights();
  mcre.reference_modulus = kNominal;
  CoupledSolverOptions inner;
  inner.tolerance = 1e-8;
  McreObjective mcre_objective = MatrixMcreObjective(coarse, data, mcre, 0.5, inner);
  ZoneMcreObjective objective(&mcre_objective, coarse.NominalModuli());
  BoundedMinimizerOptions options;
  const double low = std::log(0.5), high = std::log(2.0);
  const BoundedMinimizerSummary summary =
      MinimizeWithinBounds(options, &objective, {low, low}, {high, high}, {0.0, 0.0});
  run->converged = summary.IsSolutionUsable();
  run->message = summary.message;
  if (!summary.x.empty()) run->moduli = objective.Moduli(summary.x.data());
  run->evaluations = summary.evaluations;
  run->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Reads a CSV of numbers with one header line.
std::vector<std::vector<double>> ReadCsv(const std::string& path) {
  std::ifstream file(path);
  if (!file) {
    std::fprintf(stderr, "error: cannot read %s\n", path.c_str());
    std::exit(1);
  }
  std::vector<std::vector<double>> rows;
  std::string line;
  std::getline(file, line);
  while (std::getline(file, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');)
      row.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

// The load vector of a unit +x traction resultant spread uniformly over the free edge
// x = L (consistent nodal forces of linear edges: 1/2 of a segment's share at the
// corners), from the mesh's nodes.csv: the axial impact, in-plane like the bar's.
Vector AxialEdgeLoad(const std::string& nodes_csv, int dofs) {
  const std::vector<std::vector<double>> nodes = ReadCsv(nodes_csv);
  double length = 0.0;
  for (const std::vector<double>& node : nodes) length = std::max(length, node[1]);
  std::vector<int> edge;  // dof_x of the edge's nodes, by y
  for (const std::vector<double>& node : nodes) {
    if (std::abs(node[1] - length) < 1e-12 && node[3] >= 0)
      edge.push_back(static_cast<int>(node[3]));
  }
  Vector load = Vector::Zero(dofs);
  const double segments = static_cast<double>(edge.size()) - 1.0;
  for (std::size_t i = 0; i < edge.size(); ++i) {
    const bool corner = i == 0 || i + 1 == edge.size();
    load[edge[i]] = (corner ? 0.5 : 1.0) / segments;
  }
  return load;
}

// The error map of the noise-free data at the nominal model (200 GPa in both zones),
// per element: e_el^2 of the model's element blocks (MatrixElementGapShares,
// docs/matrix_models.md section 2) as shares of the total. Writes error_map.csv
// (element, x_centre, y_centre, half width, half height, zone index, share) and draws
// error_map.png.
void WriteErrorMap(const MatrixModelData& coarse, const std::string& coarse_folder,
                   const ChannelSet& truth, const std::string& folder) {
  if (coarse.elements.empty()) {
    std::fprintf(stderr,
                 "error: %s/model.yaml has no element blocks (elements:), which the error "
                 "map needs: regenerate it with scripts/make_plate_example.py\n",
                 coarse_folder.c_str());
    std::exit(1);
  }
  MatrixMcreProblem problem(coarse, truth, McreWeights(), kNominal, 0.5);
  CoupledSolverOptions inner;
  inner.tolerance = 1e-10;
  CoupledSolution solution;
  const CoupledSolverSummary summary = SolveCoupled(inner, &problem, nullptr, &solution);
  if (!summary.IsSolutionUsable()) {
    std::fprintf(stderr, "error: the error map's solve failed: %s\n", summary.FullReport().c_str());
    std::exit(1);
  }
  const Vector element_energy =
      MatrixElementGapShares(coarse, coarse.NominalModuli(), solution.retrograde, kTimeStep);
  const std::vector<std::vector<double>> nodes = ReadCsv(coarse_folder + "/nodes.csv");
  const std::vector<std::vector<double>> elements = ReadCsv(coarse_folder + "/elements.csv");
  if (elements.size() != coarse.elements.size()) {
    std::fprintf(stderr, "error: %s/elements.csv has %zu elements, the manifest's blocks %zu\n",
                 coarse_folder.c_str(), elements.size(), coarse.elements.size());
    std::exit(1);
  }
  const double total = element_energy.sum();
  std::ostringstream csv;
  csv.precision(17);
  csv << "element,x,y,half_width,half_height,zone,share\n";
  for (std::size_t e = 0; e < elements.size(); ++e) {
    double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300;
    for (int a = 1; a <= 4; ++a) {
      const std::vector<double>& node = nodes[static_cast<std::size_t>(elements[e][a])];
      x_min = std::min(x_min, node[1]);
      x_max = std::max(x_max, node[1]);
      y_min = std::min(y_min, node[2]);
      y_max = std::max(y_max, node[2]);
    }
    csv << e << ',' << 0.5 * (x_min + x_max) << ',' << 0.5 * (y_min + y_max) << ','
        << 0.5 * (x_max - x_min) << ',' << 0.5 * (y_max - y_min) << ',' << coarse.elements[e].zone
        << ',' << element_energy[static_cast<int>(e)] / total << '\n';
  }
  WriteFileAtomically(folder + "/error_map.csv", csv.str());
  std::ostringstream script;
  script << GnuplotPngTerminal()
         << "set title 'MCRE error map of the plate at the nominal 200 GPa (noise-free data; "
            "inclusion outlined)'\nset xlabel 'x [m]'\nset ylabel 'y [m]'\nset size ratio -1\n"
            "set palette defined (0 'white', 1 '#fdae61', 2 '#d7191c', 3 '#67001f')\n"
            "set cblabel 'share of the constitutive gap'\n"
            "set object 1 circle at 0.2, 0.05 size 0.03 front fs empty border lc rgb 'black' lw 2\n"
            "plot "
         << GnuplotString(folder + "/error_map.csv")
         << " using 2:3:4:5:7 with boxxyerror fs solid 1.0 noborder lc palette notitle\n";
  bool gnuplot_missing = false;
  const std::string why = DrawGnuplotFigure(folder, "error_map", script.str(), &gnuplot_missing);
  if (!why.empty()) std::fprintf(stderr, "error_map.png skipped: %s\n", why.c_str());
}

// The benchmark's command line: OUTPUT_DIR, then --key=value options.
struct PlateArguments {
  std::string folder, load = "transverse", model_folder = kPlate + "coarse",
                      truth_folder = kPlate + "fine";
  int seeds = 20, threads = 2;
};

// Reads the command line into arguments; 0, or the exit status 2 after an error or the
// usage on stderr.
int ParsePlateArguments(int argc, char** argv, PlateArguments* arguments) {
  for (int a = 1; a < argc; ++a) {
    const std::string argument = argv[a];
    const std::size_t equals = argument.find('=');
    const std::string key = argument.substr(0, equals);
    const std::string value = equals == std::string::npos ? "" : argument.substr(equals + 1);
    if (argument.rfind("--", 0) != 0) {
      arguments->folder = argument;
    } else if (key == "--seeds") {
      arguments->seeds = std::atoi(value.c_str());
    } else if (key == "--threads") {
      arguments->threads = std::atoi(value.c_str());
    } else if (key == "--load") {
      arguments->load = value;
    } else if (key == "--model") {
      arguments->model_folder = value;
    } else if (key == "--truth") {
      arguments->truth_folder = value;
    } else {
      std::fprintf(stderr, "error: unknown option %s\n", argument.c_str());
      return 2;
    }
  }
  if (arguments->folder.empty() || arguments->seeds < 1 || arguments->threads < 1 ||
      (arguments->load != "transverse" && arguments->load != "axial")) {
    std::fprintf(stderr,
                 "usage: %s OUTPUT_DIR [--seeds=20] [--threads=2] [--load=transverse|axial] "
                 "[--model=FOLDER] [--truth=FOLDER]\n",
                 argv[0]);
    return 2;
  }
  return 0;
}

// The runs at SNR inf (once), 20 and 10 (seeds 1..seeds each), identified from the
// truth on threads threads.
std::vector<Run> PlateRuns(const MatrixModelData& coarse, const ChannelSet& truth, int seeds,
                           int threads) {
  std::vector<Run> runs;
  for (const double snr : {std::numeric_limits<double>::infinity(), 20.0, 10.0}) {
    for (int seed = 1; seed <= (std::isinf(snr) ? 1 : seeds); ++seed) {
      Run run;
      run.snr = snr;
      run.seed = std::isinf(snr) ? 0 : static_cast<std::uint64_t>(seed);
      runs.push_back(run);
    }
  }
  std::atomic<std::size_t> next{0}, done{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < runs.size(); i = next++) {
      Identify(coarse, truth, &runs[i]);
      std::fprintf(stderr, "plate: %zu / %zu identifications\n", ++done, runs.size());
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (std::thread& thread : pool) thread.join();
  return runs;
}

// runs.csv: one row per identification, the errors against the truth's moduli.
std::string PlateRunsCsv(const std::vector<Run>& runs, const Vector& truth_moduli) {
  std::ostringstream csv;
  csv.precision(17);
  csv << "snr,seed,converged,matrix_modulus,inclusion_modulus,matrix_error,inclusion_error,"
         "evaluations,wall_time_s\n";
  for (const Run& run : runs) {
    csv << run.snr << ',' << run.seed << ',' << (run.converged ? 1 : 0) << ',' << run.moduli[0]
        << ',' << run.moduli[1] << ',' << run.moduli[0] / truth_moduli[0] - 1.0 << ','
        << run.moduli[1] / truth_moduli[1] - 1.0 << ',' << run.evaluations << ',' << run.wall_time_s
        << '\n';
  }
  return csv.str();
}

// summary.md: per SNR the statistics of the converged runs (also on stdout), and the
// issue's goals.
void WritePlateSummary(const std::string& folder, const MatrixModelData& coarse,
                       const MatrixModelData& fine, const std::string& load, int seeds,
                       const std::vector<Run>& runs, const Vector& truth_moduli) {
  std::ostringstream summary;
  summary << "# The plate example: both zone moduli from the fine plate's data\n\n"
          << "`plate_identification_benchmark` (bench/; docs/matrix_models.md): the model "
             "mesh ("
          << coarse.dofs() << " dofs) identified from data of a finer mesh (" << fine.dofs()
          << " dofs), " << load
          << " impact, truth matrix 200 GPa, inclusion 140 GPa; NLopt L-BFGS from 200 GPa in "
             "both zones; "
          << seeds << " seeds per finite SNR.\n\n"
          << "| SNR | runs | converged | matrix: mean error | matrix: rms | inclusion: mean error "
             "| inclusion: rms | inclusion: max abs | inclusion within 5 % | evaluations | time "
             "[s] |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  char line[512];
  for (const double snr : {std::numeric_limits<double>::infinity(), 20.0, 10.0}) {
    int count = 0, converged = 0, within = 0;
    double mean[2] = {0, 0}, square[2] = {0, 0}, worst = 0.0, evaluations = 0.0, time = 0.0;
    for (const Run& run : runs) {
      if (run.snr != snr) continue;
      ++count;
      if (!run.converged) continue;
      ++converged;
      for (int z = 0; z < 2; ++z) {
        const double error = run.moduli[z] / truth_moduli[z] - 1.0;
        mean[z] += error;
        square[z] += error * error;
      }
      const double inclusion = std::abs(run.moduli[1] / truth_moduli[1] - 1.0);
      worst = std::max(worst, inclusion);
      within += inclusion <= 0.05 ? 1 : 0;
      evaluations += run.evaluations;
      time += run.wall_time_s;
    }
    const double n = std::max(converged, 1);
    std::snprintf(line, sizeof line,
                  "| %s | %d | %d | %+.3f %% | %.3f %% | %+.3f %% | %.3f %% | %.3f %% | %d / %d | "
                  "%.1f | %.2f |\n",
                  std::isinf(snr) ? "inf" : std::to_string(static_cast<int>(snr)).c_str(), count,
                  converged, 100.0 * mean[0] / n, 100.0 * std::sqrt(square[0] / n),
                  100.0 * mean[1] / n, 100.0 * std::sqrt(square[1] / n), 100.0 * worst, within,
                  converged, evaluations / n, time / n);
    summary << line;
    std::fputs(line, stdout);
  }
  summary << "\nGoals of issue 15: noise-free within 1 % (both zones), SNR 10 within 5 % for the "
             "inclusion over the seeds (the table's `within 5 %` column).\n\n"
          << "error_map.png: the MCRE error map at the homogeneous 200 GPa from the noise-free "
             "data (the inclusion outlined); runs.csv: every identification.\n";
  WriteFileAtomically(folder + "/summary.md", summary.str());
}

// moduli.png: the identified zone moduli at SNR 20 and 10 around the truth.
void DrawModuliFigure(const std::string& folder) {
  std::ostringstream script;
  script << GnuplotPngTerminal()
         << "set title 'Identified zone moduli of the plate (truth: 200 / 140 GPa)'\n"
            "set xlabel 'matrix E [GPa]'\nset ylabel 'inclusion E [GPa]'\n"
            "set object 1 circle at 200, 140 size 0.5 front fs solid lc rgb 'black'\n"
            "plot "
         << GnuplotString(folder + "/runs.csv")
         << " using ($1 == 20 ? $4 * 1e-9 : 1/0):($5 * 1e-9) with points pt 7 ps 1.2 lc rgb "
            "'#1f77b4' title 'SNR 20', '' using ($1 == 10 ? $4 * 1e-9 : 1/0):($5 * 1e-9) with "
            "points pt 5 ps 1.2 lc rgb '#d62728' title 'SNR 10'\n";
  bool gnuplot_missing = false;
  const std::string why = DrawGnuplotFigure(folder, "moduli", script.str(), &gnuplot_missing);
  if (!why.empty()) std::fprintf(stderr, "moduli.png skipped: %s\n", why.c_str());
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  PlateArguments arguments;
  const int status = ParsePlateArguments(argc, argv, &arguments);
  if (status != 0) return status;
  const std::string& folder = arguments.folder;
  const std::string& model_folder = arguments.model_folder;
  const std::string& truth_folder = arguments.truth_folder;
  MatrixModelData coarse = ReadMatrixModel(model_folder + "/model.yaml");
  MatrixModelData fine = ReadMatrixModel(truth_folder + "/model.yaml");
  if (arguments.load == "axial") {
    coarse.loads[0].vector = AxialEdgeLoad(model_folder + "/nodes.csv", coarse.dofs());
    fine.loads[0].vector = AxialEdgeLoad(truth_folder + "/nodes.csv", fine.dofs());
  }
  const ChannelSet truth = FineTruth(fine);
  WriteErrorMap(coarse, model_folder, truth, folder);
  const std::vector<Run> runs = PlateRuns(coarse, truth, arguments.seeds, arguments.threads);
  const Vector truth_moduli = TruthModuli();
  WriteFileAtomically(folder + "/runs.csv", PlateRunsCsv(runs, truth_moduli));
  WritePlateSummary(folder, coarse, fine, arguments.load, arguments.seeds, runs, truth_moduli);
  DrawModuliFigure(folder);
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
