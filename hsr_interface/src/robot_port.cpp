#include "egress/hsr_interface/robot_port.h"

#include "egress/hsr_interface/error.h"

namespace egress {

void SensorSnapshot::Validate() const {
  if (scan) scan->Validate();
  if (depth) {
    depth->Validate();
    depth_intrinsics.Validate();
    ThrowUnless(depth->width == depth_intrinsics.width && depth->height == depth_intrinsics.height,
                "Invalid SensorSnapshot: depth image ", depth->width, "x", depth->height,
                " does not match its intrinsics ", depth_intrinsics.width, "x",
                depth_intrinsics.height, ".");
    ThrowUnless(X_BC.has_value(), "Invalid SensorSnapshot: a depth image needs X_BC.");
  }
  if (X_BC) ThrowUnless(X_BC->IsFinite(), "Invalid SensorSnapshot: X_BC must be finite.");
  if (color) color->Validate();
  for (const auto& detection : detections)
    detection.Validate();
  odometry.Validate();
  joints.Validate();
  gripper.Validate();
}

SensorSnapshot RobotPort::Sense() {
  SensorSnapshot snapshot = DoSense();
  snapshot.Validate();
  return snapshot;
}

void RobotPort::SendBaseVelocity(const Twist2& V_B) {
  ThrowUnless(V_B.IsFinite(), "Invalid base velocity command: (", V_B.vx, ", ", V_B.vy, ", ",
              V_B.wz, ") must be finite.");
  DoSendBaseVelocity(V_B);
}

void RobotPort::SendArmTrajectory(const JointTrajectory& trajectory) {
  trajectory.Validate();
  DoSendArmTrajectory(trajectory);
}

void RobotPort::SendGripperCommand(const GripperCommand& command) {
  command.Validate();
  DoSendGripperCommand(command);
}

void RobotPort::SendHeadCommand(const HeadCommand& command) {
  command.Validate();
  DoSendHeadCommand(command);
}

}  // namespace egress
