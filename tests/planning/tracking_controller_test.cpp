#include "egress/planning/tracking_controller.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

using ::testing::HasSubstr;

WholeBodyTrajectory Straight(const RobotModel& model, double x, double yaw = 0.0) {
  WholeBodyVector a = WholeBodyVector::Zero(), b = a;
  b[kBaseX] = x;
  b[kBaseYaw] = yaw;
  b[kArmLift] = 0.2;
  return WholeBodyTrajectory::Plan({a, b}, model);
}

// A simple kinematic loop at 100 Hz: the base follows the command exactly, delayed one tick.
TEST(TrackingControllerTest, TracksAReferenceInAKinematicLoop) {
  const RobotModel model = RobotModel::LoadDefault();
  TrackingController controller;
  const WholeBodyTrajectory trajectory = Straight(model, 1.0, 0.5);
  controller.Start(trajectory, Time{0});
  Pose2 X_MB;
  Twist2 V_B;
  double worst = 0.0;
  ControlCommand command;
  for (int k = 0; k < 1000 && !command.finished; ++k) {
    const Time now = std::chrono::milliseconds(10 * k);
    command = controller.Update(now, X_MB, V_B);
    ASSERT_FALSE(command.watchdog_tripped) << command.watchdog_reason;
    X_MB = X_MB * Pose2{V_B.vx * 0.01, V_B.vy * 0.01, V_B.wz * 0.01};  // apply the previous command
    V_B = command.V_B;
    const auto ref = trajectory.Sample(0.01 * k);
    worst = std::max(worst, std::hypot(ref.q[kBaseX] - X_MB.x, ref.q[kBaseY] - X_MB.y));
  }
  EXPECT_TRUE(command.finished);
  EXPECT_NEAR(X_MB.x, 1.0, 0.01);
  EXPECT_NEAR(X_MB.yaw, 0.5, 0.01);
  EXPECT_LT(worst, 0.03);
  EXPECT_NEAR(command.arm_q[0], 0.2, 1e-9);  // arm reference at the goal
}

TEST(TrackingControllerTest, WatchdogTripsAtItsThresholdsAndStops) {
  const RobotModel model = RobotModel::LoadDefault();
  TrackingController controller;
  controller.Start(Straight(model, 3.0), Time{0});
  // The base is blocked (never moves): the reference runs away from it.
  ControlCommand command;
  double tripped_at = -1.0;
  for (int k = 0; k < 2000; ++k) {
    const double t = 0.01 * k;
    command = controller.Update(std::chrono::milliseconds(10 * k), Pose2{}, Twist2{});
    if (command.watchdog_tripped) {
      tripped_at = t;
      break;
    }
  }
  ASSERT_GT(tripped_at, 0.0);
  const double error_at_trip = Straight(model, 3.0).Sample(tripped_at).q[kBaseX];
  EXPECT_GT(error_at_trip, 0.5);
  EXPECT_LT(error_at_trip, 0.51);
  EXPECT_THAT(command.watchdog_reason, HasSubstr("position error"));
  EXPECT_EQ(command.V_B.vx, 0.0);
  // Latched: zero commands until restarted.
  EXPECT_TRUE(controller.Update(std::chrono::seconds(30), Pose2{}, Twist2{}).watchdog_tripped);

  TrackingController yaw;
  yaw.Start(Straight(model, 0.0, 0.0), Time{0});
  const ControlCommand spun = yaw.Update(Time{0}, Pose2{0, 0, 0.6}, Twist2{});
  EXPECT_TRUE(spun.watchdog_tripped);
  EXPECT_THAT(spun.watchdog_reason, HasSubstr("yaw error"));
}

TEST(TrackingControllerTest, LimitsSpeedAndAcceleration) {
  const RobotModel model = RobotModel::LoadDefault();
  ControllerConfig config;
  config.max_linear_speed = 0.3;
  config.max_linear_accel = 0.5;
  TrackingController controller(config);
  controller.Start(Straight(model, 0.45), Time{0});
  // 0.4 m behind the reference: PD would command > 1 m/s.
  const ControlCommand first =
      controller.Update(std::chrono::milliseconds(2500), Pose2{-0.3, 0, 0}, Twist2{});
  EXPECT_LE(std::hypot(first.V_B.vx, first.V_B.vy), 0.5 * 0.01 + 1e-9);  // accel-limited from rest
  ControlCommand command = first;
  for (int k = 1; k < 200; ++k) {
    command =
        controller.Update(std::chrono::milliseconds(2500 + 10 * k), Pose2{-0.3, 0, 0}, Twist2{});
  }
  EXPECT_LE(std::hypot(command.V_B.vx, command.V_B.vy), 0.3 + 1e-9);
  EXPECT_THROW(controller.Update(Time{0}, Pose2{std::nan(""), 0, 0}, Twist2{}), InvalidArgument);
}

// Scaled time (issue 21, slowing near people): at 0 the reference waits where it is and the base
// stops on it without the watchdog tripping; at 1 it goes on; the planned velocity still says
// which way the path goes.
TEST(TrackingControllerTest, ATimeScaleHoldsTheReferenceBackWithoutTrippingTheWatchdog) {
  const RobotModel model = RobotModel::LoadDefault();
  TrackingController controller;
  const WholeBodyTrajectory trajectory = Straight(model, 1.0);
  controller.Start(trajectory, Time{0});
  Pose2 X_MB;
  Twist2 V_B;
  ControlCommand command;
  const auto run = [&](int from, int to) {
    for (int k = from; k < to && !command.finished; ++k) {
      command = controller.Update(std::chrono::milliseconds(10 * k), X_MB, V_B);
      ASSERT_FALSE(command.watchdog_tripped) << command.watchdog_reason;
      X_MB = X_MB * Pose2{V_B.vx * 0.01, V_B.vy * 0.01, V_B.wz * 0.01};
      V_B = command.V_B;
    }
  };
  run(0, 200);  // 2 s as planned
  const double x_at_2s = X_MB.x;
  EXPECT_GT(controller.planned_velocity().x(), 0.05);
  controller.SetTimeScale(0.0);
  run(200, 1000);  // 8 s held: the base stops near where the reference waits
  EXPECT_FALSE(command.finished);
  EXPECT_NEAR(X_MB.x, x_at_2s, 0.08);
  EXPECT_NEAR(V_B.vx, 0.0, 1e-3);
  EXPECT_GT(controller.planned_velocity().x(), 0.05);  // still going +x, at its planned pace
  controller.SetTimeScale(1.0);
  run(1000, 2000);
  EXPECT_TRUE(command.finished);
  EXPECT_NEAR(X_MB.x, 1.0, 0.01);
  EXPECT_THROW(controller.SetTimeScale(1.5), InvalidArgument);
  EXPECT_THROW(controller.SetTimeScale(std::nan("")), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
