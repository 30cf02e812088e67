#include <puncture/vtk_io/vtk_polydata.hpp>

#include <puncture/io/output_session.hpp>
#include <puncture/io/vtk_xml_field_data.hpp>

#include <set>
#include <stdexcept>

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

namespace puncture::io {

namespace {
void check_name(std::set<std::string>& names, const std::string& name) {
  if (name.empty()) throw std::invalid_argument("write_polydata: empty point-data array name");
  if (!names.insert(name).second)
    throw std::invalid_argument("write_polydata: duplicate point-data array name '" + name + "'");
}
}  // namespace

void write_polydata(OutputSession& session, const std::string& relative_name,
                    const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                    const std::vector<std::pair<std::string, Eigen::VectorXd>>& point_scalars,
                    const std::vector<std::pair<std::string, Eigen::MatrixX3d>>& point_vectors,
                    const Provenance* provenance) {
  const Eigen::Index n = vertices.rows();
  const std::string where = "write_polydata('" + relative_name + "')";
  if (!vertices.allFinite()) throw std::invalid_argument(where + ": non-finite vertex coordinate");
  if (triangles.size() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= n))
    throw std::invalid_argument(where + ": triangle vertex index outside [0, " + std::to_string(n) + ")");
  std::set<std::string> names;
  for (const auto& [name, values] : point_scalars) {
    check_name(names, name);
    if (values.size() != n)
      throw std::invalid_argument(where + ": scalar array '" + name + "' has " +
                                  std::to_string(values.size()) + " values for " + std::to_string(n) +
                                  " vertices");
    if (!values.allFinite()) throw std::invalid_argument(where + ": scalar array '" + name + "' is not finite");
  }
  for (const auto& [name, values] : point_vectors) {
    check_name(names, name);
    if (values.rows() != n)
      throw std::invalid_argument(where + ": vector array '" + name + "' has " +
                                  std::to_string(values.rows()) + " rows for " + std::to_string(n) +
                                  " vertices");
    if (!values.allFinite()) throw std::invalid_argument(where + ": vector array '" + name + "' is not finite");
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  for (Eigen::Index i = 0; i < n; ++i) points->SetPoint(i, vertices(i, 0), vertices(i, 1), vertices(i, 2));
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(triangles.rows(), 3 * triangles.rows());
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const vtkIdType ids[3] = {triangles(t, 0), triangles(t, 1), triangles(t, 2)};
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(polys);

  for (std::size_t k = 0; k < point_scalars.size(); ++k) {
    const auto& [name, values] = point_scalars[k];
    vtkNew<vtkDoubleArray> array;
    array->SetName(name.c_str());
    array->SetNumberOfComponents(1);
    array->SetNumberOfTuples(n);
    for (Eigen::Index i = 0; i < n; ++i) array->SetValue(i, values(i));
    poly->GetPointData()->AddArray(array);
    if (k == 0) poly->GetPointData()->SetActiveScalars(name.c_str());
  }
  for (std::size_t k = 0; k < point_vectors.size(); ++k) {
    const auto& [name, values] = point_vectors[k];
    vtkNew<vtkDoubleArray> array;
    array->SetName(name.c_str());
    array->SetNumberOfComponents(3);
    array->SetNumberOfTuples(n);
    for (Eigen::Index i = 0; i < n; ++i) array->SetTuple3(i, values(i, 0), values(i, 1), values(i, 2));
    poly->GetPointData()->AddArray(array);
    if (k == 0) poly->GetPointData()->SetActiveVectors(name.c_str());
  }

  if (provenance) {
    for (const auto& [name, value] : provenance_field_data(*provenance, "m")) {
      vtkNew<vtkStringArray> array;
      array->SetName(name.c_str());
      array->SetNumberOfValues(1);
      array->SetValue(0, value);
      poly->GetFieldData()->AddArray(array);
    }
  }

  const std::filesystem::path path = session.stage(relative_name);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetFileName(path.c_str());
  writer->SetInputData(poly);
  if (writer->Write() != 1 || writer->GetErrorCode() != 0)
    throw std::runtime_error(where + ": VTK failed to write '" + path.string() + "'");
}

}  // namespace puncture::io
