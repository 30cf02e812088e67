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

TEST(Resumption, ApproachesGoalMonotonicallyAndArrivesAfterCeilSteps) {
  // A dented disc: rest on z = 0, the broken surface pushed down near the centre.
  const int n = 19;
  Eigen::Matrix3Xd rest(3, n), broken(3, n);
  for (int i = 0; i < n; ++i) {
    const double a = 0.33 * i, r = 1e-3 * (i % 5);
    rest.col(i) = Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0);
    broken.col(i) = rest.col(i) - Eigen::Vector3d(0, 0, 2e-3 * std::exp(-r * r / 4e-6));
  }
  const Eigen::VectorXd masses = Eigen::VectorXd::Constant(n, 1e-6);
  for (double rate : {0.05, 0.3, 0.07, 1.0}) {
    SurfaceResumption res(rest, masses, rate);
    res.start(broken);
    EXPECT_DOUBLE_EQ(res.recovery_factor(), 1.0);
    Eigen::Matrix3Xd goal(3, n);
    shape_matching_goals(rest, broken, masses, goal);
    double previous = (broken - goal).norm();
    const int expected_steps = static_cast<int>(std::ceil(1.0 / rate - 1e-12));
    for (int s = 1; s <= expected_steps; ++s) {
      res.step();
      const double distance = (res.positions() - goal).norm();
      EXPECT_LT(distance, previous + 1e-15) << "rate " << rate << " step " << s;
      // Eq. 8: distance to the goal = eta * initial distance.
      EXPECT_NEAR(distance, res.recovery_factor() * (broken - goal).norm(), 1e-12);
      previous = distance;
      if (s < expected_steps) EXPECT_GT(res.recovery_factor(), 0.0);
    }
    EXPECT_EQ(res.recovery_factor(), 0.0);
    EXPECT_LT((res.positions() - goal).cwiseAbs().maxCoeff(), 1e-15);
    res.step();  // no further motion once at the goal
    EXPECT_EQ(res.steps_taken(), expected_steps);
  }
  EXPECT_THROW(SurfaceResumption(rest, masses, 0.0), std::invalid_argument);
  EXPECT_THROW(SurfaceResumption(rest, masses, 1.5), std::invalid_argument);
}

TEST(Resumption, SingleNodeSetStaysFinite) {
  Eigen::Matrix3Xd rest = Eigen::Matrix3Xd::Zero(3, 1), broken(3, 1);
  broken << 0, 0, -1e-3;
  SurfaceResumption res(rest, Eigen::VectorXd::Ones(1), 0.5);
  res.start(broken);
  res.step();
  res.step();
  EXPECT_TRUE(res.positions().allFinite());
  // A single node is its own centre of mass: its goal is where it is.
  EXPECT_LT((res.positions() - broken).norm(), 1e-15);
}
