// Provenance in VTK files, read back with VTK's own readers: .vtp field data
// written by write_polydata, field data inserted into VTK XML text written by
// another writer (what the FEM's deal.II .vtu output uses), and the .pvd
// comment read by VTK's XML parser.
#include <gtest/gtest.h>

#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>
#include <vtkXMLUtilities.h>

#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/vtk_io/vtk_polydata.hpp"
#include "puncture/io/vtk_xml_field_data.hpp"
#include "test_io_common.hpp"

namespace {

using namespace puncture::io;

std::string string_field(vtkFieldData* fd, const char* name) {
  auto* a = vtkStringArray::SafeDownCast(fd->GetAbstractArray(name));
  return a && a->GetNumberOfValues() == 1 ? a->GetValue(0) : std::string("<missing>");
}

TEST(VtkProvenance, PolyDataCarriesItAsFieldData) {
  puncture::io::testing::ScratchDir scratch;
  const Provenance p{"puncture run x.json -o out", "0.1.0", "abc1234-dirty", "2026-01-01T00:00:00Z", "host (cpu, 2 cores)"};
  {
    OutputSession session(scratch.path());
    Eigen::MatrixX3d v(3, 3);
    v << 0, 0, 0, 1, 0, 0, 0, 1, 0;
    Eigen::MatrixX3i t(1, 3);
    t << 0, 1, 2;
    write_polydata(session, "s.vtp", v, t, {}, {}, &p);
    session.commit();
  }
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName((scratch.path() / "s.vtp").c_str());
  reader->Update();
  vtkFieldData* fd = reader->GetOutput()->GetFieldData();
  EXPECT_EQ(string_field(fd, "provenance_command"), p.command);
  EXPECT_EQ(string_field(fd, "provenance_git_revision"), p.git_revision);
  EXPECT_EQ(string_field(fd, "provenance_machine"), p.machine);
  EXPECT_EQ(string_field(fd, "coordinate_unit"), "m");
}

TEST(VtkProvenance, FieldDataInsertedIntoForeignXmlTextReadsBack) {
  // An unstructured grid written by VTK in ASCII and appended form stands in
  // for deal.II's .vtu text.
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0, 0, 0);
  grid->SetPoints(points);
  for (int mode : {vtkXMLWriter::Ascii, vtkXMLWriter::Appended}) {
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetInputData(grid);
    writer->SetDataMode(mode);
    writer->WriteToOutputStringOn();
    writer->Write();
    const Provenance p{"puncture fem s.json", "0.1.0", "abc1234", "2026-01-01T00:00:00Z", "h (c, 2 cores) <&\"'>"};
    const std::string text = add_provenance_field_data(writer->GetOutputString(), p);
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->ReadFromInputStringOn();
    reader->SetInputString(text);
    reader->Update();
    vtkFieldData* fd = reader->GetOutput()->GetFieldData();
    EXPECT_EQ(string_field(fd, "provenance_command"), p.command) << "mode " << mode;
    EXPECT_EQ(string_field(fd, "provenance_machine"), p.machine) << "mode " << mode;
    EXPECT_EQ(string_field(fd, "coordinate_unit"), "m") << "mode " << mode;
    EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 1);
  }
}

TEST(VtkProvenance, PvdCommentDoesNotDisturbTheXmlParser) {
  const Provenance p{"puncture run --flag x", "0.1.0", "abc", "d", "m"};
  const std::string doc = pvd_document({{0.0, 0, "frames/a.vtp"}, {0.1, 1, "frames/b.vtp"}}, &p);
  vtkXMLDataElement* root = vtkXMLUtilities::ReadElementFromString(doc.c_str());
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->GetName(), "VTKFile");
  vtkXMLDataElement* collection = root->GetNestedElement(0);
  ASSERT_NE(collection, nullptr);
  EXPECT_EQ(collection->GetNumberOfNestedElements(), 2);
  EXPECT_STREQ(collection->GetNestedElement(1)->GetAttribute("file"), "frames/b.vtp");
  root->Delete();
}

}  // namespace
