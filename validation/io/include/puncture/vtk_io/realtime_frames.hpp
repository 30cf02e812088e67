// realtime_frames.hpp: ParaView frames of the real-time model, written by
// `puncture run` and `puncture validate` (library puncture_realtime_frames).
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

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/model/realtime_model.hpp"

namespace puncture::io {

struct FrameWriterOptions {
  std::string directory = "frames";  ///< relative to the session directory
  std::string pvd_name = "realtime.pvd";  ///< empty: no .pvd at finish()
  double x_offset_m = 0.0;            ///< translation of every point along x
  int first_part = 0;                 ///< .pvd part index of the first layer surface
  int surface_bands_theta = 48;       ///< tessellation of the SH surfaces
  int surface_azimuths = 72;
  /// Provenance stored as field data of every .vtp and as a comment in the .pvd.
  const Provenance* provenance = nullptr;
  /// Optional reference deflection (mm, > 0 into the tissue) of layer k at
  /// radius r_m from the needle axis at time t_s; NaN where there is none.
  /// When set, the surfaces carry deflection_error_mm = model - reference (0
  /// where the reference has no value) and reference_available (1 or 0).
  std::function<double(std::size_t layer, double r_m, double time_s)> reference_deflection_mm;
};

class FrameWriter {
 public:
  /// Tessellates the model's layer surfaces once (their rest shapes).
  FrameWriter(OutputSession& session, const RealtimeModel& model, const Scene& scene, FrameWriterOptions options = {});

  /// Stages frame number `frame` of every layer: surface and force mesh.
  void write(const PunctureSimulator& sim, const TickResult& tick, int frame);
  /// Stages the .pvd collection (unless options.pvd_name is empty).
  void finish();
  int frames() const { return frames_; }
  const std::vector<PvdEntry>& entries() const { return entries_; }

 private:
  double layer_top_z(std::size_t k) const { return -scene_.layer_top_depth_m(k); }
  OutputSession& session_;
  const Scene& scene_;
  FrameWriterOptions options_;
  std::vector<Eigen::MatrixX3d> rest_vertices_;
  std::vector<Eigen::MatrixX3i> triangles_;
  std::vector<Eigen::MatrixX3i> lattice_tris_;
  std::vector<PvdEntry> entries_;
  int frames_ = 0;
};

}  // namespace puncture::io
