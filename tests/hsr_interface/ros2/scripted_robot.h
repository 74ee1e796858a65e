#pragma once
// A robot whose sensors a test writes and whose commands it reads: for tests of what carries
// them (the DDS bridge), not of the robot.

#include <utility>
#include <vector>

#include "egress/hsr_interface/robot_port.h"

namespace egress::ros2::test_support {

class ScriptedRobot final : public RobotPort {
 public:
  SensorSnapshot next;  ///< What the next Sense() returns (then cleared).
  std::vector<Twist2> velocities;
  std::vector<JointTrajectory> trajectories;
  std::vector<GripperCommand> gripper;
  std::vector<HeadCommand> head;
  SimClock sim_clock;
  const Clock& clock() const override { return sim_clock; }

 protected:
  SensorSnapshot DoSense() override { return std::exchange(next, {}); }
  void DoSendBaseVelocity(const Twist2& V) override { velocities.push_back(V); }
  void DoSendArmTrajectory(const JointTrajectory& t) override { trajectories.push_back(t); }
  void DoSendGripperCommand(const GripperCommand& c) override { gripper.push_back(c); }
  void DoSendHeadCommand(const HeadCommand& c) override { head.push_back(c); }
};

}  // namespace egress::ros2::test_support
