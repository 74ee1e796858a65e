#include "egress/ros2/ros2_robot_port.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dds_domain.h"
#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/robot_port_server.h"
#include "hsr_interface/ros2/scripted_robot.h"

namespace egress::ros2 {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

using test_support::ScriptedRobot;

SensorSnapshot Sensors(Time t) {
  SensorSnapshot s;
  s.stamp = t;
  LaserScan scan;
  scan.stamp = t;
  scan.angle_min = -2.0;
  scan.angle_increment = 0.01;
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  scan.ranges.assign(401, 3.0f);
  s.scan = scan;
  s.odometry.stamp = t;
  s.odometry.X_OB = {1.0, 2.0, 0.5};
  s.odometry.V_B = {0.1, 0.0, 0.0};
  s.joints.stamp = t;
  s.joints.names = {"arm_lift_joint", "head_pan_joint"};
  s.joints.positions = {0.2, -0.1};
  s.gripper.stamp = t;
  s.gripper.hand_motor_position = 0.7;
  return s;
}

template <class Pred>
bool Eventually(Pred done, std::chrono::milliseconds limit = 20s) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

struct Bridge {
  ScriptedRobot robot;
  RobotPortServer server;
  Ros2RobotPort brain;
  explicit Bridge(int domain)
      : server(robot, Ros2Topics{}, domain), brain([&] {
          Ros2RobotPortConfig c;
          c.domain_id = domain;
          c.use_sim_time = true;
          return c;
        }()) {}
  // Publishes `s` until the brain has it (sensor data is best effort: the first messages may
  // go before discovery completes). Each retry a nanosecond later, as a new reading: the server
  // publishes odometry and joint states only when they are new.
  void Deliver(const SensorSnapshot& s) {
    // The brain's command writers matched too: a command sent before its reader is matched is
    // lost (volatile topics), and the tests send commands right after delivering.
    ASSERT_TRUE(Eventually([&] { return server.BrainConnected() && brain.CommandsConnected(); }));
    Duration later{0};
    ASSERT_TRUE(Eventually([&] {
      SensorSnapshot copy = s;
      later += Duration{1};
      copy.stamp += later;
      copy.odometry.stamp += later;
      copy.joints.stamp += later;
      robot.next = copy;
      server.PublishSensors();
      return brain.WaitUntil(copy.stamp, 50ms) && !brain.Fault();
    })) << brain.Fault().value_or("");
  }
};

TEST(Ros2RobotPortTest, SensorsAndCommandsCrossTheBridge) {
  const egress::testing::DdsDomain claim;
  Bridge b(claim.id());
  SensorSnapshot s = Sensors(Time{1'000'000'000});
  DepthImage depth;
  depth.stamp = s.stamp;
  depth.width = 4;
  depth.height = 3;
  depth.depth.assign(12, 1.5f);
  s.depth = depth;
  s.depth_intrinsics = CameraIntrinsics::FromHorizontalFov(4, 3, 1.0);
  s.X_BC = Pose3::FromXyzRpy({0.1, 0.0, 1.0}, {-1.57, 0.0, -1.57});
  s.detections = {{"person", 0.9, {1.0, 0.5, 3.0, 2.5}, s.stamp},
                  {"push_button", 0.6, {0.0, 0.0, 1.0, 1.0}, s.stamp}};
  b.Deliver(s);
  std::string missing;
  ASSERT_TRUE(b.brain.WaitForSensors(5s, &missing)) << missing;
  // The images and detections arrive on their own topics, matched later than the scan's:
  // publish and sense until all are in.
  SensorSnapshot got;
  std::vector<Detection2D> detections;
  ASSERT_TRUE(Eventually([&] {
    b.robot.next = s;
    b.server.PublishSensors();
    std::this_thread::sleep_for(10ms);
    SensorSnapshot one = b.brain.Sense();
    for (auto& d : one.detections)
      detections.push_back(d);
    if (one.depth)
      got.depth = one.depth, got.X_BC = one.X_BC, got.depth_intrinsics = one.depth_intrinsics;
    got.odometry = one.odometry;
    got.joints = one.joints;
    got.gripper = one.gripper;
    return got.depth && got.X_BC && detections.size() >= 2;
  }));
  // /clock drives the brain's time (the retries' nanoseconds on).
  EXPECT_NEAR(ToSeconds(b.brain.clock().Now() - s.stamp), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(got.odometry.X_OB.y, 2.0);
  EXPECT_NEAR(got.odometry.X_OB.yaw, 0.5, 1e-12);
  EXPECT_EQ(got.joints.Position("head_pan_joint"), -0.1);
  EXPECT_DOUBLE_EQ(got.gripper.hand_motor_position, 0.7);
  EXPECT_FLOAT_EQ(got.depth->At(3, 2), 1.5f);
  EXPECT_EQ(got.depth_intrinsics.width, 4);
  EXPECT_TRUE(got.X_BC->translation().isApprox(s.X_BC->translation()));
  EXPECT_EQ(detections[0].label, "person");
  EXPECT_DOUBLE_EQ(detections[0].box.u_max, 3.0);
  EXPECT_EQ(detections[1].stamp, s.stamp);

  b.brain.SendBaseVelocity({0.3, -0.1, 0.2});
  JointTrajectory arm;
  arm.joint_names = {"arm_lift_joint"};
  arm.points = {{{0.3}, {}, {}, Duration{1'000'000'000}}};
  b.brain.SendArmTrajectory(arm);
  // The head: a head_trajectory_controller point timed from the joint states (pan -0.1 -> 0.6
  // at 1 rad/s), the server hands the robot the head command it ends in.
  b.brain.SendHeadCommand({0.6, -0.3});
  // The gripper's goals go to the controller's actions (services: a goal sent before the
  // server is matched is lost, as with ROS 2's own clients).
  ASSERT_TRUE(Eventually([&] { return b.brain.GripperConnected(); }));
  b.brain.SendGripperCommand({GripperCommand::Mode::kGrasp, 0.0, 8.0});
  b.brain.SendGripperCommand({GripperCommand::Mode::kOpen, 0.0, 0.0});
  EXPECT_THAT(
      [&] {
        b.brain.SendGripperCommand({GripperCommand::Mode::kPosition, 0.5, 0.0});
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("FollowJointTrajectory")));
  ASSERT_TRUE(Eventually([&] {
    b.server.ApplyCommands();
    return !b.robot.velocities.empty() && !b.robot.trajectories.empty() &&
           b.robot.gripper.size() >= 2 && b.brain.gripper_goals().first == 2 &&
           !b.robot.head.empty();
  }));
  EXPECT_DOUBLE_EQ(b.robot.head[0].pan, 0.6);
  EXPECT_DOUBLE_EQ(b.robot.head[0].tilt, -0.3);
  EXPECT_EQ(b.brain.gripper_goals().second, 0);
  EXPECT_DOUBLE_EQ(b.robot.velocities[0].vy, -0.1);
  EXPECT_EQ(b.robot.trajectories[0].joint_names, arm.joint_names);
  // Two actions, two services: their arrival order is not defined.
  const bool grasp_first = b.robot.gripper[0].mode == GripperCommand::Mode::kGrasp;
  const GripperCommand& grasp = b.robot.gripper[grasp_first ? 0 : 1];
  EXPECT_EQ(grasp.mode, GripperCommand::Mode::kGrasp);
  EXPECT_DOUBLE_EQ(grasp.effort, 8.0);
  EXPECT_EQ(b.robot.gripper[grasp_first ? 1 : 0].mode, GripperCommand::Mode::kOpen);
}

// The brain's command writers report connected only once they see the robot's readers
// themselves, and no longer once the robot has gone.
TEST(Ros2RobotPortTest, CommandsAreConnectedOnlyWhileTheRobotsReadersAreThere) {
  const egress::testing::DdsDomain claim;
  Ros2RobotPortConfig c;
  c.domain_id = claim.id();
  c.use_sim_time = true;
  Ros2RobotPort brain(c);
  EXPECT_FALSE(brain.CommandsConnected());
  {
    ScriptedRobot robot;
    RobotPortServer server(robot, Ros2Topics{}, claim.id());
    EXPECT_TRUE(Eventually([&] { return brain.CommandsConnected(); }));
  }
  EXPECT_TRUE(Eventually([&] { return !brain.CommandsConnected(); }));
}

// A laser that goes quiet while the clock runs on: within its 0.3 s the port says so, and from
// then the base gets only zero, whatever the brain asks. The e-stop does the same.
TEST(Ros2RobotPortTest, AStaleSensorOrAnEstopStopsTheBase) {
  const egress::testing::DdsDomain claim;
  Bridge b(claim.id());
  b.Deliver(Sensors(Time{1'000'000'000}));
  EXPECT_EQ(b.brain.Fault(), std::nullopt);
  // 0.4 s on: odometry and joints keep coming, the scan does not.
  SensorSnapshot no_scan = Sensors(Time{1'400'000'000});
  no_scan.scan.reset();
  ASSERT_TRUE(Eventually([&] {
    b.robot.next = no_scan;
    b.server.PublishSensors();
    return b.brain.WaitUntil(no_scan.stamp, 50ms);
  }));
  const auto fault = b.brain.Fault();
  ASSERT_TRUE(fault.has_value());
  EXPECT_THAT(*fault, HasSubstr("laser stale"));
  EXPECT_THAT(*fault, HasSubstr("/scan"));
  b.brain.SendBaseVelocity({0.5, 0.0, 0.0});
  ASSERT_TRUE(Eventually([&] {
    b.server.ApplyCommands();
    return !b.robot.velocities.empty();
  }));
  EXPECT_EQ(b.robot.velocities.back().vx, 0.0);
  // Sensors back: healthy again; then an e-stop.
  b.Deliver(Sensors(Time{1'500'000'000}));
  b.brain.PublishEstop(true);
  ASSERT_TRUE(Eventually([&] { return b.brain.Fault().has_value(); }));
  EXPECT_THAT(*b.brain.Fault(), HasSubstr("e-stop"));
}

// Commands go out only while fresh: a base velocity decided from a Sense() older than the
// command timeout goes out as zero; a moving base the brain stops commanding is stopped by the
// port; an arm trajectory with an old start stamp is refused.
// The forward speed of the next base command the robot receives (those before it dropped).
double NextForwardSpeed(Bridge& b) {
  b.robot.velocities.clear();
  EXPECT_TRUE(Eventually([&] {
    b.server.ApplyCommands();
    return !b.robot.velocities.empty();
  }));
  return b.robot.velocities.empty() ? std::nan("") : b.robot.velocities.back().vx;
}

TEST(Ros2RobotPortTest, StaleCommandsAreNeverSent) {
  const egress::testing::DdsDomain claim;
  Bridge b(claim.id());
  b.Deliver(Sensors(Time{1'000'000'000}));
  b.brain.Sense();
  b.brain.SendBaseVelocity({0.4, 0.0, 0.0});
  EXPECT_EQ(NextForwardSpeed(b), 0.4);
  EXPECT_EQ(b.brain.stale_base_commands(), 0);

  // 0.3 s on (the sensors healthy) with no command since: the watchdog sends zero.
  b.Deliver(Sensors(Time{1'300'000'000}));
  EXPECT_EQ(NextForwardSpeed(b), 0.0);
  EXPECT_EQ(b.brain.watchdog_stops(), 1);

  // A command with no Sense() since 1.0 s (now 1.3 s): zero goes out.
  b.brain.SendBaseVelocity({0.4, 0.0, 0.0});
  EXPECT_EQ(NextForwardSpeed(b), 0.0);
  EXPECT_EQ(b.brain.stale_base_commands(), 1);
  // Sensed again: the command goes out as asked.
  b.brain.Sense();
  b.brain.SendBaseVelocity({0.4, 0.0, 0.0});
  EXPECT_EQ(NextForwardSpeed(b), 0.4);

  JointTrajectory arm;
  arm.joint_names = {"arm_lift_joint"};
  arm.points = {{{0.3}, {}, {}, Duration{1'000'000'000}}};
  arm.start = b.brain.clock().Now() - Duration{500'000'000};
  try {
    b.brain.SendArmTrajectory(arm);
    ADD_FAILURE() << "an arm trajectory 0.5 s old was sent";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("start stamp"));
    EXPECT_THAT(e.what(), HasSubstr("command_timeout_s"));
  }
  arm.start = b.brain.clock().Now();
  b.brain.SendArmTrajectory(arm);
  ASSERT_TRUE(Eventually([&] {
    b.server.ApplyCommands();
    return !b.robot.trajectories.empty();
  }));
  EXPECT_EQ(b.robot.trajectories.back().start, arm.start);
}

TEST(Ros2RobotPortTest, TopicMapFromYamlNamesBadEntries) {
  const std::string path = ::testing::TempDir() + "/topics_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream f(path);
    f << "topics:\n  scan: /hsrb/base_scan\n  cmd_vel: /base_velocity\n";
  }
  const Ros2Topics t = Ros2Topics::FromYamlFile(path);
  EXPECT_EQ(t.scan, "/hsrb/base_scan");
  EXPECT_EQ(t.cmd_vel, "/base_velocity");
  EXPECT_EQ(t.odometry, Ros2Topics{}.odometry);  // left out: the default
  {
    std::ofstream f(path);
    f << "topics:\n  scan: /ok\n  scna: /typo\n";
  }
  EXPECT_THAT([&] { Ros2Topics::FromYamlFile(path); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  ::testing::AllOf(HasSubstr(path), HasSubstr("line 3"), HasSubstr("scna"))));
  {
    std::ofstream f(path);
    f << "scan: no_slash\n";
  }
  EXPECT_THAT([&] { Ros2Topics::FromYamlFile(path); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("scan")));
  EXPECT_THAT([&] { Ros2Topics::FromYamlFile(path + ".missing"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("no such file")));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace egress::ros2
