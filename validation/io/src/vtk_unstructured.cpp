#include <puncture/vtk_io/vtk_unstructured.hpp>

#include <puncture/io/output_session.hpp>

#include <set>
#include <stdexcept>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

namespace puncture::io {

namespace {
vtkNew<vtkDoubleArray> make_array(const std::string& name, const Eigen::Ref<const Eigen::MatrixXd>& values) {
  vtkNew<vtkDoubleArray> array;
  array->SetName(name.c_str());
  array->SetNumberOfComponents(static_cast<int>(values.cols()));
  array->SetNumberOfTuples(values.rows());
  for (Eigen::Index i = 0; i < values.rows(); ++i)
    for (Eigen::Index c = 0; c < values.cols(); ++c) array->SetComponent(i, static_cast<int>(c), values(i, c));
  return array;
}
}  // namespace

void write_tetrahedra(OutputSession& session, const std::string& relative_name, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX4i& tetrahedra,
                      const std::vector<std::pair<std::string, Eigen::VectorXd>>& point_scalars,
                      const std::vector<std::pair<std::string, Eigen::MatrixX3d>>& point_vectors,
                      const std::vector<std::pair<std::string, Eigen::VectorXd>>& cell_scalars) {
  const Eigen::Index n = points.rows(), t = tetrahedra.rows();
  const std::string where = "write_tetrahedra('" + relative_name + "')";
  if (!points.allFinite()) throw std::invalid_argument(where + ": non-finite point coordinate");
  if (t > 0 && (tetrahedra.minCoeff() < 0 || tetrahedra.maxCoeff() >= n))
    throw std::invalid_argument(where + ": tetrahedron point index outside [0, " + std::to_string(n) + ")");
  std::set<std::string> names;
  auto check = [&](const std::string& name, Eigen::Index rows, Eigen::Index expected, bool finite, const char* kind) {
    if (name.empty()) throw std::invalid_argument(where + ": empty array name");
    if (!names.insert(name).second) throw std::invalid_argument(where + ": duplicate array name '" + name + "'");
    if (rows != expected)
      throw std::invalid_argument(where + ": " + kind + " array '" + name + "' has " + std::to_string(rows) +
                                  " rows for " + std::to_string(expected));
    if (!finite) throw std::invalid_argument(where + ": " + kind + " array '" + name + "' is not finite");
  };
  for (const auto& [name, v] : point_scalars) check(name, v.size(), n, v.allFinite(), "point");
  for (const auto& [name, v] : point_vectors) check(name, v.rows(), n, v.allFinite(), "point");
  for (const auto& [name, v] : cell_scalars) check(name, v.size(), t, v.allFinite(), "cell");

  vtkNew<vtkPoints> vtk_points;
  vtk_points->SetDataTypeToDouble();
  vtk_points->SetNumberOfPoints(n);
  for (Eigen::Index i = 0; i < n; ++i) vtk_points->SetPoint(i, points(i, 0), points(i, 1), points(i, 2));
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(t, 4 * t);
  for (Eigen::Index c = 0; c < t; ++c) {
    const vtkIdType ids[4] = {tetrahedra(c, 0), tetrahedra(c, 1), tetrahedra(c, 2), tetrahedra(c, 3)};
    cells->InsertNextCell(4, ids);
  }
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(vtk_points);
  grid->SetCells(VTK_TETRA, cells);
  for (std::size_t k = 0; k < point_scalars.size(); ++k) {
    grid->GetPointData()->AddArray(make_array(point_scalars[k].first, point_scalars[k].second));
    if (k == 0) grid->GetPointData()->SetActiveScalars(point_scalars[k].first.c_str());
  }
  for (std::size_t k = 0; k < point_vectors.size(); ++k) {
    grid->GetPointData()->AddArray(make_array(point_vectors[k].first, point_vectors[k].second));
    if (k == 0) grid->GetPointData()->SetActiveVectors(point_vectors[k].first.c_str());
  }
  for (std::size_t k = 0; k < cell_scalars.size(); ++k) {
    grid->GetCellData()->AddArray(make_array(cell_scalars[k].first, cell_scalars[k].second));
    if (k == 0) grid->GetCellData()->SetActiveScalars(cell_scalars[k].first.c_str());
  }
  const std::filesystem::path path = session.stage(relative_name);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetFileName(path.c_str());
  writer->SetInputData(grid);
  if (writer->Write() != 1 || writer->GetErrorCode() != 0)
    throw std::runtime_error(where + ": VTK failed to write '" + path.string() + "'");
}

}  // namespace puncture::io
