// `identify sensors`: where to put a few sensors among the many of a matrix model
// (docs/matrix_models.md section 15).
//
//   1. LoadMatrixModel: the config's model, its zones as model.zoning makes them; its
//      sensors (those data.channels keeps, else all) are the candidates;
//   2. the design's data: the model itself at its nominal moduli driven by the load:
//      history, noise-free (what a test of the planned layout would see without noise),
//      and the noise of data.snr on it, per kind as the synthetic data's
//      (AddMatrixModelNoise: each kind's RMS / SNR);
//   3. each candidate's Fisher information about ln E_z at the nominal moduli
//      (MatrixOutputErrorObjective::Cost's sensor_information: 1 + Z sweeps), the
//      supports' forces as information every layout has;
//   4. the greedy D-optimal choice of `count` candidates
//      (least_squares/sensor_placement.h), each kind weighted by the noise of the
//      candidates (a sensor's noise does not depend on where the others are), and the
//      Cramer-Rao standard deviations of ln E_z with them, with every candidate and with
//      none; with the chosen sensors also under the noise synthetic data of data.snr
//      would put on them alone (their own RMS / SNR), what `identify run` on them sees.
//
// WriteSensorPlacementResults writes, each file atomically:
//   sensors.csv     rank, channel, kind, log_det_gain, and the largest and the median
//                   Cramer-Rao std of ln E_z with the sensors chosen up to that rank
//                   (under the candidates' noise);
//   cramer_rao.csv  zone, name, the std of ln E_z with the chosen sensors under their own
//                   noise, with every candidate and with none, and with the chosen
//                   sensors under the candidates' noise;
//   channels.yaml   the chosen channels as the config block `data: channels: [...]` that
//                   runs an identification on them.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/least_squares/sensor_placement.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

struct SensorPlacementRun {
  Config config;
  MatrixModelData model;  // the candidates are its sensors
  NoiseLevels noise;      // the levels the design assumes (data.snr)
  Vector nominal_moduli;  // where the information is taken [Pa]
  SensorPlacementSummary placement;
  // The Cramer-Rao std of ln E_z with the chosen sensors under the noise of data.snr on
  // them alone (Z entries).
  Vector chosen_std_at_own_noise;
  double wall_time_s = 0.0;
};

// Steps 1 to 4 above. Throws InputError, naming the config and the key, when the model
// is not a matrix model (model.kind), data.snr is not finite (the design needs the test's
// noise level), or count is not in [1, the candidates]; what LoadMatrixModel throws.
SensorPlacementRun RunSensorPlacement(const Config& config, int count);

// The files above into `folder` (created when missing); returns their paths.
std::vector<std::string> WriteSensorPlacementResults(const SensorPlacementRun& run,
                                                     const std::string& folder);

}  // namespace mcrewave
