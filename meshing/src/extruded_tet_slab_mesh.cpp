// extruded_tet_slab_mesh.cpp: plan triangulation of the disc extruded through
// the layers; see extruded_tet_slab_mesh.hpp.
#include "puncture/meshing/extruded_tet_slab_mesh.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "puncture/meshing/graded_divisions.hpp"

namespace puncture::meshing {

namespace {

constexpr double kPi = 3.14159265358979323846;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("build_extruded_tet_slab_mesh: " + what);
}

/// Plan triangulation of the disc: node positions (x, y) and triangles.
struct PlanMesh {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::uint8_t> inside_needle;  ///< per triangle: every node at r <= a
};

/// Ring radii (m): inside the needle radius evenly, then graded, last at R.
std::vector<double> ring_radii(double needle_m, double radius_m, const ExtrudedSlabMeshOptions& o) {
  std::vector<double> radii;
  const int inner = std::max(1, static_cast<int>(std::ceil(needle_m / o.size_at_axis_m - 1e-9)));
  for (int i = 1; i <= inner; ++i) radii.push_back(needle_m * i / inner);
  auto size = [&](double r) { return std::min(o.size_far_m, o.size_at_axis_m + o.grading * (r - needle_m)); };
  std::vector<double> outer;
  double r = needle_m;
  while (r + 0.5 * size(r) < radius_m) {
    r += size(r);
    outer.push_back(r);
  }
  if (outer.empty()) outer.push_back(radius_m);
  const double stretch = (radius_m - needle_m) / (outer.back() - needle_m);
  for (double q : outer) radii.push_back(needle_m + (q - needle_m) * stretch);
  radii.back() = radius_m;
  return radii;
}

int ring_node_count(double r, double h) {
  return std::max(12, static_cast<int>(std::lround(2.0 * kPi * r / h)));
}

/// Triangles between two rings (first node indices a0, b0; counts na, nb;
/// angular offsets in units of a node spacing), counterclockwise.
void zip_rings(int a0, int na, double offset_a, int b0, int nb, double offset_b, PlanMesh& plan) {
  auto angle = [](int i, int n, double offset) { return 2.0 * kPi * (i + offset) / n; };
  int i = 0, j = 0;
  while (i < na || j < nb) {
    const bool advance_a = j >= nb || (i < na && angle(i + 1, na, offset_a) < angle(j + 1, nb, offset_b));
    if (advance_a) {
      plan.triangles.push_back({a0 + i % na, a0 + (i + 1) % na, b0 + j % nb});
      ++i;
    } else {
      plan.triangles.push_back({a0 + i % na, b0 + (j + 1) % nb, b0 + j % nb});
      ++j;
    }
  }
}

PlanMesh plan_mesh(double needle_m, double radius_m, const ExtrudedSlabMeshOptions& o) {
  const std::vector<double> radii = ring_radii(needle_m, radius_m, o);
  PlanMesh plan;
  plan.nodes.emplace_back(0.0, 0.0);
  int previous_first = 0, previous_count = 1;
  double previous_offset = 0.0;
  int inner_rings = 0;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i];
    if (r <= needle_m * (1.0 + 1e-12)) ++inner_rings;
    const double h = r <= needle_m ? o.size_at_axis_m : std::min(o.size_far_m, o.size_at_axis_m + o.grading * (r - needle_m));
    const int n = ring_node_count(r, h);
    const double offset = (i % 2 == 0) ? 0.0 : 0.5;
    const int first = static_cast<int>(plan.nodes.size());
    for (int k = 0; k < n; ++k) {
      const double t = 2.0 * kPi * (k + offset) / n;
      plan.nodes.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    if (i == 0) {
      for (int k = 0; k < n; ++k) plan.triangles.push_back({0, first + k, first + (k + 1) % n});
    } else {
      zip_rings(previous_first, previous_count, previous_offset, first, n, offset, plan);
    }
    plan.inside_needle.resize(plan.triangles.size(), static_cast<std::uint8_t>(inner_rings == static_cast<int>(i) + 1));
    previous_first = first, previous_count = n, previous_offset = offset;
  }
  return plan;
}

/// Node levels (z, m, descending from 0) and the layer below each level.
struct Levels {
  std::vector<double> z_m;
  std::vector<int> layer_below;  ///< layer of the elements between level i and i + 1
};

void append_part(double top_m, double bottom_m, int layer, bool fine, const ExtrudedSlabMeshOptions& o,
                 Levels& levels) {
  const double length = bottom_m - top_m;  // depths, > 0
  std::vector<double> heights;
  if (fine) {
    const int n = std::max(o.min_elements_per_layer, static_cast<int>(std::ceil(length / o.size_at_axis_m - 1e-9)));
    heights.assign(static_cast<std::size_t>(n), length / n);
  } else {
    heights = graded_divisions(length, o.size_at_axis_m, 1.0 + o.grading, o.min_elements_per_layer);
  }
  double depth = top_m;
  for (std::size_t i = 0; i < heights.size(); ++i) {
    depth = i + 1 == heights.size() ? bottom_m : depth + heights[i];
    levels.z_m.push_back(-depth);
    levels.layer_below.push_back(layer);
  }
}

Levels levels_of(const Scene& scene, const ExtrudedSlabMeshOptions& o) {
  Levels levels;
  levels.z_m.push_back(0.0);
  const double fine_to = o.deepest_tip_depth_m + 2.0 * o.size_at_axis_m;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const double top = scene.layer_top_depth_m(k);
    const double bottom = top + scene.layers[k].thickness_m;
    const int layer = static_cast<int>(k);
    // A split closer than half an element to an interface is not made.
    if (fine_to > top + 0.5 * o.size_at_axis_m && fine_to < bottom - 0.5 * o.size_at_axis_m) {
      append_part(top, fine_to, layer, true, o, levels);
      append_part(fine_to, bottom, layer, false, o, levels);
    } else {
      append_part(top, bottom, layer, fine_to >= bottom - 0.5 * o.size_at_axis_m, o, levels);
    }
  }
  return levels;
}

/// The prisms between neighbouring levels, three tetrahedra each.
TetMesh extrude(const PlanMesh& plan, const Levels& levels) {
  TetMesh mesh;
  const int np = static_cast<int>(plan.nodes.size());
  const int nl = static_cast<int>(levels.z_m.size());
  mesh.points_m.resize(3, static_cast<Eigen::Index>(np) * nl);
  for (int l = 0; l < nl; ++l)
    for (int i = 0; i < np; ++i)
      mesh.points_m.col(static_cast<Eigen::Index>(l) * np + i) =
          Eigen::Vector3d(plan.nodes[static_cast<std::size_t>(i)].x(), plan.nodes[static_cast<std::size_t>(i)].y(),
                          levels.z_m[static_cast<std::size_t>(l)]);
  for (int l = 0; l + 1 < nl; ++l) {
    for (std::size_t t = 0; t < plan.triangles.size(); ++t) {
      std::array<int, 3> v = plan.triangles[t];
      std::sort(v.begin(), v.end());
      const int b0 = l * np + v[0], b1 = l * np + v[1], b2 = l * np + v[2];
      const int t0 = b0 + np, t1 = b1 + np, t2 = b2 + np;
      for (Eigen::Vector4i tet : {Eigen::Vector4i(b0, b1, b2, t2), Eigen::Vector4i(b0, b1, t1, t2),
                                  Eigen::Vector4i(b0, t0, t1, t2)}) {
        const double volume = tet_signed_volume(mesh.points_m.col(tet[0]), mesh.points_m.col(tet[1]),
                                                            mesh.points_m.col(tet[2]), mesh.points_m.col(tet[3]));
        if (volume < 0.0) std::swap(tet[2], tet[3]);
        mesh.tets.push_back(tet);
        mesh.layer.push_back(levels.layer_below[static_cast<std::size_t>(l)]);
        mesh.needle_column.push_back(plan.inside_needle[t]);
      }
    }
  }
  return mesh;
}

}  // namespace

ExtrudedSlabMeshOptions extruded_slab_mesh_options(const Scene& scene) {
  ExtrudedSlabMeshOptions o;
  o.size_at_axis_m = scene.comparison.mesh.size_at_axis_m;
  o.size_far_m = scene.comparison.mesh.size_far_m;
  o.grading = scene.comparison.mesh.grading;
  o.deepest_tip_depth_m = scene.insertion.target_depth_m;
  return o;
}

TetMesh build_extruded_tet_slab_mesh(const Scene& scene, const ExtrudedSlabMeshOptions& options,
                                                 ExtrudedSlabMeshReport* report) {
  require(!scene.layers.empty(), "the scene has no layers");
  require(options.size_at_axis_m > 0.0, "options.size_at_axis_m must be > 0");
  require(options.size_far_m >= options.size_at_axis_m, "options.size_far_m must be >= size_at_axis_m");
  require(options.grading >= 0.0, "options.grading must be >= 0");
  require(options.min_elements_per_layer >= 1, "options.min_elements_per_layer must be >= 1");
  require(std::isfinite(options.deepest_tip_depth_m), "options.deepest_tip_depth_m must be finite");
  const double radius_m = 0.5 * scene.sample.diameter_m;
  require(radius_m > 0.0, "sample.diameter_m must be > 0");
  require(scene.needle.radius_m > 0.0 && scene.needle.radius_m < radius_m, "needle.radius_m must be in (0, R)");
  for (std::size_t k = 0; k < scene.layers.size(); ++k)
    require(scene.layers[k].thickness_m > 0.0, "layers[" + std::to_string(k) + "].thickness_m must be > 0");

  const auto start = std::chrono::steady_clock::now();
  const PlanMesh plan = plan_mesh(scene.needle.radius_m, radius_m, options);
  const Levels levels = levels_of(scene, options);
  TetMesh mesh = extrude(plan, levels);
  check_tet_mesh(mesh, static_cast<int>(scene.layers.size()));
  if (report) {
    report->wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report->plan_nodes = static_cast<int>(plan.nodes.size());
    report->plan_triangles = static_cast<int>(plan.triangles.size());
    report->levels = static_cast<int>(levels.z_m.size());
    report->vertices = mesh.node_count();
    report->tetrahedra = mesh.tet_count();
    report->quality = measure_tet_quality(mesh);
  }
  return mesh;
}

}  // namespace puncture::meshing
