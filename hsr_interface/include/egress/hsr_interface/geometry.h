#pragma once
/// @file
/// Rigid transforms in the plane (SE(2)) and in space (SE(3)), and the planar base twist.
///
/// Frame notation follows Drake's monogram convention: `X_AB` is the pose of frame B measured
/// in (and expressed in) frame A, so `X_AC = X_AB * X_BC`; `p_AQ` is the position of point Q
/// from A's origin, expressed in A. Frames used across egress: W world (ground truth), M map,
/// O odom, B base, C camera, L laser, G gripper palm, D door, P person. Units are SI: metres
/// and radians.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace egress {

/// Wraps an angle to (-pi, pi]. Non-finite input is returned unchanged.
double WrapAngle(double angle);

/// The point of segment ab nearest to p (a for a degenerate segment).
Eigen::Vector2d ClosestPointOnSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                      const Eigen::Vector2d& b);

/// A pose in the plane: position (x, y) [m] and heading yaw [rad] about +z.
struct Pose2 {
  double x{0.0};
  double y{0.0};
  double yaw{0.0};

  /// Composition: for this = X_AB and `X_BC`, returns X_AC (yaw wrapped to (-pi, pi]).
  Pose2 operator*(const Pose2& X_BC) const;
  /// Transforms a point: for this = X_AB and `p_BQ`, returns p_AQ.
  Eigen::Vector2d operator*(const Eigen::Vector2d& p_BQ) const;
  /// For this = X_AB returns X_BA.
  Pose2 Inverse() const;
  Eigen::Vector2d translation() const { return {x, y}; }
  Eigen::Matrix2d rotation() const;
  bool IsFinite() const;
};

/// Velocity of the omnidirectional base, expressed in the base frame B: forward vx [m/s],
/// leftward vy [m/s], yaw rate wz [rad/s].
struct Twist2 {
  double vx{0.0};
  double vy{0.0};
  double wz{0.0};
  bool IsFinite() const;
};

/// A rigid transform in space: rotation R_AB and translation p_AB (see the file comment).
class Pose3 {
 public:
  /// The identity transform.
  Pose3() = default;
  /// @throws InvalidArgument unless R is a rotation matrix (orthonormal, det +1, within 1e-6)
  /// and both are finite.
  Pose3(const Eigen::Matrix3d& R_AB, const Eigen::Vector3d& p_AB);
  /// @throws InvalidArgument unless q is finite and non-zero (it is normalized).
  Pose3(const Eigen::Quaterniond& q_AB, const Eigen::Vector3d& p_AB);
  /// Translation only.
  explicit Pose3(const Eigen::Vector3d& p_AB);
  /// URDF convention: fixed-axis roll about x, then pitch about y, then yaw about z
  /// (R = Rz(yaw) * Ry(pitch) * Rx(roll)).
  static Pose3 FromXyzRpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy);
  /// Lifts a planar pose into space at height z = 0.
  static Pose3 FromPose2(const Pose2& X_AB);
  /// No validation: for hot loops whose rotation is a product of rotations by construction.
  static Pose3 FromTrustedParts(const Eigen::Matrix3d& R_AB, const Eigen::Vector3d& p_AB) {
    return Pose3(R_AB, p_AB, Unchecked{});
  }

  const Eigen::Matrix3d& rotation() const { return R_; }
  const Eigen::Vector3d& translation() const { return p_; }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(R_); }
  /// Roll, pitch, yaw in the URDF convention (see FromXyzRpy).
  Eigen::Vector3d rpy() const;
  Eigen::Isometry3d ToIsometry() const;
  /// Projects onto the plane: (x, y) and the yaw of the x axis about +z.
  Pose2 ToPose2() const;

  Pose3 operator*(const Pose3& X_BC) const { return Pose3(R_ * X_BC.R_, R_ * X_BC.p_ + p_, {}); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_BQ) const { return R_ * p_BQ + p_; }
  Pose3 Inverse() const;
  bool IsFinite() const;
  /// True when rotations differ by at most `tolerance` rad and translations by `tolerance` m.
  bool IsNearlyEqualTo(const Pose3& other, double tolerance) const;

 private:
  struct Unchecked {};
  Pose3(const Eigen::Matrix3d& R, const Eigen::Vector3d& p, Unchecked) : R_(R), p_(p) {}

  Eigen::Matrix3d R_{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_{Eigen::Vector3d::Zero()};
};

}  // namespace egress
