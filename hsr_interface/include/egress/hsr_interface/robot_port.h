#pragma once
/// @file
/// RobotPort: the one boundary between the robot brain and a robot. The digital twin and the
/// real-robot bridge each implement it; perception, planning and the executive see nothing
/// else of the robot.
///
/// One control cycle: the executive calls Sense() once, updates its world model, decides, then
/// sends any of the four commands. Commands are validated here, before they reach an
/// implementation, so a NaN or malformed command never drives a motor.

#include <optional>
#include <vector>

#include "egress/hsr_interface/clock.h"
#include "egress/hsr_interface/command_types.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_state_types.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress {

/// Everything the robot brain reads in one cycle. Sensors run at their own rates: an empty
/// optional or list means that sensor produced nothing new since the previous Sense().
struct SensorSnapshot {
  Time stamp{};                       ///< Robot clock time at which the snapshot was taken.
  std::optional<LaserScan> scan;      ///< Latest base laser sweep (frame L).
  std::optional<DepthImage> depth;    ///< Latest head depth image (frame C).
  CameraIntrinsics depth_intrinsics;  ///< Intrinsics of `depth` (and of detections' image).
  std::optional<Pose3> X_BC;          ///< Camera pose in the base at `depth`'s capture time.
  /// Latest head colour image, from a robot that gives images rather than detections (the
  /// executive's detector stage runs on it); the twin leaves it empty and gives `detections`.
  std::optional<ColorImage> color;
  std::vector<Detection2D> detections;  ///< Detections produced since the previous Sense().
  Odometry odometry;                    ///< Latest wheel odometry.
  JointState joints;                    ///< Latest joint states (arm, head, gripper).
  GripperState gripper;                 ///< Latest gripper state.

  /// Validates every present field. @throws InvalidArgument naming the field.
  void Validate() const;
};

/// The robot as the brain sees it. Implementations: the twin's port, the real-HSR bridge.
class RobotPort {
 public:
  virtual ~RobotPort() = default;
  RobotPort(const RobotPort&) = delete;
  RobotPort& operator=(const RobotPort&) = delete;

  /// Reads the sensors. The result is validated before it is returned.
  SensorSnapshot Sense();
  /// Commands the base velocity V_B (expressed in the base frame). The robot holds it until the
  /// next command or its own command timeout. @throws InvalidArgument for a non-finite twist.
  void SendBaseVelocity(const Twist2& V_B);
  /// Sends an arm trajectory, replacing any running one. @throws InvalidArgument if malformed.
  void SendArmTrajectory(const JointTrajectory& trajectory);
  /// Commands the gripper. @throws InvalidArgument if malformed.
  void SendGripperCommand(const GripperCommand& command);
  /// Points the head (pan, tilt), replacing any head target an arm trajectory set.
  /// @throws InvalidArgument for a non-finite target.
  void SendHeadCommand(const HeadCommand& command);
  /// The robot's clock: simulated in the twin, steady on the real robot.
  virtual const Clock& clock() const = 0;

 protected:
  RobotPort() = default;
  virtual SensorSnapshot DoSense() = 0;
  virtual void DoSendBaseVelocity(const Twist2& V_B) = 0;
  virtual void DoSendArmTrajectory(const JointTrajectory& trajectory) = 0;
  virtual void DoSendGripperCommand(const GripperCommand& command) = 0;
  virtual void DoSendHeadCommand(const HeadCommand& command) = 0;
};

}  // namespace egress
