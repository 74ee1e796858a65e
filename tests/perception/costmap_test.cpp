#include "egress/perception/costmap.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "synthetic.h"

namespace egress::perception {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

OccupancyGrid EmptyMap() {
  return OccupancyGrid::FromBoxes({}, {0, 0}, {10, 10}, 0.05);
}

// A scan with every beam empty except the one closest to `angle`, at `range`.
LaserScan SingleReturn(double angle, float range) {
  LaserScan scan = testing::MakeScan(1081);
  const auto i =
      static_cast<std::size_t>(std::lround((angle - scan.angle_min) / scan.angle_increment));
  scan.ranges[i] = range;
  return scan;
}

double ExpectedCost(const CostmapConfig& c, double d) {
  if (d <= c.robot_radius) return kInscribedCost;
  if (d > c.inflation_radius) return 0;
  return (kInscribedCost - 1) * std::exp(-c.cost_scaling_factor * (d - c.robot_radius));
}

TEST(CostmapTest, MarksInflatesAndClears) {
  Costmap2D costmap(EmptyMap());
  const Pose2 X_ML{5.0, 5.0, 0.0};
  costmap.UpdateWithScan(SingleReturn(0.0, 2.0f), X_ML);
  EXPECT_EQ(costmap.CostAt({7.02, 5.02}), kLethalCost);
  EXPECT_EQ(costmap.CostAt({7.02 - 0.1, 5.02}), kInscribedCost);
  // Inflation follows Nav2's decay (within a cell's quantization).
  for (double d : {0.3, 0.4, 0.5}) {
    const double cost = costmap.CostAt({7.025, 5.025 + d});
    EXPECT_NEAR(cost, ExpectedCost(costmap.config(), d), 25.0) << "d = " << d;
  }
  EXPECT_EQ(costmap.CostAt({7.025, 5.025 + 0.7}), kFreeCost);
  EXPECT_EQ(costmap.CostAt({6.0, 5.02}), kFreeCost);  // along the ray: free

  // The obstacle moved away: a ray with no return clears it.
  costmap.UpdateWithScan(SingleReturn(0.0, std::numeric_limits<float>::infinity()), X_ML);
  EXPECT_EQ(costmap.CostAt({7.02, 5.02}), kFreeCost);
  EXPECT_EQ(costmap.CostAt({7.02 - 0.1, 5.02}), kFreeCost);
}

TEST(CostmapTest, FarReturnsDoNotMarkAndStaticWallsAreNotCleared) {
  const OccupancyGrid walls =
      OccupancyGrid::FromBoxes({{{9.5, 5.0, 0.0}, {0.1, 10.0}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D costmap(walls);
  costmap.UpdateWithScan(SingleReturn(0.5, 2.9f),
                         {5.0, 5.0, 0.0});  // beyond obstacle_max_range 2.5
  EXPECT_EQ(costmap.CostAt(Eigen::Vector2d(5.0, 5.0) +
                           2.9 * Eigen::Vector2d(std::cos(0.5), std::sin(0.5))),
            kFreeCost);
  costmap.UpdateWithScan(SingleReturn(0.0, std::numeric_limits<float>::infinity()),
                         {7.0, 5.0, 0.0});
  EXPECT_EQ(costmap.CostAt({9.5, 5.0}), kLethalCost);  // the ray passes the wall: static stays
}

// The paper's S7 failure: inflation sealing a doorway the robot fits through.
TEST(CostmapTest, NarrowButPassableDoorwayStaysPassable) {
  // A wall at x = 5 with a 0.50 m opening (robot diameter 0.43 m) at y in [4.75, 5.25].
  const OccupancyGrid walls = OccupancyGrid::FromBoxes(
      {{{5.0, 2.375, 0.0}, {0.1, 4.75}}, {{5.0, 7.625, 0.0}, {0.1, 4.75}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D plain(walls);
  Costmap2D door_aware(walls);
  door_aware.AddDoorway({"lab", {5.0, 4.75}, {5.0, 5.25}, 1.0, 0.3});
  // Along the crossing line through the middle of the opening, within the threshold zone.
  int plain_worst = 0, aware_worst = 0;
  for (double x = 4.72; x <= 5.28; x += 0.025) {
    plain_worst = std::max<int>(plain_worst, plain.CostAt({x, 5.0}));
    aware_worst = std::max<int>(aware_worst, door_aware.CostAt({x, 5.0}));
    EXPECT_TRUE(door_aware.IsFree({x, 5.0})) << x;
  }
  EXPECT_GT(plain_worst, 128);  // plain inflation nearly seals it
  EXPECT_EQ(aware_worst, kFreeCost);
  // Too narrow for the robot: even the doorway layer keeps it blocked (inscribed).
  const OccupancyGrid narrow = OccupancyGrid::FromBoxes(
      {{{5.0, 2.4, 0.0}, {0.1, 4.8}}, {{5.0, 7.6, 0.0}, {0.1, 4.8}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D too_narrow(narrow);
  too_narrow.AddDoorway({"slot", {5.0, 4.8}, {5.0, 5.2}, 1.0, 0.3});
  EXPECT_FALSE(too_narrow.IsFree({5.0, 5.0}));
}

TEST(CostmapTest, DoorLeafIsMarkedAsItSwings) {
  const OccupancyGrid walls = OccupancyGrid::FromBoxes(
      {{{5.0, 2.25, 0.0}, {0.1, 4.5}}, {{5.0, 7.75, 0.0}, {0.1, 4.5}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D costmap(walls);
  costmap.AddDoorway({"office", {5.0, 4.5}, {5.0, 5.5}, -1.0, 0.3});  // hinge south, opens to +x
  EXPECT_TRUE(costmap.IsFree({5.0, 5.0}));
  costmap.SetDoorLeafAngle("office", 0.0);  // closed
  EXPECT_EQ(costmap.CostAt({5.0, 5.0}), kLethalCost);
  EXPECT_FALSE(costmap.IsFree({5.1, 5.0}));
  costmap.SetDoorLeafAngle("office", std::numbers::pi / 2);  // wide open, leaf along +x
  EXPECT_TRUE(costmap.IsFree({5.0, 5.0}));
  EXPECT_EQ(costmap.CostAt({5.8, 4.52}), kLethalCost);
  costmap.SetDoorLeafAngle("office", std::nullopt);
  EXPECT_EQ(costmap.CostAt({5.8, 4.52}), kFreeCost);
  EXPECT_THROW(costmap.SetDoorLeafAngle("attic", 0.0), InvalidArgument);
  EXPECT_THROW(costmap.AddDoorway({"office", {1, 1}, {2, 1}, 1.0, 0.3}), InvalidArgument);
}

TEST(CostmapTest, ProjectedObstaclesAndFootprint) {
  Costmap2D costmap(EmptyMap());
  costmap.SetProjectedObstacles({{3.0, 3.0}});
  EXPECT_EQ(costmap.CostAt({3.0, 3.0}), kLethalCost);
  EXPECT_EQ(costmap.FootprintCost({3.1, 3.0, 0.0}), kLethalCost);  // inside the 0.215 m disc
  EXPECT_LT(costmap.FootprintCost({3.5, 3.0, 0.0}), kInscribedCost);
  costmap.SetProjectedObstacles({});
  EXPECT_EQ(costmap.CostAt({3.0, 3.0}), kFreeCost);
  EXPECT_EQ(costmap.FootprintCost({0.1, 0.1, 0.0}), kUnknownCost);  // leaves the map
}

// The search runs ring by ring out from the point's own cell (nearest first, for speed): it must
// find a lethal cell anywhere within the radius, as a scan of the whole disc of cells does.
TEST(CostmapTest, IsNearMappedObstacleFindsALethalCellAnywhereWithinTheRadius) {
  const double res = 0.05;
  const OccupancyGrid grid =
      OccupancyGrid::FromBoxes({{{5.0, 5.0, 0.3}, {0.12, 0.07}}}, {0, 0}, {10, 10}, res);
  const Costmap2D costmap(grid);
  const auto brute_force = [&](const Eigen::Vector2d& p, double radius) {
    const int cx = int(std::floor(p.x() / res)), cy = int(std::floor(p.y() / res));
    const int n = int(std::ceil(radius / res));
    for (int y = cy - n; y <= cy + n; ++y)
      for (int x = cx - n; x <= cx + n; ++x)
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= std::pow(radius / res, 2) &&
            costmap.CostAt({(x + 0.5) * res, (y + 0.5) * res}) == kLethalCost)
          return true;
    return false;
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> offset(-0.6, 0.6), radius(0.0, 0.5);
  int near = 0, far = 0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d p(5.0 + offset(rng), 5.0 + offset(rng));
    const double r = radius(rng);
    const bool expected = brute_force(p, r);
    ASSERT_EQ(costmap.IsNearMappedObstacle(p, r), expected) << p.transpose() << " r " << r;
    (expected ? near : far)++;
  }
  EXPECT_GT(near, 200);
  EXPECT_GT(far, 200);
  EXPECT_TRUE(costmap.IsNearMappedObstacle({5.0, 5.0}, 0.0)) << "its own cell";
  EXPECT_FALSE(costmap.IsNearMappedObstacle({5.0, 5.0}, -0.2)) << "no radius";
}

// The map's lethal cells are found through their distance transform (no search): on maps of
// scattered obstacles, at the edges too, and on a map with none, it answers as a scan of the
// whole disc of cells does.
TEST(CostmapTest, IsNearMappedObstacleMatchesADiscScanOnScatteredMaps) {
  const double res = 0.05;
  std::mt19937 rng(11);
  for (int map = 0; map < 4; ++map) {
    std::uniform_real_distribution<double> x(0.0, 4.0), y(0.0, 3.0), half(0.01, 0.2);
    std::vector<Box2> boxes;
    const int count = map == 0 ? 0 : 5 * map;
    for (int k = 0; k < count; ++k)
      boxes.push_back({{x(rng), y(rng), x(rng)}, {half(rng), half(rng)}});
    const OccupancyGrid grid = OccupancyGrid::FromBoxes(boxes, {0, 0}, {4, 3}, res);
    const Costmap2D costmap(grid);
    const auto brute_force = [&](const Eigen::Vector2d& p, double radius) {
      const int cx = int(std::floor(p.x() / res)), cy = int(std::floor(p.y() / res));
      for (int yy = 0; yy < grid.geometry().height; ++yy)
        for (int xx = 0; xx < grid.geometry().width; ++xx)
          if ((xx - cx) * (xx - cx) + (yy - cy) * (yy - cy) <= std::pow(radius / res, 2) &&
              grid.cells()[grid.geometry().Index(xx, yy)] == kLethalCost)
            return true;
      return false;
    };
    std::uniform_real_distribution<double> px(0.0, 3.999), py(0.0, 2.999), radius(0.0, 0.6);
    int near = 0;
    for (int k = 0; k < 400; ++k) {
      const Eigen::Vector2d p(px(rng), py(rng));
      const double r = radius(rng);
      const bool expected = brute_force(p, r);
      ASSERT_EQ(costmap.IsNearMappedObstacle(p, r), expected)
          << "map " << map << " at " << p.transpose() << " r " << r;
      near += expected;
    }
    if (map == 0) {
      EXPECT_EQ(near, 0);
    } else if (map == 3) {
      EXPECT_GT(near, 40);
    }
  }
}

TEST(CostmapTest, SensedObstaclesAreTheMapTheLaserAndLeavesNotTheProjection) {
  const OccupancyGrid walls =
      OccupancyGrid::FromBoxes({{{5.0, 2.25, 0.0}, {0.1, 4.5}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D costmap(walls);
  costmap.AddDoorway({"office", {5.0, 4.5}, {5.0, 5.5}, -1.0, 0.3});
  EXPECT_TRUE(costmap.IsNearSensedObstacle({5.1, 2.0}, 0.1));  // the map's wall
  EXPECT_FALSE(costmap.IsNearSensedObstacle({5.3, 2.0}, 0.1));
  costmap.SetProjectedObstacles({{3.0, 3.0}});
  EXPECT_FALSE(costmap.IsNearSensedObstacle({3.0, 3.0}, 0.1));       // projected: not sensed
  costmap.UpdateWithScan(SingleReturn(0.0, 1.0f), {1.0, 8.0, 0.0});  // a return at (2, 8)
  EXPECT_TRUE(costmap.IsNearSensedObstacle({2.08, 8.0}, 0.15));
  EXPECT_FALSE(costmap.IsNearSensedObstacle({2.3, 8.0}, 0.15));
  costmap.SetDoorLeafAngle("office", 0.0);
  EXPECT_TRUE(costmap.IsNearSensedObstacle({5.05, 5.0}, 0.1));
  EXPECT_FALSE(costmap.IsNearSensedObstacle({-1.0, -1.0}, 0.1));  // outside the map
}

// Door leaves are searched only near a doorway with a leaf marked: on a map without walls, with
// leaves at random angles (some removed again), a point is near a leaf exactly when a lethal
// cell of the costmap (here only leaves) lies within the radius.
TEST(CostmapTest, IsNearMappedObstacleFindsEveryLeafWithinTheRadius) {
  const double res = 0.05;
  const OccupancyGrid floor({res, {0.0, 0.0}, 120, 120}, kFreeCost);
  Costmap2D costmap(floor);
  costmap.AddDoorway({"a", {1.0, 1.0}, {1.0, 2.0}, 1.0, 0.3});
  costmap.AddDoorway({"b", {4.0, 4.0}, {4.9, 4.3}, -1.0, 0.3});
  costmap.AddDoorway({"c", {5.2, 1.0}, {4.4, 1.2}, 1.0, 0.3});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 1.6), px(0.0, 5.999), radius(0.0, 0.5);
  for (int round = 0; round < 6; ++round) {
    costmap.SetDoorLeafAngle("a", angle(rng));
    costmap.SetDoorLeafAngle("b", round % 2 == 0 ? std::optional(angle(rng)) : std::nullopt);
    costmap.SetDoorLeafAngle("c", round % 3 == 0 ? std::optional(angle(rng)) : std::nullopt);
    std::vector<Eigen::Vector2i> lethal;
    for (int y = 0; y < 120; ++y)
      for (int x = 0; x < 120; ++x)
        if (costmap.CostAt({(x + 0.5) * res, (y + 0.5) * res}) == kLethalCost)
          lethal.emplace_back(x, y);
    ASSERT_GT(lethal.size(), 10u);
    int near = 0;
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector2d p(px(rng), px(rng));
      const double r = radius(rng);
      const Eigen::Vector2i c(int(std::floor(p.x() / res)), int(std::floor(p.y() / res)));
      const bool expected = std::any_of(lethal.begin(), lethal.end(), [&](const auto& q) {
        return double((q - c).squaredNorm()) <= std::pow(r / res, 2);
      });
      ASSERT_EQ(costmap.IsNearMappedObstacle(p, r), expected)
          << "round " << round << " at " << p.transpose() << " r " << r;
      near += expected;
    }
    EXPECT_GT(near, 0);
  }
}

// What the laser marked off the map is remembered where no ray clears it: the making-room
// steps into the robot's blind sector keep clear of it (HoldForResidents), but not of the
// laser's marks on a wall, which the map explains.
TEST(CostmapTest, UnmappedMarksAreWhatTheLaserSawOffTheMapAndStayOutOfView) {
  const OccupancyGrid walls =
      OccupancyGrid::FromBoxes({{{5.0, 2.25, 0.0}, {0.1, 4.5}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D costmap(walls);
  const Pose2 X_ML{3.0, 2.0, 0.0};
  costmap.UpdateWithScan(SingleReturn(0.0, 1.95f), X_ML);           // the wall's face at (4.95, 2)
  costmap.UpdateWithScan(SingleReturn(M_PI / 2, 1.0f), X_ML);       // someone at (3, 3)
  EXPECT_TRUE(costmap.IsNearSensedObstacle({4.6, 2.0}, 0.4));       // the wall's mark, sensed ...
  EXPECT_FALSE(costmap.IsNearUnmappedMark({4.6, 2.0}, 0.4, 0.15));  // ... but the map's
  EXPECT_TRUE(costmap.IsNearUnmappedMark({3.0, 2.7}, 0.4, 0.15));
  EXPECT_FALSE(costmap.IsNearUnmappedMark({3.0, 2.5}, 0.4, 0.15));  // beyond the radius
  // The laser turned away (the mark in its rear blind sector), seeing nothing: the mark stays.
  costmap.UpdateWithScan(SingleReturn(0.0, std::numeric_limits<float>::infinity()),
                         {3.0, 2.0, -M_PI / 2});
  EXPECT_TRUE(costmap.IsNearUnmappedMark({3.0, 2.7}, 0.4, 0.15));
  // A ray through it clears it.
  costmap.UpdateWithScan(SingleReturn(M_PI / 2, std::numeric_limits<float>::infinity()), X_ML);
  EXPECT_FALSE(costmap.IsNearUnmappedMark({3.0, 2.7}, 0.4, 0.15));
  EXPECT_FALSE(costmap.IsNearUnmappedMark({-1.0, -1.0}, 0.4, 0.15));  // outside the map
}

TEST(CostmapTest, MappedObstaclesAreTheMapAndLeavesNotWhatTheLaserSaw) {
  const OccupancyGrid walls =
      OccupancyGrid::FromBoxes({{{5.0, 2.25, 0.0}, {0.1, 4.5}}}, {0, 0}, {10, 10}, 0.05);
  Costmap2D costmap(walls);
  costmap.AddDoorway({"office", {5.0, 4.5}, {5.0, 5.5}, -1.0, 0.3});
  EXPECT_TRUE(costmap.IsNearMappedObstacle({5.1, 2.0}, 0.1));        // the map's wall
  costmap.UpdateWithScan(SingleReturn(0.0, 1.0f), {1.0, 8.0, 0.0});  // a return at (2, 8)
  EXPECT_TRUE(costmap.IsNearSensedObstacle({2.0, 8.0}, 0.1));
  EXPECT_FALSE(costmap.IsNearMappedObstacle({2.0, 8.0}, 0.1));   // someone off the map
  EXPECT_FALSE(costmap.IsNearMappedObstacle({5.05, 5.0}, 0.1));  // no leaf marked yet
  costmap.SetDoorLeafAngle("office", 0.0);
  EXPECT_TRUE(costmap.IsNearMappedObstacle({5.05, 5.0}, 0.1));
}

// The proxemic layer: full within inner, fading linearly to nothing at outer, scaled by the
// weight; beside the master grid, never in it; each call replaces the last.
TEST(CostmapTest, PersonalSpaceIsGradedBesideTheMasterGridAndReplacedEachTime) {
  Costmap2D costmap(EmptyMap());
  const std::vector<std::uint8_t> master = costmap.costs();
  costmap.SetPersonalSpaces({{{5.0, 5.0}, 0.9, 1.7, 1.0}, {{2.0, 2.0}, 0.9, 1.7, 0.5}});
  EXPECT_EQ(costmap.PersonalSpaceCostAt({5.02, 5.02}), kPersonalSpacePeakCost);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({5.0 + 0.85, 5.02}), kPersonalSpacePeakCost);
  // Halfway between inner and outer: half the peak (one cell's rounding).
  EXPECT_NEAR(costmap.PersonalSpaceCostAt({5.0 + 1.3, 5.02}), kPersonalSpacePeakCost / 2.0,
              kPersonalSpacePeakCost * 0.05 / 0.8 + 1);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({5.0 + 1.75, 5.02}), kFreeCost);
  // A prediction at half weight: half the peak at its centre.
  EXPECT_NEAR(costmap.PersonalSpaceCostAt({2.02, 2.02}), kPersonalSpacePeakCost / 2.0, 1.0);
  // Where both overlap, the higher counts; the master grid is untouched (nothing is blocked).
  EXPECT_EQ(costmap.costs(), master);
  EXPECT_TRUE(costmap.IsFree({5.0, 5.0}));
  // The image shows it on free cells.
  EXPECT_EQ(costmap.ToImage().at<std::uint8_t>(costmap.geometry().height - 1 - 100, 100),
            kPersonalSpacePeakCost);
  costmap.SetPersonalSpaces({{{8.0, 8.0}, 0.5, 1.0, 1.0}});
  EXPECT_EQ(costmap.PersonalSpaceCostAt({5.02, 5.02}), kFreeCost);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({2.02, 2.02}), kFreeCost);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({8.02, 8.02}), kPersonalSpacePeakCost);
  costmap.SetPersonalSpaces({});
  EXPECT_EQ(costmap.personal_space_costs(), std::vector<std::uint8_t>(master.size(), kFreeCost));
}

TEST(CostmapTest, APersonJustOffTheMapStillReachesIntoIt) {
  Costmap2D costmap(EmptyMap());
  costmap.SetPersonalSpaces({{{-0.5, 5.0}, 0.9, 1.7, 1.0}, {{1e12, -1e12}, 0.9, 1.7, 1.0}});
  EXPECT_EQ(costmap.PersonalSpaceCostAt({0.3, 5.02}), kPersonalSpacePeakCost);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({1.3, 5.02}), kFreeCost);
}

// Every cell as the layer's definition says, whatever shortcuts fill it (the row spans, spaces
// covered by another at the same centre): random spaces, on and off the map, some repeated at
// lower weights (a standing person's predictions), against a brute-force pass over every cell.
TEST(CostmapTest, PersonalSpacesFillExactlyTheCellsTheirDefinitionGives) {
  Costmap2D costmap(EmptyMap());
  const GridGeometry& g = costmap.geometry();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-1.5, 11.5), radius(0.0, 1.5), weight(0.05, 1.0);
  for (int round = 0; round < 20; ++round) {
    std::vector<PersonalSpace> spaces;
    for (int k = 0; k < 12; ++k) {
      const double inner = radius(rng);
      PersonalSpace s{{at(rng), at(rng)}, inner, inner + 0.05 + radius(rng), weight(rng)};
      spaces.push_back(s);
      if (k % 3 == 0) {
        s.weight *= 0.5;  // covered by the one before
        spaces.push_back(s);
        s.weight = 1.0;  // not covered: heavier
        spaces.push_back(s);
      }
    }
    costmap.SetPersonalSpaces(spaces);
    std::vector<std::uint8_t> expected(costmap.personal_space_costs().size(), kFreeCost);
    for (int iy = 0; iy < g.height; ++iy) {
      for (int ix = 0; ix < g.width; ++ix) {
        for (const PersonalSpace& s : spaces) {
          const double dx = (ix + 0.5) * g.resolution + g.origin.x() - s.p_MP.x();
          const double dy = (iy + 0.5) * g.resolution + g.origin.y() - s.p_MP.y();
          const double d2 = dx * dx + dy * dy;
          if (d2 >= s.outer * s.outer) continue;
          const double f =
              d2 <= s.inner * s.inner ? 1.0 : (s.outer - std::sqrt(d2)) / (s.outer - s.inner);
          const auto cost = static_cast<std::uint8_t>(kPersonalSpacePeakCost * s.weight * f + 0.5);
          std::uint8_t& cell = expected[g.Index(ix, iy)];
          cell = std::max(cell, cost);
        }
      }
    }
    ASSERT_EQ(costmap.personal_space_costs(), expected) << "round " << round;
  }
}

TEST(CostmapTest, AMalformedPersonalSpaceIsRefusedNamingWhatIsWrong) {
  Costmap2D costmap(EmptyMap());
  const auto refused = [&](PersonalSpace space, const std::string& what) {
    EXPECT_THAT(
        [&] {
          costmap.SetPersonalSpaces({{{1, 1}, 0.5, 1.0, 1.0}, space});
        },
        ::testing::ThrowsMessage<InvalidArgument>(::testing::AllOf(
            ::testing::HasSubstr("personal space 1"), ::testing::HasSubstr(what))));
  };
  refused({{kInf, 1.0}, 0.5, 1.0, 1.0}, "centre");
  refused({{1.0, std::nan("")}, 0.5, 1.0, 1.0}, "centre");
  refused({{1.0, 1.0}, -0.1, 1.0, 1.0}, "inner");
  refused({{1.0, 1.0}, 1.0, 1.0, 1.0}, "outer");
  refused({{1.0, 1.0}, 0.5, 50.0, 1.0}, "outer");
  refused({{1.0, 1.0}, 0.5, 1.0, 0.0}, "weight");
  refused({{1.0, 1.0}, 0.5, 1.0, 1.5}, "weight");
  // A refused call leaves the layer as it was.
  costmap.SetPersonalSpaces({{{5.0, 5.0}, 0.5, 1.0, 1.0}});
  EXPECT_THROW(costmap.SetPersonalSpaces({{{5.0, 5.0}, 0.5, 0.2, 1.0}}), InvalidArgument);
  EXPECT_EQ(costmap.PersonalSpaceCostAt({5.02, 5.02}), kPersonalSpacePeakCost);
}

// A scan at `stamp_s` whose beams all return nothing (they clear up to raytrace_max_range).
LaserScan EmptyScanAt(double stamp_s) {
  LaserScan scan = testing::MakeScan(1081);
  scan.stamp = SecondsToDuration(stamp_s);
  return scan;
}

TEST(CostmapTest, AMarkNoScanCanClearIsForgottenAfterItsLifetime) {
  Costmap2D costmap(EmptyMap());  // unseen_mark_lifetime 15 s, raytrace_max_range 3 m
  const Eigen::Vector2d p_MMark(7.02, 5.02);
  LaserScan hit = SingleReturn(0.0, 2.0f);  // from (5, 5) facing +x: a return at (7, 5)
  hit.stamp = SecondsToDuration(0.0);
  costmap.UpdateWithScan(hit, {5.0, 5.0, 0.0});
  ASSERT_EQ(costmap.CostAt(p_MMark), kLethalCost);
  // Marked again at 10 s: its clock restarts.
  hit.stamp = SecondsToDuration(10.0);
  costmap.UpdateWithScan(hit, {5.0, 5.0, 0.0});
  // The robot drives 4 m west: the mark is 6 m away, out of every ray's reach.
  const Pose2 X_MLAway{1.0, 5.0, 0.0};
  costmap.UpdateWithScan(EmptyScanAt(24.0), X_MLAway);
  EXPECT_EQ(costmap.CostAt(p_MMark), kLethalCost) << "14 s after the last mark: kept";
  costmap.UpdateWithScan(EmptyScanAt(25.5), X_MLAway);
  EXPECT_EQ(costmap.CostAt(p_MMark), kFreeCost) << "15.5 s after the last mark: forgotten";
  EXPECT_EQ(costmap.CostAt(p_MMark - Eigen::Vector2d(0.1, 0.0)), kFreeCost) << "and its inflation";
}

TEST(CostmapTest, AnOldMarkWithinClearingRangeIsLeftToTheRays) {
  // A return a ray stops at (the wall of someone standing still) is not forgotten however old:
  // within reach, only a ray that passes the cell clears it.
  Costmap2D costmap(EmptyMap());
  LaserScan hit = SingleReturn(0.0, 2.0f);
  hit.stamp = SecondsToDuration(0.0);
  costmap.UpdateWithScan(hit, {5.0, 5.0, 0.0});
  // 60 s later, from 2.5 m away and facing away (the rear 90 degrees are blind): within reach.
  costmap.UpdateWithScan(EmptyScanAt(60.0), {4.5, 5.0, std::numbers::pi});
  EXPECT_EQ(costmap.CostAt({7.02, 5.02}), kLethalCost);
}

TEST(CostmapTest, MalformedInputIsRejectedWithoutCrashing) {
  Costmap2D costmap(EmptyMap());
  LaserScan empty = testing::MakeScan(2);
  empty.ranges.clear();
  EXPECT_NO_THROW(costmap.UpdateWithScan(empty, {5, 5, 0}));  // an empty scan changes nothing
  LaserScan bad = testing::MakeScan(10);
  bad.angle_increment = 0.0;
  EXPECT_THROW(costmap.UpdateWithScan(bad, {5, 5, 0}), InvalidArgument);
  EXPECT_THROW(costmap.UpdateWithScan(testing::MakeScan(10), {kInf, 5, 0}), InvalidArgument);
  EXPECT_NO_THROW(costmap.UpdateWithScan(testing::MakeScan(10), {50, 50, 0}));  // off the map
  EXPECT_THROW(Costmap2D(EmptyMap(), CostmapConfig{0.3, 0.2}), InvalidArgument);
  CostmapConfig negative_lifetime;
  negative_lifetime.unseen_mark_lifetime = -1.0;
  EXPECT_THROW(Costmap2D(EmptyMap(), negative_lifetime), InvalidArgument);
  EXPECT_THROW(costmap.FootprintCost({std::nan(""), 0, 0}), InvalidArgument);
}

}  // namespace
}  // namespace egress::perception
