#pragma once
/// @file
/// What the robot brain commands: arm joint trajectories and the gripper. Base velocity
/// commands are a Twist2 (see geometry.h).

#include <string>
#include <vector>

#include "egress/hsr_interface/time.h"

namespace egress {

/// One knot of a joint trajectory. velocities/accelerations are empty or match positions.
struct JointTrajectoryPoint {
  std::vector<double> positions;
  std::vector<double> velocities;
  std::vector<double> accelerations;
  Duration time_from_start{};
};

/// A timed sequence of joint positions for the named joints, starting at `start` (a time of
/// the robot's clock; 0 means "as soon as received").
struct JointTrajectory {
  Time start{};
  std::vector<std::string> joint_names;
  std::vector<JointTrajectoryPoint> points;
  /// @throws InvalidArgument on empty/duplicate names, size mismatch, non-finite values, or
  /// time_from_start not strictly increasing.
  void Validate() const;
};

/// Where the head points: pan and tilt joint targets [rad] (the HSR's head_pan_joint and
/// head_tilt_joint; the robot moves there at its joints' own speed and clamps to their limits).
struct HeadCommand {
  double pan{0.0};   ///< head_pan_joint target [rad], + to the left.
  double tilt{0.0};  ///< head_tilt_joint target [rad], + up.
  /// @throws InvalidArgument on a non-finite target.
  void Validate() const;
};

/// A command to the gripper.
struct GripperCommand {
  enum class Mode {
    kOpen,      ///< Open fully.
    kGrasp,     ///< Close until the fingers stop on an object, squeezing with `effort`.
    kPosition,  ///< Move hand_motor_joint to `position`.
  };
  Mode mode{Mode::kOpen};
  double position{0.0};  ///< Target hand_motor_joint angle [rad] for kPosition.
  double effort{0.0};    ///< Grip force [N] for kGrasp, >= 0.
  /// @throws InvalidArgument on a non-finite target or a negative effort.
  void Validate() const;
};

}  // namespace egress
