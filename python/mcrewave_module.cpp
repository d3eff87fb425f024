// The Python module mcrewave (docs/python.md): the one model type (MatrixModelData), the
// one record type (ChannelSet) and the one run (app/run.h) of `identify`, reached from
// Python with models from scipy.sparse and numpy, data from numpy, results as arrays.
//
//   mcrewave.Model(mass, zones, loads, sensors, stiffness_length=, length=, ...)
//   mcrewave.Model.from_manifest(path)
//   mcrewave.Data(channels, time_step, start_time=0), mcrewave.read_csv(path)
//   mcrewave.identify(config, model=None, data=None, overrides=None, progress=None)
//   mcrewave.simulate(config, model=None, overrides=None)
//
// Every computation runs with the GIL released. The config is checked by the same code
// as `identify`'s, and a bad input raises mcrewave.InputError (a ValueError) with the
// binary's message. Ctrl-C during a run (from the main thread) stops it within one inner
// iteration and raises KeyboardInterrupt; a progress callback that raises stops it too,
// and its exception is raised.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <csignal>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/app/results.h"
#include "mcrewave/app/run.h"
#include "mcrewave/core/format.h"
#include "mcrewave/core/interrupt.h"
#include "mcrewave/core/types.h"
#include "mcrewave/core/version.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/model/matrix_export.h"

namespace py = pybind11;

namespace mcrewave {
namespace {

// ---------------------------------------------------------------------------
// The wrapped types.

// A structure given by matrices, as MatrixModelData; `name` stands for its manifest in
// messages. Immutable once made: runs share it.
struct PyModel {
  std::shared_ptr<const MatrixModelData> data;
  std::string name;
};

// A record of channels on one uniform time grid; `name` stands for its file in messages.
struct PyData {
  std::shared_ptr<const ChannelSet> set;
  std::string name;
};

// Everything one identification computed.
struct PyResult {
  std::shared_ptr<const IdentificationRun> run;
};

// ---------------------------------------------------------------------------
// Conversions from Python.

// A Python object as YAML flow text: None, bool, int, float (17 digits; .inf, .nan),
// str (double-quoted), os.PathLike (its path), dict, list, tuple and numpy arrays and
// scalars (through tolist / item). Throws py::type_error for anything else.
std::string YamlText(py::handle value) {
  if (value.is_none()) return "~";
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) return py::str(value).cast<std::string>();
  if (py::isinstance<py::float_>(value)) {
    const double number = value.cast<double>();
    if (std::isnan(number)) return ".nan";
    if (std::isinf(number)) return number > 0 ? ".inf" : "-.inf";
    return fmt::format("{:.17g}", number);
  }
  if (py::isinstance(value, py::module_::import("os").attr("PathLike"))) {
    return YamlText(py::module_::import("os").attr("fspath")(value));
  }
  if (py::isinstance<py::str>(value)) {
    // Plain when it reads back as the same string (a name, a channel, a relative path),
    // else double-quoted.
    const std::string text = value.cast<std::string>();
    static const std::vector<std::string> kReserved = {"true", "false", "null", "yes", "no",
                                                       "on",   "off",   "y",    "n",   "~"};
    bool plain = !text.empty() && (std::isalpha(static_cast<unsigned char>(text[0])) != 0 ||
                                   text[0] == '_' || text[0] == '/');
    for (const char c : text) {
      plain = plain && (std::isalnum(static_cast<unsigned char>(c)) != 0 ||
                        std::string("_./@-").find(c) != std::string::npos);
    }
    std::string lower;
    for (const char c : text)
      lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (plain && std::find(kReserved.begin(), kReserved.end(), lower) == kReserved.end()) {
      return text;
    }
    std::string quoted = "\"";
    for (const char c : value.cast<std::string>()) {
      if (c == '"' || c == '\\') {
        quoted += '\\';
        quoted += c;
      } else if (static_cast<unsigned char>(c) < 0x20) {
        quoted += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
      } else {
        quoted += c;
      }
    }
    return quoted + "\"";
  }
  if (py::isinstance<py::dict>(value)) {
    std::string text = "{";
    for (const auto& [key, item] : value.cast<py::dict>()) {
      if (text.size() > 1) text += ", ";
      text += YamlText(key) + ": " + YamlText(item);
    }
    return text + "}";
  }
  if (py::hasattr(value, "tolist")) return YamlText(value.attr("tolist")());
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::string text = "[";
    for (const py::handle item : value) {
      if (text.size() > 1) text += ", ";
      text += YamlText(item);
    }
    return text + "]";
  }
  throw py::type_error(
      "a config value must be None, a bool, a number, a str, a path, a list or "
      "a dict, got " +
      py::str(py::type::handle_of(value)).cast<std::string>());
}

// The overrides "key.path=value" of a dict {key.path: value} (values as YamlText) or a
// list of such strings, as `identify --set` takes them.
std::vector<std::string> Overrides(const py::object& overrides) {
  std::vector<std::string> texts;
  if (overrides.is_none()) return texts;
  if (py::isinstance<py::dict>(overrides)) {
    for (const auto& [key, value] : overrides.cast<py::dict>()) {
      texts.push_back(py::str(key).cast<std::string>() + "=" + YamlText(value));
    }
    return texts;
  }
  if (py::isinstance<py::str>(overrides)) {
    throw py::type_error(
        "overrides: expected a dict {key.path: value} or a list of "
        "'key.path=value' strings, got one str");
  }
  for (const py::handle item : overrides) texts.push_back(py::str(item).cast<std::string>());
  return texts;
}

// The config of a path (LoadConfig: relative files resolved against its folder) or of a
// dict of sections (ParseConfig, named "the config dict" in messages; relative files
// against the working folder), the overrides applied after it. With a model (a record)
// given in code, model.kind matrix and model.manifest its name (data.source csv and
// data.path its name) are the last overrides, so that the config is checked as one of
// that model and record.
Config ConfigOf(const py::object& config, const py::object& overrides, const PyModel* model,
                const PyData* data) {
  std::vector<std::string> texts = Overrides(overrides);
  std::vector<std::string> given_in_code;
  if (model != nullptr) {
    texts.push_back("model.kind=matrix");
    texts.push_back("model.manifest=" + YamlText(py::str(model->name)));
    given_in_code.push_back("model.manifest");
  }
  if (data != nullptr) {
    texts.push_back("data.source=csv");
    texts.push_back("data.path=" + YamlText(py::str(data->name)));
    given_in_code.push_back("data.path");
  }
  if (py::isinstance<py::dict>(config)) {
    return ParseConfig(YamlText(config), "the config dict", texts);
  }
  if (py::isinstance<py::str>(config) ||
      py::isinstance(config, py::module_::import("os").attr("PathLike"))) {
    return LoadConfig(py::str(py::module_::import("os").attr("fspath")(config)), texts,
                      given_in_code);
  }
  throw py::type_error("config: expected a path to a YAML config or a dict of its sections");
}

// A 1-D array of doubles (a copy), `what` naming it in the message of anything else.
Vector VectorOf(const py::handle& value, const std::string& what) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 1) {
    throw py::type_error(what + ": expected a 1-D array of numbers");
  }
  return Eigen::Map<const Vector>(array.data(), array.shape(0));
}

// A sparse matrix from a scipy.sparse matrix or a dense 2-D array (through
// scipy.sparse.csc_matrix), `what` naming it in the message of anything else.
SparseMatrix SparseOf(const py::handle& value, const std::string& what) {
  try {
    return value.cast<SparseMatrix>();
  } catch (const py::cast_error&) {
    throw py::type_error(what + ": expected a scipy.sparse matrix or a 2-D array of numbers");
  }
}

// A sensor's observation row: a 1-D array of n numbers, or a 1 x n sparse matrix.
SparseRow RowOf(const py::handle& value, const std::string& what) {
  const auto array = py::array::ensure(value);
  if (array && array.ndim() == 1) return VectorOf(value, what).transpose().sparseView(0.0, 0.0);
  return SparseRow(SparseOf(value, what));
}

// The names of a channels list, `what` naming it.
std::vector<std::string> NamesOf(const py::handle& value, const std::string& what) {
  std::vector<std::string> names;
  try {
    for (const py::handle item : value) names.push_back(item.cast<std::string>());
  } catch (const py::cast_error&) {
    throw py::type_error(what + ": expected a list of channel names (str)");
  }
  return names;
}

SensorKind SensorKindOf(const std::string& text, const std::string& channel) {
  if (text == "displacement") return SensorKind::kDisplacement;
  if (text == "strain") return SensorKind::kStrain;
  throw InputError("sensor_kinds: '" + channel + "': expected displacement or strain, got '" +
                   text + "'");
}

// Model(...): see the class's docstring.
PyModel MakeModel(const py::object& mass, const py::list& zones, const py::object& loads,
                  const py::object& sensors, double stiffness_length, double length,
                  const py::object& supports, const py::object& sensor_kinds,
                  const py::object& elements, const std::string& name) {
  auto data = std::make_shared<MatrixModelData>();
  data->mass = SparseOf(mass, "mass");
  data->stiffness_length = stiffness_length;
  data->length = length;
  for (const py::handle zone : zones) {
    MatrixModelZone entry;
    if (py::isinstance<py::dict>(zone)) {
      const auto map = zone.cast<py::dict>();
      entry.name = map["name"].cast<std::string>();
      entry.stiffness = SparseOf(map["stiffness"], "zone '" + entry.name + "' stiffness");
      entry.nominal_modulus = map["nominal_modulus"].cast<double>();
    } else {
      const auto tuple = zone.cast<py::tuple>();
      if (tuple.size() != 3) {
        throw py::type_error(
            "zones: expected (name, stiffness, nominal_modulus) or a dict of them");
      }
      entry.name = tuple[0].cast<std::string>();
      entry.stiffness = SparseOf(tuple[1], "zone '" + entry.name + "' stiffness");
      entry.nominal_modulus = tuple[2].cast<double>();
    }
    data->zones.push_back(std::move(entry));
  }
  // loads: {channel: vector} or (G, channels), G n x C.
  if (py::isinstance<py::dict>(loads)) {
    for (const auto& [channel, vector] : loads.cast<py::dict>()) {
      const std::string text = py::str(channel);
      data->loads.push_back({text, VectorOf(vector, "load '" + text + "'")});
    }
  } else {
    const auto pair = loads.cast<py::tuple>();
    const SparseMatrix matrix = SparseOf(pair[0], "loads matrix");
    const std::vector<std::string> names = NamesOf(pair[1], "loads channels");
    if (static_cast<Eigen::Index>(names.size()) != matrix.cols()) {
      throw InputError(name + ": the loads matrix has " + std::to_string(matrix.cols()) +
                       " columns but " + std::to_string(names.size()) + " channel names");
    }
    for (std::size_t c = 0; c < names.size(); ++c) {
      data->loads.push_back({names[c], Vector(matrix.col(static_cast<Eigen::Index>(c)))});
    }
  }
  // sensors: {channel: row} or (H, channels), H S x n.
  if (py::isinstance<py::dict>(sensors)) {
    for (const auto& [channel, row] : sensors.cast<py::dict>()) {
      const std::string text = py::str(channel);
      data->sensors.push_back({text, RowOf(row, "sensor '" + text + "'")});
    }
  } else {
    const auto pair = sensors.cast<py::tuple>();
    const SparseRow matrix(SparseOf(pair[0], "sensors matrix"));
    const std::vector<std::string> names = NamesOf(pair[1], "sensors channels");
    if (static_cast<Eigen::Index>(names.size()) != matrix.rows()) {
      throw InputError(name + ": the sensors matrix has " + std::to_string(matrix.rows()) +
                       " rows but " + std::to_string(names.size()) + " channel names");
    }
    for (std::size_t k = 0; k < names.size(); ++k) {
      data->sensors.push_back({names[k], SparseRow(matrix.row(static_cast<Eigen::Index>(k)))});
    }
  }
  if (!sensor_kinds.is_none()) {
    for (const auto& [channel, kind] : sensor_kinds.cast<py::dict>()) {
      const std::string text = py::str(channel);
      bool found = false;
      for (MatrixModelSensor& sensor : data->sensors) {
        if (sensor.channel != text) continue;
        sensor.kind = SensorKindOf(py::str(kind), text);
        found = true;
      }
      if (!found) throw InputError("sensor_kinds: '" + text + "' is not a sensor channel");
    }
  }
  for (const py::handle support : supports) {
    const auto map = support.cast<py::dict>();
    MatrixModelSupport entry;
    entry.name = map["name"].cast<std::string>();
    entry.dofs = map["dofs"].cast<std::vector<int>>();
    entry.force_channel = map["force_channel"].cast<std::string>();
    if (map.contains("displacement_channel") && !map["displacement_channel"].is_none()) {
      entry.displacement_channel = map["displacement_channel"].cast<std::string>();
    }
    const int n = data->dofs();
    if (map.contains("reaction") && !map["reaction"].is_none()) {
      entry.reaction = VectorOf(map["reaction"], "support '" + entry.name + "' reaction");
    } else {
      // The manifest's default: ones on the held dofs.
      entry.reaction = Vector::Zero(n);
      for (const int dof : entry.dofs) {
        if (dof >= 0 && dof < n) entry.reaction[dof] = 1.0;
      }
    }
    if (map.contains("reaction_test") && !map["reaction_test"].is_none()) {
      entry.reaction_test =
          VectorOf(map["reaction_test"], "support '" + entry.name + "' reaction_test");
    }
    data->supports.push_back(std::move(entry));
  }
  if (!elements.is_none()) {
    // {"zones": [zone index or name per element], "dofs": [[...], ...],
    //  "stiffness": [k x k blocks], "positions": E x d array (optional)}
    const auto map = elements.cast<py::dict>();
    const py::list zone_list = map["zones"];
    const py::list dof_list = map["dofs"];
    const py::list block_list = map["stiffness"];
    if (zone_list.size() != dof_list.size() || zone_list.size() != block_list.size()) {
      throw InputError(name +
                       ": elements: 'zones', 'dofs' and 'stiffness' must have one entry "
                       "per element");
    }
    Matrix positions;
    if (map.contains("positions") && !map["positions"].is_none()) {
      positions = map["positions"].cast<Matrix>();
      if (positions.rows() != static_cast<Eigen::Index>(zone_list.size())) {
        throw InputError(name + ": elements: 'positions' must have one row per element");
      }
    }
    for (std::size_t e = 0; e < zone_list.size(); ++e) {
      MatrixModelElement element;
      if (py::isinstance<py::str>(zone_list[e])) {
        const std::string zone = zone_list[e].cast<std::string>();
        element.zone = -1;
        for (std::size_t z = 0; z < data->zones.size(); ++z) {
          if (data->zones[z].name == zone) element.zone = static_cast<int>(z);
        }
      } else {
        element.zone = zone_list[e].cast<int>();
      }
      element.dofs = dof_list[e].cast<std::vector<int>>();
      element.stiffness = block_list[e].cast<Matrix>();
      if (positions.size() > 0) element.position = positions.row(static_cast<Eigen::Index>(e));
      data->elements.push_back(std::move(element));
    }
  }
  CheckMatrixModel(*data, name);
  return {std::move(data), name};
}

// Data(channels, time_step, start_time): every channel a 1-D array of finite numbers,
// all of one length (at least two samples), as a CSV's columns.
PyData MakeData(const py::dict& channels, double time_step, double start_time,
                const std::string& name) {
  if (!(time_step > 0.0 && std::isfinite(time_step))) {
    throw InputError(name + ": time_step: expected a positive number of seconds, got " +
                     fmt::format("{:g}", time_step));
  }
  if (!std::isfinite(start_time)) {
    throw InputError(name + ": start_time: expected a finite number of seconds");
  }
  auto set = std::make_shared<ChannelSet>();
  set->time_step = time_step;
  set->start_time = start_time;
  for (const auto& [key, values] : channels) {
    const std::string channel = py::str(key);
    if (channel.empty() || set->Find(channel) >= 0) {
      throw InputError(name + ": channel '" + channel + "': expected a name given once");
    }
    Vector samples = VectorOf(values, name + ": channel '" + channel + "'");
    for (Eigen::Index k = 0; k < samples.size(); ++k) {
      if (!std::isfinite(samples[k])) {
        throw InputError(name + ": channel '" + channel + "': sample " + std::to_string(k) +
                         " is not a finite number");
      }
    }
    if (samples.size() < 2 || (!set->channels.empty() && samples.size() != set->num_samples())) {
      throw InputError(name + ": channel '" + channel + "': " + std::to_string(samples.size()) +
                       " samples, expected at least 2 and as many as every other channel");
    }
    set->Add(channel, ChannelKind::kDisplacement, std::move(samples));
  }
  if (set->channels.empty()) throw InputError(name + ": expected at least one channel");
  return {std::move(set), name};
}

// ---------------------------------------------------------------------------
// Conversions to Python.

// A vector or matrix as a read-only numpy array that shares the memory of `owner`'s
// C++ object (no copy); `owner` stays alive as long as the array.
py::array View(const Vector& values, const py::object& owner) {
  py::array array(py::dtype::of<double>(), {values.size()}, {sizeof(double)}, values.data(), owner);
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

py::array View(const Matrix& values, const py::object& owner) {
  // Eigen is column-major: rows x cols with strides (8, 8 rows).
  py::array array(py::dtype::of<double>(), {values.rows(), values.cols()},
                  {static_cast<Eigen::Index>(sizeof(double)),
                   static_cast<Eigen::Index>(sizeof(double)) * values.rows()},
                  values.data(), owner);
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

// A YAML node (summary.yaml) as Python objects: maps as dicts, sequences as lists, plain
// scalars as int, float, bool or None when they read as one, else str.
py::object PythonOf(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      py::dict map;
      for (const auto& entry : node) map[py::str(entry.first.Scalar())] = PythonOf(entry.second);
      return std::move(map);
    }
    case YAML::NodeType::Sequence: {
      py::list list;
      for (const auto& item : node) list.append(PythonOf(item));
      return std::move(list);
    }
    case YAML::NodeType::Scalar: {
      const std::string& text = node.Scalar();
      if (node.Tag() != "!") {
        long long integer = 0;
        double number = 0.0;
        bool flag = false;
        if (text == "~" || text == "null") return py::none();
        if (YAML::convert<long long>::decode(node, integer)) return py::int_(integer);
        if (YAML::convert<double>::decode(node, number)) return py::float_(number);
        if (YAML::convert<bool>::decode(node, flag)) return py::bool_(flag);
      }
      return py::str(text);
    }
    default:
      return py::none();
  }
}

// ---------------------------------------------------------------------------
// A call into the library.

// Forwards the library's log lines to a Python callable (with the GIL). An exception the
// callable raises is kept, and stops the work under way (RequestInterrupt).
class CallbackSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit CallbackSink(py::function callback) : callback_(std::move(callback)) {}
  ~CallbackSink() override {
    const py::gil_scoped_acquire gil;
    callback_ = py::function();
  }
  std::exception_ptr error() const { return error_; }

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    const std::string text(message.payload.data(), message.payload.size());
    const py::gil_scoped_acquire gil;
    if (error_) return;
    try {
      callback_(text);
    } catch (...) {
      error_ = std::current_exception();
      RequestInterrupt();
    }
  }
  void flush_() override {}

 private:
  py::function callback_;
  std::exception_ptr error_;
};

volatile std::sig_atomic_t interrupt_signal_seen = 0;

extern "C" void RequestInterruptOnSignal(int) {
  interrupt_signal_seen = 1;
  RequestInterrupt();
}

// The calls into the library under way (from any thread), and the logger the first of
// them replaced; guarded by calls_mutex.
std::mutex calls_mutex;
int calls_under_way = 0;
std::shared_ptr<spdlog::logger> logger_before_calls;

// While it lives (made and destroyed with the GIL held): the library's log lines go to
// `progress` (a callable taking each line) or to stderr (at info, or warn when quiet),
// and, on the main thread, SIGINT requests the library to stop instead of reaching
// Python's handler. The logger and the stop request are the process's: with calls under
// way at once (from several threads), the lines go where the first of them sends them,
// until the last ends, and a stop ends them all. Finish() raises what stopped the work:
// the callable's exception, or KeyboardInterrupt.
class LibraryCall {
 public:
  LibraryCall(const py::object& progress, bool quiet) {
    if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
      throw py::type_error("progress: expected a callable taking one str, or None");
    }
    {
      const std::lock_guard<std::mutex> lock(calls_mutex);
      if (calls_under_way++ == 0) {
        ClearInterrupt();
        interrupt_signal_seen = 0;
        std::shared_ptr<spdlog::sinks::sink> sink;
        if (!progress.is_none()) {
          callback_ = std::make_shared<CallbackSink>(progress.cast<py::function>());
          sink = callback_;
        } else {
          sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
        }
        auto logger = std::make_shared<spdlog::logger>("", sink);
        logger->set_level(quiet ? spdlog::level::warn : spdlog::level::info);
        logger_before_calls = spdlog::default_logger();
        spdlog::set_default_logger(std::move(logger));
      }
    }
    const py::module_ threading = py::module_::import("threading");
    if (threading.attr("current_thread")().is(threading.attr("main_thread")())) {
      struct sigaction action = {};
      action.sa_handler = RequestInterruptOnSignal;
      sigemptyset(&action.sa_mask);
      handler_installed_ = sigaction(SIGINT, &action, &previous_action_) == 0;
    }
  }
  ~LibraryCall() {
    if (handler_installed_) sigaction(SIGINT, &previous_action_, nullptr);
    const std::lock_guard<std::mutex> lock(calls_mutex);
    if (--calls_under_way == 0) {
      spdlog::set_default_logger(std::move(logger_before_calls));
      logger_before_calls.reset();
      ClearInterrupt();
    }
  }
  LibraryCall(const LibraryCall&) = delete;
  LibraryCall& operator=(const LibraryCall&) = delete;

  void Finish() const {
    if (callback_ && callback_->error()) std::rethrow_exception(callback_->error());
    if (handler_installed_ && interrupt_signal_seen != 0) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
      throw py::error_already_set();
    }
  }

 private:
  std::shared_ptr<CallbackSink> callback_;  // this call's sink, when it owns the logger
  bool handler_installed_ = false;
  struct sigaction previous_action_ = {};
};

// The model and the record of a call, type-checked (None: the config's).
const PyModel* GivenModel(const py::object& model) {
  if (model.is_none()) return nullptr;
  if (!py::isinstance<PyModel>(model)) {
    throw py::type_error("model: expected a mcrewave.Model, or None for the config's model");
  }
  return &model.cast<const PyModel&>();
}

const PyData* GivenData(const py::object& data) {
  if (data.is_none()) return nullptr;
  if (!py::isinstance<PyData>(data)) {
    throw py::type_error(
        "data: expected a mcrewave.Data (mcrewave.Data(channels, time_step) "
        "or mcrewave.read_csv(path)), or None for the config's data");
  }
  return &data.cast<const PyData&>();
}

GivenInputs GivenOf(const PyModel* model, const PyData* data) {
  GivenInputs given;
  if (model != nullptr) given.model = model->data.get();
  if (data != nullptr) {
    given.record = data->set.get();
    given.record_name = data->name;
  }
  return given;
}

py::object IdentificationErrorType() {
  return py::module_::import("mcrewave").attr("IdentificationError");
}

// `work()`, a computation of the library, run as a LibraryCall with the GIL released;
// raises what stopped it (LibraryCall::Finish), else returns its value.
template <typename Work>
auto CallLibrary(const py::object& progress, bool quiet, const Work& work) {
  const LibraryCall call(progress, quiet);
  decltype(work()) value;
  {
    const py::gil_scoped_release release;
    value = work();
  }
  call.Finish();
  return value;
}

py::object IdentifyInPython(const py::object& config, const py::object& model,
                            const py::object& data, const py::object& overrides,
                            const py::object& progress, bool quiet) {
  const PyModel* given_model = GivenModel(model);
  const PyData* given_data = GivenData(data);
  const Config resolved = ConfigOf(config, overrides, given_model, given_data);
  const GivenInputs given = GivenOf(given_model, given_data);
  auto run = std::make_shared<const IdentificationRun>(
      CallLibrary(progress, quiet, [&] { return IdentifyFromConfig(resolved, given); }));
  py::object result = py::cast(PyResult{run});
  const std::string unreportable = UnreportableMessage(*run);
  if (!unreportable.empty()) {
    const py::object type = IdentificationErrorType();
    py::object error = type("identification failed: " + unreportable);
    error.attr("result") = result;
    PyErr_SetObject(type.ptr(), error.ptr());
    throw py::error_already_set();
  }
  return result;
}

PyData SimulateInPython(const py::object& config, const py::object& model,
                        const py::object& overrides, const py::object& progress, bool quiet) {
  const PyModel* given_model = GivenModel(model);
  const Config resolved = ConfigOf(config, overrides, given_model, nullptr);
  const GivenInputs given = GivenOf(given_model, nullptr);
  auto set = std::make_shared<const ChannelSet>(
      CallLibrary(progress, quiet, [&] { return SimulatedMeasurements(resolved, given); }));
  return {std::move(set), "simulated data of " + resolved.Name()};
}

}  // namespace
}  // namespace mcrewave

PYBIND11_MODULE(mcrewave, module) {
  using namespace mcrewave;
  module.doc() =
      "mcrewave: identification of the elastic moduli of a structure from noisy transient "
      "measurements with the modified constitutive relation error (docs/python.md)";
  module.attr("__version__") = kVersion;

  static py::exception<InputError> input_error(module, "InputError", PyExc_ValueError);
  input_error.doc() =
      "A bad input (config, model, data, file): its message names the file, key or channel "
      "and what was expected, as the identify binary's.";
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const InputError& bad_input) {
      PyErr_SetString(input_error.ptr(), bad_input.what());
    }
  });
  const py::object identification_error = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("mcrewave.IdentificationError",
                                "An identification that ran but cannot be reported (it did not "
                                "converge, or its modulus lies on a bound); its `result` "
                                "attribute holds what it computed.",
                                PyExc_RuntimeError, nullptr));
  module.attr("IdentificationError") = identification_error;

  py::class_<PyModel>(module, "Model", R"doc(
A structure given by matrices (docs/matrix_models.md): the mass M, one stiffness K_z per
zone at its nominal modulus, load vectors and observation rows named by channel, and its
supports. Every input is copied once into the model, which is immutable.

Model(mass, zones, loads, sensors, *, stiffness_length, length, supports=(),
      sensor_kinds=None, elements=None, name="model")
  mass             n x n scipy.sparse matrix (or 2-D array) [kg]
  zones            [(name, K_z, nominal_modulus [Pa]), ...] or dicts with those keys
  loads            {channel: vector of n}, or (G, [channel, ...]) with G n x C
  sensors          {channel: row of n (1-D array or 1 x n sparse)}, or (H, [channel, ...])
  stiffness_length a* [m] and length l* [m], the structure's scales
  supports         [{name, dofs, force_channel, displacement_channel?, reaction?,
                     reaction_test?}, ...]
  sensor_kinds     {channel: "displacement" | "strain"}; displacement by default
  elements         {zones: [index or name], dofs: [[...]], stiffness: [k x k],
                    positions: E x d (optional)}: the element blocks of the error maps
  name             stands for the manifest in messages
The same checks as a manifest's; a bad model raises mcrewave.InputError.)doc")
      .def(py::init(&MakeModel), py::arg("mass"), py::arg("zones"), py::arg("loads"),
           py::arg("sensors"), py::kw_only(), py::arg("stiffness_length"), py::arg("length"),
           py::arg("supports") = py::tuple(), py::arg("sensor_kinds") = py::none(),
           py::arg("elements") = py::none(), py::arg("name") = "model")
      .def_static(
          "from_manifest",
          [](const std::string& path) {
            MatrixModelData data;
            {
              const py::gil_scoped_release release;
              data = ReadMatrixModel(path);
            }
            return PyModel{std::make_shared<const MatrixModelData>(std::move(data)), path};
          },
          py::arg("path"), "The model of a manifest model.yaml and its Matrix Market files.")
      .def_property_readonly("name", [](const PyModel& model) { return model.name; })
      .def_property_readonly("dofs", [](const PyModel& model) { return model.data->dofs(); })
      .def_property_readonly(
          "mass", [](const PyModel& model) { return model.data->mass; },
          "M as a scipy.sparse.csc_matrix (a copy)")
      .def_property_readonly("zone_names",
                             [](const PyModel& model) {
                               std::vector<std::string> names;
                               for (const auto& zone : model.data->zones)
                                 names.push_back(zone.name);
                               return names;
                             })
      .def_property_readonly("nominal_moduli",
                             [](const PyModel& model) { return model.data->NominalModuli(); })
      .def_property_readonly("load_channels",
                             [](const PyModel& model) {
                               std::vector<std::string> names;
                               for (const auto& load : model.data->loads)
                                 names.push_back(load.channel);
                               return names;
                             })
      .def_property_readonly("sensor_channels",
                             [](const PyModel& model) {
                               std::vector<std::string> names;
                               for (const auto& sensor : model.data->sensors) {
                                 names.push_back(sensor.channel);
                               }
                               return names;
                             })
      .def(
          "stiffness",
          [](const PyModel& model, const Vector& moduli) {
            if (moduli.size() != static_cast<Eigen::Index>(model.data->zones.size())) {
              throw InputError(model.name + ": stiffness: expected one modulus per zone (" +
                               std::to_string(model.data->zones.size()) + ")");
            }
            return model.data->Stiffness(moduli);
          },
          py::arg("moduli"), "K = sum_z (E_z / E_z,nominal) K_z as a scipy.sparse.csc_matrix.")
      .def(
          "response",
          [](const PyModel& model, const Vector& moduli, const Matrix& loads, double time_step,
             double theta) {
            const MatrixModelData& data = *model.data;
            if (moduli.size() != static_cast<Eigen::Index>(data.zones.size()) ||
                loads.rows() != static_cast<Eigen::Index>(data.loads.size()) || loads.cols() < 2 ||
                !(time_step > 0.0) || !(theta >= 0.5 && theta <= 1.0)) {
              throw InputError(model.name +
                               ": response: expected one modulus per zone, one row of at least 2 "
                               "samples per load channel, time_step > 0 and theta in [0.5, 1]");
            }
            const py::gil_scoped_release release;
            return SimulateMatrixModel(data, moduli, loads, time_step, theta);
          },
          py::arg("moduli"), py::arg("loads"), py::arg("time_step"), py::arg("theta") = 0.5,
          "The sensors' outputs H U (a row per sensor) from rest, driven by `loads` (a row per "
          "load channel [N] on t_j = j time_step), by the theta method; the supports held.")
      .def(
          "write",
          [](const PyModel& model, const std::string& folder) {
            return WriteMatrixModel(folder, *model.data);
          },
          py::arg("folder"), "Writes the manifest and its Matrix Market files; returns its path.")
      .def("__repr__", [](const PyModel& model) {
        return "<mcrewave.Model '" + model.name + "': " + std::to_string(model.data->dofs()) +
               " dofs, " + std::to_string(model.data->zones.size()) + " zones, " +
               std::to_string(model.data->loads.size()) + " loads, " +
               std::to_string(model.data->sensors.size()) + " sensors>";
      });

  py::class_<PyData>(module, "Data", R"doc(
Channels sampled on one uniform time grid t_k = start_time + k time_step, as a CSV holds
them (docs/python.md). Data(channels, time_step, start_time=0.0, name="the data"):
channels a dict {name: 1-D array}, every array of one length (copied once). data[name]
is a read-only numpy view of a channel (no copy).)doc")
      .def(py::init(&MakeData), py::arg("channels"), py::arg("time_step"),
           py::arg("start_time") = 0.0, py::arg("name") = "the data")
      .def_property_readonly("time_step", [](const PyData& data) { return data.set->time_step; })
      .def_property_readonly("start_time", [](const PyData& data) { return data.set->start_time; })
      .def_property_readonly("name", [](const PyData& data) { return data.name; })
      .def_property_readonly("times",
                             [](const PyData& data) {
                               const ChannelSet& set = *data.set;
                               Vector times(set.num_samples());
                               for (int k = 0; k < set.num_samples(); ++k) times[k] = set.Time(k);
                               return times;
                             })
      .def_property_readonly("names",
                             [](const PyData& data) {
                               std::vector<std::string> names;
                               for (const auto& channel : data.set->channels) {
                                 names.push_back(channel.name);
                               }
                               return names;
                             })
      .def("__len__", [](const PyData& data) { return data.set->channels.size(); })
      .def("__contains__",
           [](const PyData& data, const std::string& name) { return data.set->Find(name) >= 0; })
      .def("__getitem__",
           [](const py::object& self, const std::string& name) {
             const PyData& data = self.cast<const PyData&>();
             const int index = data.set->Find(name);
             if (index < 0) throw py::key_error(name);
             return View(data.set->channels[static_cast<std::size_t>(index)].values, self);
           })
      .def(
          "write_csv",
          [](const PyData& data, const std::string& path) { WriteChannelCsv(*data.set, path); },
          py::arg("path"), "Writes the CSV identify reads (t, then the channels), atomically.")
      .def("__repr__", [](const PyData& data) {
        return "<mcrewave.Data '" + data.name + "': " + std::to_string(data.set->channels.size()) +
               " channels, " + std::to_string(data.set->num_samples()) + " samples of " +
               fmt::format("{:g}", data.set->time_step) + " s>";
      });

  module.def(
      "read_csv",
      [](const std::string& path, const std::string& time_column) {
        auto set = std::make_shared<ChannelSet>();
        {
          const py::gil_scoped_release release;
          *set = ReadChannelCsv(path, {}, {}, time_column);
        }
        return PyData{std::move(set), path};
      },
      py::arg("path"), py::arg("time_column") = "t",
      "A channel CSV as Data (a header naming the columns, a uniform time column).");

  py::class_<PyResult>(module, "Result", R"doc(
What one identification computed (app/identification_run.h): the moduli, the cost, the
summary of summary.yaml as a dict, the evaluations, the error maps and the model's
outputs. Arrays are read-only views of the result's own memory (no copy).)doc")
      .def_property_readonly(
          "success",
          [](const PyResult& result) { return UnreportableMessage(*result.run).empty(); })
      .def_property_readonly("message",
                             [](const PyResult& result) {
                               const std::string why = UnreportableMessage(*result.run);
                               return why.empty() ? result.run->outer.message : why;
                             })
      .def_property_readonly(
          "structure",
          [](const PyResult& result) {
            return result.run->config.structure.kind == ModelKind::kMatrix ? "matrix" : "bar";
          })
      .def_property_readonly(
          "modulus",
          [](const PyResult& result) -> py::object {
            if (!result.run->homogeneous_ran) return py::none();
            return py::float_(result.run->identified_modulus());
          },
          "E* [Pa], one modulus in every zone (None when the zones' nominal moduli differ)")
      .def_property_readonly(
          "moduli",
          [](const py::object& self) -> py::object {
            const IdentificationRun& run = *self.cast<const PyResult&>().run;
            if (run.config.structure.kind == ModelKind::kMatrix) {
              return View(run.identified_moduli, self);
            }
            if (run.zones.ran) return View(run.zones.summary.moduli, self);
            Vector one(1);
            one[0] = run.identified_modulus();
            return py::cast(one);
          },
          "The zones' moduli [Pa] (the bar without zones: [E])")
      .def_property_readonly("zone_names",
                             [](const PyResult& result) {
                               std::vector<std::string> names;
                               if (result.run->model) {
                                 for (const auto& zone : result.run->model->zones) {
                                   names.push_back(zone.name);
                                 }
                               }
                               return names;
                             })
      .def_property_readonly(
          "truth_moduli",
          [](const py::object& self) {
            return View(self.cast<const PyResult&>().run->truth_moduli, self);
          },
          "Synthetic data of a structure given by matrices: the truth's moduli [Pa]")
      .def_property_readonly(
          "cost",
          [](const PyResult& result) {
            const IdentificationRun& run = *result.run;
            return run.config.structure.kind == ModelKind::kMatrix ? run.zone_cost : run.cost();
          },
          "e^2 at the identified moduli [J s] (least squares: J [s])")
      .def_property_readonly("evaluations_count",
                             [](const PyResult& result) { return result.run->TotalEvaluations(); })
      .def_property_readonly("sweeps",
                             [](const PyResult& result) { return result.run->TotalSweeps(); })
      .def_property_readonly("wall_time_s",
                             [](const PyResult& result) { return result.run->wall_time_s; })
      .def_property_readonly(
          "evaluations",
          [](const PyResult& result) {
            py::list list;
            for (const ObjectiveEvaluation& evaluation : result.run->evaluations) {
              py::dict entry;
              entry["moduli"] = evaluation.moduli;
              entry["cost"] = evaluation.cost;
              entry["gradient"] = evaluation.cost_gradients;
              entry["usable"] = evaluation.usable;
              entry["iterations"] = evaluation.inner.iterations;
              entry["sweeps"] = evaluation.inner.sweeps;
              list.append(entry);
            }
            return list;
          },
          "The homogeneous stage's evaluations of e^2, in order: dicts of moduli [Pa], cost "
          "[J s], gradient [J s / Pa], usable, and the inner solve's iterations and sweeps")
      .def_property_readonly(
          "summary",
          [](const PyResult& result) { return PythonOf(YAML::Load(SummaryYaml(*result.run))); },
          "summary.yaml as a dict")
      .def_property_readonly("summary_yaml",
                             [](const PyResult& result) { return SummaryYaml(*result.run); })
      .def_property_readonly("data",
                             [](const PyResult& result) {
                               return PyData{std::make_shared<const ChannelSet>(result.run->data),
                                             "the identification's data"};
                             })
      .def_property_readonly(
          "displacement",
          [](const py::object& self) {
            return View(self.cast<const PyResult&>().run->solution.displacement, self);
          },
          "U at E*, n x (m + 1) [m] (empty after a streaming solve, which stores no field)")
      .def_property_readonly(
          "retrograde",
          [](const py::object& self) {
            return View(self.cast<const PyResult&>().run->solution.retrograde, self);
          },
          "W at E*, n x (m + 1) [m] (empty after a streaming solve)")
      .def_property_readonly(
          "model_outputs",
          [](const py::object& self) {
            return View(self.cast<const PyResult&>().run->model_outputs, self);
          },
          "H U at the identified moduli, a row per sensor (a structure given by matrices)")
      .def_property_readonly(
          "model_loads",
          [](const py::object& self) {
            return View(self.cast<const PyResult&>().run->model_loads, self);
          },
          "With unmeasured loads: every load channel's history the model was driven by [N]")
      .def_property_readonly(
          "error_maps",
          [](const py::object& self) {
            const IdentificationRun& run = *self.cast<const PyResult&>().run;
            py::dict maps;
            maps["zone"] = View(run.zone_map, self);
            maps["nominal_zone"] = View(run.nominal_zone_map, self);
            maps["zone_gap"] = View(run.zone_gap, self);
            maps["nominal_zone_gap"] = View(run.nominal_zone_gap, self);
            maps["dof"] = View(run.dof_map, self);
            maps["nominal_dof"] = View(run.nominal_dof_map, self);
            maps["element"] = View(run.element_map.share, self);
            maps["nominal_element"] = View(run.nominal_element_map.share, self);
            maps["bar_element"] = View(run.error_map.share, self);
            maps["bar_position"] = View(run.error_map.position, self);
            return maps;
          },
          "The constitutive gap's maps [J s] at the identified and at the nominal moduli: per "
          "zone, its share relative to the zone's strain energy (zone_gap), per dof, per element "
          "(with element blocks), and the bar's per element with the elements' midpoints [m]; "
          "empty arrays where the run computed none")
      .def(
          "write",
          [](const PyResult& result, const std::string& folder, bool figures) {
            const IdentificationRun& run = *result.run;
            if (!UnreportableMessage(run).empty()) {
              throw InputError("write: the identification failed; nothing to write");
            }
            const py::gil_scoped_release release;
            return WriteIdentificationResults(run, folder, figures);
          },
          py::arg("folder"), py::arg("figures") = true,
          "Writes the files of `identify run` into `folder`, each atomically; returns their "
          "paths.")
      .def("__repr__", [](const PyResult& result) {
        const IdentificationRun& run = *result.run;
        return "<mcrewave.Result: " + std::to_string(run.TotalEvaluations()) + " evaluations, " +
               (UnreportableMessage(run).empty() ? std::string("usable")
                                                 : "failed: " + UnreportableMessage(run)) +
               ">";
      });

  module.def("identify", &IdentifyInPython, py::arg("config"), py::arg("model") = py::none(),
             py::arg("data") = py::none(), py::kw_only(), py::arg("overrides") = py::none(),
             py::arg("progress") = py::none(), py::arg("quiet") = false, R"doc(
Identifies the moduli as `identify run` does (app/run.h), and returns a Result.
  config     a path to a YAML config, or a dict of its sections ({"outer": {...}, ...})
  model      a mcrewave.Model (then the config's model: keys are not read), or None for
             the config's model (the bar, or model.manifest)
  data       a mcrewave.Data (its channels named as the CSV's columns), or None for the
             config's data: (synthetic, or the CSV of data.path)
  overrides  {"key.path": value} or ["key.path=value", ...], as identify --set
  progress   a callable taking each progress line (str); None: they go to stderr
  quiet      only warnings and errors
Raises mcrewave.InputError for bad input, mcrewave.IdentificationError (with .result)
when the identification cannot be reported, KeyboardInterrupt on Ctrl-C.)doc");
  module.def("simulate", &SimulateInPython, py::arg("config"), py::arg("model") = py::none(),
             py::kw_only(), py::arg("overrides") = py::none(), py::arg("progress") = py::none(),
             py::arg("quiet") = false, R"doc(
The synthetic measurements `identify simulate` writes (data: of the config; with a model
given, that model is the truth unless data.truth_manifest is set), as Data.)doc");
  module.def(
      "default_config", []() { return DefaultConfigYaml(); },
      "The commented default config (identify --print-default-config).");
  module.def(
      "resolved_config",
      [](const py::object& config, const py::object& overrides) {
        return PythonOf(YAML::Load(ConfigToYaml(ConfigOf(config, overrides, nullptr, nullptr))));
      },
      py::arg("config"), py::arg("overrides") = py::none(),
      "The config with every key, as a dict, after the same checks as identify's.");
}
