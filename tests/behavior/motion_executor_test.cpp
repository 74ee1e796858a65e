#include "egress/behavior/motion_executor.h"

#include <cmath>

#include <gtest/gtest.h>

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
  motion.FollowPath({{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, {false}, kTuckedArm, Time{});
  EXPECT_FALSE(motion.bug_active());
  EXPECT_TRUE(motion.base_moving());
}

}  // namespace
}  // namespace egress::behavior
