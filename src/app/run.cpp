#include "mcrewave/app/run.h"

#include <spdlog/spdlog.h>

#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/core/types.h"
#include "mcrewave/data/measurement.h"

namespace mcrewave {
namespace {

// The bar's record given in code, its channels of the kinds their names give; throws
// InputError naming `name` when its columns are not a bar CSV's (BarHeaderProblem).
ChannelSet BarRecord(ChannelSet record, const std::string& name) {
  std::vector<std::string> names = {"t"};
  std::string line = "t";
  for (const Channel& channel : record.channels) {
    names.push_back(channel.name);
    line += "," + channel.name;
  }
  const std::string problem = BarHeaderProblem(names, line);
  if (!problem.empty()) throw InputError(name + ": " + problem);
  for (Channel& channel : record.channels) channel.kind = BarChannelKind(channel.name);
  return record;
}

// A model given in code is a structure given by matrices: refused with model.kind bar.
void RefuseAGivenModelOfTheBar(const Config& config, const GivenInputs& given) {
  if (given.model != nullptr && config.structure.kind != ModelKind::kMatrix) {
    throw InputError(config.Name() +
                     ": a model given in code needs model.kind: matrix, naming "
                     "it as model.manifest");
  }
}

// Step 1 on a structure given by matrices: the manifest's model, or the given one.
MatrixModelData MatrixModelOf(const Config& config, const GivenInputs& given) {
  return given.model != nullptr ? PrepareMatrixModel(config, *given.model)
                                : LoadMatrixModel(config);
}

}  // namespace

IdentificationRun IdentifyFromConfig(const Config& given_config, const GivenInputs& given) {
  RefuseAGivenModelOfTheBar(given_config, given);
  // A record given in code replaces the CSV file: the run takes its data as measured,
  // with no synthetic truth and no noise level drawn at data.snr.
  Config config = given_config;
  if (given.record != nullptr) {
    config.data.source = DataSource::kCsv;
    config.data.path = given.record_name;
  }
  if (config.structure.kind == ModelKind::kMatrix) {
    const MatrixModelData model = MatrixModelOf(config, given);
    CheckMatrixModelFieldBytes(config, model);
    const MatrixMeasurements data =
        given.record != nullptr
            ? MatrixMeasurementsOfRecord(config, model, *given.record, given.record_name)
            : LoadMatrixMeasurements(config, model, given.model);
    return RunMatrixIdentification(config, model, data);
  }
  const ChannelSet data =
      given.record != nullptr
          ? BarMeasurementsOfRecord(config, BarRecord(*given.record, given.record_name),
                                    given.record_name)
          : LoadMeasurements(config);
  spdlog::info("config {}: {} elements, {} steps of {:.4g} s; data {} ({} samples)", config.Name(),
               config.model.elements, config.time.NumSteps(), config.time.step,
               config.data.source == DataSource::kCsv ? config.data.path : std::string("synthetic"),
               data.num_samples());
  return RunIdentification(config, data);
}

ChannelSet SimulatedMeasurements(const Config& config, const GivenInputs& given) {
  RefuseAGivenModelOfTheBar(config, given);
  if (config.structure.kind == ModelKind::kMatrix) {
    // A structure given by matrices: its truth's outputs and loads, under the columns
    // identify run reads (model.channel_map).
    const MatrixModelData model = MatrixModelOf(config, given);
    const MatrixMeasurements data = LoadMatrixMeasurements(config, model, given.model);
    return MatrixMeasurementTable(config, model, data.histories);
  }
  return SyntheticMeasurements(config);
}

}  // namespace mcrewave
