// The ParaView files of `puncture compare` (see comparison_frames.hpp).
#include "comparison_frames.hpp"

#include <cmath>

#include "puncture/vtk_io/vtk_polydata.hpp"
#include "puncture/vtk_io/vtk_unstructured.hpp"

namespace puncture::validation::comparison_report_detail {

namespace {
constexpr double kMm = 1e-3;
constexpr double kPi = 3.14159265358979323846;
}  // namespace

DiscFrames::DiscFrames(const Scene& scene, int radial, int azimuths) : scene_(scene) {
  const double R = 0.5 * scene.sample.diameter_m;
  radii_.push_back(0.0);
  for (int i = 1; i <= radial; ++i) radii_.push_back(R * std::pow(static_cast<double>(i) / radial, 1.7));
  azimuths_ = azimuths;
  triangles_.resize(azimuths * (2 * radial - 1), 3);
  int t = 0;
  for (int j = 0; j < azimuths; ++j) triangles_.row(t++) << 0, 1 + j, 1 + (j + 1) % azimuths;
  for (int i = 1; i < radial; ++i)
    for (int j = 0; j < azimuths; ++j) {
      const int a = 1 + (i - 1) * azimuths + j, b = 1 + (i - 1) * azimuths + (j + 1) % azimuths;
      const int c = a + azimuths, d = b + azimuths;
      triangles_.row(t++) << a, c, d;
      triangles_.row(t++) << a, d, b;
    }
}

void DiscFrames::write(io::OutputSession& session, const std::string& name, const comparison::ComparisonModel& model,
                       std::size_t layer, double x_offset_m) const {
  const std::vector<double> d = model.surface_deflection_m(layer, radii_);
  const int n = 1 + static_cast<int>(radii_.size() - 1) * azimuths_;
  Eigen::MatrixX3d v(n, 3);
  Eigen::VectorXd deflection(n), state = Eigen::VectorXd::Constant(n, static_cast<double>(model.layer_state(layer)));
  const double top = -scene_.layer_top_depth_m(layer);
  auto value = [&](std::size_t i) { return std::isfinite(d[i]) ? d[i] : 0.0; };
  v.row(0) << x_offset_m, 0.0, top - value(0);
  deflection[0] = value(0) / kMm;
  for (std::size_t i = 1; i < radii_.size(); ++i)
    for (int j = 0; j < azimuths_; ++j) {
      const int row = 1 + static_cast<int>(i - 1) * azimuths_ + j;
      const double phi = 2.0 * kPi * j / azimuths_;
      v.row(row) << x_offset_m + radii_[i] * std::cos(phi), radii_[i] * std::sin(phi), top - value(i);
      deflection[row] = value(i) / kMm;
    }
  io::write_polydata(session, name, v, triangles_, {{"deflection_mm", deflection}, {"layer_state", state}});
}

void write_volume_frame(io::OutputSession& session, const std::string& name, const comparison::ComparisonModel& model,
                        double x_offset_m) {
  comparison::VolumeFrame f = model.volume_frame();
  f.points_m.col(0).array() += x_offset_m;
  io::write_tetrahedra(session, name, f.points_m, f.tets, {}, {{"displacement_m", f.displacement_m}},
                       {{"layer", f.layer}});
}

void write_mesh_vtu(io::OutputSession& session, const std::string& name, const meshing::TetMesh& mesh) {
  Eigen::MatrixX4i tets(mesh.tet_count(), 4);
  Eigen::VectorXd layer(mesh.tet_count()), column(mesh.tet_count());
  for (int t = 0; t < mesh.tet_count(); ++t) {
    tets.row(t) = mesh.tets[static_cast<std::size_t>(t)].transpose();
    layer[t] = mesh.layer[static_cast<std::size_t>(t)];
    column[t] = mesh.needle_column[static_cast<std::size_t>(t)];
  }
  io::write_tetrahedra(session, name, mesh.points_m.transpose(), tets, {}, {},
                       {{"layer", layer}, {"needle_column", column}});
}

}  // namespace puncture::validation::comparison_report_detail
