// Shape matching (Eq. 6-7) and surface resumption (Eq. 8).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <random>
#include <vector>

#include "puncture/resumption.hpp"
#include "puncture/shape_matching.hpp"

using namespace puncture;

namespace {

Eigen::Matrix3Xd random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1e-2, 1e-2);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

bool is_rotation(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-12 && std::abs(R.determinant() - 1.0) < 1e-12;
}

}  // namespace

TEST(ShapeMatching, RigidMotionIsRecoveredExactly) {
  const Eigen::Matrix3Xd rest = random_points(20, 1);
  Eigen::VectorXd masses = Eigen::VectorXd::LinSpaced(20, 1e-6, 3e-6);
  const Eigen::Matrix3d R_true = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(1e-3, -2e-3, 5e-3);
  const Eigen::Matrix3Xd current = (R_true * rest).colwise() + t;

  const Eigen::Matrix3d R = rotation_of_polar_decomposition(shape_matching_moment(rest, current, masses));
  EXPECT_LT((R - R_true).norm(), 1e-12);
  Eigen::Matrix3Xd goals(3, 20);
  shape_matching_goals(rest, current, masses, goals);
  EXPECT_LT((goals - current).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ShapeMatching, MomentMatrixMatchesDefinition) {
  // Two unit masses: A = sum (p - cm)(p0 - cm0)^T written out by hand.
  Eigen::Matrix3Xd rest(3, 2), current(3, 2);
  rest << 0, 2, 0, 0, 0, 0;
  current << 0, 0, 0, 2, 0, 0;
  const Eigen::Matrix3d A = shape_matching_moment(rest, current, Eigen::Vector2d(1, 1));
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected(1, 0) = 2.0;  // (0,-1,0)(-1,0,0)^T + (0,1,0)(1,0,0)^T
  EXPECT_LT((A - expected).norm(), 1e-15);
  // The rest x axis is now the y axis: R is the 90 degree rotation about z.
  const Eigen::Matrix3d R = rotation_of_polar_decomposition(A);
  EXPECT_TRUE(is_rotation(R));
  EXPECT_LT((R * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

TEST(ShapeMatching, ReflectedMomentGivesProperRotation) {
  const Eigen::Matrix3Xd rest = random_points(12, 2);
  Eigen::Matrix3Xd mirrored = rest;
  mirrored.row(0) *= -1.0;  // a reflection: det A < 0
  const Eigen::VectorXd masses = Eigen::VectorXd::Ones(12);
  const Eigen::Matrix3d A = shape_matching_moment(rest, mirrored, masses);
  ASSERT_LT(A.determinant(), 0.0);
  const Eigen::Matrix3d R = rotation_of_polar_decomposition(A);
  EXPECT_TRUE(is_rotation(R));
  // R^T A is symmetric (stationarity of ||A - R||_F over rotations) ...
  const Eigen::Matrix3d S = R.transpose() * A;
  EXPECT_LT((S - S.transpose()).norm(), 1e-10 * A.norm());
  // ... and R is the closest rotation: no random rotation is closer to A.
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Matrix3d Q = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    EXPECT_LE((A - A.norm() * R).norm(), (A - A.norm() * Q).norm() + 1e-15);
  }
}

TEST(ShapeMatching, DegenerateSetsGiveFiniteGoalsAndRotation) {
  const Eigen::VectorXd masses = Eigen::VectorXd::Ones(6);
  Eigen::Matrix3Xd same = Eigen::Matrix3Xd::Zero(3, 6);
  same.colwise() += Eigen::Vector3d(1e-3, 2e-3, 3e-3);  // all points equal: A = 0
  Eigen::Matrix3Xd line(3, 6), plane(3, 6);
  for (int i = 0; i < 6; ++i) {
    line.col(i) = Eigen::Vector3d(i * 1e-3, 0, 0);
    plane.col(i) = Eigen::Vector3d(i * 1e-3, (i % 3) * 1e-3, 0);
  }
  const Eigen::Matrix3Xd random = random_points(6, 3);
  Eigen::Matrix3Xd goals(3, 6);
  const std::vector<const Eigen::Matrix3Xd*> sets{&same, &line, &plane, &random};
  for (const Eigen::Matrix3Xd* rest : sets)
    for (const Eigen::Matrix3Xd* current : sets) {
      const Eigen::Matrix3d R = rotation_of_polar_decomposition(shape_matching_moment(*rest, *current, masses));
      EXPECT_TRUE(is_rotation(R));
      shape_matching_goals(*rest, *current, masses, goals);
      EXPECT_TRUE(goals.allFinite());
    }
  EXPECT_TRUE(rotation_of_polar_decomposition(Eigen::Matrix3d::Zero()).isIdentity(0.0));
}

TEST(ShapeMatching, RejectsNonFiniteAndMismatchedInput) {
  Eigen::Matrix3Xd p = random_points(4, 4), g(3, 4);
  Eigen::Matrix3Xd bad = p;
  bad(1, 2) = std::nan("");
  EXPECT_THROW(shape_matching_goals(p, bad, Eigen::VectorXd::Ones(4), g), std::invalid_argument);
  EXPECT_THROW(shape_matching_goals(p, p, Eigen::VectorXd::Ones(3), g), std::invalid_argument);
  EXPECT_THROW(shape_matching_goals(p, p, Eigen::VectorXd::Zero(4), g), std::invalid_argument);
}

TEST(Resumption, ReturnsToTheRestShapeInTheRecoveryTimeWhateverTheStep) {
  // A dented disc: rest on z = 0, the broken surface pushed down near the
  // centre (all nodes below rest: its centre of mass is sunk, which a
  // rigid-fit goal would keep).
  const int n = 19;
  Eigen::Matrix3Xd rest(3, n), broken(3, n);
  for (int i = 0; i < n; ++i) {
    const double a = 0.33 * i, r = 1e-3 * (i % 5);
    rest.col(i) = Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0);
    broken.col(i) = rest.col(i) - Eigen::Vector3d(0, 0, 2e-3 * std::exp(-r * r / 4e-6));
  }
  const double T = 0.02, t_break = 1.3;
  const double initial = (broken - rest).norm();
  // Eq. 8 with eta = 1 - (t - t_b) / T: the distance to the rest shape at
  // time t is (1 - (t - t_b) / T) times the initial one, for any step.
  for (double dt : {1e-3, 2.5e-4, 7e-3}) {
    SurfaceResumption res(rest, T);
    res.start(broken, t_break);
    EXPECT_DOUBLE_EQ(res.recovery_factor(), 1.0);
    double previous = initial;
    for (int s = 1; t_break + s * dt <= t_break + T + 2 * dt; ++s) {
      const double t = t_break + s * dt;
      res.step(t);
      const double distance = (res.positions() - rest).norm();
      const double eta = std::max(0.0, 1.0 - s * dt / T);
      EXPECT_NEAR(distance, eta * initial, 1e-9 * initial) << "dt " << dt << " step " << s;
      EXPECT_LE(distance, previous + 1e-15);
      previous = distance;
    }
    EXPECT_EQ(res.recovery_factor(), 0.0);
    EXPECT_TRUE(res.recovered());
    // Back at rest: not at a sunk copy of it (mean height 0, not the broken mean).
    EXPECT_LT((res.positions() - rest).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_NEAR(res.positions().row(2).mean(), 0.0, 1e-15);
    EXPECT_LT(broken.row(2).mean(), -1e-4);
  }
  EXPECT_THROW(SurfaceResumption(rest, 0.0), std::invalid_argument);
  EXPECT_THROW(SurfaceResumption(rest, -1.0), std::invalid_argument);
}

TEST(Resumption, RigidFitGoalWouldLeaveTheSurfaceSunk) {
  // Why the goal is the rest shape: Eq. (6)-(7)'s goal for the dented disc
  // keeps the dented centre of mass.
  const int n = 7;
  Eigen::Matrix3Xd rest(3, n), broken(3, n), goal(3, n);
  for (int i = 0; i < n; ++i) {
    const double a = i * M_PI / 3.0, r = i == 0 ? 0.0 : 1e-3;
    rest.col(i) = Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0);
    broken.col(i) = rest.col(i) - Eigen::Vector3d(0, 0, i == 0 ? 1e-3 : 0.4e-3);
  }
  shape_matching_goals(rest, broken, Eigen::VectorXd::Ones(n), goal);
  const double sunk = broken.row(2).mean();  // (1 + 6 x 0.4) / 7 mm below rest
  EXPECT_NEAR(sunk, -(1e-3 + 6 * 0.4e-3) / 7.0, 1e-15);
  EXPECT_NEAR(goal.row(2).mean(), sunk, 1e-15);
  SurfaceResumption res(rest, 0.01);
  res.start(broken, 0.0);
  res.step(0.01);
  EXPECT_NEAR(res.positions().row(2).mean(), 0.0, 1e-18);
}

TEST(Resumption, SingleNodeReturnsToRest) {
  // A one-node mesh (w = 1): shape matching has nothing to match (A = 0),
  // but the rest-shape goal still brings it back.
  Eigen::Matrix3Xd rest = Eigen::Matrix3Xd::Zero(3, 1), broken(3, 1);
  broken << 0, 0, -1e-3;
  SurfaceResumption res(rest, 0.5);
  res.start(broken, 0.0);
  res.step(0.25);
  EXPECT_NEAR(res.positions()(2, 0), -0.5e-3, 1e-15);
  res.step(0.5);
  EXPECT_TRUE(res.positions().allFinite());
  EXPECT_LT((res.positions() - rest).norm(), 1e-15);
}

TEST(SurfaceResumption, MovedGoalsCarryTheBrokenShapeAlong) {
  // Halfway through the recovery the goals move by t: the nodes, their broken
  // positions and their goals all move by t, so the current positions move by t
  // and the recovery goes on (eta unchanged).
  Eigen::Matrix3Xd rest(3, 2), broken(3, 2);
  rest << 0.0, 1.0, 0.0, 0.0, 0.0, 0.0;
  broken << 0.0, 1.0, 0.0, 0.0, -2.0, -1.0;
  SurfaceResumption r(rest, 1.0);
  r.start(broken, 0.0);
  r.step(0.5);
  const Eigen::Matrix3Xd before = r.positions();
  const Eigen::Vector3d t(0.1, -0.2, 0.3);
  Eigen::Matrix3Xd moved = rest;
  moved.colwise() += t;
  r.move_goals(moved);
  EXPECT_TRUE(r.active());
  EXPECT_DOUBLE_EQ(r.recovery_factor(), 0.5);
  Eigen::Matrix3Xd expected = before;
  expected.colwise() += t;
  EXPECT_NEAR((r.positions() - expected).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  r.step(1.0);
  EXPECT_NEAR((r.positions() - moved).cwiseAbs().maxCoeff(), 0.0, 1e-15);
}
