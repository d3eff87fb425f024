#include "mcrewave/app/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mcrewave/core/format.h"
#include "mcrewave/core/types.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave {
namespace {

// ---------------------------------------------------------------------------
// Value types: how one YAML scalar becomes a C++ value and back.

// A value type of the config. `read` returns false (leaving *value as it was)
// when the node is not a valid T; `write` gives YAML text that `read` turns back
// into the same value.
template <typename T>
struct ValueType {
  std::string expected;  // what a valid value looks like, for messages: "a number"
  std::string choices;   // "a | b" for enums, "" otherwise (for the commented config)
  std::function<bool(const YAML::Node& node, T* value)> read;
  std::function<std::string(const T& value)> write;
};

// The shortest decimal text that reads back as exactly `value`, in fixed notation
// below 1e6 (800, not 8e+02); ".inf"/"-.inf" for infinities (YAML spelling).
std::string FormatNumber(double value) { return mcrewave::FormatNumber(value, kConfigRoundTrip); }

// Any number except NaN; .inf and -.inf are numbers (ranges are checked by the
// sections' IsValid).
ValueType<double> Number() {
  ValueType<double> type;
  type.expected = "a number";
  type.read = [](const YAML::Node& node, double* value) {
    if (!node.IsScalar()) return false;
    double parsed;
    if (!YAML::convert<double>::decode(node, parsed) || std::isnan(parsed)) return false;
    *value = parsed;
    return true;
  };
  type.write = FormatNumber;
  return type;
}

// A decimal integer >= 1 that fits Int; "1.5" and "1e3" are not integers.
template <typename Int>
ValueType<Int> PositiveInteger() {
  ValueType<Int> type;
  type.expected = "a positive integer";
  type.read = [](const YAML::Node& node, Int* value) {
    if (!node.IsScalar() || node.Scalar().empty()) return false;
    const std::string& text = node.Scalar();
    errno = 0;
    char* end = nullptr;
    const long long parsed = std::strtoll(text.c_str(), &end, 10);
    if (errno != 0 || *end != '\0' || std::isspace(static_cast<unsigned char>(text[0])) ||
        parsed < 1 || parsed > std::numeric_limits<Int>::max()) {
      return false;
    }
    *value = static_cast<Int>(parsed);
    return true;
  };
  type.write = [](const Int& value) { return std::to_string(value); };
  return type;
}

// A decimal integer >= 0 that fits int (0 often means "off").
ValueType<int> NonNegativeInteger() {
  ValueType<int> type = PositiveInteger<int>();
  type.expected = "an integer >= 0";
  type.read = [](const YAML::Node& node, int* value) {
    if (node.IsScalar() && node.Scalar() == "0") {
      *value = 0;
      return true;
    }
    return PositiveInteger<int>().read(node, value);
  };
  return type;
}

// A decimal integer in [0, 2^64 - 1].
ValueType<std::uint64_t> UnsignedInteger() {
  ValueType<std::uint64_t> type;
  type.expected = "an integer in [0, 18446744073709551615]";
  type.read = [](const YAML::Node& node, std::uint64_t* value) {
    if (!node.IsScalar() || node.Scalar().empty()) return false;
    const std::string& text = node.Scalar();
    // strtoull accepts (and wraps) a minus sign and skips leading spaces: refuse both.
    if (!std::isdigit(static_cast<unsigned char>(text[0])) && text[0] != '+') return false;
    errno = 0;
    char* end = nullptr;
    const unsigned long long parsed = std::strtoull(text.c_str(), &end, 10);
    if (errno != 0 || *end != '\0') return false;
    *value = static_cast<std::uint64_t>(parsed);
    return true;
  };
  type.write = [](const std::uint64_t& value) { return std::to_string(value); };
  return type;
}

// Any scalar, taken as text; an empty value (YAML null) is the empty string.
ValueType<std::string> Text() {
  ValueType<std::string> type;
  type.expected = "a string";
  type.read = [](const YAML::Node& node, std::string* value) {
    if (node.IsNull()) {
      value->clear();
      return true;
    }
    if (!node.IsScalar()) return false;
    *value = node.Scalar();
    return true;
  };
  type.write = [](const std::string& value) {
    YAML::Emitter emitter;
    emitter << YAML::DoubleQuoted << value;
    return std::string(emitter.c_str());
  };
  return type;
}

// true or false (YAML also accepts yes/no, on/off).
ValueType<bool> Boolean() {
  ValueType<bool> type;
  type.expected = "true or false";
  type.read = [](const YAML::Node& node, bool* value) {
    if (!node.IsScalar()) return false;
    bool parsed;
    if (!YAML::convert<bool>::decode(node, parsed)) return false;
    *value = parsed;
    return true;
  };
  type.write = [](const bool& value) { return std::string(value ? "true" : "false"); };
  return type;
}

// A YAML list of `element` values; a single value is a list of one. At most
// max_size values (0: any number). Written as a flow list of the element's own text.
template <typename T>
ValueType<std::vector<T>> ListOf(const ValueType<T>& element, const std::string& expected,
                                 std::size_t max_size = 0) {
  ValueType<std::vector<T>> type;
  type.expected = expected;
  type.read = [element, max_size](const YAML::Node& node, std::vector<T>* value) {
    std::vector<T> parsed;
    auto append = [&](const YAML::Node& item) {
      T item_value;
      if (!element.read(item, &item_value)) return false;
      parsed.push_back(item_value);
      return true;
    };
    if (node.IsScalar()) {
      if (!append(node)) return false;
    } else if (node.IsSequence()) {
      for (const YAML::Node& item : node) {
        if (!append(item)) return false;
      }
    } else {
      return false;
    }
    if (max_size > 0 && parsed.size() > max_size) return false;
    *value = parsed;
    return true;
  };
  type.write = [element](const std::vector<T>& value) {
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i) {
      text += (i == 0 ? "" : ", ") + element.write(value[i]);
    }
    return text + "]";
  };
  return type;
}

// A YAML list of numbers ([.inf, 20, 2.5]). NaN is refused; ranges are checked by the
// sections' IsValid.
ValueType<std::vector<double>> NumberList() {
  return ListOf(Number(), "a list of numbers, e.g. [.inf, 20, 2.5]");
}

// A YAML list of 1 to 3 positive integers ([16, 4]); [] (the default): no grid.
ValueType<std::vector<int>> GridCounts() {
  return ListOf(PositiveInteger<int>(),
                "1 to 3 positive integers, one per coordinate, e.g. [16, 4]", 3);
}

// A YAML list of strings ([u@0.25, e@0.65]); a single string is a list of one, an
// empty value the empty list.
ValueType<std::vector<std::string>> TextList() {
  ValueType<std::vector<std::string>> type;
  type.expected = "a list of channel names, e.g. [u@0.25, e@0.65]";
  type.read = [](const YAML::Node& node, std::vector<std::string>* value) {
    std::vector<std::string> parsed;
    if (node.IsNull()) {
      value->clear();
      return true;
    }
    if (node.IsScalar()) {
      parsed.push_back(node.Scalar());
    } else if (node.IsSequence()) {
      for (const YAML::Node& element : node) {
        if (!element.IsScalar()) return false;
        parsed.push_back(element.Scalar());
      }
    } else {
      return false;
    }
    *value = parsed;
    return true;
  };
  // A name written plain when YAML reads it back so inside a flow list (u@0.25), else
  // double-quoted ("grid 9 #2", "a, b").
  type.write = [](const std::vector<std::string>& value) {
    const auto written = [](const std::string& name) {
      YAML::Emitter emitter;
      if (name.find_first_of(",[]{}") != std::string::npos) emitter << YAML::DoubleQuoted;
      emitter << name;
      return std::string(emitter.c_str());
    };
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i) {
      text += (i == 0 ? "" : ", ") + written(value[i]);
    }
    return text + "]";
  };
  return type;
}

// A YAML list of zones, each a map {start: m, end: m, modulus: Pa} (flow or block
// style); ranges are checked against the bar by ValidateDataAgainstBar.
ValueType<std::vector<ModulusZone>> ZoneList() {
  ValueType<std::vector<ModulusZone>> type;
  type.expected = "a list of zones {start: m, end: m, modulus: Pa}";
  type.read = [](const YAML::Node& node, std::vector<ModulusZone>* value) {
    std::vector<ModulusZone> parsed;
    if (node.IsNull()) {
      value->clear();
      return true;
    }
    if (!node.IsSequence()) return false;
    const ValueType<double> number = Number();
    for (const YAML::Node& element : node) {
      if (!element.IsMap() || element.size() != 3) return false;
      ModulusZone zone;
      if (!element["start"] || !element["end"] || !element["modulus"] ||
          !number.read(element["start"], &zone.start) || !number.read(element["end"], &zone.end) ||
          !number.read(element["modulus"], &zone.modulus)) {
        return false;
      }
      parsed.push_back(zone);
    }
    *value = parsed;
    return true;
  };
  type.write = [](const std::vector<ModulusZone>& value) {
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i) {
      text += std::string(i == 0 ? "" : ", ") + "{start: " + FormatNumber(value[i].start) +
              ", end: " + FormatNumber(value[i].end) +
              ", modulus: " + FormatNumber(value[i].modulus) + "}";
    }
    return text + "]";
  };
  return type;
}

// A YAML map of names to names ({F: force_N, uy_tip: tip_y}); an empty value the
// empty map. The order of the pairs is kept.
ValueType<std::vector<std::pair<std::string, std::string>>> NameMap() {
  using Pairs = std::vector<std::pair<std::string, std::string>>;
  ValueType<Pairs> type;
  type.expected = "a map of channel names to CSV columns, e.g. {F: force, uy_tip: tip_y}";
  type.read = [](const YAML::Node& node, Pairs* value) {
    if (node.IsNull()) {
      value->clear();
      return true;
    }
    if (!node.IsMap()) return false;
    Pairs parsed;
    for (const auto& pair : node) {
      if (!pair.first.IsScalar() || !pair.second.IsScalar()) return false;
      parsed.emplace_back(pair.first.Scalar(), pair.second.Scalar());
    }
    *value = parsed;
    return true;
  };
  // Every name double-quoted, so that a column such as "F [N]" or "tip #1" reads
  // back as written.
  type.write = [](const Pairs& value) {
    const auto quoted = [](const std::string& name) {
      YAML::Emitter emitter;
      emitter << YAML::DoubleQuoted << name;
      return std::string(emitter.c_str());
    };
    std::string text = "{";
    for (std::size_t i = 0; i < value.size(); ++i) {
      text += (i == 0 ? "" : ", ") + quoted(value[i].first) + ": " + quoted(value[i].second);
    }
    return text + "}";
  };
  return type;
}

// An enum written by name, with the to/from-string pair of types.h; `values`
// lists every value (for the messages and the commented config).
template <typename Enum>
ValueType<Enum> EnumByName(std::vector<Enum> values, const char* (*to_string)(Enum),
                           bool (*from_string)(const std::string&, Enum*)) {
  ValueType<Enum> type;
  type.expected = "one of ";
  for (std::size_t i = 0; i < values.size(); ++i) {
    type.expected += std::string(i == 0 ? "" : ", ") + "'" + to_string(values[i]) + "'";
    type.choices += std::string(i == 0 ? "" : " | ") + to_string(values[i]);
  }
  type.read = [from_string](const YAML::Node& node, Enum* value) {
    return node.IsScalar() && from_string(node.Scalar(), value);
  };
  type.write = [to_string](const Enum& value) { return std::string(to_string(value)); };
  return type;
}

// ---------------------------------------------------------------------------
// The key table.

// One key of the config: its dotted path, documentation, and how its value is
// read from YAML into a Config and written back.
struct Key {
  std::string path;         // "section.name", or "section.block.name" in a block
                            // of a section (study.robustness.snr)
  std::string unit;         // SI unit, "" for dimensionless values
  std::string description;  // one line, for the commented default config
  std::string choices;      // "a | b" for enums, "" otherwise
  std::string expected;     // for messages: "a number (in m)"
  std::function<bool(const YAML::Node& node, Config* config)> read;
  std::function<std::string(const Config& config)> write;

  std::string section() const { return path.substr(0, path.find('.')); }
  // The map the key is written in: its section or its block ("study.robustness").
  std::string parent() const { return path.substr(0, path.rfind('.')); }
  // Its name in that map ("snr").
  std::string leaf() const { return path.substr(path.rfind('.') + 1); }
};

// The row of key `path` stored in config.*section.*field.
template <typename Section, typename T>
Key MakeKey(const char* path, Section Config::*section, T Section::*field, const ValueType<T>& type,
            const char* unit, const char* description) {
  Key key;
  key.path = path;
  key.unit = unit;
  key.description = description;
  key.choices = type.choices;
  key.expected = type.expected + (key.unit.empty() ? "" : " (in " + key.unit + ")");
  key.read = [section, field, read = type.read](const YAML::Node& node, Config* config) {
    return read(node, &((config->*section).*field));
  };
  key.write = [section, field, write = type.write](const Config& config) {
    return write((config.*section).*field);
  };
  return key;
}

// The row of key `path` stored in config.*section.*part.*field (a struct inside
// a section, e.g. mcre.weights.displacement_weight).
template <typename Section, typename Part, typename T>
Key MakeKey(const char* path, Section Config::*section, Part Section::*part, T Part::*field,
            const ValueType<T>& type, const char* unit, const char* description) {
  Key key;
  key.path = path;
  key.unit = unit;
  key.description = description;
  key.choices = type.choices;
  key.expected = type.expected + (key.unit.empty() ? "" : " (in " + key.unit + ")");
  key.read = [section, part, field, read = type.read](const YAML::Node& node, Config* config) {
    return read(node, &((config->*section).*part.*field));
  };
  key.write = [section, part, field, write = type.write](const Config& config) {
    return write((config.*section).*part.*field);
  };
  return key;
}

// Every CoupledSolverType, in the order of the enum: the values whose name is
// known to CoupledSolverTypeToString, from the first (the enum is contiguous
// from 0), so that a solver added to coupled_solver.h is accepted here as well.
std::vector<CoupledSolverType> AllCoupledSolverTypes() {
  std::vector<CoupledSolverType> types;
  for (int value = 0;; ++value) {
    const auto type = static_cast<CoupledSolverType>(value);
    if (std::string(CoupledSolverTypeToString(type)) == "unknown") break;
    types.push_back(type);
  }
  return types;
}

// Every key of the config, in the order of the written config. Defaults are those
// of a default-constructed Config. To add a key, add a row (and the field to its
// section struct); to add a section, also add its struct to Config and its
// IsValid to SectionValidators().
const std::vector<Key>& KeyTable() {
  static const std::vector<Key> table = {
      MakeKey("model.kind", &Config::structure, &StructureOptions::kind,
              EnumByName<ModelKind>({ModelKind::kBar, ModelKind::kMatrix}, ModelKindToString,
                                    StringToModelKind),
              "", "the structure: the built-in bar, or matrices named by model.manifest"),
      MakeKey("model.manifest", &Config::structure, &StructureOptions::manifest, Text(), "",
              "model.kind matrix: the manifest model.yaml of the matrices; relative to this file"),
      MakeKey("model.channel_map", &Config::structure, &StructureOptions::channel_map, NameMap(),
              "", "model.kind matrix: {manifest channel: CSV column} where the names differ"),
      MakeKey("model.length", &Config::model, &BarProperties::length, Number(), "m",
              "length L of the bar"),
      MakeKey("model.section", &Config::model, &BarProperties::section, Number(), "m^2",
              "cross-section area S"),
      MakeKey("model.density", &Config::model, &BarProperties::density, Number(), "kg/m^3",
              "density rho"),
      MakeKey("model.modulus", &Config::model, &BarProperties::modulus, Number(), "Pa",
              "Young's modulus E of the reference (or initial) model"),
      MakeKey("model.elements", &Config::model, &BarProperties::elements, PositiveInteger<int>(),
              "", "number N of linear finite elements"),
      MakeKey("model.coarse_elements", &Config::model, &BarProperties::coarse_elements,
              NonNegativeInteger(), "",
              "above this many elements E is identified on this many first, then refined on "
              "model.elements (0: one mesh; docs/multilevel.md)"),
      MakeKey("model.mass", &Config::model, &BarProperties::mass,
              EnumByName<MassType>({MassType::kConsistent, MassType::kLumped}, MassTypeToString,
                                   StringToMassType),
              "", "element mass matrix"),
      MakeKey("model.reaction_length", &Config::model, &BarProperties::reaction_length, Number(),
              "m", "a trusted clamp's reaction: the axial force averaged over [0, this]"),
      MakeKey("model.zoning", &Config::zones, &ZoneLayout::zoning,
              EnumByName<Zoning>(
                  {Zoning::kEqual, Zoning::kPerElement, Zoning::kBoundaries, Zoning::kGrid},
                  ZoningToString, StringToZoning),
              "",
              "zones of constant modulus the identification finds (docs/zones_and_sensors.md; "
              "a matrix model: its manifest's zones, per_element or grid)"),
      MakeKey("model.zone_count", &Config::zones, &ZoneLayout::zone_count, PositiveInteger<int>(),
              "", "zones of equal length (model.zoning: equal; 1 = the uniform bar)"),
      MakeKey("model.zone_boundaries", &Config::zones, &ZoneLayout::zone_boundaries, NumberList(),
              "m", "interior zone boundaries (model.zoning: boundaries)"),
      MakeKey("model.zone_grid", &Config::zones, &ZoneLayout::zone_grid, GridCounts(), "",
              "zones per coordinate of the element positions (model.zoning: grid)"),
      MakeKey("model.free_zones", &Config::zones, &ZoneLayout::free_zones, TextList(), "",
              "matrix model, zoning per_element or grid: the zones that keep their own "
              "modulus, the others tied into one zone 'rest' ([] = every zone free)"),
      MakeKey("load.kind", &Config::load, &LoadOptions::kind,
              EnumByName<LoadKind>({LoadKind::kHalfSine}, LoadKindToString, StringToLoadKind), "",
              "shape of the shock load applied at x = L"),
      MakeKey("load.amplitude", &Config::load, &LoadOptions::amplitude, Number(), "N",
              "peak force F0"),
      MakeKey("load.duration", &Config::load, &LoadOptions::duration, Number(), "s",
              "duration t_load of the load"),
      MakeKey("time.window", &Config::time, &TimeOptions::window, Number(), "s",
              "observation window T"),
      MakeKey("time.step", &Config::time, &TimeOptions::step, Number(), "s",
              "time step h; T / h must be a whole number"),
      MakeKey("time.theta", &Config::time, &TimeOptions::theta, Number(), "",
              "theta-method parameter in [0.5, 1] (0.5: trapezoidal rule)"),
      MakeKey("data.source", &Config::data, &DataOptions::source,
              EnumByName<DataSource>({DataSource::kSynthetic, DataSource::kCsv}, DataSourceToString,
                                     StringToDataSource),
              "", "where the measurements come from"),
      MakeKey("data.path", &Config::data, &DataOptions::path, Text(), "",
              "measurement CSV if source is csv (t,u0,uL,f0,fL; matrices: t and the manifest's "
              "channels); relative to this file"),
      MakeKey("data.truth", &Config::data, &DataOptions::truth,
              EnumByName<TruthModel>({TruthModel::kFiniteElement, TruthModel::kExact},
                                     TruthModelToString, StringToTruthModel),
              "", "truth sampled by the synthetic data"),
      MakeKey("data.truth_refinement", &Config::data, &DataOptions::truth_refinement,
              PositiveInteger<int>(), "",
              "mesh and step refinement of the finite_element truth, in [1, 64]"),
      MakeKey("data.snr", &Config::data, &DataOptions::snr, Number(), "",
              "signal-to-noise ratio of the synthetic noise (.inf: no noise)"),
      MakeKey("data.seed", &Config::data, &DataOptions::seed, UnsignedInteger(), "",
              "seed of the noise generator"),
      MakeKey("data.sensors", &Config::data, &DataOptions::sensors, TextList(), "",
              "interior channels of synthetic data beside u0, uL, f0, fL: u@X (displacement "
              "at X m), e@X (strain at X m)"),
      MakeKey("data.channels", &Config::data, &DataOptions::channels, TextList(), "",
              "channels the identification uses ([] = every channel of the data; f0 and fL "
              "always; on a matrix model: the manifest's sensors it uses, its loads and "
              "supports always)"),
      MakeKey("data.truth_zones", &Config::data, &DataOptions::truth_zones, ZoneList(), "",
              "synthetic truth: stretches of another modulus, [{start: m, end: m, modulus: Pa}]"),
      MakeKey("data.support_stiffness", &Config::data, &DataOptions::support_stiffness, Number(),
              "N/m",
              "synthetic truth: a spring of this stiffness holds x = 0 (.inf: a rigid clamp); "
              "u0 its displacement, f0 = -k_s u0"),
      MakeKey("data.truth_manifest", &Config::data, &DataOptions::truth_manifest, Text(), "",
              "model.kind matrix, synthetic: the truth's manifest (\"\": the model's own); "
              "relative to this file"),
      MakeKey("data.time_column", &Config::data, &DataOptions::time_column, Text(), "",
              "model.kind matrix, csv: the record's time column [s]"),
      MakeKey("data.time_origin", &Config::data, &DataOptions::time_origin, Number(), "s",
              "model.kind matrix, csv: the record's time that is the model's t = 0"),
      MakeKey("data.at_rest_before_record", &Config::data, &DataOptions::at_rest_before_record,
              Boolean(), "",
              "model.kind matrix, csv: the record may begin after t = 0, every channel 0 "
              "before its first sample"),
      MakeKey("data.truth_moduli", &Config::data, &DataOptions::truth_moduli, NumberList(), "Pa",
              "model.kind matrix, synthetic: the truth's zone moduli ([]: their nominal moduli)"),
      MakeKey("mcre.w_u", &Config::mcre, &McreOptions::weights, &McreWeights::displacement_weight,
              Number(), "", "displacement weight: beta = w_u S E0 / L"),
      MakeKey("mcre.w_f", &Config::mcre, &McreOptions::weights, &McreWeights::force_weight,
              Number(), "", "force weight: alpha = w_f L / (S E0)"),
      MakeKey("mcre.w_e", &Config::mcre, &McreOptions::weights, &McreWeights::strain_weight,
              Number(), "", "strain weight: beta_e = w_e S E0 L"),
      MakeKey("mcre.w_r", &Config::mcre, &McreOptions::weights, &McreWeights::reaction_weight,
              Number(), "",
              "clamp reaction weight (mcre.clamp trusted: f0 an output; pinned: f0 a load): "
              "alpha_r = w_r L / (S E0) (a matrix model's supports: w_r / k*)"),
      MakeKey("mcre.w_u0", &Config::mcre, &McreOptions::weights,
              &McreWeights::clamp_displacement_weight, Number(), "",
              "clamp displacement weight (mcre.clamp pinned): beta_0 = w_u0 S E0 / L (a "
              "matrix model's supports: w_u0 k*)"),
      MakeKey("mcre.w_fu", &Config::mcre, &McreOptions::weights,
              &McreWeights::unmeasured_force_weight, Number(), "",
              "an unmeasured load's weight against the datum 0: alpha_u = w_fu / k* (free as "
              "w_fu -> 0; docs/unmeasured_loads.md)"),
      MakeKey("mcre.unmeasured_loads", &Config::mcre, &McreOptions::unmeasured_loads, TextList(),
              "",
              "load channels nobody measured, found with the admissible fields (the data "
              "need not hold them; the bar: fL)"),
      MakeKey("mcre.unmeasured_load_interval", &Config::mcre,
              &McreOptions::unmeasured_load_interval, NumberList(), "s",
              "start and end of each unmeasured load's interval, outside which it vanishes "
              "([]: it may act over the whole window)"),
      MakeKey("mcre.reference_modulus", &Config::mcre, &McreOptions::reference_modulus, Number(),
              "Pa", "E0 of the weights: a fixed nominal modulus, not the unknown"),
      MakeKey(
          "mcre.clamp", &Config::mcre, &McreOptions::clamp,
          EnumByName<ClampModel>({ClampModel::kMeasured, ClampModel::kTrusted, ClampModel::kPinned},
                                 ClampModelToString, StringToClampModel),
          "",
          "the clamp at x = 0: measured (free-free model, f0 a load, u0 an output), "
          "trusted (u(0) = 0 imposed, f0 a measured output) or pinned (free-free model, "
          "u0's datum the known 0 with weight w_u0, f0 a load with weight w_r); a matrix "
          "model's supports alike (docs/matrix_models.md section 11)"),
      MakeKey(
          "mcre.support_check", &Config::mcre, &McreOptions::support_check,
          EnumByName<SupportCheckAction>(
              {SupportCheckAction::kSwitch, SupportCheckAction::kWarn, SupportCheckAction::kOff},
              SupportCheckActionToString, StringToSupportCheckAction),
          "",
          "with mcre.clamp trusted, a measured support displacement tested against its "
          "force: switch (a contradicted support is treated as measured, with the "
          "paper's weights), warn, or off (docs/boundaries.md)"),
      MakeKey("mcre.support_check_threshold", &Config::mcre, &McreOptions::support_check_threshold,
              Number(), "",
              "the support test's t above which the data contradict a rigid support (a false "
              "alarm rate of 1 - Phi(threshold))"),
      MakeKey("mcre.support_check_ramp_start", &Config::mcre,
              &McreOptions::support_check_ramp_start, Number(), "",
              "the support test's t from which E weighs in the paper's formulation's, "
              "linearly up to all of it at mcre.support_check_threshold (equal to it: a hard "
              "switch; docs/boundaries.md section 10)"),
      MakeKey("inner.method", &Config::inner, &CoupledSolverOptions::type,
              EnumByName<CoupledSolverType>(AllCoupledSolverTypes(), CoupledSolverTypeToString,
                                            StringToCoupledSolverType),
              "",
              "solver of the coupled direct/retrograde problem for one E; auto: "
              "conjugate_gradient when its fields fit inner.max_field_bytes, else "
              "streaming_conjugate_gradient, which stores none"),
      MakeKey("inner.preconditioner", &Config::inner, &CoupledSolverOptions::preconditioner,
              EnumByName<TracePreconditioner>(
                  {TracePreconditioner::kNone, TracePreconditioner::kDenseTraces},
                  TracePreconditionerToString, StringToTracePreconditioner),
              "",
              "streaming_conjugate_gradient's preconditioner: none, or dense_traces (I - L at "
              "nearby moduli, dense over the traces; a structure given by matrices)"),
      MakeKey("inner.preconditioner_rebuild_change", &Config::inner,
              &CoupledSolverOptions::preconditioner_rebuild_change, Number(), "",
              "dense_traces is rebuilt when a modulus moved by more than this (relative)"),
      MakeKey("inner.max_preconditioner_traces", &Config::inner,
              &CoupledSolverOptions::max_preconditioner_traces, PositiveInteger<long>(), "",
              "dense_traces only up to this many traces x samples (its factor: their square "
              "in doubles)"),
      MakeKey("inner.tolerance", &Config::inner, &CoupledSolverOptions::tolerance, Number(), "",
              "stop when ||c - A W||_P / ||c||_P falls below this, in (0, 1)"),
      MakeKey("inner.unchecked_tolerance", &Config::inner,
              &CoupledSolverOptions::unchecked_tolerance, Number(), "",
              "conjugate_gradient solves to a tolerance at least this end on the recursive "
              "residual, without the true residual's 2 sweeps; 1: every solve checked"),
      MakeKey("inner.max_iterations", &Config::inner, &CoupledSolverOptions::max_iterations,
              PositiveInteger<int>(), "", "sweep pairs allowed to one iterative solve"),
      MakeKey("inner.omega", &Config::inner, &CoupledSolverOptions::relaxation_coefficient,
              Number(), "", "relaxation coefficient of method relaxation, in (0, 2)"),
      MakeKey("inner.spectrum_steps", &Config::inner,
              &CoupledSolverOptions::spectrum_estimation_steps, PositiveInteger<int>(), "",
              "Lanczos steps of adaptive_relaxation's spectrum estimate, at least 2"),
      MakeKey("inner.spectrum_safety_factor", &Config::inner,
              &CoupledSolverOptions::spectrum_safety_factor, Number(), "",
              "adaptive_relaxation: factor (>= 1) on the estimated largest eigenvalue"),
      MakeKey("inner.divergence_factor", &Config::inner, &CoupledSolverOptions::divergence_factor,
              Number(), "", "a residual this many times above the least seen is divergence"),
      MakeKey("inner.max_all_at_once_unknowns", &Config::inner,
              &CoupledSolverOptions::max_all_at_once_unknowns, PositiveInteger<long>(), "",
              "all_at_once refuses systems with more unknowns"),
      MakeKey("inner.max_all_at_once_bytes", &Config::inner,
              &CoupledSolverOptions::max_all_at_once_bytes, PositiveInteger<long>(), "bytes",
              "all_at_once refuses when its matrix and LU factors would need more memory"),
      MakeKey("inner.max_field_bytes", &Config::inner, &CoupledSolverOptions::max_field_bytes,
              PositiveInteger<long>(), "bytes",
              "relaxation and conjugate_gradient refuse when their fields would need more "
              "memory; auto then streams, keeping the retrograde field's history when that "
              "one field fits"),
      MakeKey("inner.max_dense_solver_bytes", &Config::inner,
              &CoupledSolverOptions::max_dense_solver_bytes, PositiveInteger<long>(), "bytes",
              "riccati and multiple_shooting refuse to store more"),
      MakeKey("inner.shooting_condition_limit", &Config::inner,
              &CoupledSolverOptions::shooting_condition_limit, Number(), "",
              "shooting fails above this condition number of its matrix (> 1)"),
      MakeKey("inner.shooting_segment_growth", &Config::inner,
              &CoupledSolverOptions::shooting_segment_growth, Number(), "",
              "multiple_shooting: growth (> 1) of the fastest solution per segment"),
      MakeKey("outer.functional", &Config::outer, &IdentificationOptions::functional,
              EnumByName<OuterFunctional>({OuterFunctional::kMcre, OuterFunctional::kLeastSquares},
                                          OuterFunctionalToString, StringToOuterFunctional),
              "",
              "functional minimised over E: the MCRE e^2, or output-error least squares "
              "(identify run only)"),
      MakeKey("outer.optimizer", &Config::outer, &IdentificationOptions::optimizer,
              EnumByName<OptimizerType>({OptimizerType::kNlopt, OptimizerType::kCeres},
                                        OptimizerTypeToString, StringToOptimizerType),
              "", "outer optimiser of e^2(E)"),
      MakeKey("outer.algorithm", &Config::outer, &IdentificationOptions::algorithm,
              EnumByName<OuterAlgorithm>(
                  {OuterAlgorithm::kDefault, OuterAlgorithm::kBobyqa, OuterAlgorithm::kCobyla,
                   OuterAlgorithm::kSbplx, OuterAlgorithm::kMma, OuterAlgorithm::kLbfgs,
                   OuterAlgorithm::kSlsqp, OuterAlgorithm::kBfgs, OuterAlgorithm::kBrent,
                   OuterAlgorithm::kSecant},
                  OuterAlgorithmToString, StringToOuterAlgorithm),
              "",
              "default: bobyqa (nlopt) or lbfgs (ceres); nlopt: bobyqa, cobyla, sbplx, mma, "
              "lbfgs, slsqp, brent (bounded 1-D, derivative-free), secant (bounded 1-D, on the "
              "gradient); ceres: lbfgs, bfgs"),
      MakeKey("outer.lower_bound", &Config::outer, &IdentificationOptions::lower_bound, Number(),
              "Pa", "least modulus searched, > 0"),
      MakeKey("outer.upper_bound", &Config::outer, &IdentificationOptions::upper_bound, Number(),
              "Pa", "largest modulus searched"),
      MakeKey("outer.initial", &Config::outer, &IdentificationOptions::initial, Number(), "Pa",
              "start of the search, strictly inside the bounds; also the scale of E"),
      MakeKey("outer.relative_tolerance", &Config::outer,
              &IdentificationOptions::relative_tolerance, Number(), "",
              "stop when a step changes E by less than this fraction of E"),
      MakeKey("outer.max_evaluations", &Config::outer, &IdentificationOptions::max_evaluations,
              PositiveInteger<int>(), "",
              "evaluations allowed to the identification, the scans' and the search's included"),
      MakeKey("outer.max_time", &Config::outer, &IdentificationOptions::max_time, Number(), "s",
              "wall time allowed to the identification, scan included"),
      MakeKey("outer.scan_points", &Config::outer, &IdentificationOptions::scan_points,
              NonNegativeInteger(), "",
              "fewest moduli of the global scan over the bounds; 0: no scan, local search only"),
      MakeKey("outer.scan_samples_per_valley", &Config::outer,
              &IdentificationOptions::scan_samples_per_valley, Number(), "",
              "scan samples per predicted valley spacing of e^2 in ln E; 0: scan_points alone"),
      MakeKey("outer.scan_max_points", &Config::outer, &IdentificationOptions::scan_max_points,
              PositiveInteger<int>(), "", "most moduli of the global scan"),
      MakeKey("outer.scan_tolerance", &Config::outer, &IdentificationOptions::scan_tolerance,
              Number(), "", "relative residual of the scan's inner solves, in (0, 1)"),
      MakeKey("outer.scan_threads", &Config::outer, &IdentificationOptions::scan_threads,
              PositiveInteger<int>(), "", "threads of the scan, in [1, 64]"),
      MakeKey("outer.refine_margin", &Config::outer, &IdentificationOptions::refine_margin,
              Number(), "",
              "valleys within this fraction of the lowest scan cost are refined, in [0, 10]"),
      MakeKey("outer.refine_candidates", &Config::outer, &IdentificationOptions::refine_candidates,
              PositiveInteger<int>(), "",
              "most valleys of the scan refined by the local optimiser"),
      MakeKey("search.functional", &Config::search, &SearchOptions::functional,
              EnumByName<SearchFunctional>(
                  {SearchFunctional::kPinned, SearchFunctional::kSame, SearchFunctional::kMeasured},
                  SearchFunctionalToString, StringToSearchFunctional),
              "",
              "the functional the global scan runs on: pinned (the pinned clamp's e^2 with "
              "search.w_*, one valley; mcre:'s e^2 then refined near its minimum), measured "
              "(the measured clamp's e^2 with search.w_u and w_e, then the same) or same "
              "(mcre:'s e^2 itself)"),
      MakeKey("search.w_u", &Config::search, &SearchOptions::displacement_weight, Number(), "",
              "search functional pinned or measured: displacement weight, beta = w_u S E0 / L"),
      MakeKey("search.w_e", &Config::search, &SearchOptions::strain_weight, Number(), "",
              "search functional pinned or measured: strain weight, beta_e = w_e S E0 L"),
      MakeKey("search.w_u0", &Config::search, &SearchOptions::clamp_displacement_weight, Number(),
              "", "search functional pinned: weight of u(0) = 0, beta_0 = w_u0 S E0 / L"),
      MakeKey("search.w_r", &Config::search, &SearchOptions::reaction_weight, Number(), "",
              "search functional pinned: weight of the load f0, alpha_0 = w_r L / (S E0)"),
      MakeKey(
          "search.inner_tolerance", &Config::search, &SearchOptions::inner_tolerance, Number(), "",
          "search functional pinned or measured: relative residual of its inner solves, in (0, 1)"),
      MakeKey("search.scan_points", &Config::search, &SearchOptions::scan_points,
              PositiveInteger<int>(), "",
              "search functional pinned or measured: fewest moduli of its scan (in place of "
              "outer.scan_points)"),
      MakeKey("search.samples_per_valley", &Config::search, &SearchOptions::samples_per_valley,
              Number(), "",
              "search functional pinned or measured: its scan's samples per predicted valley "
              "spacing; 0: outer.scan_samples_per_valley"),
      MakeKey("search.window_points", &Config::search, &SearchOptions::window_points,
              PositiveInteger<int>(), "",
              "search functional pinned or measured: moduli of e^2's scan within "
              "search.refine_window, its edges included, in [3, 100]"),
      MakeKey("search.refine_window", &Config::search, &SearchOptions::refine_window, Number(), "",
              "search functional pinned or measured: mcre:'s e^2 is refined within E_search "
              "(1 -+ this), in (0, 0.5]"),
      MakeKey("search.algorithm", &Config::search, &SearchOptions::algorithm,
              EnumByName<OuterAlgorithm>({OuterAlgorithm::kBobyqa, OuterAlgorithm::kSecant},
                                         OuterAlgorithmToString, StringToOuterAlgorithm),
              "",
              "search functional pinned or measured: its valley's refinement, bobyqa "
              "(derivative-free) or secant (on its gradient), whatever outer.optimizer"),
      MakeKey("search.relative_tolerance", &Config::search, &SearchOptions::relative_tolerance,
              Number(), "",
              "search functional pinned or measured: relative tolerance on E of its valley's "
              "refinement, which places that window; 0: outer.relative_tolerance"),
      MakeKey("search.time_step_factor", &Config::search, &SearchOptions::time_step_factor,
              PositiveInteger<int>(), "",
              "search functional pinned or measured: its largest time step in steps of the data, "
              "in [1, 64], lowered as the forces' band asks (1: the data's own grid)"),
      MakeKey("prefilter.enabled", &Config::prefilter, &PrefilterOptions::enabled, Boolean(), "",
              "zero-phase Butterworth low-pass, the same on every channel the identification "
              "uses (loads, displacements, strains)"),
      MakeKey("prefilter.cutoff_frequency", &Config::prefilter, &PrefilterOptions::cutoff_frequency,
              Number(), "Hz", "cut-off of the pre-filter; 0: derived from the measured load"),
      MakeKey("prefilter.order", &Config::prefilter, &PrefilterOptions::order,
              PositiveInteger<int>(), "", "Butterworth order of one pass, even, in [2, 12]"),
      MakeKey("prefilter.at_rest_before_start", &Config::prefilter,
              &PrefilterOptions::at_rest_before_start, Boolean(), "",
              "every channel is 0 before the first sample: the filter starts from that rest"),
      MakeKey("uncertainty.samples", &Config::uncertainty, &UncertaintyOptions::samples,
              NonNegativeInteger(), "",
              "noise draws of the first-order std of E, in [2, 1000]; 0: not estimated"),
      MakeKey("uncertainty.seed", &Config::uncertainty, &UncertaintyOptions::seed,
              UnsignedInteger(), "", "seed of those noise draws"),
      MakeKey("output.folder", &Config::output, &OutputOptions::folder, Text(), "",
              "results folder of identify run, relative to the working directory"),
      MakeKey("output.figures", &Config::output, &OutputOptions::figures, Boolean(), "",
              "also draw the PNG figures with gnuplot"),
      MakeKey("output.curve_points", &Config::output, &OutputOptions::curve_points,
              PositiveInteger<int>(), "", "points of the cost curve e^2(E), in [5, 1000]"),
      MakeKey("study.kind", &Config::study, &StudyOptions::kind,
              EnumByName<StudyKind>(
                  {StudyKind::kRobustness, StudyKind::kRelaxation, StudyKind::kCostCurves,
                   StudyKind::kAll, StudyKind::kDamage, StudyKind::kComparator, StudyKind::kReadme},
                  StudyKindToString, StringToStudyKind),
              "", "which study `identify study` runs (study.h)"),
      MakeKey("study.folder", &Config::study, &StudyOptions::folder, Text(), "",
              "results folder of identify study (a subfolder per study), relative to the "
              "working directory"),
      MakeKey("study.threads", &Config::study, &StudyOptions::threads, NonNegativeInteger(), "",
              "threads running the studies' runs, in [0, 256]; 0: every core"),
      MakeKey("study.figures", &Config::study, &StudyOptions::figures, Boolean(), "",
              "also draw the studies' PNG figures with gnuplot"),
      MakeKey("study.robustness.snr", &Config::study, &StudyOptions::robustness,
              &StudyOptions::Robustness::snr, NumberList(), "",
              "SNRs of the noise (.inf: none), each > 0"),
      MakeKey("study.robustness.seeds", &Config::study, &StudyOptions::robustness,
              &StudyOptions::Robustness::seeds, PositiveInteger<int>(), "",
              "noise seeds 1..N per finite SNR"),
      MakeKey("study.relaxation.snr", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::snr, NumberList(), "",
              "SNRs of the data (noise seed data.seed)"),
      MakeKey("study.relaxation.moduli", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::moduli, NumberList(), "",
              "trial moduli E / model.modulus, in (0, 10]"),
      MakeKey("study.relaxation.omega_min", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::omega_min, Number(), "", "least omega of the grid, > 0"),
      MakeKey("study.relaxation.omega_max", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::omega_max, Number(), "", "largest omega of the grid, < 2"),
      MakeKey("study.relaxation.omega_points", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::omega_points, PositiveInteger<int>(), "",
              "omegas of the grid, in [2, 1000]"),
      MakeKey("study.relaxation.tolerance", &Config::study, &StudyOptions::relaxation,
              &StudyOptions::Relaxation::tolerance, Number(), "",
              "relative residual the grid's solves reach, in (0, 1)"),
      MakeKey("study.cost_curves.snr", &Config::study, &StudyOptions::cost_curves,
              &StudyOptions::CostCurves::snr, NumberList(), "", "SNRs of the data"),
      MakeKey("study.cost_curves.seeds", &Config::study, &StudyOptions::cost_curves,
              &StudyOptions::CostCurves::seeds, PositiveInteger<int>(), "",
              "noise seeds 1..N per finite SNR"),
      MakeKey("study.cost_curves.points", &Config::study, &StudyOptions::cost_curves,
              &StudyOptions::CostCurves::points, PositiveInteger<int>(), "",
              "moduli of each curve, in [3, 10000]"),
      MakeKey("study.cost_curves.low", &Config::study, &StudyOptions::cost_curves,
              &StudyOptions::CostCurves::low, Number(), "", "least E / model.modulus, > 0"),
      MakeKey("study.cost_curves.high", &Config::study, &StudyOptions::cost_curves,
              &StudyOptions::CostCurves::high, Number(), "", "largest E / model.modulus"),
      MakeKey("study.damage.snr", &Config::study, &StudyOptions::damage, &StudyOptions::Damage::snr,
              NumberList(), "", "SNRs of the grid (.inf: no noise)"),
      MakeKey("study.damage.seeds", &Config::study, &StudyOptions::damage,
              &StudyOptions::Damage::seeds, PositiveInteger<int>(), "",
              "noise seeds of the soft zone at SNR 10 (interior sensors, 10 zones)"),
      MakeKey("study.comparator.snr", &Config::study, &StudyOptions::comparator,
              &StudyOptions::Comparator::snr, NumberList(), "", "SNRs (.inf: no noise)"),
      MakeKey("study.comparator.seeds", &Config::study, &StudyOptions::comparator,
              &StudyOptions::Comparator::seeds, PositiveInteger<int>(), "", "noise seeds per SNR"),
      MakeKey("study.comparator.errors", &Config::study, &StudyOptions::comparator,
              &StudyOptions::Comparator::errors, TextList(), "",
              "model errors (none, density, force_gain, displacement_gain, soft_zone, support_50, "
              "support_10, support_5)"),
      MakeKey("study.comparator.data", &Config::study, &StudyOptions::comparator,
              &StudyOptions::Comparator::data, TextList(), "",
              "the data identified from (raw, prefilter)"),
      MakeKey("zone_identification.optimizer", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::optimizer,
              EnumByName<OptimizerType>({OptimizerType::kNlopt, OptimizerType::kCeres},
                                        OptimizerTypeToString, StringToOptimizerType),
              "", "optimiser of the zone moduli"),
      MakeKey("zone_identification.algorithm", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::algorithm,
              EnumByName<OuterAlgorithm>(
                  {OuterAlgorithm::kDefault, OuterAlgorithm::kBobyqa, OuterAlgorithm::kCobyla,
                   OuterAlgorithm::kSbplx, OuterAlgorithm::kMma, OuterAlgorithm::kLbfgs,
                   OuterAlgorithm::kSlsqp, OuterAlgorithm::kBfgs},
                  OuterAlgorithmToString, StringToOuterAlgorithm),
              "",
              "default: bobyqa (nlopt) or lbfgs (ceres); nlopt: bobyqa, cobyla, sbplx (a few "
              "zones only), mma, lbfgs, slsqp; ceres: lbfgs, bfgs"),
      MakeKey("zone_identification.step_tolerance", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::step_tolerance,
              Number(), "", "stop when a step changes every log E_z by less, in (0, 0.1)"),
      MakeKey("zone_identification.function_tolerance", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::function_tolerance,
              Number(), "", "stop when a step changes the cost by less than this fraction"),
      MakeKey("zone_identification.max_evaluations", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::max_evaluations,
              PositiveInteger<int>(), "", "e^2 evaluations allowed to each minimisation"),
      MakeKey("zone_identification.max_time", &Config::zone_identification,
              &ZoneIdentificationOptions::minimizer, &BoundedMinimizerOptions::max_time, Number(),
              "s", "wall time allowed to each minimisation"),
      MakeKey(
          "zone_identification.regularization", &Config::zone_identification,
          &ZoneIdentificationOptions::regularization, &RegularizationOptions::kind,
          EnumByName<RegularizationKind>({RegularizationKind::kNone, RegularizationKind::kTikhonov,
                                          RegularizationKind::kTotalVariation},
                                         RegularizationKindToString, StringToRegularizationKind),
          "",
          "penalty on the jumps of log E between neighbouring zones (zone_identification."
          "neighbours)"),
      MakeKey("zone_identification.neighbours", &Config::zone_identification,
              &ZoneIdentificationOptions::neighbours,
              EnumByName<ZoneNeighbourhood>(
                  {ZoneNeighbourhood::kOrder, ZoneNeighbourhood::kSharedNodes},
                  ZoneNeighbourhoodToString, StringToZoneNeighbourhood),
              "",
              "the penalty's neighbours: consecutive zones in the model's order (along the bar, "
              "or the manifest's list), or zones sharing a node (a 2-D or 3-D layout)"),
      MakeKey("zone_identification.least_squares_gradient", &Config::zone_identification,
              &ZoneIdentificationOptions::least_squares_gradient,
              EnumByName<LeastSquaresGradient>(
                  {LeastSquaresGradient::kForwardSensitivities, LeastSquaresGradient::kAdjoint},
                  LeastSquaresGradientToString, StringToLeastSquaresGradient),
              "",
              "outer.functional least_squares: its gradient by forward sensitivities (1 + zones "
              "sweeps an evaluation) or by the discrete adjoint (2 sweeps, the trajectory kept)"),
      MakeKey("zone_identification.regularization_weight", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::weight, Number(),
              "", "lambda of the penalty; < 0: by weight_rule"),
      MakeKey("zone_identification.weight_rule", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::weight_rule,
              EnumByName<WeightRule>({WeightRule::kLCurve, WeightRule::kDiscrepancy},
                                     WeightRuleToString, StringToWeightRule),
              "", "how an automatic lambda is chosen"),
      MakeKey("zone_identification.tv_smoothing", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::tv_smoothing,
              Number(), "", "eps of the smoothed total variation (in log E), in (0, 1)"),
      MakeKey("zone_identification.max_weight", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::max_weight,
              Number(), "", "largest lambda of the weight grid / the start's cost"),
      MakeKey("zone_identification.min_weight", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::min_weight,
              Number(), "", "least lambda of the weight grid / the start's cost"),
      MakeKey("zone_identification.grid_factor", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::grid_factor,
              Number(), "", "ratio of neighbouring lambdas of the grid, in (1, 1e6]"),
      MakeKey("zone_identification.refinement_steps", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::refinement_steps,
              NonNegativeInteger(), "",
              "regula falsi steps on log lambda after the grid, in [0, 30]"),
      MakeKey("zone_identification.weight_tolerance", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::weight_tolerance,
              Number(), "",
              "the refinement stops once the next weight is within a factor 1 + this"),
      MakeKey("zone_identification.discrepancy_factor", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization,
              &RegularizationOptions::discrepancy_factor, Number(), "",
              "tau: the misfit target is tau times the noise's expected e^2"),
      MakeKey("zone_identification.floor_margin", &Config::zone_identification,
              &ZoneIdentificationOptions::regularization, &RegularizationOptions::floor_margin,
              EnumByName<FloorMargin>({FloorMargin::kTenPercent, FloorMargin::kNoiseFit},
                                      FloorMarginToString, StringToFloorMargin),
              "",
              "the margin over the misfit floor when the target is missed and the L-curve has "
              "no corner: 10 %, or the noise the free zones fit"),
      MakeKey("zone_identification.noise_samples", &Config::zone_identification,
              &ZoneIdentificationOptions::noise_samples, PositiveInteger<int>(), "",
              "noise draws of the discrepancy target, in [1, 1000]"),
      MakeKey("zone_identification.noise_seed", &Config::zone_identification,
              &ZoneIdentificationOptions::noise_seed, UnsignedInteger(), "",
              "seed of those noise draws"),
      MakeKey("zone_identification.merge_zones", &Config::zone_identification,
              &ZoneIdentificationOptions::merge_zones, Boolean(), "",
              "merge neighbouring zones while a refit meets the discrepancy target"),
      MakeKey("zone_identification.measured_clamp", &Config::zone_identification,
              &ZoneIdentificationOptions::measured_clamp, Boolean(), "",
              "the MCRE's zones on a trusted clamp with u0 in the data: the clamp measured"),
      MakeKey("zone_identification.start_modulus", &Config::zone_identification,
              &ZoneIdentificationOptions::start_modulus, Number(), "Pa",
              "model.kind matrix: every zone starts here, no homogeneous stage (0: from E*)"),
      MakeKey("zone_identification.start_moduli", &Config::zone_identification,
              &ZoneIdentificationOptions::start_moduli, NumberList(), "Pa",
              "model.kind matrix: zone z starts at the z-th, no homogeneous stage (empty: "
              "start_modulus)"),
  };
  return table;
}

// Checks the values of one section; on failure writes a message that names the
// offending key by its dotted path (e.g. "model.length must be ...").
using SectionValidator = std::function<bool(const Config& config, std::string* error)>;

template <typename Section>
SectionValidator ValidatorOf(Section Config::*section) {
  return [section](const Config& config, std::string* error) {
    return (config.*section).IsValid(error);
  };
}

// data:'s IsValid, but on a matrix model data.channels names the manifest's sensors,
// checked against the manifest when it is read (LoadMatrixModel), not the bar's.
SectionValidator DataValidator() {
  return [](const Config& config, std::string* error) {
    if (config.structure.kind != ModelKind::kMatrix) return config.data.IsValid(error);
    DataOptions data = config.data;
    data.channels.clear();
    return data.IsValid(error);
  };
}

// One entry per section of Config, in the order of the checks.
const std::vector<SectionValidator>& SectionValidators() {
  static const std::vector<SectionValidator> validators = {
      ValidatorOf(&Config::structure),
      ValidatorOf(&Config::model),
      ValidatorOf(&Config::load),
      ValidatorOf(&Config::time),
      DataValidator(),
      ValidatorOf(&Config::mcre),
      ValidatorOf(&Config::inner),
      ValidatorOf(&Config::outer),
      ValidatorOf(&Config::search),
      ValidatorOf(&Config::prefilter),
      ValidatorOf(&Config::uncertainty),
      ValidatorOf(&Config::output),
      ValidatorOf(&Config::study),
      ValidatorOf(&Config::zone_identification),
  };
  return validators;
}

// The first key of the search: section but search.functional that is not at its
// default, or null.
const char* SearchKeyNotAtItsDefault(const SearchOptions& search) {
  const SearchOptions defaults;
  const std::pair<const char*, bool> keys[] = {
      {"search.w_u", search.displacement_weight != defaults.displacement_weight},
      {"search.w_e", search.strain_weight != defaults.strain_weight},
      {"search.w_u0", search.clamp_displacement_weight != defaults.clamp_displacement_weight},
      {"search.w_r", search.reaction_weight != defaults.reaction_weight},
      {"search.inner_tolerance", search.inner_tolerance != defaults.inner_tolerance},
      {"search.scan_points", search.scan_points != defaults.scan_points},
      {"search.samples_per_valley", search.samples_per_valley != defaults.samples_per_valley},
      {"search.window_points", search.window_points != defaults.window_points},
      {"search.refine_window", search.refine_window != defaults.refine_window},
      {"search.algorithm", search.algorithm != defaults.algorithm},
      {"search.relative_tolerance", search.relative_tolerance != defaults.relative_tolerance},
      {"search.time_step_factor", search.time_step_factor != defaults.time_step_factor},
  };
  for (const auto& [key, set] : keys) {
    if (set) return key;
  }
  return nullptr;
}

// "" when the keys of a structure given by matrices are at their defaults with the bar;
// else the message, naming the key first. (The bar's keys with model.kind matrix are
// refused where they were set: RefuseKeysOfTheBar.)
std::string StructureKeysProblem(const Config& config) {
  if (config.structure.kind == ModelKind::kBar) {
    const std::pair<const char*, bool> matrix_keys[] = {
        {"model.manifest", !config.structure.manifest.empty()},
        {"model.channel_map", !config.structure.channel_map.empty()},
        {"data.truth_manifest", !config.data.truth_manifest.empty()},
        {"data.truth_moduli", !config.data.truth_moduli.empty()},
        {"data.time_column", config.data.time_column != "t"},
        {"data.time_origin", config.data.time_origin != 0.0},
        {"data.at_rest_before_record", config.data.at_rest_before_record},
        {"zone_identification.start_modulus", config.zone_identification.start_modulus != 0.0},
        {"zone_identification.start_moduli", !config.zone_identification.start_moduli.empty()},
    };
    for (const auto& [key, set] : matrix_keys) {
      if (set) return std::string(key) + " applies to model.kind 'matrix' only (model.kind is 'bar')";
    }
  }
  // Every start modulus (start_modulus when given, each of start_moduli) strictly inside
  // the bounds.
  std::vector<std::pair<const char*, double>> starts;
  if (config.zone_identification.start_modulus != 0.0) {
    starts.emplace_back("zone_identification.start_modulus",
                        config.zone_identification.start_modulus);
  }
  for (const double modulus : config.zone_identification.start_moduli) {
    starts.emplace_back("zone_identification.start_moduli", modulus);
  }
  for (const auto& [key, modulus] : starts) {
    if (!(modulus > config.outer.lower_bound && modulus < config.outer.upper_bound)) {
      return std::string(key) + " (" + FormatNumber(modulus) +
             " Pa) must lie strictly inside [outer.lower_bound, outer.upper_bound] = [" +
             FormatNumber(config.outer.lower_bound) + ", " +
             FormatNumber(config.outer.upper_bound) + "] Pa";
    }
  }
  // outer.functional: both run on a matrix model (least squares by
  // MatrixOutputErrorObjective, app/matrix_identification_run.h).
  // Every inner.method runs on a matrix model: auto streams when its fields do not fit
  // (ResolveCoupledSolverType), Riccati and shooting take its operators
  // (docs/riccati_shooting.md).
  return "";
}

// The cross-section checks of CrossSectionValidators, one a function: true when
// the config passes, else false with *error set, naming the offending key first.

// The identification's zones on the bar (each holds an element), and no key of
// another zoning set: it would be ignored (zone_boundaries without
// model.zoning: boundaries left the bar uniform).
bool CheckZoneLayout(const Config& config, std::string* error) {
  const ZoneLayout defaults;
  const std::string zoning = ZoningToString(config.zones.zoning);
  if (config.zones.zoning != Zoning::kGrid && !config.zones.zone_grid.empty()) {
    *error = "model.zone_grid applies to model.zoning 'grid' only (model.zoning is '" + zoning +
             "'); set model.zoning: grid to use it";
    return false;
  }
  if (config.zones.zoning == Zoning::kGrid && config.zones.zone_grid.empty()) {
    *error = "model.zoning 'grid' needs model.zone_grid, the zones per coordinate (e.g. [16, 4])";
    return false;
  }
  if (!config.zones.free_zones.empty() &&
      !(config.structure.kind == ModelKind::kMatrix && config.zones.RegroupsElements())) {
    *error =
        "model.free_zones applies to a matrix model with model.zoning per_element or "
        "grid (model.zoning is '" +
        zoning + "')";
    return false;
  }
  if (config.structure.kind == ModelKind::kMatrix) {
    // The manifest's zones (the default) or its element blocks regrouped; the grid's
    // counts are checked against the positions when the manifest is read.
    if (config.zones.zoning == Zoning::kBoundaries) {
      *error =
          "model.zoning 'boundaries' applies to the bar only; on a matrix model use "
          "per_element or grid (with model.zone_grid), or leave it out for the manifest's zones";
      return false;
    }
    return true;
  }
  if (config.zones.zoning != Zoning::kBoundaries && !config.zones.zone_boundaries.empty()) {
    *error =
        "model.zone_boundaries applies to model.zoning 'boundaries' only (model.zoning "
        "is '" +
        zoning + "'); set model.zoning: boundaries to use them";
    return false;
  }
  if (config.zones.zoning != Zoning::kEqual && config.zones.zone_count != defaults.zone_count) {
    *error = "model.zone_count applies to model.zoning 'equal' only (model.zoning is '" + zoning +
             "'); leave it out with this zoning";
    return false;
  }
  *error = config.zones.Validate(config.model);
  return error->empty();
}

// The search: section's other keys belong to the pinned search functional: set
// with search.functional same they would be ignored.
bool CheckSearchKeysApply(const Config& config, std::string* error) {
  const char* key = SearchKeyNotAtItsDefault(config.search);
  if (config.search.functional == SearchFunctional::kPinned || key == nullptr) return true;
  if (config.search.functional == SearchFunctional::kMeasured) {
    const SearchOptions defaults;
    const char* pinned_only =
        config.search.clamp_displacement_weight != defaults.clamp_displacement_weight
            ? "search.w_u0"
            : (config.search.reaction_weight != defaults.reaction_weight ? "search.w_r" : nullptr);
    if (pinned_only == nullptr) return true;
    *error = std::string(pinned_only) +
             " applies to search.functional 'pinned' only (search.functional is 'measured': "
             "no datum u(0) = 0, f0 a load at mcre.w_f); leave it out with this functional";
    return false;
  }
  *error = std::string(key) +
           " applies to search.functional 'pinned' only (search.functional is 'same', "
           "the scan runs on mcre:'s e^2); leave it out with this functional";
  return false;
}

// The two stages' scans fit outer's limits (IdentifyInTwoStages): the search's
// search.scan_points and the window's search.window_points samples within
// outer.scan_max_points, and both with two evaluations of a refinement each
// within outer.max_evaluations.
bool CheckTwoStageScansFitLimits(const Config& config, std::string* error) {
  if (config.structure.kind != ModelKind::kBar ||
      config.outer.functional != OuterFunctional::kMcre || !ScansTheSearchFunctional(config)) {
    return true;
  }
  const int window_points = config.search.window_points;
  const int least_evaluations = config.search.scan_points + window_points + 4;
  std::ostringstream why;
  if (config.search.scan_points > config.outer.scan_max_points) {
    why << "search.scan_points (" << config.search.scan_points
        << ") must not exceed outer.scan_max_points (" << config.outer.scan_max_points << ")";
  } else if (config.outer.scan_max_points < window_points) {
    why << "outer.scan_max_points (" << config.outer.scan_max_points
        << ") must be at least search.window_points (" << window_points
        << ") with search.functional '" << SearchFunctionalToString(config.search.functional)
        << "': e^2 is scanned over that many moduli near the search's minimiser";
  } else if (config.outer.max_evaluations < least_evaluations) {
    why << "outer.max_evaluations (" << config.outer.max_evaluations
        << ") must be at least search.scan_points + search.window_points + 4 = "
        << least_evaluations << " with search.functional '"
        << SearchFunctionalToString(config.search.functional) << "': the search's scan, e^2's "
        << window_points << " near its minimiser and two evaluations of each refinement";
  } else {
    return true;
  }
  *error = why.str();
  return false;
}

// Sensors on the bar, truth zones inside it and apart, a truth that can give them.
bool CheckDataAgainstBar(const Config& config, std::string* error) {
  if (config.structure.kind == ModelKind::kMatrix) {
    // data.channels names the manifest's sensors (DataValidator); the bar's other keys of
    // data: are refused on a matrix model (CheckStructureKeys).
    DataOptions data = config.data;
    data.channels.clear();
    *error = ValidateDataAgainstBar(data, config.model);
    return error->empty();
  }
  *error = ValidateDataAgainstBar(config.data, config.model);
  return error->empty();
}

// The keys of one kind of structure are left at their defaults with the other.
bool CheckStructureKeys(const Config& config, std::string* error) {
  *error = StructureKeysProblem(config);
  return error->empty();
}

// Unmeasured loads: least squares fits the measured loads' response and has no
// unknown force (docs/unmeasured_loads.md section 4); on the bar only fL can be one
// (f0 is the clamp's; a matrix model's names are checked against its manifest by
// LoadMatrixModel).
bool CheckUnmeasuredLoads(const Config& config, std::string* error) {
  if (config.mcre.unmeasured_loads.empty()) return true;
  if (config.outer.functional == OuterFunctional::kLeastSquares) {
    *error =
        "mcre.unmeasured_loads: outer.functional least_squares needs every load measured (it "
        "has no unknown force); use outer.functional: mcre, or measure the load";
    return false;
  }
  if (config.structure.kind == ModelKind::kBar) {
    for (const std::string& channel : config.mcre.unmeasured_loads) {
      if (channel != "fL") {
        *error = "mcre.unmeasured_loads: '" + channel +
                 "' is no load of the bar; its one load is fL (f0 is the clamp's reaction: "
                 "mcre.clamp chooses how it enters)";
        return false;
      }
    }
  }
  return true;
}

// A load the time grid sees: the half sine of load.duration spans at least two
// steps, so that a sample falls inside it.
bool CheckLoadSpansTwoSteps(const Config& config, std::string* error) {
  if (config.structure.kind != ModelKind::kBar || config.load.duration >= 2.0 * config.time.step) {
    return true;
  }
  *error = "load.duration (" + FormatNumber(config.load.duration) +
           " s) must span at least two time steps, 2 time.step = " +
           FormatNumber(2.0 * config.time.step) + " s, or the sampled load is zero";
  return false;
}

// Sizes a bar's run can hold, refused here rather than by an allocation part way
// (the synthetic truth is simulated before the first solve): the finite-element
// truth's elements and steps (model.elements and the model's steps, each times
// data.truth_refinement) count in int, and an iterative method's fields fit
// inner.max_field_bytes (SolveCoupled's check, made before any work; auto resolved
// as SolveCoupled resolves it, so it is never refused here).
bool CheckBarRunSizes(const Config& config, std::string* error) {
  if (config.structure.kind != ModelKind::kBar) return true;
  constexpr double kMaxTruthCount = 1e9;  // below INT_MAX = 2.1e9
  const double elements = config.model.elements;
  const double steps = config.time.NumSteps();
  const double refinement = config.data.truth_refinement;
  std::ostringstream why;
  if (config.data.source == DataSource::kSynthetic &&
      config.data.truth == TruthModel::kFiniteElement &&
      (elements * refinement > kMaxTruthCount || steps * refinement > kMaxTruthCount)) {
    why << "data.truth_refinement (" << config.data.truth_refinement
        << ") gives the finite-element truth " << FormatNumber(elements * refinement)
        << " elements (model.elements x data.truth_refinement) and "
        << FormatNumber(steps * refinement)
        << " steps (time.window / time.step x data.truth_refinement), more than the limit "
           "of 1e9 for either; use a smaller refinement, fewer elements or a larger step";
    *error = why.str();
    return false;
  }
  const double field_bytes = IterativeSolverFieldBytes(elements + 1.0, steps);
  const CoupledSolverType method =
      ResolveCoupledSolverType(config.inner, elements + 1.0, steps, true);
  if (HoldsIterativeSolverFields(method) &&
      field_bytes > static_cast<double>(config.inner.max_field_bytes)) {
    why << "model.elements (" << config.model.elements << ") and " << FormatNumber(steps)
        << " steps (time.window / time.step) need " << static_cast<long long>(field_bytes)
        << " bytes for inner.method '" << CoupledSolverTypeToString(method) << "' ("
        << kIterativeSolverFields
        << " fields of (N + 1) x (steps + 1) doubles), above inner.max_field_bytes = "
        << config.inner.max_field_bytes
        << "; use inner.method: streaming_conjugate_gradient (or auto), which stores no "
           "space-time field, raise inner.max_field_bytes, or use fewer elements, a "
           "shorter window or a larger step";
    *error = why.str();
    return false;
  }
  return true;
}

// A cut-off at or above the Nyquist frequency is not a low-pass filter of the
// sampled data (the bilinear transform maps Nyquist to tan(pi/2)).
bool CheckPrefilterBelowNyquist(const Config& config, std::string* error) {
  const double cutoff = config.prefilter.cutoff_frequency;
  const double nyquist = 0.5 / config.time.step;
  if (cutoff > 0.0 && !(cutoff < nyquist)) {
    *error = "prefilter.cutoff_frequency (" + FormatNumber(cutoff) +
             " Hz) must be below the Nyquist frequency 0.5 / time.step = " + FormatNumber(nyquist) +
             " Hz (time.step = " + FormatNumber(config.time.step) +
             " s), or 0 to derive it from the data";
    return false;
  }
  return true;
}

// Checks of keys from more than one section, run once every section is valid on
// its own. The same convention as the sections' IsValid: the message names the
// offending key first (Locate places it where that key was set), then the keys
// it is compared with.
const std::vector<SectionValidator>& CrossSectionValidators() {
  static const std::vector<SectionValidator> validators = {
      CheckZoneLayout,              // model.zoning, zone_count, zone_boundaries
      CheckSearchKeysApply,         // search.* against search.functional
      CheckTwoStageScansFitLimits,  // search.scan_points against outer.*
      CheckDataAgainstBar,          // data.* against model.*
      CheckStructureKeys,           // keys of the other model.kind
      CheckLoadSpansTwoSteps,       // load.duration against time.step
      CheckUnmeasuredLoads,         // mcre.unmeasured_loads against outer.*, model.*
      CheckBarRunSizes,             // model.elements, time.*, data.truth_refinement, inner.*
      CheckPrefilterBelowNyquist,   // prefilter.cutoff_frequency against time.step
  };
  return validators;
}

// The blocks of keys inside a section, each with the line that heads it in the
// commented default config. A block is named after the study kind whose keys it
// holds; a key "section.block.name" of KeyTable() lies in one of these.
const std::vector<std::pair<std::string, std::string>>& BlockTable() {
  static const std::vector<std::pair<std::string, std::string>> table = {
      {"study.robustness", "study.kind robustness: identifications on noisy data per SNR"},
      {"study.relaxation", "study.kind relaxation: sweeps of the fixed-omega relaxation"},
      {"study.cost_curves", "study.kind cost_curves: e^2(E) around model.modulus"},
      {"study.damage", "study.kind damage: localisation of a soft zone (damage_study.h)"},
      {"study.comparator", "study.kind comparator: MCRE against least squares"},
  };
  return table;
}

// The study keys as they were before the study blocks, by their names now.
const std::map<std::string, std::string>& FlatStudyKeyRenames() {
  static const std::map<std::string, std::string> renames = {
      {"study.robustness_snr", "study.robustness.snr"},
      {"study.robustness_seeds", "study.robustness.seeds"},
      {"study.relaxation_snr", "study.relaxation.snr"},
      {"study.relaxation_moduli", "study.relaxation.moduli"},
      {"study.omega_min", "study.relaxation.omega_min"},
      {"study.omega_max", "study.relaxation.omega_max"},
      {"study.omega_points", "study.relaxation.omega_points"},
      {"study.relaxation_tolerance", "study.relaxation.tolerance"},
      {"study.cost_curve_snr", "study.cost_curves.snr"},
      {"study.cost_curve_seeds", "study.cost_curves.seeds"},
      {"study.cost_curve_points", "study.cost_curves.points"},
      {"study.cost_curve_low", "study.cost_curves.low"},
      {"study.cost_curve_high", "study.cost_curves.high"},
      {"study.damage_snr", "study.damage.snr"},
      {"study.damage_seeds", "study.damage.seeds"},
      {"study.comparator_snr", "study.comparator.snr"},
      {"study.comparator_seeds", "study.comparator.seeds"},
      {"study.comparator_errors", "study.comparator.errors"},
      {"study.comparator_data", "study.comparator.data"},
  };
  return renames;
}

bool IsBlock(const std::string& path) {
  const auto& blocks = BlockTable();
  return std::any_of(blocks.begin(), blocks.end(),
                     [&path](const auto& block) { return block.first == path; });
}

// The names of the map `path` (a section or a block) in table order, each once:
// its keys and its blocks ("kind, folder, ..., robustness, relaxation, ...").
std::vector<std::string> NamesIn(const std::string& path) {
  std::vector<std::string> names;
  for (const Key& key : KeyTable()) {
    if (key.path.rfind(path + ".", 0) != 0) continue;
    const std::string rest = key.path.substr(path.size() + 1);
    const std::string name = rest.substr(0, rest.find('.'));
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  return names;
}

// The section names in table order, each once.
std::vector<std::string> SectionNames() {
  std::vector<std::string> sections;
  for (const Key& key : KeyTable()) {
    if (std::find(sections.begin(), sections.end(), key.section()) == sections.end()) {
      sections.push_back(key.section());
    }
  }
  return sections;
}

const Key* FindKey(const std::string& path) {
  for (const Key& key : KeyTable()) {
    if (key.path == path) return &key;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------
// Messages.

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> previous(b.size() + 1), current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}

// "; did you mean '<nearest candidate>'?", or "" when there are no candidates.
std::string Suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string* nearest = nullptr;
  std::size_t best = std::numeric_limits<std::size_t>::max();
  for (const std::string& candidate : candidates) {
    const std::size_t distance = EditDistance(word, candidate);
    if (distance < best) {
      best = distance;
      nearest = &candidate;
    }
  }
  return nearest == nullptr ? "" : "; did you mean '" + *nearest + "'?";
}

// "unknown key '<path>'" with the nearest key or block, or with the name now of a
// flat study key of before the study blocks.
std::string UnknownKeyMessage(const std::string& path) {
  const auto renamed = FlatStudyKeyRenames().find(path);
  if (renamed != FlatStudyKeyRenames().end()) {
    return "unknown key '" + path + "'; the study keys are nested per study: it is now '" +
           renamed->second + "'";
  }
  std::vector<std::string> paths;
  for (const Key& key : KeyTable()) paths.push_back(key.path);
  for (const auto& [block, heading] : BlockTable()) paths.push_back(block);
  return "unknown key '" + path + "'" + Suggestion(path, paths);
}

// How a node is shown after "got": its text when a scalar, else its kind.
std::string Describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      return "'" + node.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    default:
      return "nothing";
  }
}

std::string Join(const std::vector<std::string>& words, const char* separator) {
  std::string joined;
  for (std::size_t i = 0; i < words.size(); ++i) joined += (i == 0 ? "" : separator) + words[i];
  return joined;
}

// "<name>:<line>" with the 1-based line of a node, or "<name>" when the node has
// no position.
std::string Where(const std::string& name, const YAML::Mark& mark) {
  return mark.is_null() ? name : name + ":" + std::to_string(mark.line + 1);
}

// ---------------------------------------------------------------------------
// Parsing.

// A parsed config and, for every key that was set, where it was set: "<file>:<line>"
// or "--set <override>". Used to place the messages of later checks.
struct ParsedConfig {
  Config config;
  std::map<std::string, std::string> origins;
};

void ReadMap(const std::string& path, const YAML::Node& keys, const std::string& name,
             ParsedConfig* parsed);

// Reads the value of the section or block `path` (given at `where`): nothing when
// empty ("study:" alone: every key of it at its default), else a map of its keys.
void ReadMapValue(const std::string& path, const YAML::Node& keys, const std::string& where,
                  const std::string& name, ParsedConfig* parsed) {
  if (keys.IsNull()) return;
  if (!keys.IsMap()) {
    throw InputError(where + ": " + path + ": expected a map of keys (" +
                     Join(NamesIn(path), ", ") + "), got " + Describe(keys));
  }
  ReadMap(path, keys, name, parsed);
}

// Reads the keys and blocks of the map of section or block `path` into
// parsed->config.
void ReadMap(const std::string& path, const YAML::Node& keys, const std::string& name,
             ParsedConfig* parsed) {
  std::map<std::string, int> first_lines;
  for (const auto& entry : keys) {
    const YAML::Node& key_node = entry.first;
    const std::string where = Where(name, key_node.Mark());
    if (!key_node.IsScalar()) {
      throw InputError(where + ": " + path + ": expected a key name, got " + Describe(key_node));
    }
    const std::string& key_name = key_node.Scalar();
    const std::string key_path = path + "." + key_name;
    const Key* key = FindKey(key_path);
    const std::size_t dot = key_name.find('.');
    if (dot != std::string::npos && (key != nullptr || IsBlock(key_path))) {
      // "robustness.snr:" under study: a file spells a block's key one way, nested.
      throw InputError(where + ": " + key_path + ": expected it nested, '" +
                       key_name.substr(0, dot) + ":' with '" + key_name.substr(dot + 1) +
                       ":' under it");
    }
    if (key == nullptr && !IsBlock(key_path)) {
      throw InputError(where + ": " + UnknownKeyMessage(key_path));
    }
    const int line = key_node.Mark().line + 1;
    if (!first_lines.emplace(key_path, line).second) {
      throw InputError(where + ": duplicate key '" + key_path + "' (first given on line " +
                       std::to_string(first_lines[key_path]) + ")");
    }
    if (key == nullptr) {
      ReadMapValue(key_path, entry.second, where, name, parsed);
      continue;
    }
    if (!key->read(entry.second, &parsed->config)) {
      throw InputError(where + ": " + key_path + ": expected " + key->expected + ", got " +
                       Describe(entry.second));
    }
    parsed->origins[key_path] = where;
  }
}

// Reads the YAML document (a map of sections) into parsed->config.
void ReadDocument(const YAML::Node& root, const std::string& name, ParsedConfig* parsed) {
  const std::vector<std::string> sections = SectionNames();
  if (root.IsNull()) return;  // an empty file: every key at its default
  if (!root.IsMap()) {
    throw InputError(Where(name, root.Mark()) + ": expected a map of sections (" +
                     Join(sections, ", ") + ") at the top level, got " + Describe(root));
  }
  std::map<std::string, int> first_lines;
  for (const auto& entry : root) {
    const YAML::Node& section_node = entry.first;
    const std::string where = Where(name, section_node.Mark());
    if (!section_node.IsScalar()) {
      throw InputError(where + ": expected a section name, got " + Describe(section_node));
    }
    const std::string& section = section_node.Scalar();
    if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
      throw InputError(where + ": unknown section '" + section + "'" +
                       Suggestion(section, sections));
    }
    const int line = section_node.Mark().line + 1;
    if (!first_lines.emplace(section, line).second) {
      throw InputError(where + ": duplicate section '" + section + "' (first given on line " +
                       std::to_string(first_lines[section]) + ")");
    }
    ReadMapValue(section, entry.second, where, name, parsed);
  }
}

// `text` without leading and trailing spaces and tabs.
std::string Trim(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// Applies one "key.path=value" override.
void ApplyOverride(const std::string& override_text, ParsedConfig* parsed) {
  const std::string where = "--set " + override_text;
  const std::size_t equals = override_text.find('=');
  if (equals == std::string::npos) {
    throw InputError(where + ": expected key.path=value, e.g. model.elements=200");
  }
  const std::string path = Trim(override_text.substr(0, equals));
  const Key* key = FindKey(path);
  if (key == nullptr && IsBlock(path)) {
    throw InputError(where + ": " + path + " is a block of keys (" + Join(NamesIn(path), ", ") +
                     "): set one of them, e.g. " + path + "." + NamesIn(path).front() + "=...");
  }
  if (key == nullptr) throw InputError(where + ": " + UnknownKeyMessage(path));
  YAML::Node value;
  try {
    value = YAML::Load(override_text.substr(equals + 1));
  } catch (const YAML::Exception& error) {
    throw InputError(where + ": expected " + key->expected + ", got malformed YAML (" + error.msg +
                     ")");
  }
  if (!key->read(value, &parsed->config)) {
    throw InputError(where + ": expected " + key->expected + ", got " + Describe(value));
  }
  parsed->origins[path] = where;
}

// True when `text` mentions `path` as a whole word ("data.path" but not "data.paths").
bool Mentions(const std::string& text, const std::string& path, std::size_t* position) {
  for (std::size_t at = text.find(path); at != std::string::npos; at = text.find(path, at + 1)) {
    const std::size_t after = at + path.size();
    const bool word_ends =
        after == text.size() ||
        !(std::isalnum(static_cast<unsigned char>(text[after])) || text[after] == '_');
    const bool word_starts = at == 0 || !(std::isalnum(static_cast<unsigned char>(text[at - 1])) ||
                                          text[at - 1] == '_' || text[at - 1] == '.');
    if (word_ends && word_starts) {
      *position = at;
      return true;
    }
  }
  return false;
}

// Prefixes a validation message with where the key it names was set: of the keys
// the message mentions, the first one (in the message) that was set in the file or
// by an override; the bare file name when none was.
std::string Locate(const std::string& message, const ParsedConfig& parsed,
                   const std::string& name) {
  std::size_t best_position = std::string::npos;
  std::string where = name;
  for (const auto& [path, origin] : parsed.origins) {
    std::size_t position;
    if (Mentions(message, path, &position) && position < best_position) {
      best_position = position;
      where = origin;
    }
  }
  return where + ": " + message;
}

// The first failed check of `config` (sections, then across sections), or "".
std::string FirstProblem(const Config& config) {
  for (const auto* validators : {&SectionValidators(), &CrossSectionValidators()}) {
    for (const SectionValidator& is_valid : *validators) {
      std::string error;
      if (!is_valid(config, &error)) return error;
    }
  }
  return "";
}

// The single keys of the bar's structure, its zones and its sensors, which a structure
// given by matrices does not read: refused there when set (RefuseKeysOfTheBar).
bool BarOnlyKey(const std::string& path) {
  static const std::set<std::string> bar_only = {"model.length",
                                                 "model.section",
                                                 "model.density",
                                                 "model.modulus",
                                                 "model.elements",
                                                 "model.mass",
                                                 "model.coarse_elements",
                                                 "model.reaction_length",
                                                 "model.zone_count",
                                                 "model.zone_boundaries",
                                                 "data.truth",
                                                 "data.truth_refinement",
                                                 "data.sensors",
                                                 "data.truth_zones",
                                                 "data.support_stiffness"};
  return bar_only.count(path) > 0;
}

// A key of the bar set away from its default in a config of a structure given by
// matrices: refused where it was set, naming it (every key is read by the model kind or
// refused, never ignored; at its default, as a resolved config writes it, it says
// nothing).
void RefuseKeysOfTheBar(const ParsedConfig& parsed) {
  if (parsed.config.structure.kind != ModelKind::kMatrix) return;
  const Config defaults;
  for (const auto& [path, origin] : parsed.origins) {
    const Key* key = FindKey(path);
    if (BarOnlyKey(path) && key != nullptr && key->write(parsed.config) != key->write(defaults)) {
      throw InputError(origin + ": " + path +
                       " applies to the bar only; with model.kind 'matrix' the zones, loads and "
                       "sensors are those of the manifest (model.manifest): leave it out");
    }
  }
}

void Validate(const ParsedConfig& parsed, const std::string& name) {
  // A key of the other structure first: the bar's checks of it would mislead.
  RefuseKeysOfTheBar(parsed);
  const std::string error = FirstProblem(parsed.config);
  if (!error.empty()) throw InputError(Locate(error, parsed, name));
}

ParsedConfig Parse(const std::string& yaml_text, const std::string& name,
                   const std::vector<std::string>& overrides) {
  // A config is one YAML document: YAML::Load would read the first of several and
  // drop the rest silently. A line opening with the marker '---' after content
  // starts another (yaml-cpp's LoadAll can loop forever on malformed text, so the
  // lines are read here).
  std::istringstream lines(yaml_text);
  bool content_seen = false;
  int line_number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    const bool marker = line.rfind("---", 0) == 0 &&
                        (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    if (marker && content_seen) {
      throw InputError(name + ":" + std::to_string(line_number) +
                       ": a config is one YAML document; a second one ('---') starts here");
    }
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#' && !marker) content_seen = true;
  }
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& error) {
    throw InputError(Where(name, error.mark) + ": malformed YAML: " + error.msg);
  }
  ParsedConfig parsed;
  ReadDocument(root, name, &parsed);
  for (const std::string& override_text : overrides) ApplyOverride(override_text, &parsed);
  Validate(parsed, name);
  return parsed;
}

// The whole file, or InputError("cannot read config file ...").
std::string ReadConfigFile(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError("cannot read config file " + path + ": " + std::strerror(errno));
  }
  std::string content;
  char buffer[4096];
  std::size_t count;
  while ((count = std::fread(buffer, 1, sizeof(buffer), file)) > 0) content.append(buffer, count);
  const bool failed = std::ferror(file) != 0;
  const int read_errno = errno;
  std::fclose(file);
  if (failed) {
    throw InputError("cannot read config file " + path + ": " + std::strerror(read_errno));
  }
  return content;
}

// Empty when `path` is a readable regular file, else why not.
std::string WhyUnreadable(const std::string& path) {
  std::error_code status_error;
  if (std::filesystem::is_directory(path, status_error)) return "it is a directory";
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return std::strerror(errno);
  std::fclose(file);
  return "";
}

// ---------------------------------------------------------------------------
// Writing.

// The heading line of the commented default config of block `path`, or "".
std::string BlockHeading(const std::string& path) {
  for (const auto& [block, heading] : BlockTable()) {
    if (block == path) return heading;
  }
  return "";
}

// The config as YAML, one map per table section and, inside it, one nested map
// per block (study.robustness: "study:" then "  robustness:" then "    snr: ...");
// with comments, each key line ends with "# [unit] description (choices)" and
// each block line with its heading.
std::string WriteYaml(const Config& config, bool with_comments, bool applied_only = false) {
  std::vector<std::pair<std::string, std::string>> lines;  // text, comment
  std::string parent;                                      // the map of the last key
  for (const Key& key : KeyTable()) {
    if (applied_only && !KeyApplies(key.path, config.structure.kind)) continue;
    if (key.parent() != parent) {
      // Open the maps of key.parent() that the last key was not in: its section
      // and/or its block (every block lies in a section, one level deep).
      const bool same_section = parent.substr(0, parent.find('.')) == key.section();
      if (!same_section) lines.emplace_back(key.section() + ":", "");
      if (key.parent() != key.section()) {
        lines.emplace_back("  " + key.parent().substr(key.section().size() + 1) + ":",
                           BlockHeading(key.parent()));
      }
      parent = key.parent();
    }
    std::string comment = key.unit.empty() ? "" : "[" + key.unit + "] ";
    comment += key.description;
    if (!key.choices.empty()) comment += " (" + key.choices + ")";
    const std::string indent(2 * std::count(key.path.begin(), key.path.end(), '.'), ' ');
    lines.emplace_back(indent + key.leaf() + ": " + key.write(config), comment);
  }
  std::size_t width = 0;
  for (const auto& [text, comment] : lines) width = std::max(width, text.size());

  std::ostringstream yaml;
  for (const auto& [text, comment] : lines) {
    yaml << text;
    if (with_comments && !comment.empty()) {
      yaml << std::string(width - text.size() + 2, ' ') << "# " << comment;
    }
    yaml << "\n";
  }
  return yaml.str();
}

}  // namespace

bool StructureOptions::IsValid(std::string* error) const {
  std::string why;
  if (kind == ModelKind::kMatrix && manifest.empty()) {
    why = "model.manifest must name the manifest (model.yaml) of the matrices when model.kind "
          "is matrix";
  }
  for (std::size_t i = 0; i < channel_map.size() && why.empty(); ++i) {
    const auto& [channel, column] = channel_map[i];
    if (channel.empty() || column.empty()) {
      why = "model.channel_map: pair " + std::to_string(i + 1) +
            " must name a channel and a CSV column";
    } else if (column == "t") {
      why = "model.channel_map: channel '" + channel + "' cannot map to the time column 't'";
    }
    for (std::size_t other = 0; other < i && why.empty(); ++other) {
      if (channel_map[other].first == channel) {
        why = "model.channel_map: channel '" + channel + "' is mapped twice";
      } else if (channel_map[other].second == column) {
        why = "model.channel_map: column '" + column + "' is mapped to both '" +
              channel_map[other].first + "' and '" + channel + "'";
      }
    }
  }
  if (why.empty()) return true;
  if (error != nullptr) *error = why;
  return false;
}

std::string StructureOptions::Column(const std::string& channel) const {
  for (const auto& [mapped, column] : channel_map) {
    if (mapped == channel) return column;
  }
  return channel;
}

bool OutputOptions::IsValid(std::string* error) const {
  std::string why;
  if (folder.empty()) {
    why = "output.folder must name a folder";
  } else if (curve_points < 5 || curve_points > 1000) {
    why =
        "output.curve_points must be an integer in [5, 1000], got " + std::to_string(curve_points);
  } else {
    return true;
  }
  if (error != nullptr) *error = why;
  return false;
}

Config ParseConfig(const std::string& yaml_text, const std::string& name,
                   const std::vector<std::string>& overrides) {
  return Parse(yaml_text, name, overrides).config;
}

Config LoadConfig(const std::string& path, const std::vector<std::string>& overrides,
                  const std::vector<std::string>& given_in_code) {
  ParsedConfig parsed = Parse(ReadConfigFile(path), path, overrides);
  Config& config = parsed.config;
  config.source_path = path;

  // The files the config names: relative to its folder, readable when they are used.
  const bool matrix = config.structure.kind == ModelKind::kMatrix;
  const std::tuple<const char*, std::string*, bool, const char*> files[] = {
      {"data.path", &config.data.path, config.data.source == DataSource::kCsv,
       "measurement file"},
      {"model.manifest", &config.structure.manifest, matrix, "manifest"},
      {"data.truth_manifest", &config.data.truth_manifest,
       matrix && config.data.source == DataSource::kSynthetic, "manifest"},
  };
  for (const auto& [key, file, used, what] : files) {
    if (std::find(given_in_code.begin(), given_in_code.end(), key) != given_in_code.end()) {
      continue;
    }
    const std::filesystem::path file_path(*file);
    if (!file->empty() && file_path.is_relative()) {
      *file = (std::filesystem::path(path).parent_path() / file_path).string();
    }
    if (!used || file->empty()) continue;
    const std::string why = WhyUnreadable(*file);
    if (!why.empty()) {
      const auto origin = parsed.origins.find(key);
      const std::string where = origin == parsed.origins.end() ? path : origin->second;
      throw InputError(where + ": " + key + ": cannot read " + what + " '" + *file + "': " + why);
    }
  }
  return config;
}

std::string ConfigProblem(const Config& config) { return FirstProblem(config); }

bool ScansTheSearchFunctional(const Config& config) {
  return config.outer.scan_points > 0 && config.search.functional != SearchFunctional::kSame;
}

std::string DefaultConfigYaml() {
  return "# mcrewave configuration: every key at its default value (SI units).\n"
         "# Override any key on the command line with --set section.key=value.\n" +
         WriteYaml(Config{}, /*with_comments=*/true);
}

std::string ConfigToYaml(const Config& config) {
  return WriteYaml(config, /*with_comments=*/false);
}

bool KeyApplies(const std::string& path, ModelKind kind) {
  static const std::set<std::string> matrix_only = {"model.manifest",
                                                    "model.channel_map",
                                                    "model.free_zones",
                                                    "data.truth_manifest",
                                                    "data.truth_moduli",
                                                    "data.time_column",
                                                    "data.time_origin",
                                                    "data.at_rest_before_record",
                                                    "zone_identification.start_modulus",
                                                    "zone_identification.start_moduli"};
  if (kind == ModelKind::kBar) return matrix_only.count(path) == 0;
  // Whole sections, then single keys, that a matrix run does not read.
  static const std::set<std::string> bar_sections = {"study"};
  return bar_sections.count(path.substr(0, path.find('.'))) == 0 && !BarOnlyKey(path);
}

std::string AppliedConfigToYaml(const Config& config) {
  return WriteYaml(config, /*with_comments=*/false, /*applied_only=*/true);
}

}  // namespace mcrewave
