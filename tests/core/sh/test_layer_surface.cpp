// Tests of the SH layer surface: exact parameterisation, fit convergence in l,
// ray intersection (on and near the north pole), projection, tessellation.
#include <cmath>
#include <map>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "puncture/sh/layer_surface.hpp"

namespace puncture {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Default scene (Table 2 thicknesses): skin 0.8 mm at the top, fat 8.4 mm, muscle 39 mm; 60 mm sample.
constexpr double kRadius = 0.03;
constexpr double kSkinTop = 0.0, kSkinBottom = -0.8e-3;
constexpr double kMuscleTop = -9.2e-3, kMuscleBottom = -48.2e-3;

TEST(LayerProfile, MapsTheSphereOntoTheDiscBoundary) {
  LayerProfile p{kSkinTop, kSkinBottom, kRadius, {}};
  const double zt = p.options.top_rim_cos_theta, zb = p.options.bottom_rim_cos_theta;
  EXPECT_LT((p.position(Eigen::Vector3d::UnitZ()) - Eigen::Vector3d(0, 0, kSkinTop)).norm(), 1e-18);
  EXPECT_LT((p.position(-Eigen::Vector3d::UnitZ()) - Eigen::Vector3d(0, 0, kSkinBottom)).norm(), 1e-18);
  for (double zeta = -1.0; zeta <= 1.0; zeta += 0.01) {
    const double s = std::sqrt(std::max(0.0, 1 - zeta * zeta));
    const Eigen::Vector3d x = p.position(Eigen::Vector3d(s * std::cos(1.0), s * std::sin(1.0), zeta));
    const double r = std::hypot(x.x(), x.y());
    EXPECT_LE(r, kRadius * (1 + 1e-15));
    if (zeta > zt) EXPECT_DOUBLE_EQ(x.z(), kSkinTop);
    if (zeta < zb) EXPECT_DOUBLE_EQ(x.z(), kSkinBottom);
    if (zeta < zt && zeta > zb) EXPECT_NEAR(r, kRadius, 1e-15);
    EXPECT_GE(x.z(), kSkinBottom);
    EXPECT_LE(x.z(), kSkinTop);
    if (s > 0) EXPECT_NEAR(std::atan2(x.y(), x.x()), 1.0, 1e-12);  // azimuth preserved
  }
  // Rim corners: zero speed of rho (top) and z (side) on both sides of zeta_t.
  double rho1, rho2, z1, z2;
  const double h = 1e-4;
  p.profile(zt + h, rho1, z1);
  p.profile(zt - h, rho2, z2);
  EXPECT_LT((kRadius - rho1) / kRadius, 1e-6);  // 1 - sqrt(1 - (h / (1 - zt))^4) ~ 2e-16... << h
  EXPECT_LT((kSkinTop - z2) / p.thickness_m(), 1e-6);
  // top_face_direction inverts the top face.
  for (const auto& xy : {std::pair<double, double>{0.0, 0.0}, {1e-9, 0.0}, {0.01, -0.02}, {-0.02, 0.0}}) {
    const Eigen::Vector3d u = p.top_face_direction(xy.first, xy.second);
    EXPECT_NEAR(u.norm(), 1.0, 1e-15);
    const Eigen::Vector3d x = p.position(u);
    EXPECT_NEAR(x.x(), xy.first, 1e-15);
    EXPECT_NEAR(x.y(), xy.second, 1e-15);
    EXPECT_GE(u.z(), zt);
  }
}

TEST(LayerSurface, FitErrorDecreasesWithDegreeForSkinAndMuscle) {
  for (const auto& [top, bottom] : {std::pair<double, double>{kSkinTop, kSkinBottom}, {kMuscleTop, kMuscleBottom}}) {
    const double thickness = top - bottom;
    const std::vector<LayerFitErrorRow> rows = layer_fit_error_sweep(top, bottom, kRadius, {4, 8, 16, 24});
    ASSERT_EQ(rows.size(), 4u);
    for (std::size_t i = 1; i < rows.size(); ++i) {
      EXPECT_LT(rows[i].top_face_max_error_m, rows[i - 1].top_face_max_error_m) << "degree " << rows[i].degree;
      EXPECT_LT(rows[i].top_face_rms_error_m, rows[i - 1].top_face_rms_error_m);
      EXPECT_LT(rows[i].whole_surface_rms_error_m, rows[i - 1].whole_surface_rms_error_m);
      EXPECT_LT(rows[i].condition_number, 10.0);  // the grid fit stays well conditioned
    }
    // What we honestly reach: at l = 16 the top face is flat to 1e-3 of the
    // layer thickness within 0.9 R (measured 3.1e-4 H); at l = 24 to 2e-4 H.
    EXPECT_LT(rows[2].top_face_max_error_m, 1e-3 * thickness);
    EXPECT_LT(rows[3].top_face_max_error_m, 2e-4 * thickness);
    EXPECT_LT(rows[2].whole_surface_rms_error_m, 2e-3 * kRadius);
  }
}

TEST(LayerSurface, ReportedTopFaceErrorBoundsIndependentSamples) {
  const LayerSurface layer = LayerSurface::fit(kSkinTop, kSkinBottom, kRadius, 16);
  // Independent points: the fitted surface above random lateral positions (found
  // by top_face_parameter's own Newton), compared with the exact plane.
  double worst = 0.0;
  for (int i = 0; i < 50; ++i) {
    const double r = 0.85 * kRadius * std::sqrt((i + 0.37) / 50.0), phi = 2.39996 * i;
    const Eigen::Vector3d u = layer.top_face_parameter(r * std::cos(phi), r * std::sin(phi));
    const Eigen::Vector3d x = layer.position(u);
    EXPECT_NEAR(x.x(), r * std::cos(phi), 1e-12);
    EXPECT_NEAR(x.y(), r * std::sin(phi), 1e-12);
    worst = std::max(worst, std::abs(x.z() - kSkinTop));
  }
  EXPECT_LE(worst, 1.5 * layer.top_face_max_error_m());
  EXPECT_GT(layer.top_face_max_error_m(), 0.0);
  EXPECT_EQ(layer.fit_report().unknowns, 289);
  EXPECT_GT(layer.fit_report().samples, layer.fit_report().unknowns);
  EXPECT_LE(layer.surface().max_order(), 1);
}

TEST(LayerSurface, VerticalRayOnTheAxisHitsTheTopFace) {
  for (const auto& [top, bottom] : {std::pair<double, double>{kSkinTop, kSkinBottom}, {kMuscleTop, kMuscleBottom}}) {
    const LayerSurface layer = LayerSurface::fit(top, bottom, kRadius, 16);
    const Eigen::Vector3d origin(0, 0, top + 2e-3);
    double s = -1;
    SurfacePoint hit;
    ASSERT_TRUE(layer.intersect_ray(origin, -Eigen::Vector3d::UnitZ(), s, hit));
    EXPECT_NEAR(hit.position.z(), top, layer.top_face_max_error_m() + 1e-15);
    EXPECT_NEAR(hit.position.x(), 0.0, 1e-15);
    EXPECT_NEAR(hit.position.y(), 0.0, 1e-15);
    EXPECT_NEAR(s, origin.z() - hit.position.z(), 1e-14);
    EXPECT_GT(hit.normal.z(), 1.0 - 1e-8);
    // Same hit from a start point below the face would need s < 0: rejected.
    EXPECT_FALSE(layer.intersect_ray(Eigen::Vector3d(0, 0, top - 1e-4), Eigen::Vector3d::UnitZ() * -1.0, s, hit));
  }
}

TEST(LayerSurface, RaysAtAndNearTheNorthPoleAreContinuous) {
  const LayerSurface layer = LayerSurface::fit(kSkinTop, kSkinBottom, kRadius, 16);
  const double err = layer.top_face_max_error_m();
  double s0;
  SurfacePoint axis;
  ASSERT_TRUE(layer.intersect_ray(Eigen::Vector3d(0, 0, 1e-3), -Eigen::Vector3d::UnitZ(), s0, axis));
  for (double offset : {1e-9, 1e-7, 1e-5, 1e-4, 1e-3}) {
    for (double azimuth : {0.0, 0.9, 2.5, 3.9, 5.6}) {
      const Eigen::Vector3d origin(offset * std::cos(azimuth), offset * std::sin(azimuth), 1e-3);
      double s;
      SurfacePoint hit;
      ASSERT_TRUE(layer.intersect_ray(origin, -Eigen::Vector3d::UnitZ(), s, hit)) << offset << " " << azimuth;
      EXPECT_NEAR(hit.position.x(), origin.x(), 1e-13);
      EXPECT_NEAR(hit.position.y(), origin.y(), 1e-13);
      EXPECT_NEAR(hit.position.z(), kSkinTop, err + 1e-15);
      // Continuity with the axis hit: z varies on the scale R / l of the fit wiggles.
      EXPECT_LE(std::abs(hit.position.z() - axis.position.z()), 1.0 * err * offset / 1e-3 + 1e-14)
          << offset << " " << azimuth;
      EXPECT_LT((hit.normal - axis.normal).norm(), 1e-3);
      // The hit is on the fitted surface: compare with the surface point found by
      // an independent Newton (lateral position -> parameter).
      const Eigen::Vector3d on_surface = layer.position(layer.top_face_parameter(origin.x(), origin.y()));
      EXPECT_LT((on_surface - hit.position).norm(), 1e-12);
    }
  }
}

TEST(LayerSurface, ObliqueRaysMatchThePlaneToTheFitError) {
  const LayerSurface layer = LayerSurface::fit(kMuscleTop, kMuscleBottom, kRadius, 16);
  const PlaneSurface plane(kMuscleTop);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(0.3, -0.2, -1.0), Eigen::Vector3d(-1.0, 0.5, -0.4),
                                   Eigen::Vector3d(0.0, 1.0, -0.2)}) {
    const Eigen::Vector3d dir = d.normalized();
    const Eigen::Vector3d origin(0.002, -0.001, kMuscleTop + 3e-3);
    double s, s_plane;
    SurfacePoint hit, hit_plane;
    ASSERT_TRUE(layer.intersect_ray(origin, dir, s, hit));
    ASSERT_TRUE(plane.intersect_ray(origin, dir, s_plane, hit_plane));
    EXPECT_LT((hit.position - (origin + s * dir)).norm(), 1e-13);  // on the ray
    EXPECT_LT((hit.position - hit_plane.position).norm(), layer.top_face_max_error_m() / std::abs(dir.z()) + 1e-14);
    EXPECT_GT(hit.normal.z(), 0.999);
  }
}

TEST(LayerSurface, MissesAreReported) {
  const LayerSurface layer = LayerSurface::fit(kSkinTop, kSkinBottom, kRadius, 12);
  double s;
  SurfacePoint hit;
  EXPECT_FALSE(layer.intersect_ray(Eigen::Vector3d(0.04, 0, 0.01), -Eigen::Vector3d::UnitZ(), s, hit));  // outside
  EXPECT_FALSE(layer.intersect_ray(Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d::UnitZ(), s, hit));      // away
  EXPECT_FALSE(layer.intersect_ray(Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d::UnitX(), s, hit));      // parallel
  EXPECT_FALSE(layer.intersect_ray(Eigen::Vector3d(0, 0, NAN), -Eigen::Vector3d::UnitZ(), s, hit));
  EXPECT_TRUE(layer.intersect_ray(Eigen::Vector3d(0.025, 0.01, 0.01), -Eigen::Vector3d::UnitZ(), s, hit));
}

TEST(LayerSurface, ProjectionIsTheFootOfThePerpendicular) {
  const LayerSurface layer = LayerSurface::fit(kSkinTop, kSkinBottom, kRadius, 16);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.0, 0.0, 2e-3), Eigen::Vector3d(0.01, 0.005, 1e-3),
                                   Eigen::Vector3d(-0.02, 0.003, -0.3e-3), Eigen::Vector3d(1e-8, -1e-8, 5e-4)}) {
    const SurfacePoint q = layer.project(p);
    const Eigen::Vector3d d = p - q.position;
    EXPECT_LT(d.cross(q.normal).norm(), 1e-12 * (1.0 + d.norm() / 1e-3)) << p.transpose();
    EXPECT_NEAR(q.position.z(), kSkinTop, layer.top_face_max_error_m() + 1e-15);
    EXPECT_LT(std::hypot(q.position.x() - p.x(), q.position.y() - p.y()), 1e-6);
  }
}

TEST(LayerSurface, NormalsPointOutOfTheLayerEverywhere) {
  const LayerSurface layer = LayerSurface::fit(kMuscleTop, kMuscleBottom, kRadius, 16);
  EXPECT_GT(layer.evaluate(Eigen::Vector3d::UnitZ()).normal.z(), 1.0 - 1e-8);
  EXPECT_LT(layer.evaluate(-Eigen::Vector3d::UnitZ()).normal.z(), -1.0 + 1e-8);
  // Middle of the side (sigma = 1/2): outward radial.
  const double zeta = 0.5 * (layer.profile().options.top_rim_cos_theta + layer.profile().options.bottom_rim_cos_theta);
  for (double phi : {0.0, 1.0, 3.0}) {
    const double s = std::sqrt(1 - zeta * zeta);
    const SurfacePoint p = layer.evaluate(Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), zeta));
    EXPECT_GT(p.normal.dot(Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0)), 0.99);
    EXPECT_NEAR(std::hypot(p.position.x(), p.position.y()), kRadius, 1e-3 * kRadius);
  }
}

TEST(LayerSurface, TessellationIsClosedOutwardAndEnclosesTheDiscVolume) {
  const double top = kMuscleTop, bottom = kMuscleBottom;
  const LayerSurface layer = LayerSurface::fit(top, bottom, kRadius, 24);
  Eigen::MatrixX3d v;
  Eigen::MatrixX3i t;
  const int n_theta = 240, n_phi = 256;
  layer.tessellate(n_theta, n_phi, v, t);
  EXPECT_EQ(v.rows(), 2 + (n_theta - 1) * n_phi);
  EXPECT_EQ(t.rows(), 2 * n_phi * (n_theta - 1));
  // Closed 2-manifold: every directed edge appears once and its reverse once.
  std::map<std::pair<int, int>, int> edges;
  for (int i = 0; i < t.rows(); ++i)
    for (int e = 0; e < 3; ++e) ++edges[{t(i, e), t(i, (e + 1) % 3)}];
  for (const auto& [edge, count] : edges) {
    ASSERT_EQ(count, 1);
    ASSERT_EQ(edges.count({edge.second, edge.first}), 1u);
  }
  // Divergence theorem: V = (1/6) sum (a x b) . c, positive for outward triangles.
  double volume = 0.0;
  for (int i = 0; i < t.rows(); ++i)
    volume += v.row(t(i, 0)).cross(v.row(t(i, 1))).dot(v.row(t(i, 2))) / 6.0;
  const double exact = kPi * kRadius * kRadius * (top - bottom);
  EXPECT_NEAR(volume / exact, 1.0, 2e-3);
}

TEST(LayerSurface, RejectsBadInput) {
  EXPECT_THROW(LayerSurface::fit(0.0, 0.001, kRadius, 8), std::invalid_argument);   // bottom above top
  EXPECT_THROW(LayerSurface::fit(0.001, -0.001, kRadius, 8), std::invalid_argument); // top above the skin plane
  EXPECT_THROW(LayerSurface::fit(0.0, -0.001, 0.0, 8), std::invalid_argument);
  EXPECT_THROW(LayerSurface::fit(0.0, -0.001, kRadius, 1), std::invalid_argument);
  LayerFitOptions bad;
  bad.top_rim_cos_theta = -0.1;
  EXPECT_THROW(LayerSurface::fit(0.0, -0.001, kRadius, 8, bad), std::invalid_argument);
  const LayerSurface layer = LayerSurface::fit(0.0, -0.001, kRadius, 8);
  Eigen::MatrixX3d v;
  Eigen::MatrixX3i t;
  EXPECT_THROW(layer.tessellate(1, 8, v, t), std::invalid_argument);
}

TEST(LayerSurface, DegreeThirtyTwoFits) {
  const LayerSurface layer = LayerSurface::fit(kSkinTop, kSkinBottom, kRadius, 32);
  EXPECT_EQ(layer.fit_report().unknowns, 33 * 33);
  EXPECT_LT(layer.top_face_max_error_m(), 1e-4 * (kSkinTop - kSkinBottom));
  double s;
  SurfacePoint hit;
  ASSERT_TRUE(layer.intersect_ray(Eigen::Vector3d(1e-6, 0, 0.01), -Eigen::Vector3d::UnitZ(), s, hit));
  EXPECT_NEAR(hit.position.z(), kSkinTop, layer.top_face_max_error_m());
}

}  // namespace
}  // namespace puncture
