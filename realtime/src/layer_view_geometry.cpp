#include "puncture/realtime/layer_view_geometry.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "puncture/model/force_mesh_field.hpp"
#include "puncture/sh/real_sh.hpp"

namespace puncture::realtime {

LayerViewMesh build_layer_view_mesh(const LayerSurface& surface, double bottom_z_m, const LayerViewMeshOptions& o) {
  if (!(o.first_ring_m > 0.0) || !(o.ring_growth >= 1.0) || o.half_azimuths < 2 || o.side_rows < 1)
    throw std::invalid_argument("build_layer_view_mesh: bad options");
  const LayerProfile& profile = surface.profile();
  const double R = profile.radius_m;
  std::vector<double> radii{0.0};
  for (double step = o.first_ring_m, r = step; r < R; step *= o.ring_growth, r += step) radii.push_back(r);
  if (R - radii.back() < 0.3 * (radii.back() - radii[radii.size() - 2])) radii.back() = R; else radii.push_back(R);

  const int na = o.half_azimuths + 1;  // azimuths 0..pi inclusive
  const int nr = static_cast<int>(radii.size());
  std::vector<Eigen::Vector3d> v;
  LayerViewMesh m;
  m.top_z_m = profile.top_z_m;
  m.bottom_z_m = bottom_z_m;
  // Top face: vertex 0 at the centre, then ring i (1..nr-1) x azimuth j.
  v.push_back(surface.position(Eigen::Vector3d::UnitZ()));
  m.top_face.push_back(0);
  auto top_id = [&](int i, int j) { return i == 0 ? 0 : 1 + (i - 1) * na + j; };
  for (int i = 1; i < nr; ++i)
    for (int j = 0; j < na; ++j) {
      const double phi = M_PI * j / o.half_azimuths;
      m.top_face.push_back(static_cast<int>(v.size()));
      v.push_back(surface.position(profile.top_face_direction(radii[i] * std::cos(phi), radii[i] * std::sin(phi))));
    }
  // Side wall: rows from the top rim (zeta_t) to the bottom rim (zeta_b).
  const int side0 = static_cast<int>(v.size());
  const double theta_top = std::acos(profile.options.top_rim_cos_theta);
  const double theta_bottom = std::acos(profile.options.bottom_rim_cos_theta);
  for (int row = 0; row <= o.side_rows; ++row) {
    const double theta = theta_top + (theta_bottom - theta_top) * row / o.side_rows;
    for (int j = 0; j < na; ++j) v.push_back(surface.position(unit_vector_from_angles(theta, M_PI * j / o.half_azimuths)));
  }
  // Cap bottom edge: one point on z = bottom for every top-face vertex at azimuth 0 or pi.
  const int cap0 = static_cast<int>(v.size());
  std::vector<int> cap_top;  // top-face vertices along x from -R to +R
  for (int i = nr - 1; i >= 1; --i) cap_top.push_back(top_id(i, na - 1));  // azimuth pi: x = -r
  cap_top.push_back(0);
  for (int i = 1; i < nr; ++i) cap_top.push_back(top_id(i, 0));  // azimuth 0: x = +r
  for (int id : cap_top) v.push_back(Eigen::Vector3d(v[id].x(), 0.0, bottom_z_m));

  m.rest_vertices.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.rest_vertices.row(static_cast<Eigen::Index>(i)) = v[i].transpose();

  std::vector<Eigen::Vector3i> top, side, cap;
  // Top face, seen from above (+z): counter-clockwise = increasing azimuth.
  for (int j = 0; j + 1 < na; ++j) top.emplace_back(0, top_id(1, j), top_id(1, j + 1));
  for (int i = 1; i + 1 < nr; ++i)
    for (int j = 0; j + 1 < na; ++j) {
      top.emplace_back(top_id(i, j), top_id(i + 1, j), top_id(i + 1, j + 1));
      top.emplace_back(top_id(i, j), top_id(i + 1, j + 1), top_id(i, j + 1));
    }
  // Side wall, seen from outside.
  for (int row = 0; row < o.side_rows; ++row)
    for (int j = 0; j + 1 < na; ++j) {
      const int a = side0 + row * na + j, b = a + 1, c = a + na, d = c + 1;
      side.emplace_back(a, c, d);
      side.emplace_back(a, d, b);
    }
  // Cap in the plane y = 0, seen from the front (-y).
  for (std::size_t k = 0; k + 1 < cap_top.size(); ++k) {
    const int t0 = cap_top[k], t1 = cap_top[k + 1];
    const int b0 = cap0 + static_cast<int>(k), b1 = b0 + 1;
    cap.emplace_back(b0, b1, t1);
    cap.emplace_back(b0, t1, t0);
  }
  auto to_matrix = [](const std::vector<Eigen::Vector3i>& t) {
    Eigen::MatrixX3i out(static_cast<Eigen::Index>(t.size()), 3);
    for (std::size_t i = 0; i < t.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = t[i].transpose();
    return out;
  };
  m.top_triangles = to_matrix(top);
  m.side_triangles = to_matrix(side);
  m.cap_triangles = to_matrix(cap);
  return m;
}

double LayerDeformer::apply(const LayerSnapshot& layer, const LayerViewMesh& mesh, Eigen::MatrixX3d& vertices) const {
  vertices = mesh.rest_vertices;
  if (!layer.nodes_valid || layer.rest_m.cols() != lattice_.node_count()) return 0.0;
  // The lattice frame of the mesh (as LatticeDisplacementField::of does for a ForceMesh).
  const Eigen::Vector3d origin = layer.rest_m.col(0);
  const Eigen::Vector3d n = layer.contact_normal.normalized();
  Eigen::Vector3d e1 = n.unitOrthogonal();
  for (int i = 0; i < lattice_.node_count(); ++i)
    if (lattice_.axial[i] == Eigen::Vector2i(1, 0)) {
      const Eigen::Vector3d d = layer.rest_m.col(i) - origin;
      e1 = (d - d.dot(n) * n).normalized();
    }
  const LatticeDisplacementField field(lattice_, spacing_m_, origin, e1, n.cross(e1));
  const Eigen::Matrix3Xd displacement = layer.current_m - layer.rest_m;
  double largest = 0.0;
  for (int id : mesh.top_face) {
    const Eigen::Vector3d d = field.displacement_at(mesh.rest_vertices.row(id).transpose(), displacement);
    vertices.row(id) += d.transpose();
    largest = std::max(largest, d.norm());
  }
  return largest;
}

}  // namespace puncture::realtime
