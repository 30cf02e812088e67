// layer_view_geometry.hpp: the triangle meshes the view draws for one layer,
// evaluated from the layer's SH surface, and their deformation by the force
// mesh (VTK-free, so it is unit-tested).
//
// The view shows the slab cut open along the plane y = 0 (the needle's plane):
// the back half (y >= 0) of each layer's top face and side wall, plus the
// cross-section ("cap") in the plane y = 0, so the three layers and the needle
// inside them are visible at once.
// build_layer_view_mesh(surface, bottom_z, options):
//   top face: vertices at lateral radii r_i graded from `first_ring_m` by the
//   factor `ring_growth` up to the rim, over azimuths 0..pi (`half_azimuths`
//   segments), each placed with LayerSurface::position(top-face direction),
//   i.e. the SH surface at the scene's degree; side wall: `side_rows` rows of
//   the SH surface between the top and bottom rim; cap: the top-face vertices
//   at azimuth 0 and pi (x = +-r) joined to points on z = bottom_z.
//   Out: vertices (V x 3, m), top-face, side-wall and cap triangles
//   (counter-clockwise seen from outside: from above, from outside the
//   cylinder, from the front -y), and the indices of the top-face vertices.
// LayerDeformer: from a LayerSnapshot (force-mesh node rest and current
//   positions), the piecewise-linear displacement field over the lattice
//   (LatticeDisplacementField) applied to the top-face vertices; other
//   vertices keep their rest position.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "puncture/hex_lattice.hpp"
#include "puncture/realtime/view_snapshot.hpp"
#include "puncture/sh/layer_surface.hpp"

namespace puncture::realtime {

struct LayerViewMeshOptions {
  double first_ring_m = 0.2e-3;  ///< radius of the first top-face ring
  double ring_growth = 1.08;     ///< ratio of consecutive ring spacings
  int half_azimuths = 96;        ///< segments over the half circle 0..pi
  int side_rows = 16;            ///< rows of the side wall
};

struct LayerViewMesh {
  Eigen::MatrixX3d rest_vertices;
  Eigen::MatrixX3i top_triangles;   ///< top face (deformed by the force mesh)
  Eigen::MatrixX3i side_triangles;  ///< side wall (never deformed)
  Eigen::MatrixX3i cap_triangles;   ///< cross-section in the plane y = 0
  std::vector<int> top_face;  ///< vertex indices on the top face
  double top_z_m = 0.0, bottom_z_m = 0.0;
};

LayerViewMesh build_layer_view_mesh(const LayerSurface& surface, double bottom_z_m,
                                    const LayerViewMeshOptions& options = {});

class LayerDeformer {
 public:
  LayerDeformer(HexLattice lattice, double spacing_m) : lattice_(std::move(lattice)), spacing_m_(spacing_m) {}
  /// vertices := rest vertices displaced by the snapshot's force-mesh field.
  /// Returns the largest displacement magnitude applied (m); 0 with no valid nodes.
  double apply(const LayerSnapshot& layer, const LayerViewMesh& mesh, Eigen::MatrixX3d& vertices) const;

 private:
  HexLattice lattice_;
  double spacing_m_;
};

}  // namespace puncture::realtime
