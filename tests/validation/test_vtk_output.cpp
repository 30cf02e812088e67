// write_polydata read back with vtkXMLPolyDataReader; write_pvd parsed back
// with VTK's XML parser (vtkXMLUtilities).
#include <puncture/io/output_session.hpp>
#include <puncture/io/pvd.hpp>
#include <puncture/vtk_io/vtk_polydata.hpp>

#include "test_io_common.hpp"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUtilities.h>

#include <stdexcept>

namespace {

using puncture::io::OutputSession;
using puncture::io::testing::ScratchDir;
namespace fs = std::filesystem;

/// A unit square split into two triangles plus an apex: 5 vertices, 4 triangles.
struct SmallSurface {
  Eigen::MatrixX3d vertices{5, 3};
  Eigen::MatrixX3i triangles{4, 3};
  Eigen::VectorXd pressure{5};
  Eigen::MatrixX3d displacement{5, 3};
  SmallSurface() {
    vertices << 0, 0, 0, 1e-3, 0, 0, 1e-3, 1e-3, 0, 0, 1e-3, 0, 0.5e-3, 0.5e-3, -0.1 / 3.0;
    triangles << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
    pressure << 0.1, 1.0 / 3.0, -2.5e5, 7e-300, 0;
    for (int i = 0; i < 5; ++i) displacement.row(i) = Eigen::RowVector3d(i * 1e-4, -i / 7.0, 1.0 / (i + 3));
  }
};

TEST(VtkPolyData, ReadBackGivesTheSamePointsTrianglesAndArrays) {
  ScratchDir scratch;
  const SmallSurface s;
  {
    OutputSession session(scratch.path());
    puncture::io::write_polydata(session, "frames/skin.vtp", s.vertices, s.triangles,
                                 {{"pressure_Pa", s.pressure}, {"depth_m", -s.vertices.col(2)}},
                                 {{"displacement_m", s.displacement}});
    session.commit();
  }
  vtkNew<vtkXMLPolyDataReader> reader;
  const std::string file = (scratch.path() / "frames/skin.vtp").string();
  ASSERT_TRUE(reader->CanReadFile(file.c_str()));
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  ASSERT_EQ(poly->GetNumberOfPoints(), 5);
  for (vtkIdType i = 0; i < 5; ++i) {
    double p[3];
    poly->GetPoint(i, p);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(p[k], s.vertices(i, k)) << "point " << i;
  }
  ASSERT_EQ(poly->GetNumberOfPolys(), 4);
  vtkNew<vtkIdList> ids;
  poly->GetPolys()->InitTraversal();
  for (int t = 0; t < 4; ++t) {
    ASSERT_TRUE(poly->GetPolys()->GetNextCell(ids));
    ASSERT_EQ(ids->GetNumberOfIds(), 3);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(ids->GetId(k), s.triangles(t, k)) << "triangle " << t;
  }
  vtkDataArray* pressure = poly->GetPointData()->GetArray("pressure_Pa");
  vtkDataArray* depth = poly->GetPointData()->GetArray("depth_m");
  vtkDataArray* disp = poly->GetPointData()->GetArray("displacement_m");
  ASSERT_NE(pressure, nullptr);
  ASSERT_NE(depth, nullptr);
  ASSERT_NE(disp, nullptr);
  EXPECT_EQ(disp->GetNumberOfComponents(), 3);
  EXPECT_STREQ(poly->GetPointData()->GetScalars()->GetName(), "pressure_Pa");
  EXPECT_STREQ(poly->GetPointData()->GetVectors()->GetName(), "displacement_m");
  for (vtkIdType i = 0; i < 5; ++i) {
    EXPECT_EQ(pressure->GetTuple1(i), s.pressure(i));
    EXPECT_EQ(depth->GetTuple1(i), -s.vertices(i, 2));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(disp->GetComponent(i, k), s.displacement(i, k));
  }
}

TEST(VtkPolyData, RejectsBadInputBeforeStagingAnything) {
  ScratchDir scratch;
  const SmallSurface s;
  OutputSession session(scratch.path());
  Eigen::MatrixX3i bad_index = s.triangles;
  bad_index(2, 1) = 5;
  EXPECT_THROW(puncture::io::write_polydata(session, "a.vtp", s.vertices, bad_index, {}, {}),
               std::invalid_argument);
  Eigen::MatrixX3d nan_vertices = s.vertices;
  nan_vertices(1, 1) = std::nan("");
  EXPECT_THROW(puncture::io::write_polydata(session, "a.vtp", nan_vertices, s.triangles, {}, {}),
               std::invalid_argument);
  EXPECT_THROW(puncture::io::write_polydata(session, "a.vtp", s.vertices, s.triangles,
                                            {{"short", Eigen::VectorXd::Zero(4)}}, {}),
               std::invalid_argument);
  EXPECT_THROW(puncture::io::write_polydata(session, "a.vtp", s.vertices, s.triangles,
                                            {{"x", s.pressure}}, {{"x", s.displacement}}),
               std::invalid_argument);
  EXPECT_TRUE(puncture::io::testing::list_tree(scratch.path()).empty());
}

TEST(Pvd, IsWellFormedXmlListingTheEntries) {
  ScratchDir scratch;
  const std::vector<puncture::io::PvdEntry> entries = {
      {0.0, 0, "frames/skin_0000.vtp"},
      {1.0 / 30.0, 0, "frames/skin_0001.vtp"},
      {1.0 / 30.0, 1, "frames/fat & muscle <1>.vtp"},
  };
  {
    OutputSession session(scratch.path());
    puncture::io::write_pvd(session, "surfaces.pvd", entries);
    session.commit();
  }
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile((scratch.path() / "surfaces.pvd").c_str()));
  ASSERT_NE(root, nullptr) << "not well-formed XML";
  EXPECT_STREQ(root->GetName(), "VTKFile");
  EXPECT_STREQ(root->GetAttribute("type"), "Collection");
  ASSERT_EQ(root->GetNumberOfNestedElements(), 1);
  vtkXMLDataElement* collection = root->GetNestedElement(0);
  EXPECT_STREQ(collection->GetName(), "Collection");
  ASSERT_EQ(collection->GetNumberOfNestedElements(), static_cast<int>(entries.size()));
  for (int i = 0; i < collection->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* ds = collection->GetNestedElement(i);
    EXPECT_STREQ(ds->GetName(), "DataSet");
    EXPECT_EQ(std::stod(ds->GetAttribute("timestep")), entries[i].time_s);
    EXPECT_EQ(std::stoi(ds->GetAttribute("part")), entries[i].part);
    EXPECT_EQ(std::string(ds->GetAttribute("file")), entries[i].file);
  }
}

TEST(Pvd, RejectsBadEntries) {
  EXPECT_THROW(puncture::io::pvd_document({{std::nan(""), 0, "a.vtp"}}), std::invalid_argument);
  EXPECT_THROW(puncture::io::pvd_document({{0.0, -1, "a.vtp"}}), std::invalid_argument);
  EXPECT_THROW(puncture::io::pvd_document({{0.0, 0, ""}}), std::invalid_argument);
}

}  // namespace
