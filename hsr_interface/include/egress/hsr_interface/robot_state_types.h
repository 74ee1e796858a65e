#pragma once
/// @file
/// Proprioception: joint states, wheel odometry and the gripper's state.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/time.h"

namespace egress {

/// Positions [rad or m], velocities and efforts of named joints. velocities and efforts are
/// empty or the same size as names.
struct JointState {
  Time stamp{};
  std::vector<std::string> names;
  std::vector<double> positions;
  std::vector<double> velocities;
  std::vector<double> efforts;

  /// The position of `name`, or nullopt if the joint is not in this state.
  std::optional<double> Position(std::string_view name) const;
  /// @throws InvalidArgument on size mismatch, duplicate or empty names, non-finite values.
  void Validate() const;
};

/// Wheel odometry: the base pose X_OB in the odometry frame O, the base velocity V_B expressed
/// in B, and the 3x3 covariance of (x, y, yaw) [m², rad²].
struct Odometry {
  Time stamp{};
  Pose2 X_OB;
  Twist2 V_B;
  Eigen::Matrix3d covariance{Eigen::Matrix3d::Zero()};
  /// @throws InvalidArgument on non-finite values or a covariance that is not symmetric PSD.
  void Validate() const;
};

/// State of the two-finger gripper.
struct GripperState {
  Time stamp{};
  double hand_motor_position{0.0};  ///< hand_motor_joint angle [rad]; larger is more open.
  double effort{0.0};               ///< Grip force [N], >= 0.
  void Validate() const;
};

}  // namespace egress
