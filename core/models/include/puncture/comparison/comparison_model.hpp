// comparison_model.hpp: the one interface behind which every model of
// `puncture compare` runs the scene's insertion (seed paper Sec. 3.3: MSM,
// FEM, BEM, SHF against SHF + MSM; seed 001: mass-spring and tensor-mass).
//
// A model is built from the scene (same slab, same needle, same layers) and
// advanced one haptic step at a time by the needle state of the scene's
// scripted trajectory (needle.hpp). Every step returns the contact force the
// tissue exerts on the needle tip (N, positive resisting insertion; the
// real-time model's surface force, the volumetric models' reaction on the
// nodes under the tip, the BEM/SHF punch force). The post-puncture force law
// of Table 1 (d h v, effect `damping`) is the same for every model and is
// added by the driver (validation/comparison) from the layer states.
//
// Needle contact and puncture follow the scene rules of the real-time model
// (simulator.hpp): only the first unpunctured layer is pressed; its contact
// starts when the tip reaches its top surface (or where the tip is, if it is
// already deeper); it breaks by the layer's breakthrough rule of the scene, as
// the real-time model's does (layer_breakthrough.hpp): a critical contact
// force, a critical work of the needle on the layer, or the paper's ring rule
// (its surface deflection, measured from the contact, deforms ring w of the
// force-mesh lattice, ring_criterion.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/comparison/element_inversion.hpp"
#include "puncture/comparison/internal_forces.hpp"
#include "puncture/needle.hpp"
#include "puncture/puncture_force.hpp"
#include "puncture/scene.hpp"

namespace puncture::comparison {

struct ModelSize {
  long dofs = 0;                  ///< unknowns advanced per step
  long nodes = 0;                 ///< nodes / elements of the model's discretisation
  long elements = 0;
  std::size_t memory_bytes = 0;   ///< bytes of the model's data (arrays, factors, state)
};

/// A deformed snapshot for ParaView.
struct VolumeFrame {
  Eigen::MatrixX3d points_m;        ///< deformed positions
  Eigen::MatrixX4i tets;            ///< remaining tetrahedra
  Eigen::VectorXd layer;            ///< per tetrahedron
  Eigen::MatrixX3d displacement_m;  ///< per point
};

class ComparisonModel {
 public:
  virtual ~ComparisonModel() = default;
  /// Key used on the command line and in the tables (e.g. "msm").
  virtual std::string name() const = 0;
  /// One line: what the model is and how it is integrated.
  virtual std::string description() const = 0;
  /// Advances to the needle state (one haptic step). Returns the contact force (N).
  virtual double step(const NeedleState& needle) = 0;
  virtual LayerState layer_state(std::size_t layer) const = 0;
  /// True once the needle touches the layer (its contact is set), also on the
  /// step where its deflection is still 0 and its state Untouched.
  virtual bool layer_touched(std::size_t layer) const { return layer_state(layer) != LayerState::Untouched; }
  /// The load (N) the layer carried at its break, where its rupture release
  /// starts (cutting.hpp): the contact force it broke under; the SHF, BEM
  /// and volumetric models cap it at the critical force under the
  /// critical-force rule (LayerBreakthroughRule::load_at_break_N), the
  /// real-time model gives its puncture event's surface force. NaN while the
  /// layer is not punctured.
  virtual double break_force_N(std::size_t layer) const = 0;
  /// Deflection (m, > 0 into the tissue, i.e. -u_z) of the layer's top surface
  /// at the radii r (m) from the needle axis, mean over the azimuth.
  virtual std::vector<double> surface_deflection_m(std::size_t layer, const std::vector<double>& r_m) const = 0;
  virtual ModelSize model_size() const = 0;
  /// Volumetric models: the deformed tetrahedral mesh.
  virtual bool has_volume() const { return false; }
  virtual VolumeFrame volume_frame() const { return {}; }
  /// Volumetric models: the inverted tetrahedra of the deformed mesh now
  /// (element_inversion.hpp); the others: elements == 0.
  virtual ElementInversion element_inversion() const { return {}; }
  /// Integrator statistics and notes for the report ("" if none).
  virtual std::string integrator_report() const { return ""; }
  /// Steps on which the integrator had to recover (error test or convergence failures).
  virtual long recovered_steps() const { return 0; }
};

/// Small-strain moduli and density of every scene layer (for the continuum
/// comparison models): the layer's material E (Pa) times its
/// comparison.stiffness_scale (1 when empty), nu, density (kg/m^3).
std::vector<LayerElasticity> layer_elasticity(const Scene& scene);

}  // namespace puncture::comparison
