// The YAML configuration of an mcrewave run.
//
// Every key is declared once, in a table in src/app/config.cpp, with its type, its
// default, its unit and a one-line description; loading, validation, the
// `--set key.path=value` overrides and the commented default config
// (DefaultConfigYaml) all come from that table. Values are SI units. Enums are
// written by name (see types.h).
//
// Sections and keys (defaults in brackets):
//   model: kind [bar | matrix], manifest [""], channel_map [{}] (StructureOptions),
//          length [1 m], section [1e-4 m^2], density [800 kg/m^3],
//          modulus [200e9 Pa], elements [100], mass [consistent | lumped],
//          zoning [equal | per_element | boundaries | grid], zone_count [1],
//          zone_boundaries [[] m], zone_grid [[]], free_zones [[]] (ZoneLayout,
//          bar_model.h; on a matrix model: its manifest's zones, or per_element / grid
//          regrouping its element blocks, free_zones of them free and the rest tied)
//   load:  kind [half_sine], amplitude [1000 N], duration [1e-4 s]
//   time:  window [0.63e-3 s], step [0.36e-6 s], theta [0.5]
//   data:  source [synthetic | csv], path [""], truth [finite_element | exact],
//          truth_refinement [4], snr [.inf], seed [1], sensors [[]: u@X, e@X],
//          channels [[]: every channel], truth_zones [[]: {start, end, modulus}],
//          truth_manifest [""], truth_moduli [[]], time_column ["t"],
//          time_origin [0 s], at_rest_before_record [false]
//   mcre:  w_u [1e-7], w_f [1], w_e [1e-7], w_r [1e-6], w_u0 [0.1], w_fu [1e-6],
//          reference_modulus [200e9 Pa] (E0 of the weights), clamp [trusted | measured
//          | pinned], unmeasured_loads [[]], unmeasured_load_interval [[] s]
//          (McreOptions, objective.h; docs/unmeasured_loads.md)
//   inner: method [auto: conjugate_gradient, or streaming_conjugate_gradient when the
//          fields exceed max_field_bytes | conjugate_gradient | all_at_once | relaxation
//          | adaptive_relaxation | any other CoupledSolverType], preconditioner [none |
//          dense_traces: streaming_conjugate_gradient only],
//          preconditioner_rebuild_change [0.02], max_preconditioner_traces [2048],
//          tolerance [1e-8],
//          max_iterations [5000], omega [0.5], spectrum_steps [12],
//          spectrum_safety_factor [1.05],
//          divergence_factor [1e3], max_all_at_once_unknowns [1500000],
//          max_all_at_once_bytes [2^31], max_field_bytes [2^31],
//          max_dense_solver_bytes [2^31],
//          shooting_condition_limit [1e14],
//          shooting_segment_growth [100]
//          (CoupledSolverOptions, coupled_solver.h)
//   outer: functional [mcre | least_squares], optimizer [nlopt | ceres], algorithm [default |
//   bobyqa | cobyla | sbplx |
//          mma | lbfgs | bfgs | brent | secant], lower_bound [100e9 Pa], upper_bound [400e9 Pa],
//          initial [160e9 Pa], relative_tolerance [1e-7], max_evaluations [1000],
//          max_time [600 s], scan_points [41], scan_samples_per_valley [4],
//          scan_max_points [2000], scan_tolerance [1e-4], scan_threads [2],
//          refine_margin [0.05], refine_candidates [10] (IdentificationOptions,
//          identification.h)
//   search: functional [pinned | same], w_u [0.01], w_e [0.01], w_u0 [0.1], w_r [0.1],
//          inner_tolerance [1e-6], scan_points [12], refine_window [0.03],
//          algorithm [bobyqa | secant], relative_tolerance [0: outer.relative_tolerance]
//          (SearchOptions, objective.h; the bar's global scan)
//   prefilter: enabled [true], cutoff_frequency [0 Hz: derived from the data;
//          else below the Nyquist frequency 0.5 / time.step], order [4],
//          at_rest_before_start [true] (PrefilterOptions,
//          prefilter.h; applied to the measurements before the identification)
//   uncertainty: samples [16], seed [1] (modulus_uncertainty.h)
//   output: folder ["results/identify"], figures [true], curve_points [41]
//   study: kind [all | robustness | relaxation | cost_curves | damage | comparator],
//          folder ["results"], threads [0: every core], figures [true], and one
//          block of keys per study, named after its kind:
//          robustness: snr [[.inf, 20, 10, 5, 2.5]], seeds [100];
//          relaxation: snr [[.inf, 10, 2.5]], moduli [[0.8, 1, 1.2]],
//            omega_min [0.005], omega_max [0.1], omega_points [20], tolerance [1e-4];
//          cost_curves: snr [[.inf, 10, 2.5]], seeds [3], points [41], low [0.8],
//            high [1.2];
//          damage: snr [[.inf, 20, 10, 5]], seeds [20];
//          comparator: snr [[20, 10, 5, 2.5]], seeds [100], errors [[none, density,
//            force_gain, displacement_gain, soft_zone]], data [[raw, prefilter]]
//          (a key of a block is study.<block>.<key>, e.g. study.robustness.snr)
//          (StudyOptions, study.h; used by `identify study` only)
//   zone_identification: optimizer [ceres], algorithm [default], step_tolerance [1e-8],
//          function_tolerance [1e-10], max_evaluations [2000], max_time [600 s],
//          regularization [tikhonov | total_variation | none],
//          regularization_weight [-1: discrepancy principle], tv_smoothing [1e-3],
//          max_weight [1], min_weight [1e-8], grid_factor [100], refinement_steps [4],
//          weight_tolerance [0.25], discrepancy_factor [1], noise_samples [4],
//          noise_seed [1], merge_zones [false], measured_clamp [true],
//          start_modulus [0: from the homogeneous stage's E*; model.kind matrix: every
//          zone starts at this modulus [Pa], the homogeneous stage skipped]
//          (ZoneIdentificationOptions, zone_identification.h)
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/study.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/experiment.h"
#include "mcrewave/optim/identification.h"
#include "mcrewave/identification/zone_identification.h"

namespace mcrewave {

// The `output:` section: where `identify run` writes its results and what.
struct OutputOptions {
  // Results folder; a relative path is taken from the working directory (not
  // from the config's folder); `identify run --output` replaces it.
  std::string folder = "results/identify";
  // Write the PNG figures (gnuplot) beside the CSV files.
  bool figures = true;
  // Points of the cost curve e^2(E) computed around the identified modulus.
  int curve_points = 41;

  // Valid when folder is not empty and curve_points is in [5, 1000].
  bool IsValid(std::string* error) const;
};

// The `model:` keys that choose the structure (docs/matrix_models.md section 9):
// the built-in bar (the other model: keys) or a structure given by matrices.
struct StructureOptions {
  ModelKind kind = ModelKind::kBar;
  // model.yaml of the matrices (model/matrix_export.h) when kind is matrix; a
  // relative path is taken from the config file's folder.
  std::string manifest;
  // Pairs (channel of the manifest, CSV column) for the channels whose column has
  // another name; a channel not listed is read from the column of its own name.
  std::vector<std::pair<std::string, std::string>> channel_map;

  // Valid when a matrix model names its manifest and the map pairs are named, none
  // is `t`, and no channel or column appears twice.
  bool IsValid(std::string* error) const;
  // The CSV column of a manifest channel.
  std::string Column(const std::string& channel) const;
};

struct Config {
  std::string source_path;  // the file the config was read from ("" for defaults)
  StructureOptions structure;  // keys model.kind, model.manifest, model.channel_map
  BarProperties model;
  ZoneLayout zones;  // the identification's zones (keys model.zoning, zone_count, zone_boundaries)
  LoadOptions load;
  TimeOptions time;
  DataOptions data;
  McreOptions mcre;
  CoupledSolverOptions inner;
  IdentificationOptions outer;
  SearchOptions search;  // the functional of the global scan (mcre/objective.h)
  PrefilterOptions prefilter;
  UncertaintyOptions uncertainty;
  OutputOptions output;
  StudyOptions study;
  // The identification of zone moduli after the scalar one (identification/zone_identification.h).
  ZoneIdentificationOptions zone_identification;

  // What messages call the config: its file, or "the config" when it was built in code.
  std::string Name() const { return source_path.empty() ? "the config" : source_path; }
};

// Reads a config file, applies the overrides ("key.path=value", each parsed as a
// YAML scalar and validated exactly as the same key in the file), and validates
// everything before any computation. A relative data.path is resolved against
// the config file's folder. Throws InputError with one message naming the file,
// the line (for keys from the file) or the override, the key, and what was
// expected: unknown keys (with the nearest valid key suggested; a study key of
// the flat form before the study blocks, e.g. study.robustness_snr, with its
// name now), a block of keys (e.g. study.robustness) where a key belongs or a
// key where a block belongs, wrong types,
// out-of-range values, a missing or unreadable file, malformed YAML.
// given_in_code: file keys (model.manifest, data.path, data.truth_manifest) whose
// values name a model or a record a front end gives in code (the Python module), not
// files: neither resolved against the config's folder nor checked for reading.
Config LoadConfig(const std::string& path, const std::vector<std::string>& overrides = {},
                  const std::vector<std::string>& given_in_code = {});

// The same from YAML text; `name` stands for the file name in messages.
Config ParseConfig(const std::string& yaml_text, const std::string& name,
                   const std::vector<std::string>& overrides = {});

// The checks LoadConfig makes, on a config built in code (e.g. a study's run derived
// from the user's config): "" when it is valid, else the first problem, naming the
// key first, as LoadConfig's message without the file and line.
std::string ConfigProblem(const Config& config);

// Whether the global scan runs on a search functional (search.functional pinned or
// measured, with a scan, outer.scan_points > 0): the MCRE then identifies in two stages
// (IdentifyInTwoStages, identification.h).
bool ScansTheSearchFunctional(const Config& config);

// A complete config with every key at its default, each commented with its unit
// and meaning; ParseConfig(DefaultConfigYaml(), ...) gives the default Config.
std::string DefaultConfigYaml();

// The config as resolved (every key, current values) in YAML;
// ParseConfig(ConfigToYaml(config), ...) gives the config back.
std::string ConfigToYaml(const Config& config);

// Whether a run on a structure of `kind` reads key `path` ("section.name"). The bar
// reads every key but the matrix model's own (model.manifest, model.channel_map,
// data.truth_manifest, data.truth_moduli). A structure given by matrices does not
// read the bar's geometry and zoning, its truth and sensor keys (mcre.clamp, mcre.w_r and
// mcre.w_u0 it reads: they treat the manifest's supports), the scalar
// identification's outer: keys (its zones are minimised under zone_identification:), search:,
// study:, nor the penalty and merging keys of zone_identification:
// (docs/matrix_models.md).
bool KeyApplies(const std::string& path, ModelKind kind);

// ConfigToYaml with only the keys that apply to config.structure.kind: the config
// block of a run's summary.yaml.
std::string AppliedConfigToYaml(const Config& config);

}  // namespace mcrewave
