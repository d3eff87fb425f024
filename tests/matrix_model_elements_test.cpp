// Tests of the element blocks of a matrix model (model/matrix_model_elements.h): the
// bar's elements written and read back, and every bad element file refused with one
// error naming the file, the line and what was expected.
#include "mcrewave/model/matrix_model_elements.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "file_fixture.h"
#include "identify_binary.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {
namespace {

class MatrixModelElementsTest : public FileFixture {
 protected:
  MatrixModelElementsTest() : FileFixture("elements") {}

  // A 4-element bar in two zones (elements 0, 1 and 2, 3), written into the folder.
  std::string WriteFourElementBar() {
    BarProperties bar;
    bar.elements = 4;
    const BarModel model(bar, {0, 0, 1, 1});
    data_ = BarMatrixModel(model, 2e11);
    return WriteMatrixModel(PathOf(""), data_);
  }

  // Replaces line `line` (1-based; one past the last: appends) of file `name` by `text`;
  // line 0: the line that starts with "elements:".
  void ReplaceLine(const std::string& name, int line, const std::string& text) {
    std::ifstream in(PathOf(name));
    std::string content, current;
    int i = 1;
    for (; std::getline(in, current); ++i) {
      const bool replaced = i == line || (line == 0 && current.rfind("elements:", 0) == 0);
      content += (replaced ? text : current) + "\n";
    }
    if (line == i) content += text + "\n";
    in.close();
    WriteFile(name, content);
  }

  // The message of ReadMatrixModel on the bar after line `line` of `name` became `text`
  // (ReplaceLine).
  std::string ErrorAfter(const std::string& name, int line, const std::string& text) {
    const std::string manifest = WriteFourElementBar();
    ReplaceLine(name, line, text);
    try {
      ReadMatrixModel(manifest);
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  }

  MatrixModelData data_;
};

using ::testing::AllOf;
using ::testing::HasSubstr;

TEST_F(MatrixModelElementsTest, TheBarsElementsReadBackExactly) {
  const MatrixModelData back = ReadMatrixModel(WriteFourElementBar());
  ASSERT_EQ(back.elements.size(), 4u);
  for (std::size_t e = 0; e < 4; ++e) {
    const MatrixModelElement& element = back.elements[e];
    EXPECT_EQ(element.dofs, data_.elements[e].dofs);
    EXPECT_EQ(element.dofs, (std::vector<int>{static_cast<int>(e), static_cast<int>(e) + 1}));
    EXPECT_EQ(element.zone, e < 2 ? 0 : 1);
    EXPECT_EQ(element.stiffness, data_.elements[e].stiffness);
    EXPECT_EQ(element.position, data_.elements[e].position);
    EXPECT_EQ(element.position[0], (e + 0.5) / 4.0);
    // E_nom k1_e [1 -1; -1 1] with k1_e = S / h_e.
    EXPECT_EQ(element.stiffness(0, 1), -2e11 * 1e-4 / 0.25);
  }
  // And written again, the same files.
  const std::string again = WriteMatrixModel(PathOf(""), back);
  EXPECT_EQ(ReadMatrixModel(again).elements.size(), 4u);
}

TEST_F(MatrixModelElementsTest, TheManifestNamesTheElementFiles) {
  std::ifstream manifest(WriteFourElementBar());
  std::stringstream text;
  text << manifest.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("elements: {dofs: element_dofs.csv, stiffness: "
                                    "element_stiffness.csv, positions: element_positions.csv}"));
}

TEST_F(MatrixModelElementsTest, PositionsAreOptional) {
  const std::string manifest = WriteFourElementBar();
  std::ifstream in(manifest);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string key = ", positions: element_positions.csv";
  yaml.erase(yaml.find(key), key.size());
  WriteFile("model.yaml", yaml);
  const MatrixModelData back = ReadMatrixModel(manifest);
  ASSERT_EQ(back.elements.size(), 4u);
  EXPECT_EQ(back.elements[0].position.size(), 0);
}

// Line 1 of each file is its comment; element e is on line e + 2.
TEST_F(MatrixModelElementsTest, BadDofsFilesGiveOneClearError) {
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 3, "zone0"),
              AllOf(HasSubstr("element_dofs.csv:3: 1 field"), HasSubstr("then its dofs")));
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 2, "zone0, 0, 5"),
              AllOf(HasSubstr("element_dofs.csv:2: dof '5'"),
                    HasSubstr("expected an integer from 0 to 4")));
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 2, "zone0, 0, 1.5"),
              HasSubstr("element_dofs.csv:2: dof '1.5'"));
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 2, "zone0, 1, 1"),
              HasSubstr("element_dofs.csv:2: dof 1 given twice"));
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 4, "zone7, 2, 3"),
              AllOf(HasSubstr("element_dofs.csv:4: zone 'zone7' is not a zone of the manifest")));
  // A dof moved to another element: the blocks no longer sum to K_z.
  EXPECT_THAT(ErrorAfter("element_dofs.csv", 5, "zone1, 1, 4"),
              AllOf(HasSubstr("model.yaml"), HasSubstr("element blocks of zone 'zone1'"),
                    HasSubstr("do not sum to its stiffness"), HasSubstr("misfit")));
}

TEST_F(MatrixModelElementsTest, BadBlocksGiveOneClearError) {
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 3, "1, 2, 3"),
              AllOf(HasSubstr("element_stiffness.csv:3: 3 values, expected 4"),
                    HasSubstr("the 2 x 2 block, row by row, of element 2")));
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 2, "8e7, -8e7, nan, 8e7"),
              HasSubstr("element_stiffness.csv:2: field 3 'nan' of the element's block is not a "
                        "finite number"));
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 2, "8e7, -8e7, 1e999, 8e7"),
              HasSubstr("element_stiffness.csv:2: field 3 '1e999'"));
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 4, "8e7, -8e7, -7e7, 8e7"),
              AllOf(HasSubstr("element_stiffness.csv:4: the block is not symmetric"),
                    HasSubstr("entry (1, 2) = -8e+07 but (2, 1) = -7e+07")));
  // Symmetric and finite, but twice the bar's: zone1 (elements 2, 3) misfits.
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 5, "1.6e8, -1.6e8, -1.6e8, 1.6e8"),
              AllOf(HasSubstr("model.yaml:"), HasSubstr("element_stiffness.csv"),
                    HasSubstr("element blocks of zone 'zone1' do not sum to its stiffness: "
                              "entry (4, 4) is 1.6e+08 in K_z but 2.4e+08 in the blocks' sum "
                              "(misfit 8e+07, 0.5 of the largest entry 1.6e+08"),
                    HasSubstr("relative tolerance 1e-08")));
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 6, "1, 0, 0, 1"),
              HasSubstr("element_stiffness.csv:6: a line past the last element, expected 4 lines"));
  EXPECT_THAT(ErrorAfter("element_stiffness.csv", 5, ""),
              HasSubstr("element_stiffness.csv: 3 lines, expected 4, one per element"));
}

TEST_F(MatrixModelElementsTest, BadPositionsAndKeysGiveOneClearError) {
  EXPECT_THAT(ErrorAfter("element_positions.csv", 3, "0.1, 0.2"),
              HasSubstr("element_positions.csv:3: 2 coordinates, expected 1 (as on the first"));
  EXPECT_THAT(ErrorAfter("element_positions.csv", 2, "1, 2, 3, 4"),
              HasSubstr("element_positions.csv:2: 4 coordinates, expected 1 to 3"));
  EXPECT_THAT(ErrorAfter("element_positions.csv", 2, "x"),
              HasSubstr("element_positions.csv:2: field 1 'x' of the element's position"));
  EXPECT_THAT(ErrorAfter("model.yaml", 0,
                         "elements: {dofs: element_dofs.csv, stiffness: "
                         "element_stiffness.csv, blocks: b.csv}"),
              AllOf(HasSubstr("model.yaml:"), HasSubstr("unknown key 'blocks'"),
                    HasSubstr("expected dofs, stiffness, positions")));
  EXPECT_THAT(ErrorAfter("model.yaml", 0, "elements: {stiffness: element_stiffness.csv}"),
              HasSubstr("expected key 'dofs'"));
  EXPECT_THAT(ErrorAfter("model.yaml", 0, "elements: {dofs: none.csv, stiffness: s.csv}"),
              HasSubstr("cannot read element dofs file"));
}

TEST_F(MatrixModelElementsTest, AZoneNameThatNoDofsFileCanHoldIsNotWritten) {
  BarProperties bar;
  bar.elements = 2;
  MatrixModelData data = BarMatrixModel(BarModel(bar), 2e11);
  data.zones[0].name = "a, b";
  EXPECT_THROW(WriteMatrixModel(PathOf(""), data), std::runtime_error);
}

// The stiffness of `data` at every zone's nominal modulus.
SparseMatrix NominalStiffness(const MatrixModelData& data) {
  return data.Stiffness(data.NominalModuli());
}

// The largest entry of |a - b| relative to b's largest.
double RelativeDifference(const SparseMatrix& a, const SparseMatrix& b) {
  return SparseMatrix(a - b).coeffs().cwiseAbs().maxCoeff() / b.coeffs().cwiseAbs().maxCoeff();
}

TEST_F(MatrixModelElementsTest, PerElementZonesAreTheBlocksAndKeepTheNominalStiffness) {
  const MatrixModelData data = ReadMatrixModel(WriteFourElementBar());
  ZoneLayout layout;
  layout.zoning = Zoning::kPerElement;
  std::vector<std::string> names;
  const std::vector<int> zones = RegroupedElementZones(data, layout, "m.yaml", &names);
  EXPECT_EQ(zones, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(names, (std::vector<std::string>{"element0", "element1", "element2", "element3"}));
  const MatrixModelData rezoned = RezonedMatrixModel(data, zones, names);
  ASSERT_EQ(rezoned.zones.size(), 4u);
  for (int e = 0; e < 4; ++e) {
    const MatrixModelZone& zone = rezoned.zones[static_cast<std::size_t>(e)];
    EXPECT_EQ(zone.name, names[static_cast<std::size_t>(e)]);
    EXPECT_EQ(zone.nominal_modulus, 2e11);
    // K_e = E_nom S / h_e [1 -1; -1 1] on dofs e, e + 1, and nothing else.
    EXPECT_EQ(zone.stiffness.nonZeros(), 4);
    EXPECT_EQ(zone.stiffness.coeff(e, e + 1), -2e11 * 1e-4 / 0.25);
    EXPECT_EQ(rezoned.elements[static_cast<std::size_t>(e)].zone, e);
  }
  // The blocks sum to each K_z, and K at the nominal moduli is the manifest's.
  EXPECT_EQ(CheckElementBlockSums(rezoned, "m.yaml"), "");
  EXPECT_EQ(RelativeDifference(NominalStiffness(rezoned), NominalStiffness(data)), 0.0);
  EXPECT_EQ(rezoned.loads.size(), data.loads.size());
  EXPECT_EQ(rezoned.sensors.size(), data.sensors.size());
}

TEST_F(MatrixModelElementsTest, ARegroupedZoneScalesItsBlocksToItsFirstElementsNominalModulus) {
  MatrixModelData data = ReadMatrixModel(WriteFourElementBar());
  // The manifest's second zone given at a nominal 1e11 (its K and blocks halved).
  data.zones[1].nominal_modulus = 1e11;
  data.zones[1].stiffness *= 0.5;
  for (MatrixModelElement& element : data.elements) {
    if (element.zone == 1) element.stiffness *= 0.5;
  }
  ZoneLayout layout;
  layout.zoning = Zoning::kGrid;
  layout.zone_grid = {1};
  std::vector<std::string> names;
  const std::vector<int> zones = RegroupedElementZones(data, layout, "m.yaml", &names);
  EXPECT_EQ(zones, (std::vector<int>{0, 0, 0, 0}));
  EXPECT_EQ(names, (std::vector<std::string>{"grid_0"}));
  const MatrixModelData rezoned = RezonedMatrixModel(data, zones, names);
  ASSERT_EQ(rezoned.zones.size(), 1u);
  EXPECT_EQ(rezoned.zones[0].nominal_modulus, 2e11);
  EXPECT_EQ(CheckElementBlockSums(rezoned, "m.yaml"), "");
  // One modulus for the zone: every block at 2e11, the manifest's K at [2e11, 2e11]
  // (summed in another order: measured 0 apart on this bar).
  EXPECT_LT(
      RelativeDifference(NominalStiffness(rezoned), data.Stiffness(Vector::Constant(2, 2e11))),
      1e-15);
}

TEST_F(MatrixModelElementsTest, AGridSplitsThePlatesElementsIntoEqualBoxes) {
  // The plate example's model: 24 x 6 elements of 1/60 x 1/60 m, centroids as positions.
  const MatrixModelData plate =
      ReadMatrixModel(testing::SourcePath("configs/plate/coarse/model_axial.yaml"));
  ASSERT_EQ(plate.elements.size(), 144u);
  ZoneLayout layout;
  layout.zoning = Zoning::kGrid;
  layout.zone_grid = {8, 2};
  std::vector<std::string> names;
  const std::vector<int> zones = RegroupedElementZones(plate, layout, "plate.yaml", &names);
  ASSERT_EQ(names.size(), 16u);
  EXPECT_EQ(names[0], "grid_0_0");
  EXPECT_EQ(names[1], "grid_1_0");
  EXPECT_EQ(names[15], "grid_7_1");
  // Every box 3 x 3 elements: the one of an element by its centroid (x, y).
  std::vector<int> count(16, 0);
  for (std::size_t e = 0; e < plate.elements.size(); ++e) {
    const Vector& x = plate.elements[e].position;
    const int column = static_cast<int>(x[0] * 60.0) / 3, row = static_cast<int>(x[1] * 60.0) / 3;
    EXPECT_EQ(zones[e], column + 8 * row) << "element " << e;
    ++count[static_cast<std::size_t>(zones[e])];
  }
  EXPECT_EQ(count, std::vector<int>(16, 9));
  const MatrixModelData rezoned = RezonedMatrixModel(plate, zones, names);
  EXPECT_EQ(CheckElementBlockSums(rezoned, "plate.yaml"), "");
  // The blocks as read (17 digits) against the manifest's two K_z: measured 2.2e-16.
  EXPECT_LT(RelativeDifference(NominalStiffness(rezoned), NominalStiffness(plate)), 2e-15);
}

TEST_F(MatrixModelElementsTest, ALayoutTheElementsCannotServeGivesOneClearError) {
  MatrixModelData data = ReadMatrixModel(WriteFourElementBar());
  ZoneLayout grid;
  grid.zoning = Zoning::kGrid;
  grid.zone_grid = {2, 2};
  std::vector<std::string> names;
  auto message = [&](const MatrixModelData& model, const ZoneLayout& layout) -> std::string {
    try {
      RegroupedElementZones(model, layout, "m.yaml", &names);
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  };
  EXPECT_THAT(message(data, grid),
              HasSubstr("model.zone_grid must hold one positive count per coordinate of the "
                        "element positions of m.yaml (1 coordinate), each at most its 4 "
                        "elements, got 2 values"));
  grid.zone_grid = {5};
  EXPECT_THAT(message(data, grid), HasSubstr("each at most its 4 elements"));
  for (MatrixModelElement& element : data.elements) element.position.resize(0);
  EXPECT_THAT(message(data, grid), AllOf(HasSubstr("the manifest m.yaml gives none"),
                                         HasSubstr("use model.zoning: per_element")));
  data.elements.clear();
  ZoneLayout per_element;
  per_element.zoning = Zoning::kPerElement;
  EXPECT_THAT(message(data, per_element),
              AllOf(HasSubstr("model.zoning 'per_element' regroups the element blocks of the "
                              "manifest m.yaml, which has none"),
                    HasSubstr("leave model.zoning out")));
}

}  // namespace
}  // namespace mcrewave
