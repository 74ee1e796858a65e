#include "egress/hsr_interface/robot_port.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using ::testing::HasSubstr;

// A port that replays a fixed snapshot and records what reaches the robot side: enough to check
// that the boundary validates in both directions.
class RecordingPort final : public RobotPort {
 public:
  SensorSnapshot next;
  std::vector<Twist2> base_commands;
  std::vector<JointTrajectory> arm_commands;
  std::vector<GripperCommand> gripper_commands;
  std::vector<HeadCommand> head_commands;
  SimClock sim_clock;

  const Clock& clock() const override { return sim_clock; }

 protected:
  SensorSnapshot DoSense() override { return next; }
  void DoSendBaseVelocity(const Twist2& V_B) override { base_commands.push_back(V_B); }
  void DoSendArmTrajectory(const JointTrajectory& t) override { arm_commands.push_back(t); }
  void DoSendGripperCommand(const GripperCommand& c) override { gripper_commands.push_back(c); }
  void DoSendHeadCommand(const HeadCommand& c) override { head_commands.push_back(c); }
};

TEST(RobotPortTest, ValidCommandsPassThrough) {
  RecordingPort port;
  port.SendBaseVelocity({0.2, 0.0, 0.1});
  JointTrajectory trajectory;
  trajectory.joint_names = {"arm_flex_joint"};
  trajectory.points = {{{-0.5}, {}, {}, std::chrono::seconds(2)}};
  port.SendArmTrajectory(trajectory);
  port.SendGripperCommand({GripperCommand::Mode::kOpen, 0.0, 0.0});
  port.SendHeadCommand({0.5, -0.1});
  ASSERT_EQ(port.base_commands.size(), 1u);
  ASSERT_EQ(port.head_commands.size(), 1u);
  EXPECT_DOUBLE_EQ(port.head_commands[0].pan, 0.5);
  EXPECT_DOUBLE_EQ(port.base_commands[0].vx, 0.2);
  EXPECT_EQ(port.arm_commands.size(), 1u);
  EXPECT_EQ(port.gripper_commands.size(), 1u);
}

TEST(RobotPortTest, MalformedCommandsNeverReachTheRobot) {
  RecordingPort port;
  EXPECT_THROW(port.SendBaseVelocity({std::nan(""), 0.0, 0.0}), InvalidArgument);
  EXPECT_THROW(port.SendArmTrajectory(JointTrajectory{}), InvalidArgument);
  EXPECT_THROW(port.SendGripperCommand({GripperCommand::Mode::kGrasp, 0.0, -1.0}), InvalidArgument);
  EXPECT_THROW(port.SendHeadCommand({0.0, std::numeric_limits<double>::infinity()}),
               InvalidArgument);
  EXPECT_TRUE(port.head_commands.empty());
  EXPECT_TRUE(port.base_commands.empty());
  EXPECT_TRUE(port.arm_commands.empty());
  EXPECT_TRUE(port.gripper_commands.empty());
}

TEST(RobotPortTest, SenseValidatesWhatTheRobotDelivers) {
  RecordingPort port;
  port.next.odometry.X_OB = {1.0, 0.0, 0.0};
  EXPECT_DOUBLE_EQ(port.Sense().odometry.X_OB.x, 1.0);

  port.next.odometry.X_OB.x = std::nan("");
  EXPECT_THROW(port.Sense(), InvalidArgument);
  port.next.odometry.X_OB.x = 0.0;

  // A depth image must come with matching intrinsics and the camera pose.
  DepthImage depth;
  depth.width = 2;
  depth.height = 2;
  depth.depth.assign(4, 1.0f);
  port.next.depth = depth;
  port.next.depth_intrinsics = CameraIntrinsics::FromHorizontalFov(2, 2, 1.0);
  try {
    port.Sense();
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("X_BC"));
  }
  port.next.X_BC = Pose3();
  EXPECT_NO_THROW(port.Sense());
  port.next.depth_intrinsics = CameraIntrinsics::FromHorizontalFov(4, 2, 1.0);
  EXPECT_THROW(port.Sense(), InvalidArgument);
}

TEST(RobotPortTest, ExposesTheRobotClock) {
  RecordingPort port;
  port.sim_clock.AdvanceBy(std::chrono::milliseconds(100));
  EXPECT_EQ(port.clock().Now(), std::chrono::milliseconds(100));
}

}  // namespace
}  // namespace egress
