#include <puncture/meshing/layered_cylinder_mesh.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <puncture/meshing/graded_divisions.hpp>

namespace puncture::meshing {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// One node plane of the mesh: 2D nodes (m) and quads whose 4 node indices are
/// in lexicographic order (0,0),(1,0),(0,1),(1,1) with positive orientation
/// (counter-clockwise seen from +z).
struct CrossSection {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<unsigned, 4>> quads;
};

void require(bool ok, const std::string& field, const std::string& what) {
  if (!ok) throw std::invalid_argument("build_layered_cylinder_mesh: " + field + " " + what);
}

void validate(const Scene& scene, const SlabMeshOptions& options) {
  require(!scene.layers.empty(), "layers", "must name at least one layer");
  for (std::size_t i = 0; i < scene.layers.size(); ++i) {
    const double t = scene.layers[i].thickness_m;
    require(t > 0.0 && std::isfinite(t), "layers[" + std::to_string(i) + "].thickness_m",
            "must be positive and finite, got " + std::to_string(t));
  }
  const double d = scene.sample.diameter_m;
  require(d > 0.0 && std::isfinite(d), "sample.diameter_m",
          "must be positive and finite, got " + std::to_string(d));
  const double a = scene.needle.radius_m;
  require(a > 0.0 && std::isfinite(a), "needle.radius_m",
          "must be positive and finite, got " + std::to_string(a));
  require(a < 0.5 * d, "needle.radius_m",
          "(" + std::to_string(a) + " m) must be smaller than the sample radius (" +
              std::to_string(0.5 * d) + " m)");
  require(options.elements_through_skin >= 1, "options.elements_through_skin",
          "must be >= 1, got " + std::to_string(options.elements_through_skin));
  require(options.sectors >= 4 && options.sectors % 4 == 0, "options.sectors",
          "must be a multiple of 4 and >= 4, got " + std::to_string(options.sectors));
  require(options.radial_grading >= 1.0 && std::isfinite(options.radial_grading),
          "options.radial_grading", "must be >= 1, got " + std::to_string(options.radial_grading));
  require(options.thickness_grading >= 1.0 && std::isfinite(options.thickness_grading),
          "options.thickness_grading",
          "must be >= 1, got " + std::to_string(options.thickness_grading));
}

/// Angle of the point q on the boundary of the square [-1,1]^2 under the
/// equiangular map: equal steps along a side give equal angle steps, the
/// corners go to odd multiples of pi/4.
double equiangular_angle(const Eigen::Vector2d& q) {
  const double x = q.x(), y = q.y();
  if (x >= std::abs(y)) return 0.25 * kPi * y;              // right side
  if (y >= std::abs(x)) return 0.5 * kPi - 0.25 * kPi * x;  // top side
  if (-x >= std::abs(y)) return kPi - 0.25 * kPi * y;       // left side
  return -0.5 * kPi + 0.25 * kPi * x;                       // bottom side
}

/// O-grid central block of n x n cells inside the disc of radius a. Node
/// (i, j) sits at logical (xi, eta) = (-1 + 2i/n, -1 + 2j/n); the logical
/// square rings s = max(|xi|, |eta|) are mapped to similar rounded squares
///   P = rho a s [ (1 - mu) beta q + mu c(q) ],   q = (xi, eta)/s,
/// with c(q) the equiangular circle point: a blend of a square and a circle.
/// The block's outer boundary (s = 1) stays inside the needle disc
/// (rho = n/(n+2) makes the transition ring as wide as a block cell), so the
/// valence-3 corner nodes are not on the circle and every corner angle stays
/// well away from 180 degrees (scaled Jacobian >= 0.7 for every n; tuned by a
/// parameter sweep over mu and beta). Returns the indices of the 4n boundary
/// nodes counter-clockwise from the corner at angle -pi/4.
std::vector<unsigned> add_central_block(CrossSection& cs, int n, double a) {
  constexpr double mu = 0.5;    // circle share of the ring shape
  constexpr double beta = 0.8;  // size of the square share relative to the circle share
  const double rho = static_cast<double>(n) / (n + 2);
  const unsigned base = static_cast<unsigned>(cs.nodes.size());
  auto id = [&](int i, int j) { return base + static_cast<unsigned>(i + j * (n + 1)); };
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const int ring2 = std::max(std::abs(2 * i - n), std::abs(2 * j - n));  // = n s
      Eigen::Vector2d p = Eigen::Vector2d::Zero();
      if (ring2 > 0) {
        const double s = static_cast<double>(ring2) / n;
        const Eigen::Vector2d q(static_cast<double>(2 * i - n) / ring2,
                                static_cast<double>(2 * j - n) / ring2);
        const double theta = equiangular_angle(q);
        const Eigen::Vector2d c(std::cos(theta), std::sin(theta));
        p = rho * a * s * ((1.0 - mu) * beta * q + mu * c);
      }
      cs.nodes.push_back(p);
    }
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      cs.quads.push_back({id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});

  std::vector<unsigned> boundary;
  for (int j = 0; j < n; ++j) boundary.push_back(id(n, j));   // right, upward
  for (int i = n; i > 0; --i) boundary.push_back(id(i, n));   // top, leftward
  for (int j = n; j > 0; --j) boundary.push_back(id(0, j));   // left, downward
  for (int i = 0; i < n; ++i) boundary.push_back(id(i, 0));   // bottom, rightward
  return boundary;
}

/// Adds a ring of nodes on the circle of radius r (m), node k at angle
/// -pi/4 + 2 pi k / sectors (matching the block boundary order), and the quads
/// between `inner_ring` and it. Returns the new ring's node indices.
std::vector<unsigned> add_ring(CrossSection& cs, const std::vector<unsigned>& inner_ring, double r) {
  const int sectors = static_cast<int>(inner_ring.size());
  std::vector<unsigned> ring(static_cast<std::size_t>(sectors));
  for (int k = 0; k < sectors; ++k) {
    const double theta = -0.25 * kPi + 2.0 * kPi * k / sectors;
    ring[static_cast<std::size_t>(k)] = static_cast<unsigned>(cs.nodes.size());
    cs.nodes.emplace_back(r * std::cos(theta), r * std::sin(theta));
  }
  for (int k = 0; k < sectors; ++k) {
    const auto k0 = static_cast<std::size_t>(k);
    const auto k1 = static_cast<std::size_t>((k + 1) % sectors);
    // local x = radial outward, local y = counter-clockwise: positive orientation.
    cs.quads.push_back({inner_ring[k0], ring[k0], inner_ring[k1], ring[k1]});
  }
  return ring;
}

/// The cross-section: central block, the transition ring out to the needle
/// circle r = a, then annuli whose widths start near a and grow by `grading`
/// out to the sample radius R (the last ring exactly at R).
CrossSection build_cross_section(int sectors, double a, double R, double grading) {
  CrossSection cs;
  std::vector<unsigned> ring = add_central_block(cs, sectors / 4, a);
  ring = add_ring(cs, ring, a);
  const std::vector<double> widths = graded_divisions(R - a, a, grading, 1);
  double r = a;
  for (std::size_t m = 0; m < widths.size(); ++m) {
    r = (m + 1 == widths.size()) ? R : r + widths[m];
    ring = add_ring(cs, ring, r);
  }
  return cs;
}

}  // namespace

HexMesh build_layered_cylinder_mesh(const Scene& scene, const SlabMeshOptions& options) {
  validate(scene, options);
  const double a = scene.needle.radius_m;
  const double R = 0.5 * scene.sample.diameter_m;

  const CrossSection cs = build_cross_section(options.sectors, a, R, options.radial_grading);

  // Node planes, top (z = 0) to base; element layer e lies between planes e and e+1.
  std::vector<double> plane_z{0.0};
  std::vector<int> element_layer_material;
  // The element height at every layer top follows the skin and the needle: at
  // most t_skin / elements_through_skin and at most the needle radius, so a
  // thick first layer is graded from the surface (where the punch loads it)
  // instead of getting elements_through_skin slabs of its whole thickness.
  const double t_skin = scene.layers.front().thickness_m;
  const double skin_element_height_m = std::min(t_skin / options.elements_through_skin, a);
  double layer_top_z = 0.0;
  for (std::size_t l = 0; l < scene.layers.size(); ++l) {
    const double t = scene.layers[l].thickness_m;
    const bool uniform_skin = l == 0 && t_skin / options.elements_through_skin <= a;
    const std::vector<double> heights =
        uniform_skin ? geometric_intervals(t, options.elements_through_skin, 1.0)
                     : graded_divisions(t, skin_element_height_m, options.thickness_grading,
                                        l == 0 ? options.elements_through_skin : 1);
    double z = layer_top_z;
    for (std::size_t e = 0; e < heights.size(); ++e) {
      // The interface below the layer is placed exactly (no accumulated round-off).
      z = (e + 1 == heights.size()) ? -scene.layer_top_depth_m(l + 1) : z - heights[e];
      plane_z.push_back(z);
      element_layer_material.push_back(static_cast<int>(l));
    }
    layer_top_z = z;
  }

  HexMesh mesh;
  const auto n_plane_nodes = static_cast<unsigned>(cs.nodes.size());
  mesh.vertices.reserve(plane_z.size() * n_plane_nodes);
  for (double z : plane_z)
    for (const auto& p : cs.nodes) mesh.vertices.emplace_back(p.x(), p.y(), z);

  mesh.cells.reserve(element_layer_material.size() * cs.quads.size());
  mesh.material_id.reserve(mesh.cells.capacity());
  for (std::size_t e = 0; e < element_layer_material.size(); ++e) {
    // Local z points up (+z): the lower plane is the local bottom face.
    const unsigned lower = static_cast<unsigned>(e + 1) * n_plane_nodes;
    const unsigned upper = static_cast<unsigned>(e) * n_plane_nodes;
    for (const auto& q : cs.quads) {
      mesh.cells.push_back({lower + q[0], lower + q[1], lower + q[2], lower + q[3],
                            upper + q[0], upper + q[1], upper + q[2], upper + q[3]});
      mesh.material_id.push_back(element_layer_material[e]);
    }
  }
  return mesh;
}

}  // namespace puncture::meshing
