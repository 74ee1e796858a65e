#include "egress/behavior/motion_executor.h"

#include <cmath>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

// A wall the costmap did not know, 0.4 m thick across the way from (0, 0) to (4, 0).
std::vector<Eigen::Vector2d> WallAcrossTheWay() {
  std::vector<Eigen::Vector2d> points;
  for (double y = -0.7; y <= 0.7; y += 0.02) {
    points.emplace_back(1.8, y);
    points.emplace_back(2.2, y);
  }
  for (double x = 1.8; x <= 2.2; x += 0.02) {
    points.emplace_back(x, -0.7);
    points.emplace_back(x, 0.7);
  }
  return points;
}

TEST(MotionExecutorTest, TheBugDetourGoesRoundAnObstacleToTheGoal) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  Pose2 X_MB{0.0, 0.0, 0.0};
  const auto wall = WallAcrossTheWay();
  const double dt = 0.01;
  Time now{};
  motion.FollowBug(X_MB, {4.0, 0.0}, planning::BugConfig{}, now);
  EXPECT_TRUE(motion.bug_active());
  double closest = 1e9;
  for (int step = 0; step < 20000 && motion.base_moving(); ++step) {
    // What the laser would see: the wall points within 5 m.
    std::vector<Eigen::Vector2d> seen;
    for (const auto& p : wall) {
      if ((p - X_MB.translation()).norm() < 5.0) seen.push_back(p);
    }
    motion.SetSurroundings(seen, {});
    now += SecondsToDuration(dt);
    const Twist2 V_B = motion.Update(now, X_MB, {});
    const double c = std::cos(X_MB.yaw), s = std::sin(X_MB.yaw);
    X_MB.x += (c * V_B.vx - s * V_B.vy) * dt;
    X_MB.y += (s * V_B.vx + c * V_B.vy) * dt;
    X_MB.yaw += V_B.wz * dt;
    for (const auto& p : wall)
      closest = std::min(closest, (p - X_MB.translation()).norm());
  }
  EXPECT_FALSE(motion.base_moving());
  EXPECT_FALSE(motion.base_failed()) << motion.base_failure();
  EXPECT_FALSE(motion.bug_active());
  EXPECT_NEAR(X_MB.x, 4.0, 0.1);
  EXPECT_NEAR(X_MB.y, 0.0, 0.1);
  EXPECT_GT(closest, 0.215);  // the footprint never touched the wall
}

TEST(MotionExecutorTest, StoppingOrAPathEndsTheDetour) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  motion.FollowBug({0.0, 0.0, 0.0}, {4.0, 0.0}, planning::BugConfig{}, Time{});
  motion.StopBase();
  EXPECT_FALSE(motion.bug_active());
  EXPECT_FALSE(motion.base_moving());
  motion.FollowBug({0.0, 0.0, 0.0}, {4.0, 0.0}, planning::BugConfig{}, Time{});
  motion.FollowPath({{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, {false}, TuckedArm(model), Time{});
  EXPECT_FALSE(motion.bug_active());
  EXPECT_TRUE(motion.base_moving());
}

// A brisk path (a step out of someone's way) asks the base for speed from the start: 0.1 s
// into a 1 m retreat at 0.4 m/s it is planned at the limit's 0.1 m/s, where the quintic plans
// 0.02 m/s; both take the same time.
TEST(MotionExecutorTest, ABriskPathSetsOffAtTheBasesLimit) {
  const RobotModel model = RobotModel::LoadDefault();
  const Pose2 start{0.0, 0.0, 0.0}, goal{1.0, 0.0, 0.0};
  const auto speed_at = [&](bool brisk, double t) {
    MotionExecutor motion(model);
    motion.FollowPath({start, goal}, {false}, TuckedArm(model), Time{}, 0.4, brisk);
    motion.Update(Time{} + SecondsToDuration(t), start, {});
    return std::pair{motion.planned_velocity().norm(), motion.base_duration()};
  };
  const auto [brisk_speed, brisk_duration] = speed_at(true, 0.1);
  const auto [gentle_speed, gentle_duration] = speed_at(false, 0.1);
  EXPECT_NEAR(brisk_speed, 0.1, 0.01);
  EXPECT_LT(gentle_speed, 0.03);
  EXPECT_DOUBLE_EQ(brisk_duration, gentle_duration);
}

// A brisk path is a step out of someone's way until it is stopped or another path replaces it.
TEST(MotionExecutorTest, ABriskPathIsAStepOutOfTheWayUntilStoppedOrReplaced) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  const std::vector<Pose2> path{{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  EXPECT_FALSE(motion.stepping_out_of_way());
  motion.FollowPath(path, {false}, TuckedArm(model), Time{}, 0.4, /*brisk=*/true);
  EXPECT_TRUE(motion.stepping_out_of_way());
  motion.StopBase();
  EXPECT_FALSE(motion.stepping_out_of_way());
  motion.FollowPath(path, {false}, TuckedArm(model), Time{}, 0.4, /*brisk=*/true);
  motion.FollowPath(path, {false}, TuckedArm(model), Time{}, 0.4, /*brisk=*/false);
  EXPECT_FALSE(motion.stepping_out_of_way());
  EXPECT_TRUE(motion.base_moving());
  motion.FollowPath(path, {false}, TuckedArm(model), Time{}, 0.4, /*brisk=*/true);
  motion.FollowBug({0.0, 0.0, 0.0}, {4.0, 0.0}, planning::BugConfig{}, Time{});
  EXPECT_FALSE(motion.stepping_out_of_way());
}

}  // namespace
}  // namespace egress::behavior

namespace egress::behavior {
namespace {

Time At(double t) {
  return Time{} + SecondsToDuration(t);
}

// An arm motion ends when the measured joints arrive, not when its planned time is up; one
// that never arrives fails after the timeout, naming the joint.
TEST(MotionExecutorTest, ArmMotionsEndWhenTheMeasuredJointsArrive) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  motion.SetMeasuredArm(TuckedArm(model));
  ArmPose raised = TuckedArm(model);
  raised[0] = 0.4;  // arm_lift: 0.4 m at 0.2 m/s needs 2 s, though asked for in 1 s
  motion.MoveArm({{1.0, raised}}, At(0.0));
  const auto command = motion.TakeArmCommand();
  ASSERT_TRUE(command.has_value());
  EXPECT_NEAR(ToSeconds(motion.arm_done() - At(0.0)), 1.0, 1e-9);
  EXPECT_TRUE(motion.arm_moving(At(0.9)));
  motion.Update(At(1.0), {}, {});
  EXPECT_TRUE(motion.arm_moving(At(1.0))) << "the planned time is up but the joints are not there";
  // Past the planned end but still on the way: moving.
  ArmPose halfway = raised;
  halfway[0] = 0.3;
  motion.SetMeasuredArm(halfway);
  motion.Update(At(3.0), {}, {});
  EXPECT_TRUE(motion.arm_moving(At(3.0)));
  EXPECT_FALSE(motion.arm_failed());
  motion.SetMeasuredArm(raised);
  motion.Update(At(3.1), {}, {});
  EXPECT_FALSE(motion.arm_moving(At(3.1)));
  EXPECT_FALSE(motion.arm_failed());

  // Blocked at 0.1 m: failure once the timeout is past, with the joint named.
  motion.MoveArm({{1.0, TuckedArm(model)}}, At(4.0));
  ArmPose stuck = TuckedArm(model);
  stuck[0] = 0.1;
  motion.SetMeasuredArm(stuck);
  const double end = ToSeconds(motion.arm_done());
  motion.Update(At(end + 2.9), {}, {});
  EXPECT_TRUE(motion.arm_moving(At(end + 2.9)));
  motion.Update(At(end + 3.1), {}, {});
  EXPECT_FALSE(motion.arm_moving(At(end + 3.1)));
  ASSERT_TRUE(motion.arm_failed());
  EXPECT_NE(motion.arm_failure().find("arm_lift_joint"), std::string::npos);
  // A new motion clears the failure.
  motion.MoveArm({{1.0, stuck}}, At(20.0));
  EXPECT_FALSE(motion.arm_failed());

  ArmMotionConfig bad;
  bad.timeout = -1.0;
  EXPECT_THROW(MotionExecutor(model, {}, {}, bad), InvalidArgument);
  EXPECT_THROW(motion.MoveArm({{2.0, raised}, {1.0, TuckedArm(model)}}, At(30.0)), InvalidArgument);
}

// A path's own speed (a retreat) replaces the nominal 0.2 m/s: 0.4 m takes 2 s at 0.2 m/s and
// the shortest segment, 1.5 s, at 0.4 m/s.
TEST(MotionExecutorTest, APathsOwnSpeedReplacesTheNominalSpeed) {
  const RobotModel model = RobotModel::LoadDefault();
  const Pose2 start{0.0, 0.0, 0.0}, goal{0.4, 0.0, 0.0};
  const auto run = [&](std::optional<double> speed) {
    MotionExecutor motion(model);
    motion.FollowPath({start, goal}, {false}, TuckedArm(model), Time{}, speed);
    // The base reported exactly on the reference's end: done once the trajectory is.
    for (double t = 0.0; t < 5.0; t += 0.01) {
      motion.Update(Time{} + SecondsToDuration(t), goal, {});
      if (!motion.base_moving()) return t;
    }
    return 5.0;
  };
  EXPECT_NEAR(run(std::nullopt), 2.0, 0.02);
  EXPECT_NEAR(run(0.4), 1.5, 0.02);
  MotionExecutor motion(model);
  EXPECT_THROW(motion.FollowPath({start, goal}, {false}, TuckedArm(model), Time{}, 0.0),
               InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
