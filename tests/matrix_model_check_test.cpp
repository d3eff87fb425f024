#include "mcrewave/model/matrix_model_check.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {
namespace {

using testing::Contains;

TEST(MatrixModelCheckTest, TheBarsMatricesPass) {
  BarProperties bar;
  bar.elements = 20;
  const BarModel model(bar);
  EXPECT_EQ(CheckSquare(model.mass(), "M.mtx"), "");
  EXPECT_EQ(CheckSymmetric(model.mass(), "M.mtx"), "");
  EXPECT_EQ(CheckSymmetric(model.unit_stiffness(), "K1.mtx"), "");
  EXPECT_EQ(CheckPositiveDefinite(model.mass(), "M.mtx"), "");
  EXPECT_EQ(CheckSameSize(model.unit_stiffness(), "K1.mtx", 21, "M.mtx"), "");
}

TEST(MatrixModelCheckTest, ANonSymmetricMatrixNamesItsWorstEntry) {
  BarProperties bar;
  bar.elements = 10;
  SparseMatrix k = BarModel(bar).unit_stiffness();
  k.coeffRef(3, 4) *= 1.0 + 1e-12;  // within the tolerance
  EXPECT_EQ(CheckSymmetric(k, "K1.mtx"), "");
  k.coeffRef(6, 7) *= 1.5;
  const std::string why = CheckSymmetric(k, "K1.mtx");
  EXPECT_TRUE(Contains(why, "K1.mtx: not symmetric: entry (7, 8)") ||
              Contains(why, "K1.mtx: not symmetric: entry (8, 7)"))
      << why;
  EXPECT_EQ(CheckSquare(SparseMatrix(3, 4), "K.mtx"), "K.mtx: 3 x 4 matrix, expected a square one");
}

TEST(MatrixModelCheckTest, AMassThatIsNotPositiveDefiniteNamesTheDof) {
  BarProperties bar;
  bar.elements = 10;
  bar.mass = MassType::kLumped;
  SparseMatrix mass = BarModel(bar).mass();
  mass.coeffRef(4, 4) = 0.0;  // a dof without mass
  const std::string why = CheckPositiveDefinite(mass, "M.mtx");
  EXPECT_TRUE(Contains(why, "M.mtx: not positive definite")) << why;
  EXPECT_TRUE(Contains(why, "dof 5")) << why;
  mass.coeffRef(4, 4) = -1.0;
  EXPECT_TRUE(Contains(CheckPositiveDefinite(mass, "M.mtx"), "pivot -1 at dof 5"))
      << CheckPositiveDefinite(mass, "M.mtx");
  // The stiffness of a free bar is singular (rigid translation).
  bar.mass = MassType::kConsistent;
  EXPECT_TRUE(Contains(CheckPositiveDefinite(BarModel(bar).unit_stiffness(), "K1.mtx"),
                       "K1.mtx: not positive definite"));
}

TEST(MatrixModelCheckTest, SizeMismatchesNameBothFiles) {
  EXPECT_EQ(CheckSameSize(SparseMatrix(40, 40), "K2.mtx", 42, "M.mtx"),
            "K2.mtx: 40 x 40, but M.mtx has 42 dofs");
  EXPECT_EQ(CheckVectorSize(Vector::Zero(41), "f_tip.mtx", 42, "M.mtx"),
            "f_tip.mtx: 41 entries, but M.mtx has 42 dofs");
  EXPECT_EQ(CheckVectorSize(Vector::Zero(42), "f_tip.mtx", 42, "M.mtx"), "");
}

TEST(MatrixModelCheckTest, SensorRows) {
  SparseMatrix row(1, 10);
  row.insert(0, 3) = 1.0;
  EXPECT_EQ(CheckSensorRow(row, "u_3", "u_3.mtx", 10, "M.mtx"), "");
  EXPECT_EQ(CheckSensorRow(SparseMatrix(row.transpose()), "u_3", "u_3.mtx", 10, "M.mtx"), "");
  SparseMatrix long_row(1, 12);
  long_row.insert(0, 10) = -1.0;
  EXPECT_EQ(CheckSensorRow(long_row, "e_tip", "e_tip.mtx", 10, "M.mtx"),
            "sensor 'e_tip' (e_tip.mtx): entry at dof 11, past the last dof 10 of M.mtx");
  SparseMatrix short_row(1, 8);
  short_row.insert(0, 2) = 1.0;
  EXPECT_EQ(CheckSensorRow(short_row, "u", "u.mtx", 10, "M.mtx"),
            "sensor 'u' (u.mtx): 8 entries, but M.mtx has 10 dofs");
  EXPECT_EQ(CheckSensorRow(SparseMatrix(1, 10), "u", "u.mtx", 10, "M.mtx"),
            "sensor 'u' (u.mtx): every coefficient is zero, the sensor reads nothing");
  EXPECT_TRUE(Contains(CheckSensorRow(SparseMatrix(2, 10), "u", "u.mtx", 10, "M.mtx"),
                       "2 x 10, expected one row"));
  // The same rows stored by rows (MatrixModelSensor::row) get the same answers.
  EXPECT_EQ(CheckSensorRow(SparseRow(row), "u_3", "u_3.mtx", 10, "M.mtx"), "");
  EXPECT_EQ(CheckSensorRow(SparseRow(long_row), "e_tip", "e_tip.mtx", 10, "M.mtx"),
            "sensor 'e_tip' (e_tip.mtx): entry at dof 11, past the last dof 10 of M.mtx");
  EXPECT_EQ(CheckSensorRow(SparseRow(short_row), "u", "u.mtx", 10, "M.mtx"),
            "sensor 'u' (u.mtx): 8 entries, but M.mtx has 10 dofs");
  EXPECT_EQ(CheckSensorRow(SparseRow(1, 10), "u", "u.mtx", 10, "M.mtx"),
            "sensor 'u' (u.mtx): every coefficient is zero, the sensor reads nothing");
}

}  // namespace
}  // namespace mcrewave
