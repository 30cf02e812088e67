// coupled_surfaces.hpp: the layers' surfaces drawn as one deformed slab
// (Effects::coupled_surfaces; used by the simulator, see simulator.hpp).
//
// The force of the real-time model comes from the needle layer's force mesh
// alone; this only decides where the surfaces are drawn (and so what
// `puncture validate` compares with the FEM's surfaces). Every layer k has its
// own deflection o_k (m, > 0 into the tissue, per force-mesh node along the
// inward normal: the mesh while intact, Eq. 8's resumption after it broke).
// The drawn deflection is a radial profile D_k(r) on one grid shared by all
// layers (r = 0, dr, ..., the widest mesh; dr = half the finest spacing L), so
// a layer with a small mesh still carries the deformation of a wide one:
//   O_k(r)   the own ring means at the rings' mean radii (ring 1 at r = 0),
//            linear between them, 0 beyond the outer ring;
//   needle layer a:       D_a = max(O_a, (1 - s) B_a), B_a the baseline it
//                         was met with, s = min(1, O_a(0) / B_a(0)): the
//                         layer's own mesh takes the deformation over as it
//                         is pressed (its deflection is identified against
//                         the FEM's whole surface deflection, calibrate
//                         --surface-fit, so adding B_a would count it twice);
//   a layer k below a:    D_k = max(O_k, T(a -> k) D_a), the half-space
//                         transmission (surface_transmission.hpp) through the
//                         depth between the two surfaces (the fat's top
//                         follows the pressed skin);
//   a broken layer k < a: D_k = max(O_k, D_{k+1}): it rests on the layer
//                         below and returns to it, not through it to its rest
//                         shape (bottom-up);
//   the last broken layer k = a - 1 while no layer below bears the needle's
//                         load by itself: no layer below is pressed (the last
//                         layer once all are broken), or layer a was met at the
//                         tip (layer k squeezed between it and the tip) and its
//                         mesh has not yet taken its baseline over (s < 1):
//                         D_k = max(O_k, (F_tip / F_b) T(c) P_b +
//                         (F_shaft / F_b) T(c / 2) P_b), P_b its drawn profile
//                         at the break, F_b the needle's whole force at the
//                         break, c how far the tip went on past the break,
//                         F_tip the force at the tip (the needle layer's surface
//                         force and every cutting force), F_shaft every layer's
//                         shaft friction and d h v (acting along the shaft: at
//                         c / 2). The FEM's broken surfaces keep their shape at
//                         the break scaled by the needle's force (its skin and
//                         fat a load step after their breaks, at 1-20 mm/s), so
//                         the ratio is of whole forces. By reciprocity
//                         the surface deflection of a load buried at depth c
//                         is T(c) of the deflection of the same load on the
//                         surface, so the needle's load keeps the broken
//                         surface down and lets it rise as the tip goes deeper
//                         (results/surface_transmission: within 3-17 % of the
//                         FEM's muscle top over 2-14 mm past its break); the
//                         layers above rest on it.
// Baseline: when layer a breaks and the needle meets layer a + 1 below that
// layer's rest surface (contact at the tip, simulator.hpp), layer a + 1 is
// where the pressing left it: B_{a+1} = T(a -> a+1) D_a at the break, kept
// (and taken over, above) while a + 1 is the needle layer.
// Per node i of layer k (distance rho_i from the axis in the lattice's plane):
// d_k(i) = max(o_k(i), D_k(rho_i)).
//
// In: per layer its hex lattice (nullptr: no force mesh), spacing L (m) and
// the depth of its top below the first surface (m). The transmission
// matrices of a geometry are computed once per process (shared cache), at
// construction. Nothing after construction allocates (drawn() runs in the
// real-time app's haptic thread when it copies the surfaces for the view),
// given drawn's output vectors sized to the lattices.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "puncture/hex_lattice.hpp"

namespace puncture {

class SurfaceCoupling {
 public:
  struct LayerGeometry {
    const HexLattice* lattice = nullptr;  ///< nullptr: the layer has no force mesh
    double spacing_m = 0.0;
    double top_depth_m = 0.0;
  };
  /// The needle's load on the last broken layer (see the file comment).
  struct LoadAfterBreak {
    std::size_t layer = 0;
    double tip_depth_m = 0.0;   ///< below the first surface
    double tip_force_N = 0.0;   ///< at the tip: the needle layer's surface force and every cutting force
    double shaft_force_N = 0.0; ///< every layer's shaft friction and d h v
  };
  /// slab_depth_m: how deep the tip can go below the first surface (sets
  /// the deepest transmission level). Throws std::invalid_argument for a
  /// non-positive spacing or layer tops that do not deepen.
  SurfaceCoupling(const std::vector<LayerGeometry>& layers, double slab_depth_m);

  /// own[k]: own node deflections of layer k (its lattice's size; anything
  /// for a layer without a mesh). needle_layer == layer count: all broken.
  /// Writes drawn[k] (node deflections, m).
  void drawn(const std::vector<Eigen::VectorXd>& own, std::size_t needle_layer, std::vector<Eigen::VectorXd>& drawn,
             const LoadAfterBreak* load = nullptr) const;
  /// out = T(c) P on the grid for any depth c >= 0 (m): linear between the
  /// transmissions at c = 0.25 mm x 1.3^i (made at construction up to the
  /// slab's depth, once per process), the identity blended in below 0.25 mm,
  /// the deepest level beyond. No allocation.
  void transmitted(const Eigen::VectorXd& profile, double depth_m, Eigen::VectorXd& out) const;
  /// Layer k broke with own node deflections own_at_break under the needle
  /// force force_N (N), the tip at tip_depth_m below the first surface: keeps
  /// its drawn profile P_b (no allocation).
  void freeze_break(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own_at_break, double force_N,
                    double tip_depth_m);
  /// The needle's whole force F_b at layer k's break, once the tick that broke
  /// it knows its shaft forces (after freeze_break).
  void set_break_force(std::size_t k, double force_N);
  /// True unless layer k has a baseline its own deflection own_k (its node
  /// deflections) has not yet taken over (s < 1 in the file comment).
  bool baseline_taken_over(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own_k) const;
  /// Layer k (> 0) met at the tip when layer k - 1 broke (after
  /// freeze_break(k - 1, ...)): sets B_k = T(k - 1 -> k) P_b (no allocation).
  void freeze_baseline(std::size_t k);
  /// Layer k is no longer the needle layer where it was met.
  void clear_baseline(std::size_t k) { has_baseline_[k] = false; }
  bool has_break(std::size_t k) const { return has_break_[k]; }
  bool has_baseline(std::size_t k) const { return has_baseline_[k]; }

  /// The shared radial grid (m) and a layer's drawn profile on it after drawn().
  const std::vector<double>& grid_m() const { return grid_; }
  const Eigen::VectorXd& profile(std::size_t k) const { return profile_[k]; }
  const std::vector<double>& node_radii_m(std::size_t k) const { return node_radius_[k]; }
  /// T(a -> k), a < k, on the grid (grid x grid).
  const Eigen::MatrixXd& transmission(std::size_t a, std::size_t k) const { return *weights_[a][k]; }

 private:
  /// profile = max(profile, (1 - s) B_k) for the needle layer met at the tip (no allocation).
  void add_faded_baseline(std::size_t k, Eigen::VectorXd& profile) const;
  /// O_k on the grid into out.
  void own_profile(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own, Eigen::VectorXd& out) const;

  std::size_t n_ = 0;
  std::vector<double> grid_;
  std::vector<const HexLattice*> lattice_;
  std::vector<std::vector<double>> node_radius_, ring_radius_;
  std::vector<std::vector<int>> ring_count_;
  std::vector<std::vector<std::shared_ptr<const Eigen::MatrixXd>>> weights_;
  std::vector<Eigen::VectorXd> baseline_, break_profile_;
  std::vector<double> break_force_N_, break_depth_m_;
  std::vector<bool> has_baseline_, has_break_;
  std::vector<std::shared_ptr<const Eigen::MatrixXd>> ladder_;  ///< T at the ladder depths
  mutable Eigen::VectorXd carried_, level_lo_, level_hi_;
  mutable std::vector<Eigen::VectorXd> profile_;
  mutable Eigen::VectorXd ring_means_, scratch_;
};

}  // namespace puncture
