// ring_criterion.hpp: the real-time model's breakthrough rule (force_mesh.hpp,
// seed paper Fig. 2: "when j = w the tissue surface breaks"), applied to the
// surface deflection of any comparison model, so every model punctures a
// layer by the same scene criterion.
//
// In:  the layer's force-mesh parameters (w, L, deformed_threshold_m).
// Sample points: the nodes of the hexagonal ring lattice of w rings and
// spacing L (hex_lattice.hpp) around the contact point, in the layer's
// tangent plane (planar offsets in m; node 0 = ring 1 = the contact point).
// The model supplies its surface deflection at these points (m, positive INTO
// the tissue, measured from the moment the needle first touched the layer,
// as the force mesh does from its contact).
// Out: ring mean deflections dZ_j and the number of deformed rings, the
// largest j such that rings 1..j all have a mean deflection whose magnitude
// exceeds the threshold (ForceMesh::deformed_rings); the layer breaks when it
// reaches w. The magnitude: a force mesh only ever deflects into the tissue
// (same count as ForceMesh), but a continuum surface bulges up around the
// dimple (a stiff skin on nearly incompressible fat: the FEM reference's skin
// rises by about 1.5 % of the indentation 8-20 mm from the axis), and a ring
// lifted by more than the threshold is deformed too.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "puncture/scene.hpp"

namespace puncture::comparison {

class RingBreakthroughCriterion {
 public:
  explicit RingBreakthroughCriterion(const ForceMeshParams& params);

  int rings() const { return rings_w_; }
  double spacing_m() const { return spacing_m_; }
  double threshold_m() const { return threshold_m_; }
  /// Planar offsets (m) of the sample points, ring by ring.
  const std::vector<Eigen::Vector2d>& points_m() const { return points_; }
  /// 1-based ring of every sample point.
  const std::vector<int>& point_rings() const { return ring_of_point_; }
  /// Distance of every sample point from the contact point (m).
  const std::vector<double>& point_radii_m() const { return radius_; }

  /// Mean deflection of each ring (size w) from per-point deflections.
  std::vector<double> ring_means_m(const std::vector<double>& point_deflection_m) const;
  int deformed_rings(const std::vector<double>& point_deflection_m) const;
  bool broken(const std::vector<double>& point_deflection_m) const {
    return deformed_rings(point_deflection_m) >= rings_w_;
  }

 private:
  int rings_w_ = 1;
  double spacing_m_ = 0.0;
  double threshold_m_ = 0.0;
  std::vector<Eigen::Vector2d> points_;
  std::vector<int> ring_of_point_;
  std::vector<double> radius_;
  std::vector<int> ring_size_;
};

}  // namespace puncture::comparison
