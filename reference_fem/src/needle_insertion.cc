// needle_insertion.cc: the needle-insertion problem on the layered slab (see
// needle_insertion.hpp): the 3D slab's triangulation, and run_needle_insertion,
// which dispatches on the geometry to the axisymmetric run
// (axisymmetric_insertion.cc) or the 3D run (slab_insertion_run.cc).
#include <puncture/fem/needle_insertion.hpp>

#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria.h>

#include <puncture/meshing/inclined_path_mesh.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "slab_insertion_run.hpp"

namespace puncture::fem {

using namespace dealii;

void build_slab_triangulation(const Scene& scene, const meshing::SlabMeshOptions& options,
                              int refinement, parallel::distributed::Triangulation<3>& tria) {
  meshing::HexMesh mesh = meshing::build_layered_cylinder_mesh(scene, options);
  if (scene.insertion.angle_deg != 0.0) meshing::incline_needle_path(mesh, meshing::inclined_path_of(scene));
  std::vector<Point<3>> vertices;
  vertices.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) vertices.emplace_back(v.x(), v.y(), v.z());
  std::vector<CellData<3>> cells(mesh.cells.size());
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    for (unsigned i = 0; i < 8; ++i) cells[c].vertices[i] = mesh.cells[c][i];
    cells[c].material_id = static_cast<types::material_id>(mesh.material_id[c]);
  }
  GridTools::consistently_order_cells(cells);
  tria.create_triangulation(vertices, cells, SubCellData());

  const double thickness = scene.total_thickness_m();
  const double tol = 1e-9 * std::max(thickness, scene.sample.diameter_m);
  for (const auto& cell : tria.active_cell_iterators())
    for (const auto& face : cell->face_iterators()) {
      if (!face->at_boundary()) continue;
      const double z = face->center()[2];
      if (z > -tol)
        face->set_boundary_id(slab_insertion::kTop);
      else if (z < -thickness + tol)
        face->set_boundary_id(slab_insertion::kBase);
      else {
        face->set_boundary_id(slab_insertion::kLateral);
        face->set_all_manifold_ids(1);
      }
    }
  tria.set_manifold(1, CylindricalManifold<3>(2));
  if (refinement > 0) tria.refine_global(refinement);
}

std::string resolved_geometry(const Scene& scene) {
  if (scene.fem.geometry != "auto") return scene.fem.geometry;
  return scene.needle.tip == "blunt" ? "3d" : "axisymmetric";
}

FemRunSummary run_needle_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm) {
  if (resolved_geometry(scene) == "axisymmetric") return run_axisymmetric_insertion(scene, options, comm);
  slab_insertion::SlabInsertionRun run(scene, options, comm);  // checks the scene; slab, solver, node sets
  return run.run();  // per load step: advance, detect puncture, open the hole, release, record; write
}

}  // namespace puncture::fem
