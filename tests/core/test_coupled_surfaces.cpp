// Surfaces drawn as one deformed slab: the half-space transmission
// (surface_transmission.hpp) against closed forms, brute-force quadrature and
// an independent Hankel-transform evaluation; SurfaceCoupling's rules
// (coupled_surfaces.hpp); the simulator with Effects::coupled_surfaces.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "allocation_counter.hpp"
#include "puncture/coupled_surfaces.hpp"
#include "puncture/needle.hpp"
#include "puncture/simulator.hpp"
#include "puncture/surface_transmission.hpp"
#include "table2_scene.hpp"
#include "thin_over_thick_scene.hpp"

using namespace puncture;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Integral of G_h over the disc of radius R: 1 - h^3 / (R^2 + h^2)^(3/2).
double disc_fraction(double R, double h) { return 1.0 - h * h * h / std::pow(R * R + h * h, 1.5); }

TEST(SurfaceTransmission, KernelIntegratesToTheClosedFormOverADisc) {
  for (double h : {0.8e-3, 9.2e-3}) {
    for (double R : {2e-3, 20e-3}) {
      const int n = 200000;
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        const double rho = (i + 0.5) * R / n;
        sum += boussinesq_kernel_per_m2(rho, h) * 2.0 * kPi * rho * R / n;
      }
      EXPECT_NEAR(sum, disc_fraction(R, h), 1e-7) << h << " " << R;
    }
  }
}

TEST(SurfaceTransmission, RingKernelMatchesTheAngularQuadratureOfTheKernel) {
  for (double h : {0.5e-3, 4e-3}) {
    for (double rho : {0.0, 1e-3, 3e-3}) {
      for (double s : {0.0, 0.9e-3, 3.1e-3, 10e-3}) {
        const int n = 20000;  // periodic trapezoid: spectrally accurate
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
          const double t = 2.0 * kPi * i / n;
          sum += boussinesq_kernel_per_m2(std::sqrt(rho * rho + s * s - 2.0 * rho * s * std::cos(t)), h);
        }
        sum *= 2.0 * kPi / n;
        EXPECT_NEAR(boussinesq_ring_kernel_per_m(rho, s, h), sum, 1e-9 * std::max(1.0, sum))
            << h << " " << rho << " " << s;
      }
    }
  }
}

TEST(SurfaceTransmission, UniformDeflectionOverADiscPassesByTheDiscFraction) {
  const double R = 15e-3, h = 2e-3;
  std::vector<double> r;
  for (int j = 0; j <= 30; ++j) r.push_back(R * j / 30.0);
  const Eigen::MatrixXd W = transmission_weights(r, {0.0}, h);
  // The profile is 1 up to R and 0 beyond: at the centre the disc fraction
  // (the last hat's outer half is cut off at R, as the profile is).
  EXPECT_NEAR(W.row(0).sum(), disc_fraction(R, h), 1e-6);
  // A narrow kernel (h much smaller than the spacing) passes the profile almost unchanged.
  const Eigen::MatrixXd near = transmission_weights(r, {5e-3}, 0.05e-3);
  EXPECT_NEAR(near.row(0).sum(), 1.0, 1e-3);
}

TEST(SurfaceTransmission, GaussianProfileAgainstTheHankelTransform) {
  // u(s) = exp(-s^2 / c^2): Hankel transform U(k) = c^2 / 2 exp(-k^2 c^2 / 4);
  // at depth h: u_h(rho) = integral U(k) (1 + k h) exp(-k h) J0(k rho) k dk,
  // an evaluation that shares nothing with the real-space kernel.
  const double c = 3e-3, h = 2e-3;
  std::vector<double> r;
  std::vector<double> u;
  for (int j = 0; j <= 600; ++j) {
    r.push_back(6.0 * c * j / 600.0);
    u.push_back(std::exp(-r.back() * r.back() / (c * c)));
  }
  const std::vector<double> targets{0.0, 1e-3, 3e-3, 6e-3};
  const Eigen::MatrixXd W = transmission_weights(r, targets, h);
  const Eigen::VectorXd values = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const int n = 40000;
    const double kmax = 12.0 / c;
    double hankel = 0.0;
    for (int m = 0; m < n; ++m) {
      const double k = (m + 0.5) * kmax / n;
      hankel += 0.5 * c * c * std::exp(-k * k * c * c / 4.0) * (1.0 + k * h) * std::exp(-k * h) *
                std::cyl_bessel_j(0.0, k * targets[i]) * k * kmax / n;
    }
    const double real_space = W.row(static_cast<Eigen::Index>(i)).dot(values);
    EXPECT_NEAR(real_space, hankel, 2e-4) << targets[i];
    EXPECT_LT(real_space, 1.0);
  }
}

TEST(SurfaceTransmission, BadInputIsRejectedAndProfilesInterpolate) {
  EXPECT_THROW(transmission_weights({0.0, 1e-3}, {0.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(transmission_weights({1e-3, 2e-3}, {0.0}, 1e-3), std::invalid_argument);
  EXPECT_THROW(transmission_weights({0.0, 2e-3, 1e-3}, {0.0}, 1e-3), std::invalid_argument);
  EXPECT_THROW(transmission_weights({0.0, 1e-3}, {-1e-3}, 1e-3), std::invalid_argument);
  const std::vector<double> r{0.0, 1.0, 3.0};
  const double u[] = {2.0, 1.0, 0.5};
  EXPECT_DOUBLE_EQ(profile_value_at(r, u, 0.0), 2.0);
  EXPECT_DOUBLE_EQ(profile_value_at(r, u, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(profile_value_at(r, u, 2.0), 0.75);
  EXPECT_DOUBLE_EQ(profile_value_at(r, u, 3.0), 0.5);
  EXPECT_DOUBLE_EQ(profile_value_at(r, u, 3.5), 0.0);
}

// ---------------------------------------------------------------------------
// SurfaceCoupling

struct TwoLayers {
  HexLattice top = make_hex_lattice(12), bottom = make_hex_lattice(12);
  SurfaceCoupling coupling{{{&top, 1e-3, 0.0}, {&bottom, 1e-3, 2e-3}}, 20e-3};
  std::vector<Eigen::VectorXd> own{Eigen::VectorXd::Zero(top.node_count()),
                                   Eigen::VectorXd::Zero(bottom.node_count())};
  std::vector<Eigen::VectorXd> drawn{own};
};

TEST(SurfaceCoupling, TheLayerBelowFollowsThePressedSurfaceThroughTheLayerBetween) {
  TwoLayers s;
  s.own[0].setConstant(1e-3);  // the whole top mesh sunk by 1 mm
  s.coupling.drawn(s.own, 0, s.drawn);
  EXPECT_LE((s.drawn[0] - s.own[0]).cwiseAbs().maxCoeff(), 1e-15);
  // Centre of the layer 2 mm below: the uniform disc of radius 11 mm (the outer
  // ring) through 2 mm, less the linear fall to 0 over the last half spacing.
  const double R = 11e-3, h = 2e-3;
  EXPECT_NEAR(s.drawn[1](0), 1e-3 * disc_fraction(R, h), 0.01e-3);
  EXPECT_LT(s.drawn[1](0), 1e-3);
  // Farther out the transmitted deflection falls off (the edge of the loaded disc).
  EXPECT_LT(s.drawn[1](s.drawn[1].size() - 1), 0.6e-3);
}

TEST(SurfaceCoupling, ABrokenLayerRestsOnTheLayerBelow) {
  TwoLayers s;
  for (Eigen::Index i = 0; i < s.own[1].size(); ++i) s.own[1](i) = 2e-3;  // the needle layer pressed flat
  s.coupling.drawn(s.own, 1, s.drawn);
  EXPECT_NEAR(s.drawn[0](0), 2e-3, 1e-15);  // the broken top layer (own 0) rests on it
  EXPECT_LE((s.drawn[1] - s.own[1]).cwiseAbs().maxCoeff(), 1e-15);
  // Its own recovery wins where it is deeper than the support.
  s.own[0](0) = 3e-3;
  s.coupling.drawn(s.own, 1, s.drawn);
  EXPECT_DOUBLE_EQ(s.drawn[0](0), 3e-3);
  // All broken: the last layer as its own, the top one rests on it.
  s.own[0].setZero();
  s.own[1].setZero();
  s.own[1](0) = 1e-3;
  s.coupling.drawn(s.own, 2, s.drawn);
  EXPECT_DOUBLE_EQ(s.drawn[1](0), 1e-3);
  EXPECT_NEAR(s.drawn[0](0), 1e-3, 1e-15);
}

TEST(SurfaceCoupling, ALayerMetAtTheTipKeepsTheDeformationUntilItsMeshTakesItOver) {
  TwoLayers s;
  Eigen::VectorXd at_break(s.top.node_count());
  at_break.setConstant(1e-3);
  s.coupling.freeze_break(0, at_break, 1.0, 1.5e-3);
  s.coupling.freeze_baseline(1);
  ASSERT_TRUE(s.coupling.has_baseline(1));
  s.coupling.drawn(s.own, 1, s.drawn);
  const double baseline_centre = s.drawn[1](0);
  const Eigen::Index outer = s.own[1].size() / 2;
  const double baseline_outer = s.drawn[1](outer);
  EXPECT_NEAR(baseline_centre, 1e-3 * disc_fraction(11e-3, 2e-3), 0.01e-3);
  EXPECT_GT(baseline_outer, 0.0);
  // Pressed by half the baseline at its centre: half of the baseline is left.
  s.own[1](0) = 0.5 * baseline_centre;
  s.coupling.drawn(s.own, 1, s.drawn);
  EXPECT_NEAR(s.drawn[1](0), 0.5 * baseline_centre, 1e-12);
  EXPECT_NEAR(s.drawn[1](outer), 0.5 * baseline_outer, 1e-12);
  // Pressed beyond it: the mesh alone.
  s.own[1](0) = 2.0 * baseline_centre;
  s.coupling.drawn(s.own, 1, s.drawn);
  EXPECT_EQ(s.drawn[1](0), s.own[1](0));
  EXPECT_EQ(s.drawn[1](s.own[1].size() - 1), 0.0);
  s.coupling.clear_baseline(1);
  s.own[1].setZero();
  s.coupling.drawn(s.own, 1, s.drawn);
  EXPECT_EQ(s.drawn[1].cwiseAbs().maxCoeff(), 0.0);
}

TEST(SurfaceCoupling, TheNeedlesLoadHoldsTheBrokenSurfaceAndFadesWithDepthByReciprocity) {
  TwoLayers s;
  Eigen::VectorXd at_break(s.bottom.node_count());
  for (Eigen::Index i = 0; i < at_break.size(); ++i)
    at_break(i) = 2e-3 * std::exp(-std::pow(s.coupling.node_radii_m(1)[static_cast<std::size_t>(i)] / 3e-3, 2));
  s.coupling.freeze_break(1, at_break, 2.0, 10e-3);  // broke under 2 N with the tip 10 mm deep
  SurfaceCoupling::LoadAfterBreak load;
  load.layer = 1;
  load.tip_depth_m = 10e-3;
  load.tip_force_N = 1.0;  // half the force, at the break depth: half the shape
  s.coupling.drawn(s.own, 2, s.drawn, &load);
  EXPECT_NEAR(s.drawn[1](0), 0.5 * at_break(0), 1e-3 * at_break(0));
  EXPECT_NEAR(s.drawn[0](0), s.drawn[1](0), 1e-15);  // the layer above rests on it
  // The same load 4 mm deeper: T(4 mm) of the break shape, as the grid profile
  // transmitted through 4 mm gives it (and less than at the break depth).
  load.tip_depth_m = 14e-3;
  s.coupling.drawn(s.own, 2, s.drawn, &load);
  Eigen::VectorXd grid_shape(static_cast<Eigen::Index>(s.coupling.grid_m().size()));
  for (std::size_t g = 0; g < s.coupling.grid_m().size(); ++g)
    grid_shape(static_cast<Eigen::Index>(g)) = 2e-3 * std::exp(-std::pow(s.coupling.grid_m()[g] / 3e-3, 2));
  const Eigen::MatrixXd W = transmission_weights(s.coupling.grid_m(), {0.0}, 4e-3);
  const double expected = 0.5 * W.row(0).dot(grid_shape);
  EXPECT_NEAR(s.drawn[1](0), expected, 0.03 * expected);  // ring means and the depth ladder's interpolation
  EXPECT_LT(s.drawn[1](0), 0.45 * at_break(0));
  // Shaft friction acts at half the depth: it holds the surface more than the same force at the tip.
  load.tip_force_N = 0.0;
  load.shaft_force_N = 1.0;
  s.coupling.drawn(s.own, 2, s.drawn, &load);
  EXPECT_GT(s.drawn[1](0), expected);
  // A load pulling outwards (withdrawal) does not lift the surface above its own.
  load.shaft_force_N = -1.0;
  s.coupling.drawn(s.own, 2, s.drawn, &load);
  EXPECT_EQ(s.drawn[1](0), 0.0);
}

// ---------------------------------------------------------------------------
// The simulator with coupled surfaces

using test::descent;
using test::thin_over_thick;

double centre_deflection(const PunctureSimulator& sim, std::size_t k) {
  return sim.node_rest_positions(k)(2, 0) - sim.node_positions(k)(2, 0);
}

TEST(CoupledSurfaces, ForcesUnchangedSurfacesDrawnTogether) {
  PunctureSimulator plain(thin_over_thick(false), test::plane_surfaces(thin_over_thick(false)));
  PunctureSimulator coupled(thin_over_thick(true), test::plane_surfaces(thin_over_thick(true)));
  double below_while_pressed = 0.0, top_after_recovery = 0.0, top_plain_after_recovery = 0.0;
  double break_t = -1.0;
  const std::vector<NeedleState> states = descent(600);
  for (std::size_t i = 0; i < states.size(); ++i) {
    const NeedleState& n = states[i];
    const TickResult& a = plain.tick(n);
    const double force_plain = a.total_force_N;
    const TickResult& b = coupled.tick(n);
    ASSERT_EQ(b.total_force_N, force_plain) << "tick " << i;  // the effect changes no force
    if (coupled.puncture_events().empty()) {
      below_while_pressed = centre_deflection(coupled, 1);
      EXPECT_EQ(centre_deflection(plain, 1), 0.0);
      EXPECT_LE(centre_deflection(coupled, 1), centre_deflection(coupled, 0) + 1e-15);
    } else if (break_t < 0.0) {
      break_t = n.time_s;
    } else if (n.time_s > break_t + 0.05) {  // long after the 20 ms recovery
      top_after_recovery = centre_deflection(coupled, 0);
      top_plain_after_recovery = centre_deflection(plain, 0);
      break;
    }
  }
  ASSERT_GT(break_t, 0.0);
  ASSERT_EQ(coupled.puncture_events().size(), 1u);
  const double break_depth = coupled.puncture_events()[0].depth_m;
  ASSERT_GT(break_depth, 1e-3);  // broken below the lower layer's rest surface
  // While the thin layer was pressed, the surface below followed it (most of its deflection through 1 mm).
  EXPECT_GT(below_while_pressed, 0.5 * (break_depth - 1e-3));
  // After the break and the recovery time the broken layer rests on the
  // pressed layer below instead of returning to its rest shape through it.
  EXPECT_EQ(top_plain_after_recovery, 0.0);
  EXPECT_GT(top_after_recovery, 0.5e-3);
}

TEST(CoupledSurfaces, TickAllocatesNothing) {
  Scene scene = thin_over_thick(true);
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const std::vector<NeedleState> states = descent(400);
  test::start_counting_allocations();
  for (const NeedleState& n : states) sim.tick(n);
  EXPECT_EQ(test::stop_counting_allocations(), 0);
  EXPECT_EQ(sim.puncture_events().size(), 1u);  // the break (and its baseline) happened in the counted ticks
}

TEST(CoupledSurfaces, ReadingTheSurfacesAllocatesNothing) {
  // The real-time app copies the drawn surfaces for its view from the haptic
  // thread: pressing, the layer met at the tip, the broken one resting on it,
  // and, with the lower layer broken too, the load after the last break.
  Scene scene = thin_over_thick(true);
  scene.layers[1].force_law.breakthrough.critical_force_N = 1.5;
  scene.layers[1].force_law.cutting_force_N = 0.5;
  scene.effects.cutting = true;
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const std::vector<NeedleState> states = descent(1500);
  long allocations = 0;
  double deepest_after_all_broke = 0.0;
  for (const NeedleState& n : states) {
    sim.tick(n);
    test::start_counting_allocations();
    for (std::size_t k = 0; k < sim.layer_count(); ++k) sim.node_positions(k);
    allocations += test::stop_counting_allocations();
    if (sim.active_layer() == sim.layer_count()) deepest_after_all_broke = centre_deflection(sim, 1);
  }
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(sim.puncture_events().size(), 2u);
  EXPECT_GT(deepest_after_all_broke, 0.0);  // the cutting load holds the broken lower surface down
}

}  // namespace

TEST(CoupledSurfaces, ABrokenLayerSqueezedOntoTheLayerMetAtTheTipIsHeldByTheNeedlesLoad) {
  // The thin layer breaks below the thick one's rest surface: it is squeezed
  // between the tip and the layer met there. While the needle still cuts
  // through it (its load stays), it is drawn held down by that load, not
  // resting on the layer below: deeper than without the cutting load, and no
  // deeper than (F / F_b) times its centre deflection at the break (the load
  // rule with T(c) <= 1 at the centre of a peaked profile), until that layer's
  // own mesh takes its baseline over.
  Scene cut = thin_over_thick(true), plain = thin_over_thick(true);
  cut.effects.cutting = true;
  cut.layers[0].force_law.cutting_force_N = 0.8;
  PunctureSimulator with_cut(cut, test::plane_surfaces(cut)), without_cut(plain, test::plane_surfaces(plain));
  const std::vector<NeedleState> states = descent(600);
  double centre_at_break = 0.0, break_force = 0.0, break_t = -1.0;
  int held_ticks = 0, compared_ticks = 0;
  for (const NeedleState& n : states) {
    const double before_cut = centre_deflection(with_cut, 0);
    const TickResult& r = with_cut.tick(n);
    without_cut.tick(n);
    if (with_cut.puncture_events().empty()) continue;
    if (break_t < 0.0) {
      break_t = n.time_s;
      centre_at_break = before_cut;
      break_force = with_cut.puncture_events()[0].total_force_N;
      ASSERT_GT(break_force, 0.8);
      continue;
    }
    if (n.time_s < break_t + 0.025 || n.time_s > break_t + 0.1) continue;  // own meshes recovered
    ++compared_ticks;
    const double held = centre_deflection(with_cut, 0), rests = centre_deflection(without_cut, 0);
    // (the breaking tick pressed 0.01 mm further than the tick before it)
    EXPECT_LE(held, r.total_force_N / break_force * (centre_at_break + 0.02e-3)) << "t = " << n.time_s;
    EXPECT_GE(held, centre_deflection(with_cut, 1) - 1e-15);  // never through the layer below
    if (held > rests + 1e-6) ++held_ticks;
    // Once the pressed layer's mesh has taken its baseline over it bears the
    // load: the broken layer rests on it again, as without the cutting load.
    if (n.time_s > break_t + 0.09) EXPECT_NEAR(held, rests, 1e-12) << "t = " << n.time_s;
  }
  ASSERT_GT(compared_ticks, 50);
  EXPECT_GE(held_ticks, 20);  // held from the recovery (25 ms) for at least 20 ms
}
