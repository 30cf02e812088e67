// VTK unstructured-grid (.vtu) output of a tetrahedral mesh, read back with
// VTK's own reader.
#include <gtest/gtest.h>

#include <filesystem>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "puncture/io/output_session.hpp"
#include "puncture/vtk_io/vtk_unstructured.hpp"

namespace puncture::io {
namespace {

TEST(VtkUnstructured, TetrahedraRoundTripThroughVtksReader) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "puncture_test_vtu";
  std::filesystem::remove_all(dir);
  Eigen::MatrixX3d points(5, 3);
  points << 0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 1e-3, 1e-3, 1e-3;
  Eigen::MatrixX4i tets(2, 4);
  tets << 0, 1, 2, 3, 1, 2, 3, 4;
  Eigen::MatrixX3d displacement = 0.5 * points;
  Eigen::VectorXd layer(2);
  layer << 0, 2;
  {
    OutputSession session(dir);
    write_tetrahedra(session, "mesh.vtu", points, tets, {}, {{"displacement_m", displacement}}, {{"layer", layer}});
    EXPECT_THROW(write_tetrahedra(session, "bad.vtu", points, Eigen::MatrixX4i::Constant(1, 4, 7)), std::invalid_argument);
    EXPECT_THROW(write_tetrahedra(session, "bad.vtu", points, tets, {}, {}, {{"layer", Eigen::VectorXd::Zero(3)}}),
                 std::invalid_argument);
    session.commit();
  }
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir / "mesh.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfPoints(), 5);
  ASSERT_EQ(grid->GetNumberOfCells(), 2);
  EXPECT_EQ(grid->GetCellType(1), 10);  // VTK_TETRA
  double p[3];
  grid->GetPoint(4, p);
  EXPECT_EQ(p[2], 1e-3);
  EXPECT_EQ(grid->GetCellData()->GetArray("layer")->GetTuple1(1), 2.0);
  EXPECT_EQ(grid->GetPointData()->GetArray("displacement_m")->GetComponent(4, 0), 0.5e-3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace puncture::io
