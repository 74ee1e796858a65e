#include "egress/planning/route_planner.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

using perception::Box2;
using perception::Doorway;

// The lab: a room x -3..3, y -1..7 cut by a wall across y = 3 with a 1 m doorway (x -0.5..0.5);
// the leaf hinged at x = 0.475 opens away from the south half (+y).
struct Lab {
  perception::OccupancyGrid grid;
  Doorway door{"lab_door", {0.475, 3.0}, {-0.475, 3.0}};
  Lab() {
    std::vector<Box2> walls{{{0, -1.05, 0}, {6.2, 0.1}}, {{0, 7.05, 0}, {6.2, 0.1}},
                            {{-3.05, 3, 0}, {0.1, 8.2}}, {{3.05, 3, 0}, {0.1, 8.2}},
                            {{-1.75, 3, 0}, {2.5, 0.1}}, {{1.75, 3, 0}, {2.5, 0.1}}};
    grid = perception::OccupancyGrid::FromBoxes(walls, {-3.2, -1.2}, {3.2, 7.2}, 0.05);
    door.swing_sign = -1.0;  // the latch (x -0.475) turns clockwise about the hinge: to +y
  }
};

TEST(RoutePlannerTest, FindsTheDoorOnTheRouteAndWaitsBeforeIt) {
  const Lab lab;
  const RoutePlanner planner(lab.grid, {lab.door});
  const RouteResult r = planner.Plan({0.0, 1.0, M_PI / 2}, {0.5, 5.5, 0.0});
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.route->legs.size(), 1u);
  const RouteLeg& leg = r.route->legs[0];
  EXPECT_EQ(leg.door, "lab_door");
  EXPECT_FALSE(leg.opens_towards_robot);
  EXPECT_NEAR(leg.X_MB_approach.x, 0.0, 1e-9);
  EXPECT_NEAR(leg.X_MB_approach.y, 3.0 - 1.2, 1e-9);
  EXPECT_NEAR(leg.X_MB_approach.yaw, M_PI / 2, 1e-9);  // facing the door
  EXPECT_NEAR(leg.X_MB_exit.y, 3.9, 1e-9);
  EXPECT_GT(r.route->length, 4.5);
  EXPECT_LT(r.route->length, 6.0);
  EXPECT_TRUE(r.route->path.front().isApprox(Eigen::Vector2d(0.0, 1.0))) << r.route->path.front();
  EXPECT_TRUE(r.route->path.back().isApprox(Eigen::Vector2d(0.5, 5.5)));
}

TEST(RoutePlannerTest, ALeafOpeningTowardsTheRobotIsAwaitedOutsideItsSweep) {
  const Lab lab;
  const RoutePlanner planner(lab.grid, {lab.door});
  const RouteResult r = planner.Plan({0.0, 5.5, -M_PI / 2}, {0.0, 0.5, 0.0});
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.route->legs.size(), 1u);
  EXPECT_TRUE(r.route->legs[0].opens_towards_robot);
  // The leaf reaches 0.95 m into the north half: wait 0.35 m beyond it.
  EXPECT_NEAR(r.route->legs[0].X_MB_approach.y, 3.0 + 0.95 + 0.35, 1e-9);
  EXPECT_NEAR(r.route->legs[0].X_MB_approach.yaw, -M_PI / 2, 1e-9);
}

TEST(RoutePlannerTest, NoDoorWithinARoomAndClearReasonsWithoutARoute) {
  const Lab lab;
  const RoutePlanner planner(lab.grid, {lab.door});
  const RouteResult same_room = planner.Plan({-2.0, 0.0, 0.0}, {2.0, 2.0, 0.0});
  ASSERT_TRUE(same_room.ok());
  EXPECT_TRUE(same_room.route->legs.empty());
  const RouteResult avoided = planner.Plan({0.0, 1.0, 0.0}, {0.0, 5.0, 0.0}, {"lab_door"});
  EXPECT_FALSE(avoided.ok());
  EXPECT_NE(avoided.message.find("avoiding door(s) lab_door"), std::string::npos);
  const RouteResult in_wall = planner.Plan({0.0, 1.0, 0.0}, {2.0, 3.0, 0.0});
  EXPECT_FALSE(in_wall.ok());
  EXPECT_NE(in_wall.message.find("goal (2, 3) is inside a wall"), std::string::npos);
  const RouteResult off_map = planner.Plan({0.0, 1.0, 0.0}, {20.0, 3.0, 0.0});
  EXPECT_NE(off_map.message.find("outside the map"), std::string::npos);
  EXPECT_NE(planner.Plan({0, 1, 0}, {0, 5, 0}, {"back_door"}).message.find("no such door"),
            std::string::npos);
  EXPECT_FALSE(planner.Plan({0, 1, 0}, {std::nan(""), 5, 0}).ok());
  // A start 0.1 m from a wall moves to free space.
  EXPECT_TRUE(planner.Plan({-2.9, 0.0, 0.0}, {2.0, 2.0, 0.0}).ok());
}

TEST(RoutePlannerTest, ADoorAtACorridorCornerIsApproachedAlongTheRoute) {
  // An L corridor 1.2 m wide: along x (y 0..1.2) then up along y (x 4..5.2); the door across
  // the vertical leg at y = 1.6, its leaf opening towards the robot (reach 1.0 m): straight
  // before it (y = 0.25) is the corridor's south wall, so the approach comes from the route.
  std::vector<Box2> walls{{{2.6, -0.05, 0}, {5.4, 0.1}}, {{2.0, 1.25, 0}, {4.0, 0.1}},
                          {{-0.05, 0.6, 0}, {0.1, 1.4}}, {{5.25, 2.5, 0}, {0.1, 5.2}},
                          {{3.95, 3.1, 0}, {0.1, 3.8}},  {{4.6, 5.05, 0}, {1.4, 0.1}}};
  const auto grid = perception::OccupancyGrid::FromBoxes(walls, {-0.2, -0.2}, {5.4, 5.2}, 0.05);
  Doorway door{"corner_door", {4.05, 1.6}, {5.15, 1.6}};
  door.swing_sign = -1.0;  // clockwise about the west hinge: the latch swings to -y
  const RoutePlanner planner(grid, {door});
  const RouteResult r = planner.Plan({0.5, 0.6, 0.0}, {4.6, 4.5, 0.0});
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.route->legs.size(), 1u);
  const RouteLeg& leg = r.route->legs[0];
  EXPECT_TRUE(leg.opens_towards_robot);
  EXPECT_GE(planner.ClearanceAt(leg.X_MB_approach.translation()), 0.24);
  // Out of the leaf's sweep (1.1 m from the hinge) and facing the doorway.
  EXPECT_GT((leg.X_MB_approach.translation() - door.p_MHinge).norm(), 1.1);
  const Eigen::Vector2d to_door = Eigen::Vector2d(4.6, 1.6) - leg.X_MB_approach.translation();
  EXPECT_NEAR(leg.X_MB_approach.yaw, std::atan2(to_door.y(), to_door.x()), 1e-9);
}

TEST(RoutePlannerTest, ClearanceIsTheDistanceToTheNearestOccupiedCellWithinAFractionOfACell) {
  // The lab with a pillar and a slanted wall: every free cell's clearance against a brute-force
  // search over all occupied cells. The propagation's distance is always to some occupied
  // cell (never below the true one) and never more than a fifth of a cell above it.
  Lab lab;
  lab.grid.AddBox({{1.2, 5.1, 0.0}, {0.3, 0.3}});
  lab.grid.AddBox({{-1.5, 1.0, 0.6}, {1.5, 0.1}});
  const RoutePlanner planner(lab.grid, {lab.door});
  const perception::GridGeometry& g = lab.grid.geometry();
  std::vector<Eigen::Vector2i> occupied;
  for (int iy = 0; iy < g.height; ++iy) {
    for (int ix = 0; ix < g.width; ++ix) {
      if (lab.grid.at(ix, iy) != perception::kFreeCost) occupied.emplace_back(ix, iy);
    }
  }
  ASSERT_GT(occupied.size(), 100u);
  double worst_over = 0.0;
  for (int iy = 0; iy < g.height; iy += 3) {
    for (int ix = 0; ix < g.width; ix += 3) {
      double nearest = 1e9;
      for (const Eigen::Vector2i& o : occupied) {
        nearest = std::min(
            nearest, std::sqrt(double((o.x() - ix) * (o.x() - ix) + (o.y() - iy) * (o.y() - iy))) *
                         g.resolution);
      }
      const double clearance = planner.ClearanceAt(g.CellCenter(ix, iy));
      ASSERT_GE(clearance, nearest - 1e-6) << ix << ", " << iy;
      worst_over = std::max(worst_over, clearance - nearest);
    }
  }
  EXPECT_LE(worst_over, 0.2 * g.resolution);
}

TEST(RoutePlannerTest, BadConfigAndDoorsAreRefused) {
  const Lab lab;
  RoutePlannerConfig bad;
  bad.clearance = -1;
  EXPECT_THROW(RoutePlanner(lab.grid, {lab.door}, bad), InvalidArgument);
  Doorway point{"point", {1, 1}, {1, 1}};
  EXPECT_THROW(RoutePlanner(lab.grid, {point}), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
