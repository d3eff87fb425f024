// libFuzzer target of the matrix model manifest reader (ReadMatrixModel,
// model/matrix_export.h): the model.yaml that names a structure's Matrix Market files.
//
// ReadMatrixModel takes a path, so the input is written as model.yaml into a
// temporary folder made once per process, next to small Matrix Market and channel
// names files it may name (a 3-dof model: kFiles below, valid ones and some that fail
// a check, element files among them). The input is the manifest's text. InputError is the expected
// answer to bad input; anything else escaping (another exception, a crash, a sanitizer report, a
// hang) is a defect. An accepted manifest must give a checked 3-dof model.
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/model/matrix_export.h"

namespace {

struct File {
  const char* name;
  const char* text;
};

// The folder's Matrix Market files (fuzz/corpus/manifest/ names them).
constexpr File kFiles[] = {
    // Valid: M (symmetric positive definite), two zone stiffnesses, loads, sensor rows.
    {"M.mtx",
     "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 0.5\n2 2 2\n3 2 0.5\n"
     "3 3 2\n"},
    {"K_a.mtx",
     "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n"
     "3 3 1\n"},
    {"K_b.mtx", "%%MatrixMarket matrix array real general\n3 3\n1\n0\n0\n0\n0\n0\n0\n0\n0\n"},
    {"load_f.mtx", "%%MatrixMarket matrix array real general\n3 1\n0\n0\n1\n"},
    {"load_row.mtx", "%%MatrixMarket matrix coordinate integer general\n1 3 1\n1 1 -1\n"},
    {"sensor_u.mtx", "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 3 1\n"},
    {"sensor_e.mtx", "%%MatrixMarket matrix coordinate real general\n3 1 2\n2 1 -10\n3 1 10\n"},
    // A load matrix (3 x 2) and an observation matrix (2 x 3) with their channel names.
    {"G.mtx", "%%MatrixMarket matrix coordinate real general\n3 2 2\n1 1 1\n3 2 -1\n"},
    {"load_channels.txt", "# loads\nfa\n\n  fb \n"},
    {"H.mtx", "%%MatrixMarket matrix coordinate real general\n2 3 3\n1 1 1\n2 2 -10\n2 3 10\n"},
    {"sensor_channels.txt", "ua\r\neb\r\n"},
    // Element blocks of zones a and b (they sum to K_a and K_b) and their positions.
    {"element_dofs.csv", "# zone, dofs\na, 0\na, 0, 1\n\na, 1, 2\nb, 0\n"},
    {"element_stiffness.csv", "1\n1, -1, -1, 1\n 1 , -1, -1, 1\n1\n"},
    {"element_positions.csv", "0, 0\n0.5, 0\n1.5, 0\n0, 1\n"},
    // Each fails one check of ReadMatrixModel.
    {"element_dofs_bad.csv", "a, 0\na, 0, 3\na, 1, 2\nb, 0\n"},
    {"element_stiffness_asymmetric.csv", "1\n1, -1, -2, 1\n1, -1, -1, 1\n1\n"},
    {"element_stiffness_misfit.csv", "2\n1, -1, -1, 1\n1, -1, -1, 1\n1\n"},
    {"K_4.mtx", "%%MatrixMarket matrix coordinate pattern symmetric\n4 4 1\n4 4\n"},
    {"K_skew.mtx", "%%MatrixMarket matrix coordinate real general\n3 3 2\n1 2 1\n2 1 -1\n"},
    {"M_singular.mtx", "%%MatrixMarket matrix coordinate real symmetric\n3 3 2\n1 1 1\n2 2 1\n"},
    {"sensor_zero.mtx", "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 2 0\n"},
    {"sensor_past.mtx", "%%MatrixMarket matrix coordinate real general\n1 5 1\n1 5 1\n"},
    {"not_mtx.txt", "mass: M.mtx\n"},
    {"channels_twice.txt", "fa\nfa\n"},
    {"channels_none.txt", "# none\n\n"},
    {"channels_three.txt", "x\ny\nz\n"},
};

std::string folder;

void RemoveFolder() {
  for (const File& file : kFiles) std::remove((folder + "/" + file.name).c_str());
  std::remove((folder + "/model.yaml").c_str());
  ::rmdir(folder.c_str());
}

bool Usable(const mcrewave::MatrixModelData& model) {
  const int n = model.dofs();
  bool usable = n == 3 && model.mass.cols() == 3 && !model.zones.empty() && !model.loads.empty() &&
                !model.sensors.empty() && std::isfinite(model.stiffness_length) &&
                model.stiffness_length > 0.0 && std::isfinite(model.length) && model.length > 0.0;
  for (const mcrewave::MatrixModelZone& zone : model.zones) {
    usable = usable && !zone.name.empty() && zone.stiffness.rows() == n &&
             zone.stiffness.cols() == n && std::isfinite(zone.nominal_modulus) &&
             zone.nominal_modulus > 0.0;
  }
  for (const mcrewave::MatrixModelLoad& load : model.loads) {
    usable = usable && !load.channel.empty() && load.vector.size() == n;
  }
  for (const mcrewave::MatrixModelSensor& sensor : model.sensors) {
    usable = usable && !sensor.channel.empty() && sensor.row.rows() == 1 && sensor.row.cols() == n;
  }
  for (const mcrewave::MatrixModelElement& element : model.elements) {
    const auto k = static_cast<Eigen::Index>(element.dofs.size());
    usable = usable && k > 0 && element.stiffness.rows() == k && element.stiffness.cols() == k &&
             element.stiffness.allFinite() && element.zone >= 0 &&
             element.zone < static_cast<int>(model.zones.size()) && element.position.size() <= 3;
    for (const int dof : element.dofs) usable = usable && dof >= 0 && dof < n;
  }
  return usable;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern =
      std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/mcrewave_manifest_fuzz_XXXXXX";
  if (::mkdtemp(&pattern[0]) == nullptr) {
    std::perror("model_manifest_fuzzer: mkdtemp");
    std::abort();
  }
  folder = pattern;
  for (const File& file : kFiles) {
    std::ofstream(folder + "/" + file.name, std::ios::binary) << file.text;
  }
  std::atexit(RemoveFolder);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string manifest = folder + "/model.yaml";
  {
    std::ofstream out(manifest, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();
  }
  try {
    if (!Usable(mcrewave::ReadMatrixModel(manifest))) __builtin_trap();
  } catch (const mcrewave::InputError&) {
  }
  return 0;
}
