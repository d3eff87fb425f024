// The two computations of the front ends, `identify run` and `identify simulate`
// (identify/main.cpp) and the Python module (python/), from one validated config: on
// the model and the measurements the config names, or on a model and a record given in
// code. Both front ends call these, so that a model or record given in code takes the
// same steps, checks and messages as the files the config names.
//
//   IdentifyFromConfig:
//     1. the model: the bar of model:, the manifest of model.manifest (LoadMatrixModel),
//        or the given model (PrepareMatrixModel: the same channel selection, zoning and
//        checks);
//     2. the measurements: synthetic or the CSV of data: (LoadMeasurements,
//        LoadMatrixMeasurements), or the given record (BarMeasurementsOfRecord,
//        MatrixMeasurementsOfRecord: the same resampling and checks as a CSV's);
//     3. the identification (RunIdentification, RunMatrixIdentification).
//   SimulatedMeasurements: the measurements `identify simulate` writes.
#pragma once

#include <string>

#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

// What a caller gives in code instead of the files the config names.
struct GivenInputs {
  // A structure given by matrices (nullable): identified instead of the config's model.
  // config.structure.kind must be kMatrix (else InputError); config.structure.manifest
  // names the model in messages (it is not read).
  const MatrixModelData* model = nullptr;
  // Measurements (nullable), instead of data: (synthetic or CSV): one channel a column
  // as a CSV holds them, sampled from record->start_time on record->time_step; on the
  // bar its channels named as the bar's CSV columns (t excluded), on a structure given
  // by matrices a channel per column of the model's channels (model.channel_map). The
  // run takes them as a CSV's: data.source csv, data.path the record's name.
  const ChannelSet* record = nullptr;
  std::string record_name = "the record";  // stands for the CSV file in messages
};

// Steps 1 to 3 above. Throws InputError naming the file, key, record or channel that
// is wrong, as `identify run` reports it. Never throws for a failed identification:
// see UnreportableMessage (identification_run.h).
IdentificationRun IdentifyFromConfig(const Config& config, const GivenInputs& given = {});

// The measurements `identify simulate` writes to its CSV: on the bar
// SyntheticMeasurements(config) (t, u0, uL, f0, fL and the sensors), on a structure
// given by matrices its truth's channels under their columns (MatrixMeasurementTable of
// LoadMatrixMeasurements; the truth is data.truth_manifest, or the given model when
// that key is empty). given.record is not used. Throws InputError as IdentifyFromConfig.
ChannelSet SimulatedMeasurements(const Config& config, const GivenInputs& given = {});

}  // namespace mcrewave
