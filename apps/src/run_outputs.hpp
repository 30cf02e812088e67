// run_outputs.hpp (internal to apps/src): ParaView frames of the real-time
// model, shared by `puncture run` and `puncture validate`.
//
// FrameWriter writes, per frame and per layer, the layer's SH surface displaced
// by its force-mesh displacement field (<dir>/<layer>_surface_NNNN.vtp, point
// fields deflection_mm (> 0 into the tissue), layer_state, and optionally
// deflection_error_mm) and the force-mesh nodes (<dir>/<layer>_force_mesh_NNNN.vtp,
// fields ring, deflection_mm), and at finish() one .pvd collection.
//   In:  the session, the model (surfaces), the scene, FrameWriterOptions.
//   Out: staged files in the session; entries() for a combined .pvd.
// Part indices: surface of layer k = first_part + k, its force mesh =
// first_part + n_layers + k. Coordinates in m (scene frame), shifted by
// x_offset_m along x (validate puts the real-time model beside the FEM slab);
// point arrays in the unit their name says (deflection_mm in mm).
#pragma once
#ifdef PUNCTURE_HAVE_VTK  // the frames are VTK files: only in builds with VTK

#include <cmath>
#include <cstdio>
#include <limits>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/io/output_session.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/io/vtk_polydata.hpp"
#include "puncture/model/force_mesh_field.hpp"
#include "puncture/model/realtime_model.hpp"

namespace puncture::apps {

struct FrameWriterOptions {
  std::string directory = "frames";  ///< relative to the session directory
  std::string pvd_name = "realtime.pvd";  ///< empty: no .pvd at finish()
  double x_offset_m = 0.0;            ///< translation of every point along x
  int first_part = 0;                 ///< .pvd part index of the first layer surface
  int surface_bands_theta = 48;       ///< tessellation of the SH surfaces
  int surface_azimuths = 72;
  /// Provenance stored as field data of every .vtp and as a comment in the .pvd.
  const io::Provenance* provenance = nullptr;
  /// Optional reference deflection (mm, > 0 into the tissue) of layer k at
  /// radius r_m from the needle axis at time t_s; NaN where there is none.
  /// When set, the surfaces carry deflection_error_mm = model - reference (0
  /// where the reference has no value) and reference_available (1 or 0).
  std::function<double(std::size_t layer, double r_m, double time_s)> reference_deflection_mm;
};

class FrameWriter {
 public:
  FrameWriter(io::OutputSession& session, const RealtimeModel& model, const Scene& scene,
              FrameWriterOptions options = {})
      : session_(session), scene_(scene), options_(std::move(options)) {
    for (const LayerSurface* s : model.surfaces) {
      Eigen::MatrixX3d v;
      Eigen::MatrixX3i t;
      s->tessellate(options_.surface_bands_theta, options_.surface_azimuths, v, t);
      rest_vertices_.push_back(v);
      triangles_.push_back(t);
    }
  }

  void write(const PunctureSimulator& sim, const TickResult& tick, int frame) {
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
      io::write_polydata(session_, surface_file, vertices, triangles_[k], fields, {}, options_.provenance);
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
        io::write_polydata(session_, mesh_file, nodes, lattice_tris_[k],
                           {{"ring", ring}, {"deflection_mm", node_deflection}}, {}, options_.provenance);
        entries_.push_back({tick.time_s, options_.first_part + static_cast<int>(n_layers + k), mesh_file});
      }
    }
    ++frames_;
  }

  void finish() {
    if (!entries_.empty() && !options_.pvd_name.empty()) io::write_pvd(session_, options_.pvd_name, entries_, options_.provenance);
  }
  int frames() const { return frames_; }
  const std::vector<io::PvdEntry>& entries() const { return entries_; }

 private:
  double layer_top_z(std::size_t k) const { return -scene_.layer_top_depth_m(k); }
  io::OutputSession& session_;
  const Scene& scene_;
  FrameWriterOptions options_;
  std::vector<Eigen::MatrixX3d> rest_vertices_;
  std::vector<Eigen::MatrixX3i> triangles_;
  std::vector<Eigen::MatrixX3i> lattice_tris_;
  std::vector<io::PvdEntry> entries_;
  int frames_ = 0;
};

}  // namespace puncture::apps

#endif  // PUNCTURE_HAVE_VTK
