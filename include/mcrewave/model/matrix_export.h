// A structure given by matrices (docs/matrix_models.md), in memory and as files:
// the mass M, one stiffness K_z per zone assembled at a nominal modulus E_z,nominal
// (K = sum_z (E_z / E_z,nominal) K_z), one spatial vector per load channel and one
// sparse observation row per sensor channel, each named by its CSV column.
//
// On disk: one Matrix Market file per matrix, vector and row, and a manifest
// `model.yaml` that names them:
//
//   mass: M.mtx
//   stiffness_length: 1.0e-4   # a* [m]: k* = E0 a* is the structure's stiffness scale
//   length: 1.0                # l* [m]: the span that turns a strain into a displacement
//   zones:
//     - {name: zone0, stiffness: K_zone0.mtx, nominal_modulus: 2.0e+11}
//   loads:
//     - {channel: fL, vector: load_fL.mtx}
//   sensors:
//     - {channel: uL, row: sensor_uL.mtx}
//     - {channel: e@0.5, row: sensor_e_at_0.5.mtx, kind: strain}
//   supports:                  # optional (docs/matrix_models.md section 11)
//     - {name: clamp, dofs: [0], force_channel: f0, displacement_channel: u0}
//
// (a relative file name is relative to the manifest's folder, an absolute one is used
// as it is). The loads and the sensors may instead, or as well, come as one matrix each,
// as a finite-element code assembles them, with a file of their channel names:
//
//   loads_matrix: {matrix: G.mtx, channels: load_channels.txt}     # n x C
//   sensors_matrix:                                                # S x n
//     - {matrix: H_u.mtx, channels: sensor_channels_u.txt}         # kind displacement
//     - {matrix: H_e.mtx, channels: sensor_channels_e.txt, kind: strain}
//
// Column c of G is the spatial vector of the load channel on the c-th name of its
// channels file; row k of H is the observation row of the sensor channel on the k-th
// name, of the entry's `kind` (displacement by default, or strain). Each key takes one
// map or a list of them. A channels file holds one name a line, trimmed of blanks; blank
// lines and lines starting with '#' are skipped; as many names as G has columns (H rows).
// The channels are appended to MatrixModelData::loads (sensors) in the manifest's
// order: those of `loads` (`sensors`) first, then each matrix's in its list's order.
// `loads` and `sensors` become optional: the model needs at least one load channel and
// one sensor channel from either form. WriteMatrixModel writes either form
// (MatrixModelLayout); with BarMatrixModel it exports the built-in bar, so that the
// general path can be tested against it.
//
// Optionally, the element blocks that split every zone's K_z by element, for the error
// map per element (model/matrix_model_elements.h, docs/matrix_models.md section 4):
//
//   elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv,
//              positions: element_positions.csv}          # positions optional
//
// element_dofs.csv: a line per element, its zone's name then its dofs (0-based):
// `zone0, 3, 4`; element_stiffness.csv: the same lines' blocks K_el [N/m] at the zone's
// nominal modulus, row by row: `2e9, -2e9, -2e9, 2e9`; element_positions.csv: 1 to 3
// coordinates [m] of a point of each element (its centroid, say): `0.025`. Blank lines
// and lines starting with '#' are skipped. The blocks of each zone must sum to its K_z.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_model_elements.h"

namespace mcrewave {

struct MatrixModelZone {
  std::string name;
  SparseMatrix stiffness;        // K_z [N/m] at nominal_modulus
  double nominal_modulus = 1.0;  // E_z,nominal [Pa]
};

struct MatrixModelLoad {
  std::string channel;  // the CSV column of its time history [N]
  Vector vector;        // spatial distribution [-]: the load is f(t) vector
};

struct MatrixModelSensor {
  std::string channel;  // the CSV column it is compared with
  SparseRow row;        // 1 x n observation row: channel = row U
  // What the row measures: a displacement [m] or a strain [-] (manifest key `kind`,
  // default displacement); it chooses the weight of the channel's data term.
  SensorKind kind = SensorKind::kDisplacement;
};

// A support: a set of dofs the structure is held by, with the measured force it takes
// (docs/matrix_models.md section 11). How it enters the MCRE problem, free with its force
// as a load (measured, pinned) or held with its reaction as an output (trusted), is the
// run's choice (mcre.clamp), not the model's.
struct MatrixModelSupport {
  std::string name;
  std::vector<int> dofs;  // the held dofs, 0-based, distinct, in [0, n)
  // g [-], n entries, nonzero only on `dofs`: the support's force is g^T times the dofs'
  // reaction forces, and its displacement g^T U / (g^T g). Manifest key `reaction` (a
  // vector file); default: ones on the dofs.
  Vector reaction;
  std::string force_channel;         // the CSV column of the measured force [N]
  std::string displacement_channel;  // the CSV column of the measured displacement [m]; "" if none
  // phi [-]: the virtual displacement of a trusted support's reaction r(U) = phi^T K(E) U
  // (docs/boundaries.md section 7). It equals g on the support's dofs and may extend over
  // free dofs near it, where phi^T K U adds the elastic forces, so that r is a mean force
  // over a fixed region and its gain does not grow as the mesh is refined. Manifest key
  // `reaction_test` (a vector file); empty: g.
  Vector reaction_test;
};

// The virtual displacement of a support's trusted reaction: reaction_test, or g when it
// is empty.
const Vector& TrustedReactionTest(const MatrixModelSupport& support);

struct MatrixModelData {
  SparseMatrix mass;  // M [kg], n x n
  // The structure's own scales that make the MCRE weights dimensionless
  // (docs/matrix_models.md section 3): k* = E0 stiffness_length [N/m] and l* = length.
  // The bar: S / L and L; a plate in plane stress: its thickness and its length.
  double stiffness_length = 0.0;  // a* [m]
  double length = 0.0;            // l* [m]
  std::vector<MatrixModelZone> zones;
  std::vector<MatrixModelLoad> loads;
  std::vector<MatrixModelSensor> sensors;
  std::vector<MatrixModelSupport> supports;  // none: a structure held by nothing but its data
  // The element blocks (none: the zone is the finest unit of the error maps): those of
  // zone z sum to K_z; every element has a position or none has, all of one dimension.
  std::vector<MatrixModelElement> elements;

  int dofs() const { return static_cast<int>(mass.rows()); }
  // K = sum_z (E_z / E_z,nominal) K_z; zone_moduli has zones.size() entries [Pa].
  SparseMatrix Stiffness(const Vector& zone_moduli) const;
  // E_z,nominal of every zone [Pa].
  Vector NominalModuli() const;
};

// The observation row of a channel as a 1 x n sparse matrix.
SparseMatrix ObservationRowMatrix(const ObservationRow& row, int dofs);

// The bar as matrices (scales a* = S / L, l* = L): M, K1_z times nominal_modulus per zone (zone z
// named "zone<z>"), its elements (element e: dofs e and e + 1, its zone, the block
// nominal_modulus K1_e = nominal_modulus k1_e [1 -1; -1 1], its midpoint [m]), the end loads
// (channels f0: e_0, fL: e_N), the end displacement rows (u0, uL) and the rows of `sensors`
// (channels u@X / e@X, as the measurement CSV names them; their index is not used). With clamp
// kSupport, f0 and u0 are the channels of the support "clamp" at dof 0 instead: the loads are fL
// alone, the sensors uL and `sensors`.
MatrixModelData BarMatrixModel(const BarModel& model, double nominal_modulus,
                               const std::vector<BarSensor>& sensors = {},
                               BarClampExport clamp = BarClampExport::kLoadAndSensor);

// Which end displacement channels enter the data term (config data.channels); the
// interior sensors are those of the data set.
struct EndDisplacementChannels {
  bool u0 = true;
  bool uL = true;
};

// The bar of an identification as the structure every MCRE and least-squares solve of
// a bar's run takes (least squares holds its clamp): BarMatrixModel of `model` (its
// zones) at its modulus, with the clamp the support "clamp" at node 0 (its channels f0
// and u0), the sensors uL and those of `data` (BarSensors, each named as its data
// channel); without uL (u0) when ends.uL (ends.u0) is false.
MatrixModelData BarRunModel(const BarModel& model, const ChannelSet& data,
                            EndDisplacementChannels ends);

// How WriteMatrixModel writes the loads and sensors.
enum class MatrixModelLayout {
  kFilePerChannel,  // load_<channel>.mtx and sensor_<channel>.mtx (keys loads, sensors)
  // G.mtx with load_channels.txt (key loads_matrix), and H_<i>.mtx with
  // sensor_channels_<i>.txt (key sensors_matrix) for the i-th run of consecutive sensors of
  // one kind, i = 1, 2, ...: the same channels in the same order.
  kMatrices,
};

// Writes `data` into `folder` (which must exist): M.mtx, K_<zone>.mtx, the loads and
// sensors as `layout` says (per channel, '@' of a channel becomes '_at_' in its file
// name), support_<name>.mtx (a support's reaction g, only when it is not the default),
// the element files (WriteMatrixModelElements, when there are elements)
// and the manifest model.yaml, each atomically, M and K_z in symmetric storage, 17
// digits. Returns the manifest's path. Throws std::runtime_error when a file cannot be
// written, or, with kMatrices, when a channel name cannot stand on a line of a channels
// file (empty, a line break, a leading '#', leading or trailing blanks).
std::string WriteMatrixModel(const std::string& folder, const MatrixModelData& data,
                             MatrixModelLayout layout = MatrixModelLayout::kFilePerChannel);

// Reads a manifest and its files, and checks them (model/matrix_model_check.h): M
// square, symmetric, positive definite; every K_z symmetric and of M's size; the
// load vectors of M's size; the sensor rows within M's dofs and not all zero; a load
// matrix with M's dofs as rows, an observation matrix with them as columns, each with a
// channels file of one distinct name per column (row), not empty; at least one load and
// one sensor; zone names and channels (of files and matrices alike) distinct; nominal moduli and
// the scales stiffness_length and length finite and positive; a sensor's kind displacement or
// strain; every support named once, its dofs distinct, in range and held by no other support, its
// reaction of M's size and nonzero on its dofs only, its channels distinct from every other channel
// (loads', sensors', supports'); the element files' every line (ReadMatrixModelElements) and each
// zone's blocks summing to its K_z (CheckElementBlockSums). Throws InputError naming the file (and
// line, for the manifest, the Matrix Market files and a channels file's bad name; both counts for a
// channels file that does not match its matrix) on the first problem.
MatrixModelData ReadMatrixModel(const std::string& manifest_path);

// ReadMatrixModel's checks of the model's contents on a model given in code (the
// Python module's), `name` standing for the manifest and its files in messages: the
// scales positive, M finite, square, symmetric and positive definite, every zone named
// once with a positive nominal modulus and a finite symmetric K_z of M's size, at least
// one load and one sensor, every channel named once (loads', sensors', supports'), the
// load vectors finite and of M's size, the sensor rows finite and within M's dofs, the
// supports' dofs and reactions as the manifest's, the element blocks summing to K_z.
// Throws InputError naming `name` and what is wrong on the first problem.
void CheckMatrixModel(const MatrixModelData& data, const std::string& name);

}  // namespace mcrewave
