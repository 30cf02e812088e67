#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <puncture/meshing/graded_divisions.hpp>

namespace puncture::meshing {
namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw std::invalid_argument("axisymmetric slab mesh: " + field + " " + what);
}

/// Sizes covering `length` that start at `first` and grow by `ratio` per
/// element up to `largest`; the rest is split into equal elements no larger
/// than `largest`.
std::vector<double> growing_sizes(double length, double first, double ratio, double largest) {
  std::vector<double> sizes;
  double sum = 0.0, s = std::min(first, largest);
  while (s < largest && sum + s < length) {
    sizes.push_back(s);
    sum += s;
    s = std::min(s * ratio, largest);
  }
  const double rest = length - sum;
  if (rest > 1e-12 * length) {
    const int n = std::max(1, static_cast<int>(std::ceil(rest / largest - 1e-9)));
    sizes.insert(sizes.end(), static_cast<std::size_t>(n), rest / n);
  }
  return sizes;
}

/// Appends the lines start - cumulative sizes (downward) or start + sizes.
void append_lines(std::vector<double>& lines, const std::vector<double>& sizes, double sign) {
  double x = lines.back();
  for (double s : sizes) {
    x += sign * s;
    lines.push_back(x);
  }
}

/// Inserts 2^refinement - 1 equally spaced lines into every interval.
std::vector<double> refine_lines(const std::vector<double>& lines, int refinement) {
  const int parts = 1 << refinement;
  std::vector<double> out{lines.front()};
  for (std::size_t i = 1; i < lines.size(); ++i)
    for (int p = 1; p <= parts; ++p)
      out.push_back(p == parts ? lines[i] : lines[i - 1] + (lines[i] - lines[i - 1]) * p / parts);
  return out;
}

std::size_t index_of(const std::vector<double>& lines, double x) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < lines.size(); ++i)
    if (std::abs(lines[i] - x) < std::abs(lines[best] - x)) best = i;
  return best;
}

void check_inputs(const Scene& scene, int refinement) {
  if (scene.layers.empty()) fail("layers", "must not be empty");
  for (std::size_t i = 0; i < scene.layers.size(); ++i)
    if (!(scene.layers[i].thickness_m > 0.0))
      fail("layers[" + std::to_string(i) + "].thickness_m", "must be > 0");
  const double a = scene.needle.radius_m;
  const double R_s = 0.5 * scene.sample.diameter_m;
  if (!(a > 0.0) || !(a < 0.5 * R_s)) fail("needle.radius_m", "must lie in (0, sample radius / 2)");
  const FemMeshSettings& ms = scene.fem.mesh;
  if (ms.elements_per_needle_radius < 2) fail("fem.mesh.elements_per_needle_radius", "must be >= 2");
  if (ms.min_elements_per_layer < 1) fail("fem.mesh.min_elements_per_layer", "must be >= 1");
  if (!(ms.radial_growth >= 1.0)) fail("fem.mesh.radial_growth", "must be >= 1");
  if (!(ms.path_element_size_mm > 0.0)) fail("fem.mesh.path_element_size_mm", "must be > 0");
  if (refinement < 0 || refinement > 4) fail("refinement", "must lie in [0, 4]");
}

/// Radial lines: the core [0, r_c] and the needle wall [r_c, a] in elements of
/// about h_tip, then graded by `growth` to the sample radius R_s.
std::vector<double> radial_lines(double r_c, double a, double R_s, double h_tip, double growth) {
  std::vector<double> R{0.0};
  const int n_core = std::max(2, static_cast<int>(std::lround(r_c / h_tip)));
  append_lines(R, std::vector<double>(n_core, r_c / n_core), +1.0);
  if (a - r_c > 1e-3 * a) {
    const int n_wall = std::max(2, static_cast<int>(std::lround((a - r_c) / h_tip)));
    append_lines(R, std::vector<double>(n_wall, (a - r_c) / n_wall), +1.0);
  }
  append_lines(R, graded_divisions(R_s - a, h_tip, growth), +1.0);
  return R;
}

/// Element sizes through layer i along the needle path: h_tip at its top,
/// growing by 1.2 up to min(path size, thickness / min_elements_per_layer).
/// A property of the layer alone, so the path's lines above any depth are the
/// same whatever the target depth.
std::vector<double> path_sizes(const Scene& scene, std::size_t i, double h_tip) {
  const FemMeshSettings& ms = scene.fem.mesh;
  const double t = scene.layers[i].thickness_m;
  const double largest = std::min(ms.path_element_size_mm * 1e-3, t / ms.min_elements_per_layer);
  return growing_sizes(t, std::min(h_tip, largest), 1.2, largest);
}

/// Axial lines, layer by layer (Z decreasing from 0; see the header's layout):
/// each layer's path sizes down to the path depth D_p (a line of that
/// pattern), then sizes graded toward the base.
std::vector<double> axial_lines(const Scene& scene, double D_p, double h_tip) {
  const FemMeshSettings& ms = scene.fem.mesh;
  std::vector<double> Z{0.0};
  double below_path_size = h_tip;
  for (std::size_t i = 0; i < scene.layers.size(); ++i) {
    const double top = scene.layer_top_depth_m(i), t = scene.layers[i].thickness_m, bottom = top + t;
    std::vector<double> sizes;
    if (top < D_p - 1e-12) {
      double depth = top;
      for (double s : path_sizes(scene, i, h_tip)) {
        if (depth >= D_p - 1e-12) break;
        // The element that reaches the path depth ends on it (stretched up
        // to 1.5 of its size rather than leaving a sliver above it).
        if (D_p - depth < 1.5 * s) s = D_p - depth;
        sizes.push_back(s);
        depth += s;
      }
      const double below_part = bottom - depth;
      if (below_part > 1e-12) {
        // The crack line ends inside this layer: sizes graded below its end;
        // both parts keep the layer's minimum count.
        const int n_min_below = std::max(1, ms.min_elements_per_layer - static_cast<int>(sizes.size()));
        const auto below = graded_divisions(below_part, sizes.back(), ms.radial_growth, n_min_below);
        sizes.insert(sizes.end(), below.begin(), below.end());
      }
    } else {
      sizes = graded_divisions(t, below_path_size, ms.radial_growth, ms.min_elements_per_layer);
    }
    below_path_size = sizes.back();
    append_lines(Z, sizes, -1.0);
    Z.back() = -bottom;  // exact interface
  }
  return Z;
}

/// Per layer: the elements through its thickness and the largest one on the path.
void record_path_statistics(const Scene& scene, AxisymmetricSlabMesh& mesh) {
  const std::vector<double>& Z = mesh.axial_lines_m;
  const double D_p = mesh.path_depth_m;
  for (std::size_t i = 0; i < scene.layers.size(); ++i) {
    const double top = -scene.layer_top_depth_m(i), bottom = top - scene.layers[i].thickness_m;
    int n = 0;
    double largest = 0.0;
    for (std::size_t j = 0; j + 1 < Z.size(); ++j)
      if (Z[j] <= top + 1e-12 && Z[j + 1] >= bottom - 1e-12) {
        ++n;
        if (-Z[j + 1] <= D_p + 1e-12) largest = std::max(largest, Z[j] - Z[j + 1]);
      }
    mesh.elements_through_layer.push_back(n);
    mesh.largest_path_element_m.push_back(largest);
  }
}

/// The vertices of the tensor-product grid: (k, j) at (R[k], Z[j]), plus for a
/// blunt punch an outer-side copy of each crack-line vertex above the path depth.
struct GridVertices {
  std::size_t nR = 0;   ///< radial lines
  std::size_t k_c = 0;  ///< radial line of the crack
  std::size_t j_p = 0;  ///< axial line of the path depth
  bool open_channel = false;
  std::vector<Eigen::Vector2d> points;
  std::vector<unsigned> outer_copy;                     ///< per axial line above j_p (blunt)
  std::vector<std::pair<unsigned, unsigned>> pairs;     ///< (core side, outer side) of the crack
  unsigned grid(std::size_t k, std::size_t j) const { return static_cast<unsigned>(j * nR + k); }
  /// The vertex a cell on the outer (R >= r_c) or core side uses at (k, j).
  unsigned vertex(std::size_t k, std::size_t j, bool outer_side) const {
    return (!open_channel && outer_side && k == k_c && j < j_p) ? outer_copy[j] : grid(k, j);
  }
};

GridVertices grid_vertices(const std::vector<double>& R, const std::vector<double>& Z, std::size_t k_c,
                           std::size_t j_p, bool open_channel) {
  GridVertices g;
  g.nR = R.size();
  g.k_c = k_c;
  g.j_p = j_p;
  g.open_channel = open_channel;
  g.points.reserve(R.size() * Z.size() + j_p);
  for (std::size_t j = 0; j < Z.size(); ++j)
    for (std::size_t k = 0; k < R.size(); ++k) g.points.emplace_back(R[k], Z[j]);
  g.outer_copy.assign(Z.size(), 0);
  if (!open_channel)
    for (std::size_t j = 0; j < j_p; ++j) {
      g.outer_copy[j] = static_cast<unsigned>(g.points.size());
      g.points.emplace_back(R[k_c], Z[j]);
      g.pairs.emplace_back(g.grid(k_c, j), g.outer_copy[j]);
    }
  return g;
}

/// Cells row by row, with the layer of their centre; none inside the open channel.
std::vector<std::array<unsigned, 4>> grid_cells(const Scene& scene, const std::vector<double>& Z,
                                                const GridVertices& g, std::vector<int>& material_id) {
  std::vector<std::array<unsigned, 4>> cells;
  for (std::size_t j = 0; j + 1 < Z.size(); ++j) {
    const double zc = 0.5 * (Z[j] + Z[j + 1]);
    int layer = static_cast<int>(scene.layers.size()) - 1;
    for (std::size_t i = 0; i < scene.layers.size(); ++i)
      if (-zc < scene.layer_top_depth_m(i) + scene.layers[i].thickness_m) {
        layer = static_cast<int>(i);
        break;
      }
    for (std::size_t k = 0; k + 1 < g.nR; ++k) {
      const bool outer_side = k >= g.k_c;
      if (g.open_channel && !outer_side && j < g.j_p) continue;
      cells.push_back({g.vertex(k, j + 1, outer_side), g.vertex(k + 1, j + 1, outer_side),
                       g.vertex(k, j, outer_side), g.vertex(k + 1, j, outer_side)});
      material_id.push_back(layer);
    }
  }
  return cells;
}

/// Keeps only the vertices the cells use (the channel's interior has none),
/// numbered in the order the cells first use them; the crack pairs and faces follow.
void keep_used_vertices(const GridVertices& g, std::vector<std::array<unsigned, 4>> cells,
                        AxisymmetricSlabMesh& mesh) {
  std::vector<long> new_index(g.points.size(), -1);
  for (auto& c : cells)
    for (unsigned& v : c) {
      if (new_index[v] < 0) {
        new_index[v] = static_cast<long>(mesh.vertices.size());
        mesh.vertices.push_back(g.points[v]);
      }
      v = static_cast<unsigned>(new_index[v]);
    }
  mesh.cells = std::move(cells);
  for (const auto& [c, o] : g.pairs) mesh.crack_vertex_pairs.emplace_back(new_index[c], new_index[o]);
  if (g.open_channel)
    for (std::size_t j = 0; j < g.j_p; ++j)
      mesh.crack_face_vertices.push_back(static_cast<unsigned>(new_index[g.grid(g.k_c, j)]));
}

}  // namespace

double crack_radius_for_tip(const Needle& needle) {
  if (needle.tip == "bevel") return 2.0 * needle.radius_m / kPi;
  if (needle.tip == "hollow") return needle.inner_radius_m;
  return needle.radius_m;
}

double crack_path_depth(const Scene& scene) {
  // The path runs through the whole slab whatever the target depth, to one
  // tip element above the base. A path that stopped below the target would
  // mesh the tissue under it coarser and without the channel, and the force
  // would depend on where the insertion stops (1.4 % of the peak between the
  // default slab to 20 mm and to 30 mm, results/fem_reproducibility).
  const double h_tip = scene.needle.radius_m / std::max(2, scene.fem.mesh.elements_per_needle_radius);
  return scene.total_thickness_m() - h_tip;
}

AxisymmetricSlabMesh build_axisymmetric_slab_mesh(const Scene& scene, int refinement) {
  check_inputs(scene, refinement);
  const double a = scene.needle.radius_m;
  const FemMeshSettings& ms = scene.fem.mesh;
  AxisymmetricSlabMesh mesh;
  const double r_c = crack_radius_for_tip(scene.needle);
  if (!(r_c > 0.0 && r_c <= a)) fail("needle.inner_radius_m", "must lie in (0, needle radius]");
  const double h_tip = a / ms.elements_per_needle_radius;
  const double D_p = crack_path_depth(scene);
  if (!(D_p > 0.0)) fail("layers", "leave no room for the needle path");
  if (scene.insertion.target_depth_m > D_p) fail("insertion.target_depth_m", "lies below the needle path (within a tip element of the base)");
  mesh.crack_radius_m = r_c;
  mesh.path_depth_m = D_p;
  mesh.tip_element_size_m = h_tip / (1 << refinement);
  mesh.open_channel = scene.needle.tip == "bevel" || scene.needle.tip == "hollow";

  const double R_s = 0.5 * scene.sample.diameter_m;
  mesh.radial_lines_m = refine_lines(radial_lines(r_c, a, R_s, h_tip, ms.radial_growth), refinement);
  mesh.axial_lines_m = refine_lines(axial_lines(scene, D_p, h_tip), refinement);
  record_path_statistics(scene, mesh);

  const std::vector<double>& R = mesh.radial_lines_m;
  const std::vector<double>& Z = mesh.axial_lines_m;
  const GridVertices grid = grid_vertices(R, Z, index_of(R, r_c), index_of(Z, -D_p), mesh.open_channel);
  keep_used_vertices(grid, grid_cells(scene, Z, grid, mesh.material_id), mesh);
  return mesh;
}

}  // namespace puncture::meshing
