// Interop with a DDS stack no one here wrote: Cyclone DDS (cyclone/cyclone_peer.c, C API, types
// from Cyclone's idlc on the same ROS 2 IDL) reads the scan and odometry our RobotPortServer
// publishes and sends a Twist that arrives at our robot. Field values checked both ways.

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dds_domain.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/robot_port_server.h"
#include "hsr_interface/ros2/scripted_robot.h"

extern char** environ;

namespace egress::ros2 {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

TEST(CycloneInteropTest, ACycloneNodeReadsOurScanAndOdometryAndDrivesOurBase) {
  const egress::testing::DdsDomain claim;
  const int domain = claim.id();
  test_support::ScriptedRobot robot;
  RobotPortServer server(robot, Ros2Topics{}, domain);
  const std::string log =
      ::testing::TempDir() + "/cyclone_peer_" + std::to_string(::getpid()) + ".log";
  const std::string domain_arg = std::to_string(domain);
  char* argv[] = {const_cast<char*>(EGRESS_CYCLONE_PEER), const_cast<char*>(domain_arg.c_str()),
                  nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, EGRESS_CYCLONE_PEER, &actions, nullptr, argv, environ), 0);
  posix_spawn_file_actions_destroy(&actions);

  // The robot's readings, published every 20 ms (fresh stamps) while the peer runs.
  int status = 0;
  bool exited = false;
  const auto until = std::chrono::steady_clock::now() + 60s;
  for (int k = 1; std::chrono::steady_clock::now() < until; ++k) {
    const Time t{std::int64_t(k) * 20'000'000 + 5};
    SensorSnapshot s;
    s.stamp = t;
    LaserScan scan;
    scan.stamp = t;
    scan.angle_min = -2.0;
    scan.angle_increment = 0.00436;
    scan.range_min = 0.05;
    scan.range_max = 20.0;
    scan.ranges.assign(1081, 4.0f);
    scan.ranges[7] = 1.2345f;
    s.scan = scan;
    s.odometry.stamp = t;
    s.odometry.X_OB = {1.5, -0.75, 0.6};
    s.odometry.V_B = {0.2, 0.0, -0.1};
    s.odometry.covariance = Eigen::Vector3d(0.01, 0.01, 0.02).asDiagonal();
    s.joints.stamp = t;
    robot.next = s;
    server.PublishSensors();
    server.ApplyCommands();
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(20ms);
  }
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  server.ApplyCommands();
  std::ifstream in(log);
  std::stringstream out;
  out << in.rdbuf();
  ASSERT_TRUE(exited && WIFEXITED(status) && WEXITSTATUS(status) == 0) << out.str();
  // What Cyclone read of ours.
  EXPECT_THAT(out.str(), HasSubstr("scan frame_id=base_range_sensor_link"));
  EXPECT_THAT(out.str(), HasSubstr("n=1081 r7=1.2345 angle_min=-2.0000 range_max=20.00"));
  EXPECT_THAT(out.str(), HasSubstr("odom frame_id=odom child=base_footprint x=1.5000 y=-0.7500"));
  EXPECT_THAT(out.str(), HasSubstr(" vx=0.2000 wz=-0.1000 cov35=0.0200"));
  const std::string qz = std::to_string(std::sin(0.3)).substr(0, 8);
  EXPECT_THAT(out.str(), HasSubstr("qz=" + qz));
  EXPECT_THAT(out.str(), HasSubstr("00005 n=1081"));  // the stamp to the nanosecond
  // What our robot got of Cyclone's Twist.
  ASSERT_FALSE(robot.velocities.empty()) << out.str();
  EXPECT_DOUBLE_EQ(robot.velocities.back().vx, 0.25);
  EXPECT_DOUBLE_EQ(robot.velocities.back().vy, -0.05);
  EXPECT_DOUBLE_EQ(robot.velocities.back().wz, 0.5);
  std::remove(log.c_str());
}

}  // namespace
}  // namespace egress::ros2
