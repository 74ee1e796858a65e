// IsPathAheadBlocked (behavior/src/task_node_support.h): what blocks the path being followed,
// so that the drive plans again, and what must not (a plan just made, which a plan from here
// would only repeat).

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

// A 1.6 m corridor running east (y 0 to 1.6) that turns south at its east end (x 14.4 to 16),
// the walls 0.1 m thick, the whole turned by `turn` about the origin (as a building may be).
perception::OccupancyGrid CorridorCorner(double turn) {
  const auto box = [&](double x, double y, double sx, double sy) {
    const Eigen::Vector2d p = Eigen::Rotation2Dd(turn) * Eigen::Vector2d(x, y);
    return perception::Box2{{p.x(), p.y(), turn}, {sx, sy}};
  };
  return perception::OccupancyGrid::FromBoxes(
      {box(7.2, -0.05, 14.5, 0.1), box(8.0, 1.65, 16.1, 0.1), box(16.05, -3.0, 0.1, 9.4),
       box(14.35, -4.5, 0.1, 8.9), box(0.05, 0.8, 0.1, 1.6)},
      {-2.0, -6.0}, {20.0, 8.0}, 0.05);
}

MissionMap MapOf(perception::OccupancyGrid grid) {
  MissionMap map;
  map.grid = std::move(grid);
  return map;
}

class PathAheadTest : public ::testing::Test {
 protected:
  PathAheadTest()
      : map_(MapOf(CorridorCorner(0.0))),
        model_(RobotModel::LoadDefault()),
        motion_(model_),
        costmap_(map_.grid),
        planner_(costmap_, nullptr) {
    services_.map = &map_;
    services_.model = &model_;
    services_.motion = &motion_;
    services_.planner = &planner_;
    services_.belief = &belief_;
  }
  // The building turned by `turn` instead.
  void Turn(double turn) {
    turn_ = turn;
    map_.grid = CorridorCorner(turn);
    costmap_ = perception::Costmap2D(map_.grid);
    planner_ = planning::BasePlanner(costmap_, nullptr);
  }
  Pose2 InBuilding(double x, double y, double yaw) const {
    const Eigen::Vector2d p = Eigen::Rotation2Dd(turn_) * Eigen::Vector2d(x, y);
    return {p.x(), p.y(), yaw + turn_};
  }
  // Plans from `start` to `goal` and starts following the plan from `start`.
  bool Follow(const Pose2& start, const Pose2& goal) {
    belief_.X_MB = start;
    const NodeStatus s = StartPath(services_, goal, "the goal", [](const std::string&) {});
    return s == NodeStatus::kRunning;
  }

  MissionMap map_;
  RobotModel model_;
  MotionExecutor motion_;
  perception::Costmap2D costmap_;
  planning::BasePlanner planner_;
  Belief belief_;
  TaskServices services_;
  double turn_{0.0};
};

TEST_F(PathAheadTest, APathJustPlannedIsNotBlocked) {
  // Round the corner from all along the east-west leg to all along the south leg, the robot
  // facing any way: a plan from here would be this plan again.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(1.0, 13.5), y(0.4, 1.2), down(-8.5, -1.0),
      across(14.8, 15.6), yaw(-std::numbers::pi, std::numbers::pi);
  int planned = 0;
  for (const double turn : {0.0, 0.3}) {
    Turn(turn);
    for (int k = 0; k < 40; ++k) {
      const Pose2 start = InBuilding(x(random), y(random), yaw(random));
      const Pose2 goal = InBuilding(across(random), down(random), yaw(random));
      if (!Follow(start, goal)) continue;
      ++planned;
      EXPECT_FALSE(IsPathAheadBlocked(services_))
          << "turn " << turn << ": from (" << start.x << ", " << start.y << ", " << start.yaw
          << ") to (" << goal.x << ", " << goal.y << ")";
    }
  }
  EXPECT_GT(planned, 60);
}

TEST_F(PathAheadTest, AnObstacleOnThePathAheadBlocksIt) {
  ASSERT_TRUE(Follow(InBuilding(2.0, 0.8, 0.0), InBuilding(12.0, 0.8, 0.0)));
  EXPECT_FALSE(IsPathAheadBlocked(services_));
  // A body 1 m ahead, across the corridor's middle: blocked.
  LaserScan scan;
  scan.angle_min = -0.1;
  scan.angle_increment = 0.01;
  scan.range_max = 20.0;
  scan.ranges.assign(21, 1.0f);
  costmap_.UpdateWithScan(scan, belief_.X_MB);
  EXPECT_TRUE(IsPathAheadBlocked(services_));
}

TEST_F(PathAheadTest, AnObstacleBeyondTheLookaheadDoesNotBlockYet) {
  ASSERT_TRUE(Follow(InBuilding(2.0, 0.8, 0.0), InBuilding(12.0, 0.8, 0.0)));
  LaserScan scan;
  scan.angle_min = -0.03;
  scan.angle_increment = 0.005;
  scan.range_max = 20.0;
  scan.ranges.assign(13, float(kPathLookahead + 2.0));
  costmap_.UpdateWithScan(scan, belief_.X_MB);
  EXPECT_FALSE(IsPathAheadBlocked(services_));
}

}  // namespace
}  // namespace egress::behavior::detail
