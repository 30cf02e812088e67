// Inverted tetrahedra of a deformed mesh (element_inversion.hpp): J = V / V0
// of an affinely mapped tetrahedron is det A (closed form); a reflection
// turns it inside out (J = -1), a flattening gives J = 0 (counted inverted);
// removed tetrahedra are skipped; wrong sizes are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "puncture/comparison/element_inversion.hpp"

namespace puncture::comparison {
namespace {

/// Two tetrahedra sharing the face (1, 2, 3): nodes 0 and 4 on either side.
TetMesh two_tetrahedra() {
  TetMesh mesh;
  mesh.points_m.resize(3, 5);
  mesh.points_m << 0.0, 1.0, 0.0, 0.0, 1.0,  //
      0.0, 0.0, 1.0, 0.0, 1.0,              //
      0.0, 0.0, 0.0, 1.0, 1.0;
  mesh.points_m *= 1e-3;
  mesh.tets = {Eigen::Vector4i(0, 1, 2, 3), Eigen::Vector4i(4, 2, 1, 3)};
  mesh.layer = {0, 0};
  mesh.needle_column = {0, 0};
  return mesh;
}

Eigen::VectorXd mapped(const TetMesh& mesh, const Eigen::Matrix3d& A, const Eigen::Vector3d& shift) {
  Eigen::VectorXd x(3 * mesh.node_count());
  for (int a = 0; a < mesh.node_count(); ++a) x.segment<3>(3 * a) = A * mesh.points_m.col(a) + shift;
  return x;
}

TEST(ElementInversion, TheVolumeRatioOfAnAffineMapIsItsDeterminant) {
  const TetMesh mesh = two_tetrahedra();
  ASSERT_GT(meshing::tet_signed_volume(mesh.points_m.col(4), mesh.points_m.col(2), mesh.points_m.col(1), mesh.points_m.col(3)),
            0.0);
  Eigen::Matrix3d A;
  A << 1.3, 0.4, -0.2,  //
      0.1, 0.7, 0.5,    //
      -0.3, 0.2, 0.9;
  const ElementInversion e = measure_element_inversion(mesh, mapped(mesh, A, Eigen::Vector3d(2e-3, -1e-3, 4e-3)));
  EXPECT_EQ(e.elements, 2);
  EXPECT_EQ(e.inverted, 0);
  EXPECT_NEAR(e.min_volume_ratio, A.determinant(), 1e-12);
  EXPECT_DOUBLE_EQ(e.inverted_share(), 0.0);
}

TEST(ElementInversion, AReflectionTurnsEveryTetrahedronInsideOutAndAFlatteningCounts) {
  const TetMesh mesh = two_tetrahedra();
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  const ElementInversion reflected = measure_element_inversion(mesh, mapped(mesh, mirror, Eigen::Vector3d::Zero()));
  EXPECT_EQ(reflected.inverted, 2);
  EXPECT_NEAR(reflected.min_volume_ratio, -1.0, 1e-12);
  EXPECT_DOUBLE_EQ(reflected.inverted_share(), 1.0);
  const Eigen::Matrix3d flatten = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  const ElementInversion flat = measure_element_inversion(mesh, mapped(mesh, flatten, Eigen::Vector3d::Zero()));
  EXPECT_EQ(flat.inverted, 2);
  EXPECT_DOUBLE_EQ(flat.min_volume_ratio, 0.0);
}

TEST(ElementInversion, OneNodeThroughTheSharedFaceInvertsOnlyItsTetrahedron) {
  // Node 0 moved from (0, 0, 0) to (0.6, 0.6, 0.6) mm, through the shared
  // face x + y + z = 1 mm: its tetrahedron's volume is then (1 - 1.8) / 6 mm^3
  // (J = -0.8); the other keeps J = 1.
  const TetMesh mesh = two_tetrahedra();
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), 15);
  x.segment<3>(0) = Eigen::Vector3d(0.6e-3, 0.6e-3, 0.6e-3);
  const ElementInversion e = measure_element_inversion(mesh, x);
  EXPECT_EQ(e.elements, 2);
  EXPECT_EQ(e.inverted, 1);
  EXPECT_NEAR(e.min_volume_ratio, -0.8, 1e-12);
  // Removed, it no longer counts.
  const ElementInversion without = measure_element_inversion(mesh, x, {1, 0});
  EXPECT_EQ(without.elements, 1);
  EXPECT_EQ(without.inverted, 0);
  EXPECT_NEAR(without.min_volume_ratio, 1.0, 1e-12);
  // Nothing left: no ratio.
  const ElementInversion none = measure_element_inversion(mesh, x, {1, 1});
  EXPECT_EQ(none.elements, 0);
  EXPECT_TRUE(std::isnan(none.min_volume_ratio));
  EXPECT_TRUE(std::isnan(none.inverted_share()));
}

TEST(ElementInversion, WrongSizesAreRefused) {
  const TetMesh mesh = two_tetrahedra();
  EXPECT_THROW(measure_element_inversion(mesh, Eigen::VectorXd::Zero(14)), std::invalid_argument);
  EXPECT_THROW(measure_element_inversion(mesh, Eigen::VectorXd::Zero(15), {0}), std::invalid_argument);
}

}  // namespace
}  // namespace puncture::comparison
