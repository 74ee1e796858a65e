// The grid searches of planning/src/grid_path.cpp: whether a path exists is decided on either
// side of a wall the same way, whichever side is the smaller, and no path slips through a
// corner.

#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "egress/planning/base_planner.h"

namespace egress::planning {
namespace {

using perception::Box2;
using perception::Costmap2D;
using perception::CostmapConfig;
using perception::OccupancyGrid;

constexpr double kCellM = 0.1;

// A 6 m x 4 m room of 0.1 m cells with `boxes` as walls. The robot's radius is below a cell,
// so exactly the walls' cells are impassable and the cells between them are what they look.
Costmap2D Room(const std::vector<Box2>& boxes) {
  CostmapConfig config;
  config.robot_radius = 0.01;
  config.inflation_radius = 0.02;
  return Costmap2D(OccupancyGrid::FromBoxes(boxes, {0.0, 0.0}, {6.0, 4.0}, kCellM), config);
}

// A wall box spanning x0..x1, y0..y1 [m].
Box2 Wall(double x0, double y0, double x1, double y1) {
  return {{0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0}, {x1 - x0, y1 - y0}};
}

// The path runs from the start's cell to the goal's over passable cells, a cell at a time,
// each diagonal step with both cells beside it passable.
void ExpectAGridPath(const Costmap2D& costmap, const std::vector<Eigen::Vector2d>& path,
                     const Eigen::Vector2d& start, const Eigen::Vector2d& goal) {
  const auto& g = costmap.geometry();
  ASSERT_GE(path.size(), 2u);
  EXPECT_EQ(*g.CellOf(path.front()), *g.CellOf(start));
  EXPECT_EQ(*g.CellOf(path.back()), *g.CellOf(goal));
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Eigen::Vector2i c = *g.CellOf(path[i]);
    EXPECT_TRUE(costmap.IsFree(path[i])) << "cell " << c.transpose();
    if (i == 0) continue;
    const Eigen::Vector2i d = c - *g.CellOf(path[i - 1]);
    ASSERT_LE(std::abs(d.x()), 1);
    ASSERT_LE(std::abs(d.y()), 1);
    if (d.x() != 0 && d.y() != 0) {
      const Eigen::Vector2i from = c - d;
      EXPECT_TRUE(costmap.IsFree(g.CellCenter(from.x() + d.x(), from.y())));
      EXPECT_TRUE(costmap.IsFree(g.CellCenter(from.x(), from.y() + d.y())));
    }
  }
}

// A closet walled round in the room's corner: no path into it or out of it, however much
// larger the other side is; a door in its wall lets the path through.
TEST(GridPathTest, AGoalShutInHasNoPathAndNeitherHasAStartShutIn) {
  const std::vector<Box2> closet = {Wall(4.5, 2.5, 6.0, 2.6), Wall(4.5, 2.5, 4.6, 4.0)};
  const Costmap2D shut = Room(closet);
  const Eigen::Vector2d outside(1.05, 1.05), inside(5.35, 3.35);
  EXPECT_FALSE(GridShortestPath(shut, outside, inside));
  EXPECT_FALSE(GridShortestPath(shut, inside, outside));
  EXPECT_FALSE(GridCheapestPath(shut, outside, inside, {.close_weight = 2.0}));
  // A door 0.5 m wide in the closet's west wall.
  const Costmap2D open =
      Room({Wall(4.5, 2.5, 6.0, 2.6), Wall(4.5, 2.5, 4.6, 3.0), Wall(4.5, 3.5, 4.6, 4.0)});
  const auto in = GridShortestPath(open, outside, inside);
  ASSERT_TRUE(in);
  ExpectAGridPath(open, *in, outside, inside);
  const auto out = GridShortestPath(open, inside, outside);
  ASSERT_TRUE(out);
  ExpectAGridPath(open, *out, inside, outside);
}

// A wall across the room in two staggered halves that meet only at a corner: the two cells
// either side of that corner touch diagonally, with both cells beside the step blocked. No
// path cuts that corner; once the halves leave a cell between them, the path goes through.
TEST(GridPathTest, NoPathSlipsThroughACornerOnlyAGapWide) {
  const Eigen::Vector2d west(1.05, 1.05), east(5.05, 3.05);
  const Costmap2D corner = Room({Wall(3.0, 0.0, 3.1, 2.0), Wall(3.1, 2.0, 3.2, 4.0)});
  EXPECT_FALSE(GridShortestPath(corner, west, east));
  EXPECT_FALSE(GridShortestPath(corner, east, west));
  const Costmap2D gap = Room({Wall(3.0, 0.0, 3.1, 2.0), Wall(3.1, 2.1, 3.2, 4.0)});
  const auto path = GridShortestPath(gap, west, east);
  ASSERT_TRUE(path);
  ExpectAGridPath(gap, *path, west, east);
  // Through the gap's cell, (3.15, 2.05).
  bool through = false;
  for (const auto& p : *path)
    through |= (p - Eigen::Vector2d(3.15, 2.05)).norm() < 1e-6;
  EXPECT_TRUE(through);
  // Start and goal in one cell: a path of that cell.
  const auto here = GridShortestPath(gap, west, west + Eigen::Vector2d(0.01, 0.01));
  ASSERT_TRUE(here);
  EXPECT_EQ(here->size(), 1u);
}

// Unknown cells join the sides only where the search may cross them.
TEST(GridPathTest, UnknownCellsJoinOnlyWhenAllowed) {
  OccupancyGrid grid =
      OccupancyGrid::FromBoxes({Wall(3.0, 0.0, 3.1, 4.0)}, {0.0, 0.0}, {6.0, 4.0}, kCellM);
  // The wall's cells from y 1.5 to 2.5 become unknown.
  for (int iy = 15; iy < 25; ++iy)
    grid.at(30, iy) = perception::kUnknownCost;
  CostmapConfig config;
  config.robot_radius = 0.01;
  config.inflation_radius = 0.02;
  const Costmap2D costmap(grid, config);
  const Eigen::Vector2d west(1.05, 2.05), east(5.05, 2.05);
  EXPECT_FALSE(GridShortestPath(costmap, west, east, false));
  const auto path = GridShortestPath(costmap, west, east, true);
  ASSERT_TRUE(path);
  EXPECT_EQ(*costmap.geometry().CellOf(path->back()), *costmap.geometry().CellOf(east));
}

}  // namespace
}  // namespace egress::planning
