// surface_models.hpp: the two surface-only comparison models of the seed
// paper's ranking (Sec. 3.3): a boundary-element model (BEM) and a
// spherical-harmonic-only model (SHF). Both are quasi-static and linear: the
// pressed layer answers the needle's indentation delta (m, tip depth past the
// contact point) with a force k delta and a surface deflection delta g(r)
// (g(0) = 1). Contact and puncture as every comparison model
// (comparison_model.hpp): the ring-w rule on delta g at the lattice points.
//
// BoundaryElementModel: the rigid flat needle tip (radius a) on the surface
// of the active layer, the contact disc cut into annular boundary elements of
// constant pressure (sine-graded toward the rim, where the pressure is
// singular), collocation at the element mid-radii: G p = 1 gives the pressure
// per unit indentation, k = sum p_j A_j (Sneddon's 2 a E delta / (1 - nu^2) for
// a homogeneous half-space). Green's function: the layered elastic half-space
// of the layers from the pressed one down to the fixed base (bonded layers,
// rigid base: Burmister's layered system, layered_half_space.hpp), i.e. the
// Boussinesq/Love half-space of the pressed layer (closed form) plus the
// effect of the layers below and of the base (Hankel integral). Layers above
// the pressed surface (punctured) do not carry load; the sample's finite
// radius is not modelled (the half-space is laterally unbounded).
//
// SphericalHarmonicModel: the layer surface of the real-time model (the SH
// LayerSurface of degree l = realtime.sh_degree) deforms through its SH
// coefficients alone, without the force mesh. Radial displacement
// u = sum_{l=1..L} sum_m u_lm Y_lm on the parameter sphere; elastic energy of
// the half-space surface mode of wavenumber sqrt(l (l+1)) / R_s:
// kappa_l = E R_s sqrt(l (l+1)) / (2 (1 - nu^2)) per unit u_lm^2 (R_s: the
// parameterisation's length scale at the north pole, where the needle enters).
// A point force F at the pole gives u(gamma) = F G(gamma),
//     G(gamma) = sum_{l=1..L} (2l+1) / (4 pi kappa_l) P_l(cos gamma),
// which tends to Boussinesq's (1 - nu^2) / (pi E r) (minus the l = 0 mean) as
// L grows. The needle disc is held at delta at 13 collocation points (centre,
// rings at a/2 and a; least-squares pseudo-inverse when the degree cannot
// resolve them): k = sum of the point forces. The layer's own E, nu only. The
// degree l is the model's accuracy knob: at l = 16 the deformation cannot be
// narrower than about pi R_s / l.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "puncture/comparison/comparison_model.hpp"
#include "puncture/comparison/layered_half_space.hpp"
#include "puncture/comparison/layer_breakthrough.hpp"
#include "puncture/sh/layer_surface.hpp"

namespace puncture::comparison {

/// Per-layer linear response to the needle, contact and puncture bookkeeping.
class LinearSurfaceModel : public ComparisonModel {
 public:
  double step(const NeedleState& needle) override;
  LayerState layer_state(std::size_t layer) const override { return layers_[layer].state; }
  double break_force_N(std::size_t layer) const override { return layers_[layer].break_force_N; }
  std::vector<double> surface_deflection_m(std::size_t layer, const std::vector<double>& r_m) const override;
  /// Force per unit indentation of each layer (N/m).
  double stiffness_N_per_m(std::size_t layer) const { return layers_[layer].stiffness_N_per_m; }
  /// Deflection per unit indentation at radius r (1 inside the needle disc).
  virtual double unit_deflection(std::size_t layer, double r_m) const = 0;

 protected:
  explicit LinearSurfaceModel(const Scene& scene);
  /// Call at the end of the derived constructor: stiffnesses set, ring
  /// points' unit deflections computed.
  void finish_setup(const std::vector<double>& stiffness_N_per_m);

  struct LayerRuntime {
    double top_depth_m = 0.0;
    double stiffness_N_per_m = 0.0;
    LayerBreakthroughRule breakthrough;
    std::vector<double> ring_unit_deflection;
    LayerState state = LayerState::Untouched;
    bool contact_started = false;
    double contact_depth_m = 0.0;
    double indentation_m = 0.0;
    double break_force_N = std::numeric_limits<double>::quiet_NaN();  ///< contact force at the break
  };
  const Scene* scene_;
  std::vector<LayerRuntime> layers_;
  std::size_t active_ = 0;
  double activation_depth_m_ = -1e300;
};

struct BemSettings {
  int elements_in_contact = 32;   ///< annular elements on the needle disc
};

class BoundaryElementModel final : public LinearSurfaceModel {
 public:
  explicit BoundaryElementModel(const Scene& scene, const BemSettings& settings = {});
  std::string name() const override { return "bem"; }
  std::string description() const override;
  ModelSize model_size() const override;
  double unit_deflection(std::size_t layer, double r_m) const override;

  /// The layered half-space under the pressed surface of `layer`.
  const LayeredHalfSpace& half_space(std::size_t layer) const { return half_spaces_[layer]; }
  /// Element edges (size n + 1) and the pressure per unit indentation (Pa/m) of each element.
  const std::vector<double>& element_edges_m() const { return edges_; }
  const std::vector<double>& unit_pressure_Pa_per_m(std::size_t layer) const { return unit_pressure_[layer]; }

 private:
  double love_part(std::size_t layer, double r_m) const;
  std::vector<LayeredHalfSpace> half_spaces_;
  std::vector<std::vector<double>> unit_spectrum_;  ///< spectrum of the unit-indentation pressure, per layer
  BemSettings settings_;
  std::vector<double> edges_;
  std::vector<std::vector<double>> unit_pressure_;
};

class SphericalHarmonicModel final : public LinearSurfaceModel {
 public:
  explicit SphericalHarmonicModel(const Scene& scene);
  std::string name() const override { return "shf"; }
  std::string description() const override;
  ModelSize model_size() const override;
  double unit_deflection(std::size_t layer, double r_m) const override;

  int degree() const { return degree_; }
  /// kappa_l (N/m) for a layer.
  static double spectral_stiffness_N_per_m(int l, double E, double nu, double length_scale_m);
  /// G(gamma) (m/N) of a layer.
  double green_m_per_N(std::size_t layer, double cos_gamma) const;
  double length_scale_m(std::size_t layer) const { return length_scale_m_[layer]; }

 private:
  Eigen::Vector3d direction_at(std::size_t layer, double x_m, double y_m) const;
  int degree_ = 16;
  std::vector<LayerSurface> surfaces_;
  std::vector<double> length_scale_m_;
  std::vector<std::vector<double>> g_l_;                ///< (2l+1)/(4 pi kappa_l), l = 0..L (g_0 = 0)
  std::vector<std::vector<Eigen::Vector3d>> collocation_;  ///< parameter directions of the collocation points
  std::vector<Eigen::VectorXd> unit_forces_;           ///< point forces per unit indentation (N/m)
};

}  // namespace puncture::comparison
