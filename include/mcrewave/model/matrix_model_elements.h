// The element blocks of a structure given by matrices (docs/matrix_models.md section 4,
// "Element blocks"): for each element its dofs, its zone and its stiffness block at the
// zone's nominal modulus, optionally a point of it for figures and tables. They split
// each zone's stiffness by element, K_z = sum_{el in z} P_el^T K_el P_el (P_el picks the
// element's dofs), so that the constitutive gap splits by element as well
// (mcre/element_error_map.h).
//
// On disk: two CSV files and an optional third, named by the manifest's key
//
//   elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv,
//              positions: element_positions.csv}   # positions optional
//
// one element a line, in the same order in every file; blank lines and lines starting
// with '#' skipped; values separated by commas (blanks around them ignored):
//   dofs       zone name, then the element's k global dofs (0-based, distinct, in [0, n)):
//              `inclusion, 12, 13, 40, 41`
//   stiffness  the k x k block K_el [N/m] at the zone's nominal modulus, row by row
//              (k^2 numbers, symmetric): `1.5e9, -1.5e9, -1.5e9, 1.5e9`
//   positions  1 to 3 coordinates of a point of the element [m] (e.g. its centroid),
//              as many on every line
// Elements may have different k. The blocks of a zone must sum to its K_z.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {

struct MatrixModelData;

struct MatrixModelElement {
  std::vector<int> dofs;  // its k dofs: global, 0-based, distinct, in [0, n)
  int zone = 0;           // an index into MatrixModelData::zones
  Matrix stiffness;       // K_el [N/m], k x k, symmetric, at the zone's nominal modulus
  Vector position;        // [m] 1 to 3 coordinates of a point of it; empty: none given
};

// Relative tolerance of the check that a zone's blocks sum to its K_z:
// max |sum_el K_el - K_z| <= tol max |K_z| entry by entry. Blocks written with ten or
// more significant digits pass; %g's six do not.
constexpr double kElementSumTolerance = 1e-8;

// The files of the manifest's `elements` key, as paths (positions "" when not given).
struct MatrixModelElementFiles {
  std::string dofs, stiffness, positions;
};

// Reads the element files, each line checked: the dofs file's zone one of zone_names,
// at least one dof, every dof an integer in [0, dofs) and none twice in an element;
// the stiffness file's line k^2 finite numbers forming a symmetric block
// (|K_ab - K_ba| <= kSymmetryTolerance max|K_el|); the positions file's line 1 to 3
// finite numbers, as many as on its first line; every file one line per element of
// the dofs file (at least one). Throws InputError "FILE:LINE: ..." saying what was
// expected (mass_file names where the dofs come from) on the first problem.
std::vector<MatrixModelElement> ReadMatrixModelElements(const MatrixModelElementFiles& files,
                                                        const std::vector<std::string>& zone_names,
                                                        int dofs, const std::string& mass_file);

// "" when the blocks of every zone sum to its K_z within relative_tolerance (above);
// otherwise, for the first zone that does not, e.g. "model.yaml: the element blocks of
// zone 'inclusion' do not sum to its stiffness: entry (3, 7) is 1.5 in K_z but 1.2 in
// the blocks' sum (misfit 0.3, 0.1 of the largest entry 3, relative tolerance 1e-08)"
// (indices 1-based, as in a Matrix Market file). O(nnz of the zones and the blocks).
// Precondition: every element's dofs in range and zone valid.
std::string CheckElementBlockSums(const MatrixModelData& data, const std::string& manifest_name,
                                  double relative_tolerance = kElementSumTolerance);

// The zone of each element of data.elements under `layout` (one that RegroupsElements)
// and the regrouped zones' names, in their order:
//   per_element  zone e = element e, named "element<e>" (0-based, as error_map.csv counts);
//   grid         the bounding box of the elements' positions split into zone_grid[d]
//                equal boxes along coordinate d; an element lies in the box of its position
//                (floor((x_d - min_d) / (max_d - min_d) zone_grid[d]), the last box closed).
//                The boxes that hold an element are the zones, numbered with the first
//                coordinate fastest and named "grid_<i>[_<j>[_<k>]]" (0-based box indices);
//                empty boxes are left out (a plate with a hole, say).
// Throws InputError naming manifest_name and the key to change when the model has no
// element blocks, a grid has no positions to place them, or zone_grid does not hold one
// count per coordinate of the positions, each in [1, elements].
std::vector<int> RegroupedElementZones(const MatrixModelData& data, const ZoneLayout& layout,
                                       const std::string& manifest_name,
                                       std::vector<std::string>* zone_names);

// `data` with its zones replaced by one zone per name of zone_names, zone z' holding the
// elements e with element_zones[e] = z':
//   K_z' = sum_{e in z'} (E_z',nom / E_zone(e),nom) P_e^T K_e P_e,
// so that at a modulus E of z' every one of its elements is at E. E_z',nom is the
// nominal modulus of the manifest zone of z''s first element; where the manifest's zones
// share one nominal modulus, the stiffness at the nominal moduli is the manifest's (up to
// the order of the sums; the blocks sum to each K_z within kElementSumTolerance when
// read). The elements point to their new zone and their blocks are scaled the same way;
// mass, loads, sensors and supports are kept. Precondition: data.elements not empty, element_zones
// one entry in [0, zone_names.size()) per element, every zone holding an element.
MatrixModelData RezonedMatrixModel(const MatrixModelData& data,
                                   const std::vector<int>& element_zones,
                                   const std::vector<std::string>& zone_names);

// Writes data.elements into `folder` as element_dofs.csv, element_stiffness.csv and
// (when the elements have positions) element_positions.csv, 17 significant digits,
// atomically; returns their file names (relative to folder; positions "" when none).
// Throws std::runtime_error when a file cannot be written or a zone name cannot stand
// as a dofs file's field (empty, a comma or a line break, a leading '#', leading or
// trailing blanks). Precondition: data.elements not empty.
MatrixModelElementFiles WriteMatrixModelElements(const std::string& folder,
                                                 const MatrixModelData& data);

}  // namespace mcrewave
