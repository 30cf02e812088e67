// field_output.cc: DataOut-based VTU/PVTU/PVD writer (see field_output.hpp).
#include <puncture/fem/field_output.hpp>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>

#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <puncture/fem/finite_strain_solver.hpp>
#include <puncture/io/atomic_file.hpp>

namespace puncture::fem {

FieldOutputSeries::FieldOutputSeries(std::filesystem::path folder, std::string base_name, MPI_Comm comm)
    : folder_(std::move(folder)), base_name_(std::move(base_name)), comm_(comm) {}

std::vector<std::string> FieldOutputSeries::write_frame(const FiniteStrainSolver& solver, double time_s) {
  using namespace dealii;
  const unsigned rank = Utilities::MPI::this_mpi_process(comm_);
  const unsigned n_ranks = Utilities::MPI::n_mpi_processes(comm_);
  const CellFields fields = solver.cell_fields();
  auto to_vector = [](const std::vector<double>& v) {
    Vector<float> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) out[i] = static_cast<float>(v[i]);
    return out;
  };
  const Vector<float> layer = to_vector(fields.material_id), removed = to_vector(fields.removed),
                      J = to_vector(fields.jacobian), vm = to_vector(fields.von_mises_Pa),
                      stretch = to_vector(fields.max_principal_stretch);

  DataOut<3> data_out;
  data_out.attach_dof_handler(solver.dof_handler());
  const std::vector<std::string> names(3, "displacement");
  const std::vector<DataComponentInterpretation::DataComponentInterpretation> interpretation(
      3, DataComponentInterpretation::component_is_part_of_vector);
  data_out.add_data_vector(solver.solution(), names, DataOut<3>::type_dof_data, interpretation);
  data_out.add_data_vector(layer, "layer_id", DataOut<3>::type_cell_data);
  data_out.add_data_vector(removed, "removed", DataOut<3>::type_cell_data);
  data_out.add_data_vector(J, "J", DataOut<3>::type_cell_data);
  data_out.add_data_vector(vm, "von_mises_Pa", DataOut<3>::type_cell_data);
  data_out.add_data_vector(stretch, "max_principal_stretch", DataOut<3>::type_cell_data);
  data_out.build_patches(solver.settings().degree);

  std::ostringstream frame_name;
  frame_name << base_name_ << "_" << std::setw(4) << std::setfill('0') << frames_.size();
  std::vector<std::string> written;
  const std::string piece = frame_name.str() + "." + std::to_string(rank) + ".vtu";
  {
    std::ostringstream vtu;
    data_out.write_vtu(vtu);
    io::write_file_atomically(folder_ / piece, vtu.str());
    written.push_back(piece);
  }
  const std::string pvtu = frame_name.str() + ".pvtu";
  if (rank == 0) {
    std::vector<std::string> pieces;
    for (unsigned r = 0; r < n_ranks; ++r) pieces.push_back(frame_name.str() + "." + std::to_string(r) + ".vtu");
    std::ostringstream out;
    data_out.write_pvtu_record(out, pieces);
    io::write_file_atomically(folder_ / pvtu, out.str());
    written.push_back(pvtu);
  }
  frames_.emplace_back(time_s, pvtu);
  // Every piece must exist before anyone reads the record.
  MPI_Barrier(comm_);
  return written;
}

std::string FieldOutputSeries::write_collection() const {
  if (dealii::Utilities::MPI::this_mpi_process(comm_) != 0) return {};
  std::ostringstream out;
  dealii::DataOutBase::write_pvd_record(out, frames_);
  const std::string name = base_name_ + ".pvd";
  io::write_file_atomically(folder_ / name, out.str());
  return name;
}

}  // namespace puncture::fem
