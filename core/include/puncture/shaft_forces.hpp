// shaft_forces.hpp: the forces the force law adds behind the tip once layers
// are punctured, as one rule that the haptic tick (simulator.cpp, step 5) and
// the comparison harness (validation/comparison, for every compared model)
// both call.
//
// Per punctured layer with h (m) of shaft inside it (shaft_length_in_layer_m
// of the tip depth, divided by the cosine of the needle axis to the vertical
// for an inclined needle) and axial velocity v (m/s, > 0 inserting), forces
// on the needle along its axis in N, positive resisting insertion:
//     friction  phi h_eff  (Effects::friction, shaft_friction.hpp; h_eff = h
//                          unless the contact pressure relaxes,
//                          shaft_pressure_relaxation.hpp)
//     damping   d h v      (Effects::damping, the seed's Table 1)
// The deepest punctured layer is cut (Effects::cutting, cutting.hpp) while
// its crack is open: every layer is punctured, or the next layer is not yet
// touched, or the next layer was met at the tip when this one broke (the tip
// below its rest surface: the broken layer is squeezed between them and the
// crack goes on while the tip presses the next layer).
#pragma once

#include <limits>

#include "puncture/cutting.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene.hpp"
#include "puncture/shaft_friction.hpp"
#include "puncture/shaft_pressure_relaxation.hpp"

namespace puncture {

/// The shaft forces of one punctured layer.
struct LayerShaftForce {
  double shaft_length_m = 0.0;  ///< h; 0 when neither friction nor damping is on
  double friction_N = 0.0;      ///< phi h_eff
  double damping_N = 0.0;       ///< d h v
};

/// The friction state of one punctured layer: Karnopp's stick / slip (and
/// presliding) level phi, and the relaxed contact length when the law's
/// pressure relaxes with the layer's material (else h_eff = h).
struct LayerShaftFriction {
  /// Throws std::invalid_argument for an invalid law or Prony series.
  LayerShaftFriction(const ShaftFrictionLaw& law, const Viscoelasticity& material);
  KarnoppFriction stick_slip;
  ShaftPressureRelaxation contact_pressure;
};

/// Friction (updated: `friction` keeps its stick / presliding state and the
/// shaft's pass times; nullptr when friction is off) and damping (damping_N_s_per_m2 d, used when
/// damping_on) of a punctured layer whose top lies top_depth_m below the skin
/// surface, thickness thickness_m, for the needle state `needle`.
LayerShaftForce punctured_layer_shaft_force(double top_depth_m, double thickness_m, LayerShaftFriction* friction,
                                            bool damping_on, double damping_N_s_per_m2, const NeedleState& needle);

/// What the tip meets below the deepest punctured layer.
enum class NextLayerContact {
  None,      ///< every layer is punctured, or the next one is not touched yet
  MetAtTip,  ///< touched below its rest surface when the layer above broke
  Touched    ///< touched at its surface
};

/// Cutting force (N, by part) of the deepest punctured layer with force law
/// `law` and crack front front_m (m along the needle axis; advanced to the tip
/// while the crack is open) for the tip at tip_axial_m moving at
/// axial_speed_m_per_s (m/s): C(v) of cutting.hpp times its release factor
/// while the crack is open (next != Touched), else 0; of its fracture part
/// at most fracture_limit_N (N, before the release factor; G_c w, cutting.hpp)
/// counts as fracture, the rest goes to the bevel's part. The crack grows only
/// while the tip moves in (speed > 0) at its front: otherwise (a dwell, a
/// retraction) nothing is fracture and the whole force is the bevel's part,
/// as the FEM's cutting column (its cohesive energy per unit advance) is 0
/// there. The total does not depend on the split.
CuttingForceParts open_crack_force_N(const ForceLaw& law, double& front_m, double tip_axial_m,
                                     double axial_speed_m_per_s, NextLayerContact next,
                                     double fracture_limit_N = std::numeric_limits<double>::infinity());

/// G_c w (N) of `layer` for `needle`: its measured toughness (a fracture-energy
/// puncture criterion) times the cut width 2a; infinity without one.
double fracture_limit_N(const Layer& layer, const Needle& needle);

}  // namespace puncture
