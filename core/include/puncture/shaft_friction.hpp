// shaft_friction.hpp: Karnopp friction on the needle shaft inside one
// punctured layer (Effects::friction, ShaftFrictionLaw in scene.hpp).
//
// Force on the needle (N, positive resisting insertion), for h (m) of shaft
// inside the layer and axial velocity v (m/s, > 0 inserting):
//     F = phi h            (+ the paper's viscous part d h v, Effects::damping)
// with phi (N/m) from Karnopp's model (Karnopp 1985; the form Okamura et al.
// 2004 fitted to needle insertion) with static level f_s, dynamic level
// f_d <= f_s and velocity band dv:
//     v >  dv:   phi = +f_d   (sliding in)
//     v < -dv:   phi = -f_d   (sliding out: withdrawal reverses the friction)
//     |v| <= dv: sticking: phi keeps the value it had when the shaft entered
//                the band, limited to [-f_s, f_s].
// Why "keeps": Karnopp's stick force balances the other forces applied to a
// body that is free to move. Our needle's position is prescribed (a script
// or a haptic device), so there is no applied force to balance: the stuck
// interface keeps the shear it carried when it stopped (a quasi-static
// Coulomb contact does the same during a dwell). phi starts at 0 (no shear
// before the shaft first slides). Rate-independent: the result depends on v
// only through its sign outside the band.
//
// Presliding (law.presliding_m = delta > 0, update with the tip depth): the
// tissue round the shaft is dragged along before it slips, so phi follows
// the shaft travel dx elastically, phi <- clamp(phi + (f_d / delta) dx,
// -f_d, f_d), outside the band (inside it phi is kept as above). Reversing
// from +f_d, phi reaches -f_d after 2 delta of withdrawal (linearly), where
// the Karnopp law jumps at once.
#pragma once

#include "puncture/scene.hpp"

namespace puncture {

class KarnoppFriction {
 public:
  explicit KarnoppFriction(const ShaftFrictionLaw& law);
  /// Updates the stick state with velocity v and returns phi (N per m of shaft)
  /// (Karnopp; presliding is not used).
  double update(double axial_velocity_m_per_s);
  /// As above, with the tip depth (m) of this update: with presliding > 0 phi
  /// follows the travel since the previous update (none on the first).
  double update(double axial_velocity_m_per_s, double depth_m);
  /// phi of the last update (N/m).
  double force_per_length_N_per_m() const { return phi_; }
  bool sticking() const { return sticking_; }
  void reset() { phi_ = 0.0, sticking_ = true, has_depth_ = false; }
  const ShaftFrictionLaw& law() const { return law_; }

 private:
  ShaftFrictionLaw law_;
  double phi_ = 0.0;
  bool sticking_ = true;
  bool has_depth_ = false;
  double last_depth_m_ = 0.0;
};

}  // namespace puncture
