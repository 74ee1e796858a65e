#include "egress/hsr_interface/geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "egress/hsr_interface/error.h"

namespace egress {

Eigen::Vector2d ClosestPointOnSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                      const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) * ab;
}

double WrapAngle(double angle) {
  if (!std::isfinite(angle)) return angle;
  double wrapped = std::remainder(angle, 2.0 * std::numbers::pi);  // in [-pi, pi]
  if (wrapped <= -std::numbers::pi) wrapped += 2.0 * std::numbers::pi;
  return wrapped;
}

Pose2 Pose2::operator*(const Pose2& X_BC) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {x + c * X_BC.x - s * X_BC.y, y + s * X_BC.x + c * X_BC.y, WrapAngle(yaw + X_BC.yaw)};
}

Eigen::Vector2d Pose2::operator*(const Eigen::Vector2d& p_BQ) const {
  return rotation() * p_BQ + translation();
}

Pose2 Pose2::Inverse() const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {-c * x - s * y, s * x - c * y, WrapAngle(-yaw)};
}

Eigen::Matrix2d Pose2::rotation() const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Eigen::Matrix2d R;
  R << c, -s, s, c;
  return R;
}

bool Pose2::IsFinite() const {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(yaw);
}

bool Twist2::IsFinite() const {
  return std::isfinite(vx) && std::isfinite(vy) && std::isfinite(wz);
}

namespace {
constexpr double kRotationTolerance = 1e-6;
}  // namespace

Pose3::Pose3(const Eigen::Matrix3d& R_AB, const Eigen::Vector3d& p_AB) : R_(R_AB), p_(p_AB) {
  ThrowUnless(R_AB.allFinite() && p_AB.allFinite(), "Invalid Pose3: rotation and translation ",
              "must be finite.");
  const double orthonormality_error =
      (R_AB * R_AB.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  ThrowUnless(orthonormality_error < kRotationTolerance && R_AB.determinant() > 0.0,
              "Invalid Pose3: rotation matrix must be orthonormal with determinant +1 ",
              "(orthonormality error ", orthonormality_error, ").");
}

Pose3::Pose3(const Eigen::Quaterniond& q_AB, const Eigen::Vector3d& p_AB) : p_(p_AB) {
  ThrowUnless(q_AB.coeffs().allFinite() && p_AB.allFinite(),
              "Invalid Pose3: quaternion and translation must be finite.");
  ThrowUnless(q_AB.norm() > 1e-12, "Invalid Pose3: quaternion must be non-zero.");
  R_ = q_AB.normalized().toRotationMatrix();
}

Pose3::Pose3(const Eigen::Vector3d& p_AB) : p_(p_AB) {
  ThrowUnless(p_AB.allFinite(), "Invalid Pose3: translation must be finite.");
}

Pose3 Pose3::FromXyzRpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  ThrowUnless(xyz.allFinite() && rpy.allFinite(), "Invalid Pose3: xyz and rpy must be finite.");
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  return Pose3(R, xyz, Unchecked{});
}

Pose3 Pose3::FromPose2(const Pose2& X_AB) {
  return FromXyzRpy(Eigen::Vector3d(X_AB.x, X_AB.y, 0.0), Eigen::Vector3d(0.0, 0.0, X_AB.yaw));
}

Eigen::Vector3d Pose3::rpy() const {
  // Inverse of R = Rz(yaw) Ry(pitch) Rx(roll).
  const double pitch = std::asin(std::clamp(-R_(2, 0), -1.0, 1.0));
  double roll, yaw;
  if (std::abs(R_(2, 0)) < 1.0 - 1e-12) {
    roll = std::atan2(R_(2, 1), R_(2, 2));
    yaw = std::atan2(R_(1, 0), R_(0, 0));
  } else {  // Gimbal lock: roll and yaw share one axis; put it all in yaw.
    roll = 0.0;
    yaw = std::atan2(-R_(0, 1), R_(1, 1));
  }
  return {roll, pitch, yaw};
}

Eigen::Isometry3d Pose3::ToIsometry() const {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_;
  X.translation() = p_;
  return X;
}

Pose2 Pose3::ToPose2() const {
  return {p_.x(), p_.y(), std::atan2(R_(1, 0), R_(0, 0))};
}

Pose3 Pose3::Inverse() const {
  const Eigen::Matrix3d R_BA = R_.transpose();
  return Pose3(R_BA, -(R_BA * p_), Unchecked{});
}

bool Pose3::IsFinite() const {
  return R_.allFinite() && p_.allFinite();
}

bool Pose3::IsNearlyEqualTo(const Pose3& other, double tolerance) const {
  const double angle = Eigen::AngleAxisd(R_.transpose() * other.R_).angle();
  return (p_ - other.p_).norm() <= tolerance && std::abs(angle) <= tolerance;
}

}  // namespace egress
