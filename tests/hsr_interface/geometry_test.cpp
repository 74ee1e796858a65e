#include "egress/hsr_interface/geometry.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(WrapAngleTest, MapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(WrapAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapAngle(-kPi), kPi);  // (-pi, pi]: -pi maps to +pi
  EXPECT_NEAR(WrapAngle(3 * kPi / 2), -kPi / 2, 1e-12);
  EXPECT_NEAR(WrapAngle(-7.0), -7.0 + 2 * kPi, 1e-12);
  EXPECT_NEAR(WrapAngle(100.0), std::remainder(100.0, 2 * kPi), 1e-12);
  EXPECT_TRUE(std::isnan(WrapAngle(std::nan(""))));
}

TEST(Pose2Test, CompositionAndInverseRoundTrip) {
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  for (int n = 0; n < 100; ++n) {
    const Pose2 X_AB{u(generator), u(generator), u(generator)};
    const Pose2 X_BC{u(generator), u(generator), u(generator)};
    const Pose2 identity = X_AB * X_AB.Inverse();
    EXPECT_NEAR(identity.x, 0.0, 1e-12);
    EXPECT_NEAR(identity.y, 0.0, 1e-12);
    EXPECT_NEAR(identity.yaw, 0.0, 1e-12);
    // Composition agrees with the 3D transform it lifts to.
    const Pose2 X_AC = X_AB * X_BC;
    const Pose3 X_AC3 = Pose3::FromPose2(X_AB) * Pose3::FromPose2(X_BC);
    EXPECT_NEAR(X_AC.x, X_AC3.translation().x(), 1e-12);
    EXPECT_NEAR(X_AC.y, X_AC3.translation().y(), 1e-12);
    EXPECT_NEAR(WrapAngle(X_AC.yaw - X_AC3.ToPose2().yaw), 0.0, 1e-12);
    // Point transforms compose the same way.
    const Eigen::Vector2d p_CQ(u(generator), u(generator));
    EXPECT_LT((X_AC * p_CQ - X_AB * (X_BC * p_CQ)).norm(), 1e-12);
  }
}

TEST(Pose2Test, KnownComposition) {
  const Pose2 X_MB{1.0, 2.0, kPi / 2};
  const Eigen::Vector2d p_MQ = X_MB * Eigen::Vector2d(1.0, 0.0);  // one metre ahead of the base
  EXPECT_NEAR(p_MQ.x(), 1.0, 1e-12);
  EXPECT_NEAR(p_MQ.y(), 3.0, 1e-12);
  EXPECT_FALSE((Pose2{0, std::nan(""), 0}).IsFinite());
}

TEST(Pose3Test, CompositionInverseAndRpyRoundTrip) {
  std::mt19937 generator(11);
  std::uniform_real_distribution<double> u(-1.4, 1.4);
  for (int n = 0; n < 100; ++n) {
    const Eigen::Vector3d rpy(u(generator), u(generator), u(generator));
    const Eigen::Vector3d xyz(u(generator), u(generator), u(generator));
    const Pose3 X = Pose3::FromXyzRpy(xyz, rpy);
    EXPECT_LT((X.rpy() - rpy).norm(), 1e-9);
    EXPECT_TRUE((X * X.Inverse()).IsNearlyEqualTo(Pose3(), 1e-12));
    EXPECT_TRUE((X.Inverse() * X).IsNearlyEqualTo(Pose3(), 1e-12));
    const Pose3 Y = Pose3::FromXyzRpy(xyz.reverse(), rpy.reverse());
    const Eigen::Vector3d p(0.3, -0.2, 0.9);
    EXPECT_LT(((X * Y) * p - X * (Y * p)).norm(), 1e-12);
    // Quaternion and Isometry views agree with the matrix.
    const Pose3 from_q(X.quaternion(), X.translation());
    EXPECT_TRUE(from_q.IsNearlyEqualTo(X, 1e-12));
    EXPECT_LT((X.ToIsometry() * p - X * p).norm(), 1e-12);
  }
}

TEST(Pose3Test, UrdfRpyConvention) {
  // Fixed axes: roll about x first, then yaw about z. x axis after yaw pi/2 points along +y.
  const Pose3 X = Pose3::FromXyzRpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, kPi / 2));
  EXPECT_LT((X.rotation().col(0) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  const Pose3 optical =
      Pose3::FromXyzRpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(-kPi / 2, 0, -kPi / 2));
  // The camera-optical rotation used in the HSR URDF: optical z is body x, optical x is -body y.
  EXPECT_LT((optical.rotation().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_LT((optical.rotation().col(0) + Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

TEST(Pose3Test, RejectsBadInput) {
  Eigen::Matrix3d scaled = 2.0 * Eigen::Matrix3d::Identity();
  EXPECT_THROW(Pose3(scaled, Eigen::Vector3d::Zero()), InvalidArgument);
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  reflection(2, 2) = -1.0;
  EXPECT_THROW(Pose3(reflection, Eigen::Vector3d::Zero()), InvalidArgument);
  EXPECT_THROW(Pose3(Eigen::Vector3d(0, std::nan(""), 0)), InvalidArgument);
  EXPECT_THROW(Pose3(Eigen::Quaterniond(0, 0, 0, 0), Eigen::Vector3d::Zero()), InvalidArgument);
  EXPECT_THROW(Pose3::FromXyzRpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, INFINITY, 0)),
               InvalidArgument);
}

TEST(Pose3Test, ProjectsToPlanarPose) {
  const Pose2 X_MB{0.5, -1.0, 2.5};
  const Pose2 back = Pose3::FromPose2(X_MB).ToPose2();
  EXPECT_NEAR(back.x, 0.5, 1e-12);
  EXPECT_NEAR(back.y, -1.0, 1e-12);
  EXPECT_NEAR(back.yaw, 2.5, 1e-12);
}

}  // namespace
}  // namespace egress
