// comparison_tet_slab_mesh.cpp: the comparison mesh by scene.comparison.mesh.kind;
// see comparison_tet_slab_mesh.hpp.
#include "puncture/meshing/comparison_tet_slab_mesh.hpp"

#include <stdexcept>

#include "puncture/meshing/extruded_tet_slab_mesh.hpp"
#include "puncture/meshing/tet_slab_mesh.hpp"

namespace puncture::meshing {

TetMesh build_comparison_tet_mesh(const Scene& scene, ComparisonTetMeshReport* report) {
  const std::string& kind = scene.comparison.mesh.kind;
  ComparisonTetMeshReport r;
  r.kind = kind;
  TetMesh mesh;
  if (kind == "extruded") {
    ExtrudedSlabMeshReport e;
    mesh = build_extruded_tet_slab_mesh(scene, extruded_slab_mesh_options(scene), &e);
    r.description = "plan triangulation extruded through the layers: " + std::to_string(e.plan_nodes) +
                    " plan nodes x " + std::to_string(e.levels) + " levels";
    r.wall_time_s = e.wall_time_s, r.vertices = e.vertices, r.tetrahedra = e.tetrahedra, r.quality = e.quality;
  } else if (kind == "delaunay") {
    TetSlabMeshReport d;
    mesh = build_tet_slab_mesh(scene, tet_slab_mesh_options(scene), &d);
    r.description = "CGAL Mesh_3 Delaunay refinement";
    r.wall_time_s = d.wall_time_s, r.vertices = d.vertices, r.tetrahedra = d.tetrahedra, r.quality = d.quality;
  } else {
    throw std::invalid_argument("comparison mesh: unknown kind '" + kind + "' (known: extruded, delaunay)");
  }
  if (report) *report = r;
  return mesh;
}

}  // namespace puncture::meshing
