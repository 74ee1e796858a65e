#pragma once
/// @file
/// Conversions between egress's robot types and ROS 2 messages (the fastddsgen types generated
/// from ROS 2's message IDL). Pure functions: no DDS here.
///
/// Conventions (ROS REPs 103/105/117): stamps are {sec, nanosec} of the producing clock (egress's
/// Time is nanoseconds of that clock); nav_msgs/Odometry's pose is X_OB in header.frame_id
/// ("odom") and its twist is expressed in child_frame_id (the base), as egress's Odometry::V_B;
/// a laser range of +inf is "no return", NaN "invalid"; depth images are "32FC1" metres (NaN:
/// no return) on output, "32FC1" or "16UC1" millimetres (0: no return) on input.
///
/// FromRos functions check what the message's own layout requires (sizes, encodings) and throw
/// InvalidArgument naming the message type and field; the egress values' own checks (finite,
/// ordered) are the RobotPort boundary's (SensorSnapshot::Validate).

#include <optional>
#include <string_view>
#include <vector>

#include <builtin_interfaces/msg/Duration.h>
#include <builtin_interfaces/msg/Time.h>
#include <geometry_msgs/msg/Transform.h>
#include <geometry_msgs/msg/Twist.h>
#include <nav_msgs/msg/Odometry.h>
#include <sensor_msgs/msg/CameraInfo.h>
#include <sensor_msgs/msg/Image.h>
#include <sensor_msgs/msg/JointState.h>
#include <sensor_msgs/msg/LaserScan.h>
#include <tmc_control_msgs/action/GripperApplyEffort.h>
#include <trajectory_msgs/msg/JointTrajectory.h>
#include <vision_msgs/msg/Detection2DArray.h>

#include "egress/hsr_interface/command_types.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_state_types.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/hsr_interface/time.h"

namespace egress::ros2 {

/// @throws InvalidArgument for a time before the clock's epoch or past 2^31 s (ROS's int32 sec).
builtin_interfaces::msg::Time ToRos(Time t);
/// @throws InvalidArgument for nanosec >= 1e9.
Time FromRos(const builtin_interfaces::msg::Time& t);
builtin_interfaces::msg::Duration DurationToRos(Duration d);
Duration FromRos(const builtin_interfaces::msg::Duration& d);

sensor_msgs::msg::LaserScan ToRos(const LaserScan& scan);
LaserScan FromRos(const sensor_msgs::msg::LaserScan& msg);

/// "32FC1", row-major, little-endian floats in metres.
sensor_msgs::msg::Image ToRos(const DepthImage& depth);
/// Accepts "32FC1" (metres) and "16UC1" (millimetres, 0 = no return).
DepthImage DepthFromRos(const sensor_msgs::msg::Image& msg);
/// "bgr8".
sensor_msgs::msg::Image ToRos(const ColorImage& color);
/// Accepts "bgr8" and "rgb8".
ColorImage ColorFromRos(const sensor_msgs::msg::Image& msg);

/// A pinhole camera without distortion ("plumb_bob" with zero coefficients).
sensor_msgs::msg::CameraInfo ToRos(const CameraIntrinsics& intrinsics, Time stamp,
                                   std::string_view frame_id);
/// Reads K (fx, fy, cx, cy) and the size. @throws InvalidArgument for an uncalibrated K.
CameraIntrinsics FromRos(const sensor_msgs::msg::CameraInfo& msg);

sensor_msgs::msg::JointState ToRos(const JointState& joints);
JointState FromRos(const sensor_msgs::msg::JointState& msg);

/// The covariance's (x, y, yaw) block goes to the 6x6 (x, y, z, roll, pitch, yaw) matrices; the
/// other diagonal entries are large (a planar base knows nothing of z, roll, pitch).
nav_msgs::msg::Odometry ToRos(const Odometry& odometry);
/// Reads x, y and the yaw of the orientation quaternion, the twist's vx, vy, wz and the
/// (x, y, yaw) covariance block. @throws InvalidArgument for a zero quaternion.
Odometry FromRos(const nav_msgs::msg::Odometry& msg);

geometry_msgs::msg::Twist ToRos(const Twist2& V_B);
Twist2 FromRos(const geometry_msgs::msg::Twist& msg);

geometry_msgs::msg::Transform ToRos(const Pose3& X_AB);
/// @throws InvalidArgument for a zero quaternion.
Pose3 FromRos(const geometry_msgs::msg::Transform& msg);

/// header.stamp is the trajectory's start (0: as soon as received, as in ROS).
trajectory_msgs::msg::JointTrajectory ToRos(const JointTrajectory& trajectory);
JointTrajectory FromRos(const trajectory_msgs::msg::JointTrajectory& msg);

/// The HSR's hand_motor_joint fully open [rad] (its URDF's upper limit).
inline constexpr double kHandOpenRad = 1.24;

/// A gripper command as the HSR's ROS 2 gripper controller takes it: a goal of one of its
/// tmc_control_msgs/action/GripperApplyEffort actions. A grasp is `apply_force` with the grip
/// force [N] (the controller closes until the fingers press with it); open is `grasp` with a
/// positive motor torque [Nm] (`open_torque`: the hand opens until its stop).
struct GripperGoal {
  enum class Action { kGrasp, kApplyForce };
  Action action{Action::kGrasp};
  tmc_control_msgs::action::GripperApplyEffort_Goal goal;
};
/// The HSR's default opening torque for GripperToRos [Nm].
inline constexpr double kHandOpenTorqueNm = 0.8;
/// @throws InvalidArgument for a position command: the HSR takes positions only as a
/// control_msgs FollowJointTrajectory action, which is not built (no egress task sends one).
GripperGoal GripperToRos(const GripperCommand& command, double open_torque = kHandOpenTorqueNm);
/// @throws InvalidArgument for a goal the twin cannot carry out (a closing `grasp` torque: the
/// twin grips with a force, take `apply_force`), or a non-finite or negative force.
GripperCommand GripperFromRos(const GripperGoal& goal);

/// [rad/s] The HSR's head joints' speed (hsrb.urdf's velocity limit): a head command's point
/// is timed to reach its target no faster.
inline constexpr double kHeadSpeedRadPerSec = 1.0;
/// A head command as the HSR's head_trajectory_controller takes it: one point for
/// head_pan_joint and head_tilt_joint, timed from the measured head joints in `from` (if it has
/// them) at kHeadSpeedRadPerSec, at least 0.1 s.
JointTrajectory HeadTrajectory(const HeadCommand& command, const std::optional<JointState>& from);
/// The head command a head trajectory ends in (its last point).
/// @throws InvalidArgument unless it names head_pan_joint and head_tilt_joint (and nothing
/// else) and has a point.
HeadCommand HeadFromTrajectory(const JointTrajectory& trajectory);

/// Detections of one image (all with its capture stamp): one Detection2D per box, its label the
/// hypothesis' class_id and its confidence the score.
vision_msgs::msg::Detection2DArray ToRos(const std::vector<Detection2D>& detections, Time stamp,
                                         std::string_view frame_id);
/// @throws InvalidArgument for a detection without a hypothesis or with a rotated box.
std::vector<Detection2D> FromRos(const vision_msgs::msg::Detection2DArray& msg);

}  // namespace egress::ros2
