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
#pragma once

#include "puncture/scene.hpp"

namespace puncture {

class KarnoppFriction {
 public:
  explicit KarnoppFriction(const ShaftFrictionLaw& law);
  /// Updates the stick state with velocity v and returns phi (N per m of shaft).
  double update(double axial_velocity_m_per_s);
  /// phi of the last update (N/m).
  double force_per_length_N_per_m() const { return phi_; }
  bool sticking() const { return sticking_; }
  void reset() { phi_ = 0.0, sticking_ = true; }
  const ShaftFrictionLaw& law() const { return law_; }

 private:
  ShaftFrictionLaw law_;
  double phi_ = 0.0;
  bool sticking_ = true;
};

}  // namespace puncture
