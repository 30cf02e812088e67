// tet_slab_mesh.cpp: CGAL Mesh_3 tetrahedral mesh of the layered slab; see
// tet_slab_mesh.hpp. Kept to this one translation unit (CGAL compiles slowly).
#include "puncture/meshing/tet_slab_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iterator>
#include <map>
#include <stdexcept>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_domain_with_polyline_features_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/exude_mesh_3.h>
#include <CGAL/make_mesh_3.h>

namespace puncture::meshing {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using LabeledDomain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Domain = CGAL::Mesh_domain_with_polyline_features_3<LabeledDomain>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

constexpr double kPi = 3.14159265358979323846;

/// Geometry in millimetres inside CGAL (well-scaled numbers for its tolerances).
struct SlabGeometry {
  double radius_mm = 0.0;
  double needle_mm = 0.0;
  std::vector<double> interface_z_mm;  ///< 0, -t0, -(t0 + t1), ..., -total: n + 1 planes
  int layers() const { return static_cast<int>(interface_z_mm.size()) - 1; }
};

/// Subdomain label: 0 outside, 1 + k annulus of layer k, 1 + n + k needle column of layer k.
int label_of(const SlabGeometry& g, const Point& p) {
  const double r = std::hypot(p.x(), p.y());
  const double z = p.z();
  if (r > g.radius_mm || z > g.interface_z_mm.front() || z < g.interface_z_mm.back()) return 0;
  int k = 0;
  while (k + 1 < g.layers() && z < g.interface_z_mm[static_cast<std::size_t>(k) + 1]) ++k;
  return r <= g.needle_mm ? 1 + g.layers() + k : 1 + k;
}

struct SizeField {
  using FT = Kernel::FT;
  using Index = Domain::Index;
  double needle_mm, axis_mm, far_mm, grading;
  double size(const Point& p) const {
    const double r = std::hypot(p.x(), p.y());
    return std::min(far_mm, axis_mm + grading * std::max(0.0, r - needle_mm));
  }
  FT operator()(const Point& p, const int, const Index&) const { return size(p); }
};

struct DistanceField {
  using FT = Kernel::FT;
  using Index = Domain::Index;
  SizeField size;
  double radius_mm;
  FT operator()(const Point& p, const int, const Index&) const {
    const double r = std::hypot(p.x(), p.y());
    // The needle column's side: chords of at most 0.63 a (10 or more facets around).
    if (r < 2.0 * size.needle_mm) return std::min(0.1 * size.size(p), 0.05 * size.needle_mm);
    return std::min(0.1 * size.size(p), 0.005 * radius_mm);
  }
};

int circle_segments(double radius, double max_segment) {
  return std::max(16, static_cast<int>(std::ceil(2.0 * kPi * radius / max_segment)));
}

std::vector<Point> circle(double radius, double z, double max_segment) {
  const int n = circle_segments(radius, max_segment);
  std::vector<Point> c;
  c.reserve(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * kPi * i / n;
    c.emplace_back(radius * std::cos(t), radius * std::sin(t), z);
  }
  c.push_back(c.front());  // closed polyline
  return c;
}

/// CGAL's sliver exudation (same criterion and bound as make_mesh_3's
/// p::exude(): maximise the smallest dihedral angle) run until it cannot
/// improve any more. make_mesh_3's own exudation stops at a wall-clock limit,
/// by default the refinement's wall time, so how many slivers it treated, and
/// hence the mesh, depended on the machine's load. Without the limit the
/// exuder's work depends on the triangulation alone: its queues order cells by
/// quality and break ties by insertion order and by the creation time stamps
/// of Mesh_3's cells and vertices, not by address.
void exude_slivers_to_completion(Complex& c3t3) {
  namespace p = CGAL::parameters;
  const CGAL::Mesh_optimization_return_code code = CGAL::exude_mesh_3(c3t3, p::time_limit = 0.0, p::sliver_bound = 0.0);
  if (code == CGAL::TIME_LIMIT_REACHED)
    throw std::logic_error("build_tet_slab_mesh: sliver exudation stopped at a time limit (none was set)");
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("build_tet_slab_mesh: " + what);
}

}  // namespace

TetSlabMeshOptions tet_slab_mesh_options(const Scene& scene) {
  TetSlabMeshOptions o;
  o.size_at_axis_m = scene.comparison.mesh.size_at_axis_m;
  o.size_far_m = scene.comparison.mesh.size_far_m;
  o.grading = scene.comparison.mesh.grading;
  return o;
}

namespace {

/// Mesh_3's refinement of the labelled slab (features on the interface and
/// rim circles, sizes graded from the axis), sliver exudation optional.
Complex refine_slab(const SlabGeometry& g, const TetSlabMeshOptions& options) {
  constexpr double kMmPerM = 1e3;
  CGAL::Random random(options.random_seed);
  CGAL::get_default_random() = CGAL::Random(options.random_seed);
  const double margin = 1.0;
  std::function<int(const Point&)> labels = [g](const Point& p) { return label_of(g, p); };
  Domain domain(labels,
                Kernel::Iso_cuboid_3(-g.radius_mm - margin, -g.radius_mm - margin, g.interface_z_mm.back() - margin,
                                     g.radius_mm + margin, g.radius_mm + margin, margin),
                1e-6, CGAL::Null_subdomain_index(), &random);

  const SizeField size{g.needle_mm, options.size_at_axis_m * kMmPerM, options.size_far_m * kMmPerM, options.grading};
  std::vector<std::vector<Point>> features;
  for (double z : g.interface_z_mm) {
    features.push_back(circle(g.needle_mm, z, 0.25 * size.axis_mm));
    features.push_back(circle(g.radius_mm, z, 0.25 * size.far_mm));
  }
  domain.add_features(features.begin(), features.end());

  const DistanceField distance{size, g.radius_mm};
  namespace p = CGAL::parameters;
  const Criteria criteria(p::edge_size = size, p::facet_angle = 25.0, p::facet_size = size,
                          p::facet_distance = distance, p::cell_radius_edge_ratio = 3.0, p::cell_size = size);
  Complex c3t3 =
      CGAL::make_mesh_3<Complex>(domain, criteria, p::no_perturb(), p::no_exude(), p::no_odt(), p::no_lloyd());
  if (c3t3.number_of_cells_in_complex() == 0) throw std::runtime_error("build_tet_slab_mesh: CGAL returned no cells");
  return c3t3;
}

/// The tetrahedra of the triangulation that make the slab: the finite cells
/// whose centroid lies in the slab and whose vertices do not all lie on one
/// boundary surface (the side r = R or one interface plane), labelled by
/// their centroid. Mesh_3 labels cells by their circumcentre, and a flat cell
/// spanning the thin skin can have its circumcentre outside the slab: the
/// complex alone would leave a hole through the skin. Cells whose vertices
/// all lie on one boundary surface are flat slivers on that surface (of the
/// convex hull or of the complex).
TetMesh slab_tetrahedra(const Complex& c3t3, const SlabGeometry& g, const TetSlabMeshOptions& options) {
  constexpr double kMmPerM = 1e3;
  const SizeField size{g.needle_mm, options.size_at_axis_m * kMmPerM, options.size_far_m * kMmPerM, options.grading};
  TetMesh mesh;
  const Triangulation& tr = c3t3.triangulation();
  std::map<Triangulation::Vertex_handle, int> index;
  std::vector<Eigen::Vector3d> points;
  const int n_layers = g.layers();
  const double tolerance_mm = 1e-6 * g.radius_mm;
  const double on_surface_mm = 1e-4 * options.size_at_axis_m * kMmPerM;
  // Rim vertices lie on the feature polyline, inside the circle by up to the
  // sagitta of its segments.
  const double rim_segment_mm = 2.0 * kPi * g.radius_mm / circle_segments(g.radius_mm, 0.25 * size.far_mm);
  const double on_side_mm = 1.5 * rim_segment_mm * rim_segment_mm / (8.0 * g.radius_mm) + on_surface_mm;
  for (auto c = tr.finite_cells_begin(); c != tr.finite_cells_end(); ++c) {
    Eigen::Vector3d q[4];
    bool outside = false, all_on_side = true;
    std::vector<int> planes_shared;  // interface planes every vertex lies on
    for (int i = 0; i < 4; ++i) {
      const Point& v = c->vertex(i)->point().point();
      q[i] = Eigen::Vector3d(v.x(), v.y(), v.z());
      const double r = std::hypot(v.x(), v.y());
      outside = outside || r > g.radius_mm + tolerance_mm || v.z() > g.interface_z_mm.front() + tolerance_mm ||
                v.z() < g.interface_z_mm.back() - tolerance_mm;
      all_on_side = all_on_side && std::abs(r - g.radius_mm) < on_side_mm;
      std::vector<int> planes;
      for (int k = 0; k <= n_layers; ++k)
        if (std::abs(v.z() - g.interface_z_mm[static_cast<std::size_t>(k)]) < on_surface_mm) planes.push_back(k);
      if (i == 0) {
        planes_shared = planes;
      } else {
        std::vector<int> common;
        std::set_intersection(planes_shared.begin(), planes_shared.end(), planes.begin(), planes.end(),
                              std::back_inserter(common));
        planes_shared = common;
      }
    }
    if (outside) continue;  // a vertex outside the slab (none expected)
    if (all_on_side || !planes_shared.empty()) continue;
    const Eigen::Vector3d centroid = 0.25 * (q[0] + q[1] + q[2] + q[3]);
    const int label = label_of(g, Point(centroid.x(), centroid.y(), centroid.z()));
    if (label == 0) continue;
    double longest = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (q[i] - q[j]).norm());
    const double volume = tet_signed_volume(q[0], q[1], q[2], q[3]);
    if (std::abs(volume) < 1e-8 * longest * longest * longest) continue;  // flat cell on a boundary plane
    Eigen::Vector4i tet;
    for (int i = 0; i < 4; ++i) {
      auto [it, inserted] = index.emplace(c->vertex(i), static_cast<int>(points.size()));
      if (inserted) points.push_back(q[i] / kMmPerM);
      tet[i] = it->second;
    }
    if (volume < 0.0) std::swap(tet[2], tet[3]);
    mesh.tets.push_back(tet);
    mesh.layer.push_back((label - 1) % n_layers);
    mesh.needle_column.push_back(label > n_layers ? 1 : 0);
  }
  mesh.points_m.resize(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) mesh.points_m.col(static_cast<Eigen::Index>(i)) = points[i];
  check_tet_mesh(mesh, n_layers);
  return mesh;
}

}  // namespace

TetMesh build_tet_slab_mesh(const Scene& scene, const TetSlabMeshOptions& options,
                                        TetSlabMeshReport* report) {
  require(!scene.layers.empty(), "the scene has no layers");
  require(options.size_at_axis_m > 0.0, "options.size_at_axis_m must be > 0");
  require(options.size_far_m >= options.size_at_axis_m, "options.size_far_m must be >= size_at_axis_m");
  require(options.grading >= 0.0, "options.grading must be >= 0");
  const double radius_m = 0.5 * scene.sample.diameter_m;
  require(radius_m > 0.0, "sample.diameter_m must be > 0");
  require(scene.needle.radius_m > 0.0 && scene.needle.radius_m < radius_m, "needle.radius_m must be in (0, R)");

  const auto start = std::chrono::steady_clock::now();
  constexpr double kMmPerM = 1e3;
  SlabGeometry g;
  g.radius_mm = radius_m * kMmPerM;
  g.needle_mm = scene.needle.radius_m * kMmPerM;
  g.interface_z_mm.push_back(0.0);
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    require(scene.layers[k].thickness_m > 0.0, "layers[" + std::to_string(k) + "].thickness_m must be > 0");
    g.interface_z_mm.push_back(-(scene.layer_top_depth_m(k) + scene.layers[k].thickness_m) * kMmPerM);
  }

  Complex c3t3 = refine_slab(g, options);
  const auto refined = std::chrono::steady_clock::now();
  if (options.exude_slivers) exude_slivers_to_completion(c3t3);
  const auto exuded = std::chrono::steady_clock::now();
  TetMesh mesh = slab_tetrahedra(c3t3, g, options);

  if (report) {
    report->wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report->refinement_time_s = std::chrono::duration<double>(refined - start).count();
    report->exudation_time_s = std::chrono::duration<double>(exuded - refined).count();
    report->vertices = mesh.node_count();
    report->tetrahedra = mesh.tet_count();
    report->quality = measure_tet_quality(mesh);
  }
  return mesh;
}

}  // namespace puncture::meshing
