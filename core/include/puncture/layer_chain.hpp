// layer_chain.hpp: layers in series along the needle axis
// (Effects::layer_interaction; used by the simulator, see simulator.hpp).
//
// Each layer j of the chain is one link: its force mesh's contact node is
// deflected by r_j (m, >= 0) relative to the surface of the layer below (its
// base), and for the step being taken the link transmits
//     F_j(r) = a_j + b_j r + g_j(r)                               (N)
// with a_j, b_j > 0 the affine step response of the force mesh
// (ForceMesh::predicted_reaction_N) and g_j the tip stiffening
// (stiffening.hpp; 0 for links the needle does not touch or without the
// effect). F_j is strictly increasing in r.
//
// Deflection of one link under force F:  r_j(F) = 0 if F <= a_j, else the
// root of F_j(r) = F (closed form without stiffening, else Newton from the
// right, which converges monotonically for convex g).
//
// Displacement-driven chain (the needle presses the top link and the tip is
// D past the top link's rest surface): the links share one force F with
//     sum_j r_j(F) = D,
// solved for F by a safeguarded Newton iteration (bisection fallback) to
// |sum r - D| <= 1e-12 D + 1e-18 m. With linear links (g = 0, a = 0) this is
// the series-spring law F = D / sum_j (1 / b_j).
// Force-driven chain (the layer above is cut through and transmits the
// cutting force F): r_j = r_j(F) for every link.
// No allocation; at most kMaxChainLinks links.
#pragma once

namespace puncture {

struct StiffeningLaw;

constexpr int kMaxChainLinks = 16;

struct ChainLink {
  double intercept_N = 0.0;        ///< a: force at r = 0 for this step
  double slope_N_per_m = 0.0;      ///< b > 0
  const StiffeningLaw* stiffening = nullptr;  ///< g, or nullptr for none
};

/// F_j(r) (N).
double link_force_N(const ChainLink& link, double deflection_m);
/// r_j(F) (m, >= 0).
double link_deflection_m(const ChainLink& link, double force_N);

/// Displacement-driven chain: returns F (N) and writes r[0..n) (m) with
/// sum r = D (D > 0). F is below 0 only when the meshes' own motion (a_j < 0,
/// a rebounding dynamic mesh) would carry the surface past the tip: the
/// caller then treats the needle as out of contact. Throws std::invalid_argument for n outside 1..kMaxChainLinks,
/// a non-positive slope or non-finite input; std::runtime_error if the
/// iteration does not converge.
double solve_series_chain(const ChainLink* links, int n, double total_deflection_m, double* deflections_m);

}  // namespace puncture
