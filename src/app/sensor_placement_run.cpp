#include "mcrewave/app/sensor_placement_run.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"

namespace mcrewave {
namespace {

std::string TableNumber(double value) { return FormatNumber(value, kTenDigits); }

// The median of a row's entries.
double MedianOf(Vector values) {
  std::sort(values.data(), values.data() + values.size());
  const Eigen::Index n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

SensorPlacementRun RunSensorPlacement(const Config& config, int count) {
  const auto start = std::chrono::steady_clock::now();
  const std::string name = config.Name();
  if (config.structure.kind != ModelKind::kMatrix) {
    throw InputError(name +
                     ": model.kind: identify sensors chooses among a matrix model's sensors, "
                     "got 'bar' (set model.kind: matrix and model.manifest)");
  }
  if (!std::isfinite(config.data.snr)) {
    throw InputError(name +
                     ": data.snr: identify sensors needs the noise level of the planned test, "
                     "got .inf (set it, e.g. --set data.snr=20)");
  }
  SensorPlacementRun run;
  run.config = config;
  // 1. The model and its candidate sensors.
  run.model = LoadMatrixModel(config);
  const int candidates = static_cast<int>(run.model.sensors.size());
  if (count < 1 || count > candidates) {
    throw InputError(name + ": --count must lie in [1, " + std::to_string(candidates) +
                     "] (the sensors of " + config.structure.manifest +
                     (config.data.channels.empty() ? "" : " that data.channels keeps") + "), got " +
                     std::to_string(count));
  }

  // 2. The design's data: the model at its nominal moduli, driven by load:, with the
  //    noise levels of data.snr.
  Config design = config;
  design.data.source = DataSource::kSynthetic;
  design.data.truth_manifest.clear();
  design.data.truth_moduli.clear();
  design.data.snr = std::numeric_limits<double>::infinity();
  const MatrixMeasurements data = LoadMatrixMeasurements(design, run.model);
  run.noise = MatrixModelNoiseLevels(run.model, data.histories, config.data.snr);
  run.nominal_moduli.resize(static_cast<Eigen::Index>(run.model.zones.size()));
  for (std::size_t z = 0; z < run.model.zones.size(); ++z) {
    run.nominal_moduli[static_cast<Eigen::Index>(z)] = run.model.zones[z].nominal_modulus;
  }

  // 3. Each candidate's information about ln E_z: D I_k D, D = diag(E_z).
  spdlog::info(
      "{}: the Fisher information of {} candidate sensors about {} zone moduli ({} sweeps)",
      config.structure.manifest, candidates, run.model.zones.size(), 1 + run.model.zones.size());
  MatrixOutputErrorObjective objective(run.model, data.histories, run.noise, config.time.theta);
  Vector gradient;
  Matrix total;
  std::vector<Matrix> information;
  objective.Cost(run.nominal_moduli, &gradient, &total, &information);
  const auto scale = run.nominal_moduli.asDiagonal();
  Matrix base = total;
  for (Matrix& sensor : information) {
    base -= sensor;
    sensor = scale * sensor * scale;
  }
  // I_0: the supports' forces (the total less every sensor's part), none without supports.
  base = run.model.supports.empty() ? Matrix() : Matrix(scale * base * scale);

  // 4. The greedy D-optimal choice.
  SensorPlacementOptions options;
  options.count = count;
  run.placement = PlaceSensors(options, information, base);
  if (run.placement.termination != TerminationType::kConvergence) {
    throw std::runtime_error("identify sensors: " + run.placement.BriefReport());
  }

  // The chosen sensors under the noise that synthetic data of data.snr put on them
  // alone (MatrixModelNoiseLevels of the model with those sensors, in its order): I_k
  // scales by (s_design / s_chosen)^2 of its kind.
  std::vector<int> chosen_in_order = run.placement.chosen;
  std::sort(chosen_in_order.begin(), chosen_in_order.end());
  MatrixModelData chosen_model;  // the loads and chosen sensors MatrixModelNoiseLevels reads
  chosen_model.loads = run.model.loads;
  for (const int k : chosen_in_order) {
    chosen_model.sensors.push_back(run.model.sensors[static_cast<std::size_t>(k)]);
  }
  const NoiseLevels own = MatrixModelNoiseLevels(chosen_model, data.histories, config.data.snr);
  const double design_std[2] = {run.noise.displacement_std, run.noise.strain_std};
  const double chosen_std[2] = {own.displacement_std, own.strain_std};
  double factor[2] = {1.0, 1.0};
  for (int kind = 0; kind < 2; ++kind) {
    // (A kind not chosen, or chosen sensors that read nothing, keep the candidates' level.)
    if (chosen_std[kind] > 0.0) factor[kind] = std::pow(design_std[kind] / chosen_std[kind], 2);
  }
  const double prior = 1.0 / std::pow(options.prior_log_modulus_std, 2);
  Matrix chosen = prior * Matrix::Identity(information.front().rows(), information.front().cols());
  if (base.size() > 0) chosen += base;
  for (const int k : run.placement.chosen) {
    const int kind = run.model.sensors[static_cast<std::size_t>(k)].kind == SensorKind::kStrain;
    chosen += factor[kind] * information[static_cast<std::size_t>(k)];
  }
  run.chosen_std_at_own_noise = CramerRaoStd(chosen);
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

std::vector<std::string> WriteSensorPlacementResults(const SensorPlacementRun& run,
                                                     const std::string& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw std::runtime_error("cannot create folder " + folder + ": " + error.message());
  const SensorPlacementSummary& placement = run.placement;
  std::ostringstream sensors, zones, channels;
  sensors << "rank,channel,kind,log_det_gain,largest_std,median_std\n";
  for (std::size_t i = 0; i < placement.chosen.size(); ++i) {
    const MatrixModelSensor& sensor =
        run.model.sensors[static_cast<std::size_t>(placement.chosen[i])];
    const Vector stds = placement.chosen_std.row(static_cast<Eigen::Index>(i)).transpose();
    sensors << i + 1 << "," << sensor.channel << "," << SensorKindToString(sensor.kind) << ","
            << TableNumber(placement.log_det_gain[i]) << "," << TableNumber(stds.maxCoeff()) << ","
            << TableNumber(MedianOf(stds)) << "\n";
  }
  zones << "zone,name,std_chosen,std_every_candidate,std_no_sensor,std_chosen_design_noise\n";
  const Eigen::Index last = placement.chosen_std.rows() - 1;
  for (std::size_t z = 0; z < run.model.zones.size(); ++z) {
    const auto index = static_cast<Eigen::Index>(z);
    zones << z << "," << run.model.zones[z].name << ","
          << TableNumber(run.chosen_std_at_own_noise[index]) << ","
          << TableNumber(placement.all_candidates_std[index]) << ","
          << TableNumber(placement.no_sensor_std[index]) << ","
          << TableNumber(placement.chosen_std(last, index)) << "\n";
  }
  channels << "# " << placement.chosen.size() << " of the " << run.model.sensors.size()
           << " sensors of " << run.config.structure.manifest
           << ", chosen by identify sensors (greedy D-optimal design on the Fisher information "
              "of the zone moduli at SNR "
           << FormatNumber(run.config.data.snr, kSixDigits)
           << "; docs/matrix_models.md section 15)\ndata:\n  channels: [";
  for (std::size_t i = 0; i < placement.chosen.size(); ++i) {
    channels << (i > 0 ? ", " : "")
             << run.model.sensors[static_cast<std::size_t>(placement.chosen[i])].channel;
  }
  channels << "]\n";
  std::vector<std::string> written;
  for (const auto& [file, text] :
       {std::pair<std::string, std::string>{"sensors.csv", sensors.str()},
        {"cramer_rao.csv", zones.str()},
        {"channels.yaml", channels.str()}}) {
    WriteFileAtomically(folder + "/" + file, text);
    written.push_back(folder + "/" + file);
  }
  return written;
}

}  // namespace mcrewave
