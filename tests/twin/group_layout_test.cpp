// Where a group's members stand at the start (GroupLayout): the grid where the building has room,
// the nearest fit place on the start's side of the walls where it has not.

#include "group_layout.h"

#include <optional>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::twin::world_detail {
namespace {

// The grid TwinWorld lays a group of `count` out on around `start`, `spacing` apart.
std::vector<Eigen::Vector2d> Grid(const Eigen::Vector2d& start, int count, double spacing) {
  std::vector<Eigen::Vector2d> grid;
  for (int k = 0; k < count; ++k)
    grid.push_back(start + GroupLayout::GridUnit(k, count) * spacing);
  return grid;
}

// The outline of the axis-aligned box lo..hi.
std::vector<WallSegment> Box(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const Eigen::Vector2d a = lo, b(hi.x(), lo.y()), c = hi, d(lo.x(), hi.y());
  return {{a, b, 0}, {b, c, 0}, {c, d, 0}, {d, a, 0}};
}

TEST(GroupLayoutTest, InTheOpenEveryoneStandsAtTheirGridPlace) {
  const auto grid = Grid({1.0, 2.0}, 12, 0.99);
  GroupLayout layout({1.0, 2.0}, grid, 0.99, Box({-10, -10}, {10, 10}));
  for (int k = 0; k < 12; ++k) {
    const auto place = layout.Place(k, 0.35);
    ASSERT_TRUE(place.has_value());
    EXPECT_EQ(*place, grid[std::size_t(k)]) << k;  // to the bit
  }
}

TEST(GroupLayoutTest, PlacesBeyondAWallMoveToTheStartsSideAndTheRestStay) {
  // A wall at x = 0.7: the grid's column at x = 1 lies beyond it.
  const std::vector<WallSegment> wall = {{{0.7, -10.0}, {0.7, 10.0}, -1}};
  const auto grid = Grid({0.0, 0.0}, 9, 1.0);
  GroupLayout layout({0.0, 0.0}, grid, 1.0, wall);
  std::set<std::pair<double, double>> taken;
  for (int k = 0; k < 9; ++k) {
    const auto place = layout.Place(k, 0.3);
    ASSERT_TRUE(place.has_value()) << k;
    EXPECT_LE(place->x(), 0.7 - 0.3) << k;
    if (grid[std::size_t(k)].x() < 0.7) {
      EXPECT_EQ(*place, grid[std::size_t(k)]) << k;
    } else {  // the nearest spare places on the start's side: (0, -2), (-2, 0), (0, 2)
      EXPECT_NEAR(place->norm(), 2.0, 1e-12) << k;
    }
    EXPECT_TRUE(taken.insert({place->x(), place->y()}).second) << "two members at one place";
  }
}

TEST(GroupLayoutTest, AGridPlaceTouchingAWallOnTheStartsSideStays) {
  // 0.1 m from the wall, for a body of 0.3 m: the walls' force moves it clear, as it always has.
  const std::vector<WallSegment> wall = {{{1.1, -10.0}, {1.1, 10.0}, -1}};
  const auto grid = Grid({0.0, 0.0}, 9, 1.0);
  GroupLayout layout({0.0, 0.0}, grid, 1.0, wall);
  for (int k = 0; k < 9; ++k)
    EXPECT_EQ(layout.Place(k, 0.3), std::optional<Eigen::Vector2d>(grid[std::size_t(k)])) << k;
}

TEST(GroupLayoutTest, APlaceBehindAPillarIsReachedRoundIt) {
  // The pillar hides the grid place (1, 0) from the start; grid steps reach it round the pillar.
  const auto grid = Grid({0.0, 0.0}, 9, 1.0);
  GroupLayout layout({0.0, 0.0}, grid, 1.0, Box({0.35, -0.2}, {0.65, 0.2}));
  for (int k = 0; k < 9; ++k)
    EXPECT_EQ(layout.Place(k, 0.3), std::optional<Eigen::Vector2d>(grid[std::size_t(k)])) << k;
}

TEST(GroupLayoutTest, AMovedMemberNeedsRoomForTheirBody) {
  // A corridor 1 m wide (y -0.5..0.5) along x: the grid's rows at y = +-1 lie beyond its walls;
  // its spare places along y = 0 clear them by 0.5 m, enough for a body of 0.3 m, not of 0.6 m.
  std::vector<WallSegment> corridor = {{{-20.0, -0.5}, {20.0, -0.5}, -1},
                                       {{-20.0, 0.5}, {20.0, 0.5}, -1}};
  const auto grid = Grid({0.0, 0.0}, 9, 1.0);
  GroupLayout narrow({0.0, 0.0}, grid, 1.0, corridor);
  EXPECT_EQ(narrow.Place(0, 0.6), std::nullopt);
  GroupLayout layout({0.0, 0.0}, grid, 1.0, corridor);
  for (int k = 0; k < 9; ++k) {
    const auto place = layout.Place(k, 0.3);
    ASSERT_TRUE(place.has_value()) << k;
    EXPECT_DOUBLE_EQ(place->y(), 0.0) << k;
  }
}

TEST(GroupLayoutTest, ARoomTooSmallForTheGroupLeavesAMemberWithoutAPlace) {
  // A closed room 1.6 m a side: of the 3 x 3 grid only the middle place is inside, and it is
  // member 4's.
  const auto grid = Grid({0.0, 0.0}, 9, 1.0);
  GroupLayout layout({0.0, 0.0}, grid, 1.0, Box({-0.8, -0.8}, {0.8, 0.8}));
  EXPECT_EQ(layout.Place(4, 0.3), std::optional<Eigen::Vector2d>(grid[4]));
  EXPECT_EQ(layout.Place(0, 0.3), std::nullopt);
}

TEST(GroupLayoutTest, NobodyStartsInADoorwayEvenAtTheirGridPlace) {
  // A wall at x = 0.1 with a doorway at y -0.5..0.5, its line to keep off. Member 4's grid place
  // (-0.1, 0) is 0.2 m from that line: a body of 0.3 m there stands in the doorway. Members 1
  // and 7, 0.2 m from the wall beside it, may touch the wall (and stay); the column at x = 0.9
  // lies beyond.
  const std::vector<WallSegment> walls = {{{0.1, -10.0}, {0.1, -0.5}, -1},
                                          {{0.1, 0.5}, {0.1, 10.0}, -1}};
  const std::vector<WallSegment> doorway = {{{0.1, -0.6}, {0.1, 0.6}, -1}};
  const auto grid = Grid({-0.1, 0.0}, 9, 1.0);
  GroupLayout layout({-0.1, 0.0}, grid, 1.0, walls, doorway);
  for (int k = 0; k < 9; ++k) {
    const auto place = layout.Place(k, 0.3);
    ASSERT_TRUE(place.has_value()) << k;
    if (k == 4 || k % 3 == 2) {
      EXPECT_NE(*place, grid[std::size_t(k)]) << k;
      EXPECT_LE(place->x(), 0.1 - 0.3) << k;
      EXPECT_GE((*place - Eigen::Vector2d(0.1, 0.0)).norm(), 0.6) << k;
    } else {
      EXPECT_EQ(*place, grid[std::size_t(k)]) << k;
    }
  }
}

TEST(GroupLayoutTest, TheGridIsSquareRowByRowAroundTheStart) {
  EXPECT_EQ(GroupLayout::Columns(12), 4);
  EXPECT_EQ(GroupLayout::Columns(16), 4);
  EXPECT_EQ(GroupLayout::Columns(17), 5);
  EXPECT_EQ(GroupLayout::GridUnit(0, 12), Eigen::Vector2d(-1.5, -1.5));
  EXPECT_EQ(GroupLayout::GridUnit(5, 12), Eigen::Vector2d(-0.5, -0.5));
  EXPECT_EQ(GroupLayout::GridUnit(4, 9), Eigen::Vector2d(0.0, 0.0));
}

TEST(GroupLayoutTest, BadArgumentsAreRefused) {
  EXPECT_THROW(GroupLayout({0.0, 0.0}, {}, 1.0, {}), InvalidArgument);
  EXPECT_THROW(GroupLayout({0.0, 0.0}, Grid({0, 0}, 4, 1.0), 0.0, {}), InvalidArgument);
  GroupLayout layout({0.0, 0.0}, Grid({0, 0}, 4, 1.0), 1.0, {});
  EXPECT_THROW(layout.Place(4, 0.3), InvalidArgument);
}

}  // namespace
}  // namespace egress::twin::world_detail
