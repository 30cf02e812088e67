// shaft_pressure_relaxation.hpp: the shaft's contact pressure in one punctured
// layer relaxing with the layer's own Prony series
// (ShaftFrictionLaw::pressure_relaxation, scene.hpp).
//
// The tip opens a hole narrower than the shaft; the tissue round the shaft is
// held stretched from the moment the tip passed. In a (nearly) incompressible
// solid the pressure on the wall of a held cavity is carried by shear alone
// (cavity expansion: p is proportional to the shear modulus), so it relaxes
// as the layer's normalised shear relaxation function
//     g(s) = 1 - sum_i g_i (1 - exp(-s / tau_i)),   s: time since the tip passed,
// and so does the Coulomb friction per unit length it carries. The friction of
// h (m) of shaft in the layer is then phi h_eff (shaft_friction.hpp) with the
// relaxed contact length
//     h_eff(t) = integral over the shaft in the layer of g(t - t_pass(z)) dz
//              = g_inf h + sum_i g_i S_i,  S_i = integral exp(-(t - t_pass(z)) / tau_i) dz,
// g_inf = 1 - sum_i g_i. Consequences the FEM reference shows (default slab,
// muscle g 0.55, tau 6 s; Bosboom et al. 2001): the friction per mm of shaft
// grows with the insertion speed and saturates (the shaft passed recently
// everywhere), and it relaxes while the needle dwells. No term: h_eff = h.
//
// Cost: the tip passes shaft points in order of depth and withdraws them in
// reverse, so the pass times form a stack. Each update decays S_i by
// exp(-dt / tau_i), pushes the new length with weight 1 when the shaft in the
// layer grows and pops the newest lengths (with their weights) when it
// shrinks: O(terms) per update, amortised. Entries passed within
// kMergeFraction x min tau_i of the newest are merged into it (a weight error
// below that fraction). The stack is allocated at construction
// (kMaxEntries; update() never allocates): when it is full, the older half's
// neighbouring entries are merged pairwise at their length-weighted pass
// time, which first happens after kMaxEntries merge windows of insertion in
// one layer (10 s for the skin's tau of 0.25 s).
#pragma once

#include <cstddef>
#include <vector>

#include "puncture/scene.hpp"

namespace puncture {

class ShaftPressureRelaxation {
 public:
  /// Time window (as a fraction of the shortest tau_i) within which newly
  /// passed shaft lengths are merged into one stack entry.
  static constexpr double kMergeFraction = 0.01;
  /// Stack entries allocated at construction.
  static constexpr std::size_t kMaxEntries = 4096;

  /// terms: the layer's normalised Prony series (empty: no relaxation).
  /// Throws std::invalid_argument unless every g_i > 0, sum g_i <= 1 and every
  /// tau_i > 0 (finite).
  explicit ShaftPressureRelaxation(std::vector<PronyRelaxationTerm> terms = {});

  /// The shaft length h (m, >= 0) inside the layer at time t (s, not
  /// decreasing between calls; a call with an earlier time counts as the same
  /// time): returns the relaxed contact length h_eff (m, in [g_inf h, h]).
  double update(double shaft_length_m, double time_s);
  /// h_eff (m) of the last update.
  double relaxed_length_m() const { return relaxed_m_; }
  bool relaxes() const { return !terms_.empty(); }
  /// Stack entries held (for tests of the memory bound).
  std::size_t entries() const { return stack_.size(); }

 private:
  void halve_stack();
  struct PassedLength {
    double length_m;
    double time_s;  ///< when the tip passed it
  };
  std::vector<PronyRelaxationTerm> terms_;
  double relaxed_fraction_ = 1.0;  ///< g_inf
  double merge_window_s_ = 0.0;
  std::vector<PassedLength> stack_;
  std::vector<double> weighted_m_;  ///< S_i
  double length_m_ = 0.0;
  double time_s_ = 0.0;
  bool started_ = false;
  double relaxed_m_ = 0.0;
};

}  // namespace puncture
