#include "egress/ros2/conversions.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::ros2 {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(Ros2ConversionsTest, TimeSplitsIntoSecondsAndNanoseconds) {
  const auto msg = ToRos(Time{12'345'678'901});
  EXPECT_EQ(msg.sec(), 12);
  EXPECT_EQ(msg.nanosec(), 345'678'901u);
  EXPECT_EQ(FromRos(msg), Time{12'345'678'901});
  EXPECT_THAT([] { ToRos(Time{-1}); }, ThrowsMessage<InvalidArgument>(HasSubstr("Time")));
  builtin_interfaces::msg::Time bad;
  bad.nanosec(1'000'000'000);
  EXPECT_THAT([&] { FromRos(bad); }, ThrowsMessage<InvalidArgument>(HasSubstr("nanosec")));
  // A negative duration keeps nanosec in [0, 1e9), as ROS's.
  const auto d = DurationToRos(Duration{-1'500'000'000});
  EXPECT_EQ(d.sec(), -2);
  EXPECT_EQ(d.nanosec(), 500'000'000u);
  EXPECT_EQ(FromRos(d), Duration{-1'500'000'000});
}

TEST(Ros2ConversionsTest, LaserScanRoundTripsWithInfAndNaN) {
  LaserScan scan;
  scan.stamp = Time{2'000'000'123};
  scan.angle_min = -2.0;
  scan.angle_increment = 0.5;
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  scan.ranges = {1.0f, std::numeric_limits<float>::infinity(), std::nanf(""), 3.5f};
  const auto msg = ToRos(scan);
  EXPECT_EQ(msg.header().frame_id(), std::string(frames::kLaser));
  EXPECT_FLOAT_EQ(msg.angle_max(), -0.5f);  // angle_min + 3 increments
  const LaserScan back = FromRos(msg);
  EXPECT_EQ(back.stamp, scan.stamp);
  EXPECT_DOUBLE_EQ(back.angle_increment, 0.5);
  ASSERT_EQ(back.ranges.size(), 4u);
  EXPECT_TRUE(std::isinf(back.ranges[1]));
  EXPECT_TRUE(std::isnan(back.ranges[2]));
  EXPECT_FLOAT_EQ(back.ranges[3], 3.5f);
  auto bad = msg;
  bad.intensities({1.0f});
  EXPECT_THAT([&] { FromRos(bad); }, ThrowsMessage<InvalidArgument>(HasSubstr("intensities")));
}

TEST(Ros2ConversionsTest, DepthImagesIn32FC1And16UC1) {
  DepthImage depth;
  depth.width = 3;
  depth.height = 2;
  depth.depth = {0.5f, 1.0f, std::nanf(""), 2.0f, 2.5f, 3.0f};
  const auto msg = ToRos(depth);
  EXPECT_EQ(msg.encoding(), "32FC1");
  EXPECT_EQ(msg.step(), 12u);
  const DepthImage back = DepthFromRos(msg);
  EXPECT_FLOAT_EQ(back.At(1, 0), 1.0f);
  EXPECT_TRUE(std::isnan(back.At(2, 0)));
  EXPECT_FLOAT_EQ(back.At(2, 1), 3.0f);
  // A driver's millimetres, rows padded to 8 bytes; 0 is no return.
  sensor_msgs::msg::Image mm;
  mm.encoding("16UC1");
  mm.width(3);
  mm.height(1);
  mm.step(8);
  mm.data().assign(8, 0);
  const std::uint16_t values[3] = {1500, 0, 250};
  std::memcpy(mm.data().data(), values, sizeof(values));
  const DepthImage from_mm = DepthFromRos(mm);
  EXPECT_FLOAT_EQ(from_mm.At(0, 0), 1.5f);
  EXPECT_TRUE(std::isnan(from_mm.At(1, 0)));
  EXPECT_FLOAT_EQ(from_mm.At(2, 0), 0.25f);
  mm.data().resize(7);
  EXPECT_THAT([&] { DepthFromRos(mm); }, ThrowsMessage<InvalidArgument>(HasSubstr("data holds")));
  mm.encoding("mono8");
  EXPECT_THAT([&] { DepthFromRos(mm); }, ThrowsMessage<InvalidArgument>(HasSubstr("mono8")));
}

TEST(Ros2ConversionsTest, ColourImagesSwapChannelsFromRgb8) {
  ColorImage color;
  color.width = 1;
  color.height = 1;
  color.bgr = {10, 20, 30};
  auto msg = ToRos(color);
  EXPECT_EQ(msg.encoding(), "bgr8");
  EXPECT_EQ(ColorFromRos(msg).bgr, color.bgr);
  msg.encoding("rgb8");
  EXPECT_EQ(ColorFromRos(msg).bgr, (std::vector<std::uint8_t>{30, 20, 10}));
}

TEST(Ros2ConversionsTest, CameraInfoCarriesThePinhole) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.0);
  const auto msg = ToRos(K, Time{5}, frames::kHeadCamera);
  EXPECT_DOUBLE_EQ(msg.k()[0], K.fx);
  EXPECT_DOUBLE_EQ(msg.k()[5], K.cy);
  EXPECT_DOUBLE_EQ(msg.p()[10], 1.0);
  const CameraIntrinsics back = FromRos(msg);
  EXPECT_EQ(back.width, 80);
  EXPECT_DOUBLE_EQ(back.fy, K.fy);
  EXPECT_DOUBLE_EQ(back.cx, K.cx);
  EXPECT_THAT([] { FromRos(sensor_msgs::msg::CameraInfo{}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("uncalibrated")));
}

TEST(Ros2ConversionsTest, OdometryPoseTwistAndCovarianceBlock) {
  Odometry odometry;
  odometry.stamp = Time{7'000'000'000};
  odometry.X_OB = {1.0, -2.0, 2.5};
  odometry.V_B = {0.3, -0.1, 0.2};
  odometry.covariance << 0.01, 0.002, 0.003, 0.002, 0.02, 0.004, 0.003, 0.004, 0.05;
  const auto msg = ToRos(odometry);
  EXPECT_EQ(msg.header().frame_id(), "odom");
  EXPECT_EQ(msg.child_frame_id(), std::string(frames::kBase));
  EXPECT_DOUBLE_EQ(msg.pose().covariance()[5], 0.003);  // (x, yaw)
  EXPECT_DOUBLE_EQ(msg.pose().covariance()[35], 0.05);  // (yaw, yaw)
  EXPECT_GT(msg.pose().covariance()[14], 1e3);          // z: unknown
  const Odometry back = FromRos(msg);
  EXPECT_NEAR(back.X_OB.yaw, 2.5, 1e-12);
  EXPECT_DOUBLE_EQ(back.X_OB.y, -2.0);
  EXPECT_DOUBLE_EQ(back.V_B.vy, -0.1);
  EXPECT_TRUE(back.covariance.isApprox(odometry.covariance));
  // An unnormalised quaternion gives the same yaw; a zero one is an error naming the message.
  auto scaled = msg;
  scaled.pose().pose().orientation().z(msg.pose().pose().orientation().z() * 3);
  scaled.pose().pose().orientation().w(msg.pose().pose().orientation().w() * 3);
  EXPECT_NEAR(FromRos(scaled).X_OB.yaw, 2.5, 1e-12);
  auto zero = msg;
  zero.pose().pose().orientation().z(0.0);
  zero.pose().pose().orientation().w(0.0);
  EXPECT_THAT([&] { FromRos(zero); }, ThrowsMessage<InvalidArgument>(HasSubstr("nav_msgs")));
}

TEST(Ros2ConversionsTest, TwistTransformAndTrajectory) {
  const Twist2 V{0.2, 0.1, -0.3};
  const Twist2 back = FromRos(ToRos(V));
  EXPECT_DOUBLE_EQ(back.vx, 0.2);
  EXPECT_DOUBLE_EQ(back.wz, -0.3);
  const Pose3 X = Pose3::FromXyzRpy({1, 2, 3}, {0.1, -0.2, 0.3});
  const Pose3 X_back = FromRos(ToRos(X));
  EXPECT_TRUE(X_back.rotation().isApprox(X.rotation(), 1e-12));
  EXPECT_TRUE(X_back.translation().isApprox(X.translation()));
  JointTrajectory trajectory;
  trajectory.start = Time{3'000'000'000};
  trajectory.joint_names = {"arm_lift_joint", "arm_flex_joint"};
  trajectory.points = {{{0.1, -0.2}, {}, {}, Duration{500'000'000}},
                       {{0.2, -0.4}, {0.0, 0.0}, {}, Duration{1'500'000'000}}};
  const JointTrajectory t_back = FromRos(ToRos(trajectory));
  EXPECT_EQ(t_back.start, trajectory.start);
  EXPECT_EQ(t_back.joint_names, trajectory.joint_names);
  ASSERT_EQ(t_back.points.size(), 2u);
  EXPECT_EQ(t_back.points[1].time_from_start, Duration{1'500'000'000});
  EXPECT_EQ(t_back.points[1].velocities.size(), 2u);
  EXPECT_NO_THROW(t_back.Validate());
}

// The HSR's head controller takes a trajectory for its two joints; one point, timed at the
// joints' 1 rad/s from where they are (at least 0.1 s); the twin's side reads the target back.
TEST(Ros2ConversionsTest, HeadCommandsAsTheHeadControllersTrajectory) {
  JointState joints;
  joints.names = {"arm_lift_joint", "head_pan_joint", "head_tilt_joint"};
  joints.positions = {0.1, -0.5, 0.0};
  const JointTrajectory t = HeadTrajectory({0.7, -0.2}, joints);
  EXPECT_EQ(t.joint_names, (std::vector<std::string>{"head_pan_joint", "head_tilt_joint"}));
  ASSERT_EQ(t.points.size(), 1u);
  EXPECT_NEAR(std::chrono::duration<double>(t.points[0].time_from_start).count(), 1.2, 1e-9);
  EXPECT_NEAR(
      std::chrono::duration<double>(HeadTrajectory({-0.5, 0.0}, joints).points[0].time_from_start)
          .count(),
      0.1, 1e-9);
  EXPECT_NEAR(std::chrono::duration<double>(
                  HeadTrajectory({0.7, 0.0}, std::nullopt).points[0].time_from_start)
                  .count(),
              0.1, 1e-9);
  const HeadCommand back = HeadFromTrajectory(FromRos(ToRos(t)));
  EXPECT_DOUBLE_EQ(back.pan, 0.7);
  EXPECT_DOUBLE_EQ(back.tilt, -0.2);
  JointTrajectory arm = t;
  arm.joint_names = {"head_pan_joint", "arm_flex_joint"};
  EXPECT_THAT([&] { HeadFromTrajectory(arm); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'arm_flex_joint' is not a head joint")));
  JointTrajectory one = t;
  one.joint_names = {"head_pan_joint"};
  one.points[0].positions = {0.1};
  EXPECT_THAT([&] { HeadFromTrajectory(one); },
              ThrowsMessage<InvalidArgument>(HasSubstr("head_tilt_joint")));
}

// The HSR's gripper controller: a grasp is its apply_force action with the force [N], open its
// grasp action with a positive torque; what the twin cannot do is refused by name.
TEST(Ros2ConversionsTest, GripperCommandsAsTheHsrsActionGoals) {
  const GripperGoal grasp = GripperToRos({GripperCommand::Mode::kGrasp, 0.0, 12.5});
  EXPECT_EQ(grasp.action, GripperGoal::Action::kApplyForce);
  EXPECT_DOUBLE_EQ(grasp.goal.effort(), 12.5);
  EXPECT_FALSE(grasp.goal.do_control_stop());
  const GripperCommand grasp_back = GripperFromRos(grasp);
  EXPECT_EQ(grasp_back.mode, GripperCommand::Mode::kGrasp);
  EXPECT_DOUBLE_EQ(grasp_back.effort, 12.5);
  const GripperGoal open = GripperToRos({GripperCommand::Mode::kOpen, 0.0, 0.0}, 0.6);
  EXPECT_EQ(open.action, GripperGoal::Action::kGrasp);
  EXPECT_DOUBLE_EQ(open.goal.effort(), 0.6);
  EXPECT_EQ(GripperFromRos(open).mode, GripperCommand::Mode::kOpen);
  EXPECT_THAT(
      [] {
        GripperToRos({GripperCommand::Mode::kPosition, 0.3, 0.0});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("position command")));
  EXPECT_THAT(
      [] {
        GripperToRos({GripperCommand::Mode::kOpen, 0.0, 0.0}, -1.0);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("opening torque")));
  GripperGoal closing{GripperGoal::Action::kGrasp, {}};
  closing.goal.effort(-0.5);
  EXPECT_THAT([&] { GripperFromRos(closing); },
              ThrowsMessage<InvalidArgument>(HasSubstr("closing torque")));
  GripperGoal negative{GripperGoal::Action::kApplyForce, {}};
  negative.goal.effort(-2.0);
  EXPECT_THAT([&] { GripperFromRos(negative); },
              ThrowsMessage<InvalidArgument>(HasSubstr(">= 0 N")));
}

}  // namespace
}  // namespace egress::ros2
