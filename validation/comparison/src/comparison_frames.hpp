// comparison_frames.hpp (internal to the comparison report): the ParaView
// files of `puncture compare`. VTK through puncture_io.
//
// DiscFrames: the top surface of every layer as a polar disc (radii graded
//   towards the needle axis, 40 rings x 36 azimuths by default) displaced by a
//   model's azimuthal-mean deflection; the same picture for every model.
//   write(): one .vtp, coordinates in m (scene frame, shifted by x_offset_m
//   along x), point fields deflection_mm (> 0 into the tissue) and layer_state.
// write_volume_frame: the model's deformed tetrahedra (.vtu, coordinates in m
//   shifted by x_offset_m, point vectors displacement_m, cell field layer).
// write_mesh_vtu: the undeformed comparison mesh (.vtu, m; cell fields layer,
//   needle_column).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/comparison/comparison_model.hpp"
#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene.hpp"

namespace puncture::validation::comparison_report_detail {

class DiscFrames {
 public:
  explicit DiscFrames(const Scene& scene, int radial = 40, int azimuths = 36);
  void write(io::OutputSession& session, const std::string& name, const comparison::ComparisonModel& model,
             std::size_t layer, double x_offset_m) const;

 private:
  const Scene& scene_;
  std::vector<double> radii_;
  int azimuths_ = 36;
  Eigen::MatrixX3i triangles_;
};

void write_volume_frame(io::OutputSession& session, const std::string& name, const comparison::ComparisonModel& model,
                        double x_offset_m);

void write_mesh_vtu(io::OutputSession& session, const std::string& name, const meshing::TetMesh& mesh);

}  // namespace puncture::validation::comparison_report_detail
