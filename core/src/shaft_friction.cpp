#include "puncture/shaft_friction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace puncture {

KarnoppFriction::KarnoppFriction(const ShaftFrictionLaw& law) : law_(law) {
  if (!(law.dynamic_N_per_m >= 0.0) || !std::isfinite(law.dynamic_N_per_m))
    throw std::invalid_argument("shaft friction: dynamic level must be >= 0 and finite");
  if (!(law.static_N_per_m >= law.dynamic_N_per_m) || !std::isfinite(law.static_N_per_m))
    throw std::invalid_argument("shaft friction: static level must be >= the dynamic level and finite");
  if (!(law.velocity_band_m_per_s > 0.0) || !std::isfinite(law.velocity_band_m_per_s))
    throw std::invalid_argument("shaft friction: velocity band must be > 0");
  if (!(law.presliding_m >= 0.0) || !std::isfinite(law.presliding_m))
    throw std::invalid_argument("shaft friction: presliding must be >= 0 and finite");
}

double KarnoppFriction::update(double v, double depth_m) {
  const double dx = has_depth_ ? depth_m - last_depth_m_ : 0.0;
  has_depth_ = true;
  last_depth_m_ = depth_m;
  // Without presliding, or inside the band (sticking), Karnopp's rule.
  if (!(law_.presliding_m > 0.0) || std::abs(v) <= law_.velocity_band_m_per_s) return update(v);
  phi_ = std::clamp(phi_ + law_.dynamic_N_per_m / law_.presliding_m * dx, -law_.dynamic_N_per_m, law_.dynamic_N_per_m);
  sticking_ = false;
  return phi_;
}

double KarnoppFriction::update(double v) {
  if (v > law_.velocity_band_m_per_s) {
    phi_ = law_.dynamic_N_per_m;
    sticking_ = false;
  } else if (v < -law_.velocity_band_m_per_s) {
    phi_ = -law_.dynamic_N_per_m;
    sticking_ = false;
  } else {
    phi_ = std::clamp(phi_, -law_.static_N_per_m, law_.static_N_per_m);
    sticking_ = true;
  }
  return phi_;
}

}  // namespace puncture
