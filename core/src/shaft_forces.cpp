#include "puncture/shaft_forces.hpp"

#include <algorithm>

#include "puncture/cutting.hpp"
#include "puncture/puncture_force.hpp"

namespace puncture {

namespace {
std::vector<PronyRelaxationTerm> relaxation_terms(const ShaftFrictionLaw& law, const Viscoelasticity& material) {
  if (!law.pressure_relaxes_with_material) return {};
  return material.terms;
}
}  // namespace

LayerShaftFriction::LayerShaftFriction(const ShaftFrictionLaw& law, const Viscoelasticity& material)
    : stick_slip(law), contact_pressure(relaxation_terms(law, material)) {}

LayerShaftForce punctured_layer_shaft_force(double top_depth_m, double thickness_m, LayerShaftFriction* friction,
                                            bool damping_on, double damping_N_s_per_m2, const NeedleState& needle) {
  LayerShaftForce out;
  if (!damping_on && !friction) return out;
  // The layer's depth range [top, top + thickness] holds its vertical extent
  // of the shaft; along an inclined needle that is 1 / cos a as long.
  out.shaft_length_m = needle.along_axis_m(shaft_length_in_layer_m(needle.depth_m(), top_depth_m, thickness_m));
  if (friction)
    out.friction_N = friction->stick_slip.update(needle.axial_velocity_m_per_s, needle.axial_position_m()) *
                     friction->contact_pressure.update(out.shaft_length_m, needle.time_s);
  if (damping_on)
    out.damping_N = puncture_damping_force_N(damping_N_s_per_m2, out.shaft_length_m, needle.axial_velocity_m_per_s);
  return out;
}

CuttingForceParts open_crack_force_N(const ForceLaw& law, double& front_m, double tip_axial_m,
                                     double axial_speed_m_per_s, NextLayerContact next, double fracture_limit_N) {
  if (next == NextLayerContact::Touched) return {};
  const double release = cutting_force_N(1.0, law.cutting_release_m, front_m, tip_axial_m);
  // The crack grows (and costs its fracture energy) only while the tip moves
  // in at its front; otherwise the same force is the bevel's pressure.
  const bool advancing = axial_speed_m_per_s > 0.0 && tip_axial_m >= front_m;
  front_m = std::max(front_m, tip_axial_m);
  const CuttingForceParts c = rate_cutting_force(law, axial_speed_m_per_s);
  const double fracture = advancing ? std::min(c.fracture_N, fracture_limit_N) : 0.0;
  return {fracture * release, (c.bevel_N + c.fracture_N - fracture) * release};
}

double fracture_limit_N(const Layer& layer, const Needle& needle) {
  if (layer.puncture.kind != PunctureCriterion::Kind::FractureEnergy || !(layer.puncture.toughness_J_per_m2 > 0.0))
    return std::numeric_limits<double>::infinity();
  return layer.puncture.toughness_J_per_m2 * 2.0 * needle.radius_m;
}

}  // namespace puncture
