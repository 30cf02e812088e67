// Boundary-element and SH-only models against half-space closed forms:
// Love's uniform disc against a direct quadrature of Boussinesq's point load,
// the BEM flat punch against Sneddon's force and profile, the layered Green's
// function against the homogeneous one, the SH spectral compliance against
// Boussinesq.
#include <gtest/gtest.h>

#include <cmath>

#include "puncture/comparison/boussinesq.hpp"
#include "puncture/comparison/layered_half_space.hpp"
#include "puncture/comparison/surface_models.hpp"
#include "puncture/scene_io.hpp"

namespace puncture::comparison {
namespace {

constexpr double kPi = 3.14159265358979323846;

Scene one_layer_scene(double thickness_mm, double E_kPa, double nu) {
  Scene s = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  s.layers.resize(1);
  s.layers[0].thickness_m = thickness_mm * 1e-3;
  s.layers[0].material.youngs_modulus_Pa = E_kPa * 1e3;
  s.layers[0].material.poisson_ratio = nu;
  s.sample.diameter_m = 0.2;
  s.insertion.target_depth_m = 0.5 * s.layers[0].thickness_m;
  return s;
}

TEST(Boussinesq, LoveDiscEqualsQuadratureOfPointLoads) {
  const double E = 20e3, nu = 0.45, a = 1e-3, p = 500.0;
  for (double r : {0.0, 0.4e-3, 0.9e-3, 1.5e-3, 4e-3}) {
    // Integrate P (1 - nu^2) / (pi E d) over the disc in polar coordinates centred
    // at the field point where it lies inside (integrable 1/d), midpoint rule.
    double sum = 0.0;
    const int nr = 400, nt = 400;
    for (int i = 0; i < nr; ++i)
      for (int j = 0; j < nt; ++j) {
        const double rho = a * (i + 0.5) / nr, theta = 2 * kPi * (j + 0.5) / nt;
        const double d = std::sqrt(r * r + rho * rho - 2 * r * rho * std::cos(theta));
        if (d < 1e-12) continue;
        sum += p * rho * (a / nr) * (2 * kPi / nt) * boussinesq_surface_uz_m(1.0, d, E, nu);
      }
    EXPECT_NEAR(love_uniform_disc_uz_m(p, a, r, E, nu), sum, 0.01 * sum) << "r = " << r;
  }
  // Centre value 2 (1 - nu^2) p a / E.
  EXPECT_NEAR(love_uniform_disc_uz_m(p, a, 0.0, E, nu), 2 * (1 - nu * nu) * p * a / E, 1e-15);
}

TEST(Boussinesq, SurfaceLimitOfTheDepthField) {
  EXPECT_NEAR(boussinesq_uz_m(2.0, 3e-3, 1e-12, 10e3, 0.3), boussinesq_surface_uz_m(2.0, 3e-3, 10e3, 0.3), 1e-12);
  EXPECT_THROW(boussinesq_surface_uz_m(1.0, 0.0, 10e3, 0.3), std::invalid_argument);
}

TEST(BoundaryElementModel, FlatPunchOnADeepHalfSpaceMatchesSneddon) {
  const Scene scene = one_layer_scene(1e5, 15.0, 0.45);  // 100 m deep: a half-space for a 0.6 mm punch
  const BoundaryElementModel bem(scene);
  const double a = scene.needle.radius_m;
  const double sneddon = sneddon_flat_punch_force_N(1.0, a, 15e3, 0.45);
  EXPECT_NEAR(bem.stiffness_N_per_m(0), sneddon, 0.02 * sneddon);
  for (double r : {1.2 * a, 2 * a, 5 * a, 20 * a})
    EXPECT_NEAR(bem.unit_deflection(0, r), flat_punch_surface_uz_m(1.0, a, r), 0.02 * flat_punch_surface_uz_m(1.0, a, r))
        << "r / a = " << r / a;
  // The pressure rises toward the rim (Sneddon: p ~ 1 / sqrt(a^2 - r^2)).
  const std::vector<double>& p = bem.unit_pressure_Pa_per_m(0);
  EXPECT_GT(p.back(), 2 * p.front());
}

TEST(LayeredHalfSpace, ComplianceLimitsAreTheClosedForms) {
  // Thick top layer: C(k) -> 2 (1 - nu^2) / (E k) once k h >> 1.
  const LayeredHalfSpace deep({{0.05, 20e3, 0.45}, {0.05, 5e3, 0.3}}, 0.03);
  for (double k : {2e3, 1e4}) EXPECT_NEAR(deep.compliance(k) * k * 20e3 / (2 * (1 - 0.45 * 0.45)), 1.0, 1e-8);
  // k -> 0: uniaxial strain of the stack on the rigid base, sum h_i / (lambda_i + 2 mu_i).
  auto constrained = [](double E, double nu) { return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); };
  const LayeredHalfSpace stack({{0.8e-3, 35e3, 0.48}, {8.4e-3, 2e3, 0.48}, {39e-3, 15e3, 0.48}}, 0.03);
  const double expected = 0.8e-3 / constrained(35e3, 0.48) + 8.4e-3 / constrained(2e3, 0.48) + 39e-3 / constrained(15e3, 0.48);
  EXPECT_NEAR(stack.compliance(1e-3), expected, 1e-5 * expected);
  // Two identical layers are one layer.
  const LayeredHalfSpace split({{3e-3, 10e3, 0.4}, {7e-3, 10e3, 0.4}}, 0.03), whole({{10e-3, 10e3, 0.4}}, 0.03);
  for (double k : {10.0, 300.0, 3000.0}) EXPECT_NEAR(split.compliance(k), whole.compliance(k), 1e-10 * whole.compliance(k));
  EXPECT_THROW(LayeredHalfSpace({}, 0.03), std::invalid_argument);
}

TEST(LayeredHalfSpace, DiscLoadOnAThickLayerIsLovesDisc) {
  // 0.5 m deep: the base is invisible from a 1 mm disc, so the Hankel integral
  // of the remainder must vanish and the displacement be Love's closed form.
  const LayeredHalfSpace thick({{0.5, 15e3, 0.45}}, 0.03);
  for (double r : {0.0, 0.5e-3, 2e-3, 10e-3})
    EXPECT_NEAR(thick.disc_displacement(1e-3, r), love_uniform_disc_uz_m(1.0, 1e-3, r, 15e3, 0.45),
                2e-3 * love_uniform_disc_uz_m(1.0, 1e-3, 0.0, 15e3, 0.45));
  // A soft layer under a stiff skin makes the surface more compliant, a
  // rigid base close below makes it stiffer.
  const LayeredHalfSpace skin_on_fat({{0.8e-3, 35e3, 0.48}, {8.4e-3, 2e3, 0.48}, {39e-3, 15e3, 0.48}}, 0.03);
  const LayeredHalfSpace skin_only({{48.2e-3, 35e3, 0.48}}, 0.03);
  EXPECT_GT(skin_on_fat.disc_displacement(0.635e-3, 0.0), skin_only.disc_displacement(0.635e-3, 0.0));
  const LayeredHalfSpace thin({{3e-3, 15e3, 0.45}}, 0.03);
  EXPECT_LT(thin.disc_displacement(1e-3, 0.0), thick.disc_displacement(1e-3, 0.0));
  // A layer bonded on a much stiffer one behaves as the same layer on the rigid base.
  const LayeredHalfSpace on_steel({{3e-3, 15e3, 0.45}, {10e-3, 15e9, 0.3}}, 0.03);
  for (double r : {0.0, 2e-3, 8e-3})
    EXPECT_NEAR(on_steel.disc_displacement(1e-3, r), thin.disc_displacement(1e-3, r), 1e-4 * thin.disc_displacement(1e-3, 0.0));
}

TEST(BoundaryElementModel, PressesLayersInOrderAndBreaksByTheRingRule) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  BoundaryElementModel bem(scene);
  ScriptedTrajectory trajectory(scene.insertion);
  double last_depth = -1.0;
  std::vector<double> puncture_depth(scene.layers.size(), -1.0);
  for (double t = 0.0; t < trajectory.insertion_end_s(); t += 1e-3) {
    const NeedleState needle = trajectory.sample(t);
    const double force = bem.step(needle);
    EXPECT_GE(force, 0.0);
    for (std::size_t k = 0; k < scene.layers.size(); ++k)
      if (bem.layer_state(k) == LayerState::Punctured && puncture_depth[k] < 0) puncture_depth[k] = needle.depth_m();
    last_depth = needle.depth_m();
  }
  EXPECT_GT(last_depth, 0.02);
  ASSERT_GT(puncture_depth[0], 0.0);
  // The skin breaks at the first depth where every ring's mean deflection
  // delta g_j passes the threshold: delta = max_j threshold / |g_j| (+ one
  // step of needle travel, 10 um).
  const RingBreakthroughCriterion skin(scene.layers[0].force_mesh);
  std::vector<double> unit;
  for (double r : skin.point_radii_m()) unit.push_back(bem.unit_deflection(0, r));
  double breaking = 0.0;
  for (double g : skin.ring_means_m(unit)) breaking = std::max(breaking, skin.threshold_m() / std::abs(g));
  EXPECT_GE(puncture_depth[0], breaking - 1e-12);
  EXPECT_LE(puncture_depth[0], breaking + 1.1e-5);
  for (std::size_t k = 1; k < scene.layers.size(); ++k)
    if (puncture_depth[k] > 0) EXPECT_GE(puncture_depth[k], puncture_depth[k - 1]);
}

TEST(SphericalHarmonicModel, SpectralComplianceReproducesLovesDisc) {
  // A uniform pressure p on a polar cap of angle alpha, applied through the SH
  // Green's function G(gamma) = sum_{l>=1} (2l+1)/(4 pi kappa_l) P_l(cos gamma),
  // displaces the pole by p R^2 2 pi int_0^alpha G sin(gamma) d gamma. Love's
  // closed form for a disc of radius a on a half-space is 2 (1 - nu^2) p a / E;
  // leaving out l = 0 (the rigid mode) removes (1 - nu^2) p a^2 / (E R).
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.realtime.sh_degree = 64;
  const SphericalHarmonicModel shf(scene);
  const double E = scene.layers[0].material.youngs_modulus_Pa, nu = scene.layers[0].material.poisson_ratio;
  const double R = shf.length_scale_m(0), p = 100.0, alpha = 0.2;
  const int n = 20000;
  double integral = 0.0;
  for (int i = 0; i < n; ++i) {
    const double g = alpha * (i + 0.5) / n;
    integral += shf.green_m_per_N(0, std::cos(g)) * std::sin(g) * alpha / n;
  }
  const double pole = p * R * R * 2 * kPi * integral;
  const double a = 2 * R * std::sin(alpha / 2);
  const double love = (1 - nu * nu) * p / E * (2 * a - a * a / R);
  EXPECT_NEAR(pole, love, 0.02 * love);
  EXPECT_NEAR(love_uniform_disc_uz_m(p, a, 0.0, E, nu), 2 * (1 - nu * nu) * p * a / E, 1e-12);
  // Length scale of the parameterisation at the pole: R sqrt(k / (2 (1 - zeta_t))).
  const LayerFitOptions o;
  EXPECT_NEAR(R, 0.5 * scene.sample.diameter_m * std::sqrt(o.corner_order / (2 * (1 - o.top_rim_cos_theta))), 1e-6 * R);
}

TEST(SphericalHarmonicModel, HigherDegreeLocalisesTheDeformation) {
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.realtime.sh_degree = 8;
  const SphericalHarmonicModel coarse(scene);
  scene.realtime.sh_degree = 32;
  const SphericalHarmonicModel fine(scene);
  // The finer expansion is softer under the needle (narrower dimple) and
  // decays faster away from it.
  EXPECT_LT(fine.stiffness_N_per_m(0), coarse.stiffness_N_per_m(0));
  EXPECT_LT(fine.unit_deflection(0, 5e-3), coarse.unit_deflection(0, 5e-3));
  EXPECT_DOUBLE_EQ(fine.unit_deflection(0, 0.0), 1.0);
}

}  // namespace
}  // namespace puncture::comparison

namespace puncture::comparison {
namespace {

/// Depth of the first step at which layer k is punctured (-1 if never), and
/// the force on the step before.
struct FirstPuncture {
  double depth_m = -1.0;
  double force_before_N = 0.0;
};
FirstPuncture first_puncture(LinearSurfaceModel& model, const Scene& scene, std::size_t k) {
  ScriptedTrajectory trajectory(scene.insertion);
  FirstPuncture p;
  double last_force = 0.0;
  for (double t = 0.0; t < trajectory.insertion_end_s(); t += 1e-3) {
    const NeedleState needle = trajectory.sample(t);
    const double force = model.step(needle);
    if (model.layer_state(k) == LayerState::Punctured) {
      p.depth_m = needle.depth_m();
      p.force_before_N = last_force;
      return p;
    }
    last_force = force;
  }
  return p;
}

/// The default scene whose skin breaks by the critical-force rule at the
/// BEM's force at 4 mm, F_c = S 4 mm (S: the BEM's skin stiffness, N/m),
/// scaled by (v / 10 mm/s)^rate_exponent.
struct CriticalForceSkin {
  Scene scene;
  double stiffness_N_per_m = 0.0;
  double critical_N = 0.0;
};
CriticalForceSkin critical_force_skin(double rate_exponent) {
  CriticalForceSkin c{load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json")};
  c.stiffness_N_per_m = BoundaryElementModel(c.scene).stiffness_N_per_m(0);
  c.critical_N = c.stiffness_N_per_m * 4e-3;
  BreakthroughCriterion& b = c.scene.layers[0].force_law.breakthrough;
  b.kind = BreakthroughCriterion::Kind::CriticalForce;
  b.critical_force_N = c.critical_N;
  b.rate_exponent = rate_exponent;
  b.reference_speed_m_per_s = 0.01;
  return c;
}

TEST(BoundaryElementModel, BreaksAtTheLayersCriticalForce) {
  // Linear layer: F = S (depth - contact); with a critical force F_c the skin
  // breaks on the first step with S (depth - 0) >= F_c, i.e. at
  // depth = F_c / S (+ at most one step of needle travel, 10 um). F_c: the
  // force at 4 mm of the BEM's stiffness (checked against Sneddon above).
  const auto [scene, S, critical] = critical_force_skin(0.0);
  BoundaryElementModel bem(scene);
  const FirstPuncture p = first_puncture(bem, scene, 0);
  ASSERT_GT(p.depth_m, 0.0);
  EXPECT_GE(p.depth_m, critical / S - 1e-12);
  EXPECT_LE(p.depth_m, critical / S + 1.1e-5);
  EXPECT_LT(p.force_before_N, critical);
}

TEST(BoundaryElementModel, TheCriticalForceScalesWithThePressingSpeedAsTheRealTimeModels) {
  // The rate law of breakthrough_rate.hpp, n = 0.5 about 10 mm/s: at 2.5 and
  // 10 mm/s the skin breaks at depth F_c s / S, s = sqrt(v / 10 mm/s).
  const auto [scene, S, critical] = critical_force_skin(0.5);
  for (double v : {0.0025, 0.01}) {
    Scene at_speed = scene;
    at_speed.insertion.speed_m_per_s = v;
    BoundaryElementModel bem(at_speed);
    const FirstPuncture p = first_puncture(bem, at_speed, 0);
    const double want = critical * std::sqrt(v / 0.01) / S;
    EXPECT_GE(p.depth_m, want - 1e-12) << v;
    EXPECT_LE(p.depth_m, want + v * 1e-3 + 1e-9) << v;
  }
}

TEST(BoundaryElementModel, ALayerCarriesNoMoreThanItsCriticalForceAtTheBreak) {
  // The needle jumps from the surface to 6 mm in one step (0.6 s at 10 mm/s,
  // the rate law's reference speed): the contact force S 6 mm is 1.5 F_c
  // there, but the layer broke when the force crossed F_c between the steps,
  // so the load it carried at the break (the start of its rupture release) is
  // F_c; at half the reference speed with n = 0.5 it is F_c sqrt(1/2). Under
  // the energy rule the load at the break is the force on the step.
  auto [scene, S, critical] = critical_force_skin(0.5);
  auto jump = [](LinearSurfaceModel& model, double depth_m, double duration_s) {
    NeedleState needle;
    needle.axial_velocity_m_per_s = depth_m / duration_s;
    model.step(needle);
    needle.tip_position_m.z() = -depth_m;
    needle.time_s = duration_s;
    return model.step(needle);
  };
  for (const double duration_s : {0.6, 1.2}) {
    BoundaryElementModel bem(scene);
    jump(bem, 6e-3, duration_s);
    ASSERT_EQ(bem.layer_state(0), LayerState::Punctured) << duration_s;
    const double v = 6e-3 / duration_s;
    EXPECT_NEAR(bem.break_force_N(0), critical * std::sqrt(v / 0.01), 1e-12 * critical) << duration_s;
  }
  scene.layers[0].force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalEnergy;
  scene.layers[0].force_law.breakthrough.critical_energy_J = 0.5 * S * 4e-3 * 4e-3;
  BoundaryElementModel bem(scene);
  jump(bem, 6e-3, 0.6);
  ASSERT_EQ(bem.layer_state(0), LayerState::Punctured);
  EXPECT_NEAR(bem.break_force_N(0), S * 6e-3, 1e-12 * S * 6e-3);
}

TEST(BoundaryElementModel, BreaksAtTheLayersCriticalWork) {
  // The work of F = S z from contact to z is S z^2 / 2 (the trapezoidal rule
  // is exact for a linear force): the skin breaks at z = sqrt(2 W_c / S).
  Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  scene.layers[0].force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalEnergy;
  const double S = BoundaryElementModel(scene).stiffness_N_per_m(0);
  const double critical = 0.5 * S * 4e-3 * 4e-3;  // the work at 4 mm
  scene.layers[0].force_law.breakthrough.critical_energy_J = critical;
  BoundaryElementModel bem(scene);
  const double z = std::sqrt(2.0 * critical / S);
  const FirstPuncture p = first_puncture(bem, scene, 0);
  EXPECT_GE(p.depth_m, z - 1e-12);
  EXPECT_LE(p.depth_m, z + 1.1e-5);
}

}  // namespace
}  // namespace puncture::comparison
