// puncture_force.hpp: the per-layer puncture force law of seed paper Table 1.
//
// Layers are taken in order, top (skin) to bottom, any number >= 1. Each
// layer is Untouched, Pressed (its force mesh carries the needle: surface
// force F_s / F_f / F_m) or Punctured (surface force gone for good). Once a
// layer is punctured the needle shaft inside it feels the damping force
//     F_k = d_k h_k v                                               (N)
// with d_k the layer's damping per unit inserted needle length (N s / m^2),
// h_k (m) the length of shaft inside layer k and v (m/s) the needle speed
// along its axis (signed: positive while inserting; withdrawal reverses the
// force and leaves the layers punctured).
//
// Unit reading of d: Table 1 writes F = d h v, which is a force only if d is
// per unit length, N s / m^2. Table 2's "3 Ns/m" is read per mm of needle:
// d = 3 N s / m per mm = 3000 N s / m^2. Calibration sets the final value.
//
// h_k is the overlap of the shaft (from the tip up, out of the tissue) with
// the depth range [top_k, top_k + thickness_k] of the layer: it equals the
// layer thickness for layers fully passed and the inserted length for the
// layer the tip is in. With three layers this is Table 1 row by row:
//   skin   post:  d_s h v                  (h = depth below the skin top)
//   fat    pre:   F_f + d_s h_s v          post: (d_f h + d_s h_s) v
//   muscle pre:   F_m + (d_s h_s + d_f h_f) v
//          post:  (d_s h_s + d_f h_f + d_m h) v
//
// Sign convention: every force here is the axial force the tissue exerts on
// the needle, positive when it resists insertion (pushes the needle out).
#pragma once

#include <string_view>

namespace puncture {

enum class LayerState { Untouched, Pressed, Punctured };

const char* to_string(LayerState state);

/// Length (m) of needle shaft inside a layer whose top lies layer_top_depth_m
/// below the skin surface, for a tip at tip_depth_m (depths positive down).
/// In [0, layer_thickness_m].
double shaft_length_in_layer_m(double tip_depth_m, double layer_top_depth_m, double layer_thickness_m);

/// Table 1 damping term of one punctured layer: d h v (N).
inline double puncture_damping_force_N(double damping_N_s_per_m2, double shaft_length_m,
                                       double axial_speed_m_per_s) {
  return damping_N_s_per_m2 * shaft_length_m * axial_speed_m_per_s;
}

/// A layer breaking: recorded by the simulator when a force mesh reaches
/// ring w (storage is reserved at construction).
struct PunctureEvent {
  int layer = -1;               ///< index, 0 = top layer
  std::string_view layer_name;  ///< view of the simulator's copy of Layer::name
  double time_s = 0.0;
  double depth_m = 0.0;         ///< tip depth below the undeformed skin surface
  double surface_force_N = 0.0; ///< the layer's surface force at breakthrough
  double total_force_N = 0.0;   ///< needle force just before the surface gave way: surface force + cutting + shaft forces of the layers above
  double cutting_force_N = 0.0; ///< cutting force of the open crack above (the broken layer squeezed between, shaft_forces.hpp) at the break
  // The surface force by term, at the break (N; 0 without a force mesh):
  double eq5_force_N = 0.0;            ///< Eq. 5 on the mesh's own deflections (ForceMesh::eq5_force_N)
  double mesh_reaction_N = 0.0;        ///< the mesh's contact reaction (Eq. 5 + the mesh's inertia and damping)
  double tip_stiffening_force_N = 0.0; ///< g(z0) of the tip spring (stiffening.hpp), 0 without it
};

}  // namespace puncture
