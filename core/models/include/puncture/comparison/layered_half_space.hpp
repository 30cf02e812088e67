// layered_half_space.hpp: surface response of a stack of bonded elastic
// layers on a rigid base (Burmister's layered system) to axisymmetric normal
// surface loads, for the boundary-element comparison model.
//
// In:  layers top first (thickness m, E Pa, nu), bonded to each other and to a
//      rigid base under the last one; frictionless surface.
// Out: the surface compliance C(k) (m/Pa) of wavenumber k (1/m), i.e. the
//      Hankel-domain normal displacement per unit normal traction, and the
//      surface displacement under a uniform pressure on a disc or annulus.
//
// Method. In each layer the static Navier equations for a displacement mode
// (U(z) sin kx, W(z) cos kx) (plane strain; the axisymmetric problem with
// J_1, J_0 kernels has the same equations in z) have the solutions
//   s = -1 (decaying downward from the layer top, z from the top):
//     U = (a + k D z) e^{-kz},  W = (a + kappa D + k D z) e^{-kz}
//   s = +1 (decaying upward from the layer bottom, z' = z - h <= 0):
//     U = (a - k D z') e^{kz'}, W = (-a - kappa D + k D z') e^{kz'}
// with kappa = 3 - 4 nu; tractions S_x = mu (U' - k W), S_z = lambda k U + (lambda + 2 mu) W'.
// Only decaying exponentials appear, so every k is numerically safe. Each
// layer gives a 4 x 4 stiffness (face tractions from face displacements);
// the layers are assembled, the base fixed, and a unit normal traction
// applied at the surface: C(k) = W(0). Checks: C -> 2 (1 - nu_1^2) / (E_1 k)
// for k h_1 >> 1 (the top layer's half-space) and C(0) = sum h_i / (lambda_i +
// 2 mu_i) (uniaxial strain of the stack).
//
// Disc load p on radius a: u(r) = p a int_0^inf C(k) J_1(k a) J_0(k r) dk.
// The top layer's half-space part 2 (1 - nu_1^2) / (E_1 k) is integrated in
// closed form (Love's uniform disc, boussinesq.hpp); the remainder decays
// like e^{-2 k h_1} and is integrated by Gauss-Legendre panels (a quarter
// period of the fastest Bessel oscillation wide) up to k = 30 / h_1, with the
// remainder cached at the nodes.
#pragma once

#include <vector>

namespace puncture::comparison {

struct ElasticLayer {
  double thickness_m = 0.0;
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
};

class LayeredHalfSpace {
 public:
  /// max_radius_m: the largest radius (field point or load edge) that will be
  /// evaluated (sets the quadrature panel width). Throws std::invalid_argument
  /// for no layers or bad moduli.
  LayeredHalfSpace(std::vector<ElasticLayer> layers, double max_radius_m);

  /// C(k) (m/Pa), k > 0.
  double compliance(double k_per_m) const;
  /// Surface displacement at radius r (m) under unit pressure on the disc r <= a (m/Pa).
  double disc_displacement(double a_m, double r_m) const;
  /// Under unit pressure on the annulus r1 <= r <= r2 (r1 may be 0).
  double annulus_displacement(double r1_m, double r2_m, double r_m) const;
  /// Hankel spectrum of unit pressure on the annulus [r1, r2] at the quadrature
  /// nodes, r2 J_1(k r2) - r1 J_1(k r1), times the node weights and the
  /// remainder C(k) - C_top(k). Loads combine linearly.
  std::vector<double> annulus_spectrum(double r1_m, double r2_m) const;
  /// The remainder integral of a spectrum at radius r (add the closed-form
  /// Love part of the same load for the displacement).
  double remainder_displacement(const std::vector<double>& spectrum, double r_m) const;

  const std::vector<ElasticLayer>& layers() const { return layers_; }
  std::size_t quadrature_nodes() const { return nodes_.size(); }
  const std::vector<double>& wavenumbers_per_m() const { return nodes_; }

 private:
  std::vector<ElasticLayer> layers_;
  double max_radius_m_;
  std::vector<double> nodes_;      ///< k (1/m)
  std::vector<double> weights_;    ///< quadrature weights times [C(k) - C_top(k)]
};

}  // namespace puncture::comparison
