#include "egress/planning/bug2_navigator.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/perception/door_estimation.h"
#include "synthetic.h"

namespace egress::planning {
namespace {

using perception::Box2;
using perception::OccupancyGrid;

struct DriveResult {
  bool reached{false};
  BugMode final_mode{BugMode::kMotionToGoal};
  double min_clearance{1e9};  // robot centre to the obstacle box's surface
  Pose2 final_pose;
};

// A kinematic loop at 10 Hz with a 360-degree laser ray-cast in `grid`.
DriveResult Drive(const OccupancyGrid& grid, const Box2& obstacle, Eigen::Vector2d start,
                  Eigen::Vector2d goal, const std::vector<Eigen::Vector2d>& people = {},
                  double seconds = 150.0) {
  Bug2Navigator bug(start, goal);
  Pose2 X_MB{start.x(), start.y(), 0.0};
  LaserScan scan;
  scan.angle_min = -std::numbers::pi;
  scan.angle_increment = 2 * std::numbers::pi / 360;
  scan.range_min = 0.05;
  scan.range_max = 3.0;  // enough to see the box; keeps the ray casting cheap
  scan.ranges.assign(360, 0.0f);
  DriveResult run;
  for (int k = 0; k < int(seconds * 10); ++k) {
    perception::testing::CastScan(grid, X_MB, &scan);
    const BugCommand command = bug.Step(X_MB, perception::ScanPoints(scan, X_MB), people, 0.1);
    run.final_mode = command.mode;
    if (command.mode == BugMode::kReached || command.mode == BugMode::kFailed ||
        command.mode == BugMode::kWaitingForPerson) {
      run.reached = command.mode == BugMode::kReached;
      break;
    }
    X_MB = X_MB * Pose2{command.V_B.vx * 0.1, command.V_B.vy * 0.1, command.V_B.wz * 0.1};
    const Eigen::Vector2d local = obstacle.X_MBox.Inverse() * X_MB.translation();
    const Eigen::Vector2d outside = (local.cwiseAbs() - obstacle.size / 2).cwiseMax(0.0);
    run.min_clearance = std::min(run.min_clearance, outside.norm());
  }
  run.final_pose = X_MB;
  return run;
}

OccupancyGrid Room(const Box2& obstacle) {
  return OccupancyGrid::FromBoxes({{{5.0, 0.05, 0.0}, {10.0, 0.1}},
                                   {{5.0, 5.95, 0.0}, {10.0, 0.1}},
                                   {{0.05, 3.0, 0.0}, {0.1, 6.0}},
                                   {{9.95, 3.0, 0.0}, {0.1, 6.0}},
                                   obstacle},
                                  {0, 0}, {10, 6}, 0.02);
}

TEST(Bug2Test, GoesAroundABoxOnTheStraightLine) {
  const Box2 box{{5.0, 3.0, 0.3}, {1.0, 1.2}};
  const DriveResult run = Drive(Room(box), box, {1.0, 3.0}, {9.0, 3.0});
  EXPECT_TRUE(run.reached) << ToString(run.final_mode);
  EXPECT_GT(run.min_clearance, 0.215) << "the footprint touched the box";
  EXPECT_LT((run.final_pose.translation() - Eigen::Vector2d(9.0, 3.0)).norm(), 0.1);
}

TEST(Bug2Test, NeverPushesIntoAPerson) {
  const Box2 box{{5.0, 1.0, 0.0}, {0.2, 0.2}};  // out of the way
  const DriveResult run = Drive(Room(box), box, {1.0, 3.0}, {9.0, 3.0}, {{1.8, 3.05}});
  EXPECT_EQ(run.final_mode, BugMode::kWaitingForPerson);
  EXPECT_LT(run.final_pose.x, 1.0 + 1e-9);  // it did not move toward the person
}

TEST(Bug2Test, GivesUpOnAnEnclosedGoalSoThePlannerCanReplan) {
  // The goal sits inside a closed box: walking round it comes back to the hit point.
  const Box2 box{{6.0, 3.0, 0.0}, {1.6, 1.6}};
  const DriveResult run = Drive(Room(box), box, {1.0, 3.0}, {6.0, 3.0});
  EXPECT_EQ(run.final_mode, BugMode::kFailed);
  EXPECT_FALSE(run.reached);
  EXPECT_THROW(Bug2Navigator({std::nan(""), 0}, {1, 1}), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
