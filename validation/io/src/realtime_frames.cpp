#include "puncture/vtk_io/realtime_frames.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

#include "puncture/vtk_io/vtk_polydata.hpp"
#include "puncture/model/force_mesh_field.hpp"

namespace puncture::io {

FrameWriter::FrameWriter(OutputSession& session, const RealtimeModel& model, const Scene& scene,
                         FrameWriterOptions options)
    : session_(session), scene_(scene), options_(std::move(options)) {
  for (const LayerSurface* s : model.surfaces) {
    Eigen::MatrixX3d v;
    Eigen::MatrixX3i t;
    s->tessellate(options_.surface_bands_theta, options_.surface_azimuths, v, t);
    rest_vertices_.push_back(v);
    triangles_.push_back(t);
  }
}

void FrameWriter::write(const PunctureSimulator& sim, const TickResult& tick, int frame) {
  constexpr double kMm = 1e-3;
  char index[16];
  std::snprintf(index, sizeof index, "%04d", frame);
  const std::size_t n_layers = sim.layer_count();
  const Eigen::RowVector3d offset(options_.x_offset_m, 0.0, 0.0);
  for (std::size_t k = 0; k < n_layers; ++k) {
    const std::string& name = scene_.layers[k].name;
    const double state = static_cast<double>(tick.layers[k].state);
    // Layer surface: SH surface displaced by the force-mesh displacement field.
    Eigen::MatrixX3d vertices = rest_vertices_[k];
    Eigen::VectorXd deflection = Eigen::VectorXd::Zero(vertices.rows());
    const ForceMesh* mesh = sim.force_mesh(k);
    if (mesh && mesh->node_count() > 0) {
      const Eigen::Matrix3Xd displacement = sim.node_positions(k) - sim.node_rest_positions(k);
      const LatticeDisplacementField field = LatticeDisplacementField::of(*mesh);
      for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
        const Eigen::Vector3d p = vertices.row(i).transpose();
        if (p.z() < layer_top_z(k) - 1e-9) continue;  // only the top face carries the force mesh
        const Eigen::Vector3d d = field.displacement_at(p, displacement);
        vertices.row(i) += d.transpose();
        deflection[i] = -d.z() / kMm;
      }
    }
    std::vector<std::pair<std::string, Eigen::VectorXd>> fields{
        {"deflection_mm", deflection}, {"layer_state", Eigen::VectorXd::Constant(vertices.rows(), state)}};
    if (options_.reference_deflection_mm) {
      // VTK arrays must be finite: 0 where the reference has no value, flagged by reference_available.
      Eigen::VectorXd error = Eigen::VectorXd::Zero(vertices.rows());
      Eigen::VectorXd available = Eigen::VectorXd::Zero(vertices.rows());
      for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
        const Eigen::Vector3d p = rest_vertices_[k].row(i).transpose();
        if (p.z() < layer_top_z(k) - 1e-9) continue;
        const double reference = options_.reference_deflection_mm(k, std::hypot(p.x(), p.y()), tick.time_s);
        if (std::isfinite(reference)) error[i] = deflection[i] - reference, available[i] = 1.0;
      }
      fields.emplace_back("deflection_error_mm", error);
      fields.emplace_back("reference_available", available);
    }
    vertices.rowwise() += offset;
    const std::string surface_file = options_.directory + "/" + name + "_surface_" + index + ".vtp";
    write_polydata(session_, surface_file, vertices, triangles_[k], fields, {}, options_.provenance);
    entries_.push_back({tick.time_s, options_.first_part + static_cast<int>(k), surface_file});

    if (mesh && mesh->node_count() > 0) {
      const Eigen::Matrix3Xd& pos = sim.node_positions(k);
      Eigen::MatrixX3d nodes = pos.transpose();
      nodes.rowwise() += offset;
      Eigen::VectorXd ring(mesh->node_count()), node_deflection(mesh->node_count());
      const Eigen::Matrix3Xd disp = pos - sim.node_rest_positions(k);
      for (int i = 0; i < mesh->node_count(); ++i) {
        ring[i] = sim.node_rings(k)[static_cast<std::size_t>(i)];
        node_deflection[i] = -disp(2, i) / kMm;
      }
      if (lattice_tris_.size() <= k) lattice_tris_.resize(n_layers);
      if (lattice_tris_[k].rows() == 0) lattice_tris_[k] = lattice_triangles(mesh->lattice());
      const std::string mesh_file = options_.directory + "/" + name + "_force_mesh_" + index + ".vtp";
      write_polydata(session_, mesh_file, nodes, lattice_tris_[k],
                         {{"ring", ring}, {"deflection_mm", node_deflection}}, {}, options_.provenance);
      entries_.push_back({tick.time_s, options_.first_part + static_cast<int>(n_layers + k), mesh_file});
    }
  }
  ++frames_;
}

void FrameWriter::finish() {
  if (!entries_.empty() && !options_.pvd_name.empty()) write_pvd(session_, options_.pvd_name, entries_, options_.provenance);
}

}  // namespace puncture::io
