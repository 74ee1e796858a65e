#include "egress/planning/base_planner.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

using perception::Box2;
using perception::Costmap2D;
using perception::OccupancyGrid;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// The office (worlds/office): 14 m x 6 m, three rooms; door A (x = 5, y 2.5..3.5), door B
// (x = 9, y 1..2), a table in room 1.
OccupancyGrid Office() {
  return OccupancyGrid::LoadMapServerYaml(EGRESS_OFFICE_MAP);
}

class BasePlannerTest : public ::testing::Test {
 protected:
  BasePlannerTest() : costmap_(Office()) {
    costmap_.AddDoorway({"A", {5.0, 2.5}, {5.0, 3.5}});
    costmap_.AddDoorway({"B", {9.0, 1.0}, {9.0, 2.0}});
  }
  BasePlanner MakePlanner(std::shared_ptr<const octomap::OcTree> octree = nullptr,
                          BasePlannerConfig config = {}) {
    BasePlanner planner(costmap_, std::move(octree), config);
    planner.AddDoor({"A", {5.0, 2.5}, {5.0, 3.5}});
    planner.AddDoor({"B", {9.0, 1.0}, {9.0, 2.0}});
    return planner;
  }
  // Every point along the path, at 2 cm, keeps the footprint off inflated obstacles.
  void ExpectCollisionFree(const BasePlanner& planner, const std::vector<Pose2>& path) {
    for (std::size_t i = 1; i < path.size(); ++i) {
      const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
      const int steps = std::max(1, int((b - a).norm() / 0.02));
      for (int k = 0; k <= steps; ++k) {
        const Eigen::Vector2d p = a + (b - a) * (double(k) / steps);
        ASSERT_LT(costmap_.CostAt(p), perception::kInscribedCost) << p.transpose();
        ASSERT_TRUE(planner.IsValid({p.x(), p.y(), 0.0}));
      }
    }
  }
  Costmap2D costmap_;
};

TEST_F(BasePlannerTest, ThroughOpenDoorwaysOnTheirCentrelines) {
  const BasePlanner planner = MakePlanner();
  const PlanResult result = planner.Plan({1.5, 4.5, 0.0}, {12.5, 1.5, 0.0});
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_THAT(result.doors_crossed, ElementsAre("A", "B"));
  ExpectCollisionFree(planner, result.path);
  EXPECT_NEAR(result.path.front().x, 1.5, 1e-9);
  EXPECT_NEAR(result.path.back().y, 1.5, 1e-9);
  // The crossing of door A is the straight segment from its approach to its exit pose.
  bool found = false;
  for (std::size_t i = 1; i < result.path.size(); ++i) {
    if (std::abs(result.path[i - 1].x - 4.4) < 1e-9 && std::abs(result.path[i].x - 5.6) < 1e-9) {
      EXPECT_NEAR(result.path[i - 1].y, 3.0, 1e-9);
      EXPECT_NEAR(result.path[i].y, 3.0, 1e-9);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  const auto grid = GridShortestPathLength(costmap_, {1.5, 4.5}, {12.5, 1.5});
  ASSERT_TRUE(grid.has_value());
  EXPECT_LT(result.length, *grid * 1.15);
  EXPECT_GT(result.planning_time, 0.0);
}

TEST_F(BasePlannerTest, WestwardThroughDoorsAndYawsOfExactlyPiArePlanned) {
  // Westward crossings put the door poses at atan2(+0, -1) = pi, which OMPL's SO2 rejects
  // unless mapped into [-pi, pi); start and goal yaws of +-pi too.
  BasePlannerConfig config;
  config.deterministic = true;
  for (const BasePlanner& planner : {MakePlanner(), MakePlanner(nullptr, config)}) {
    const PlanResult result = planner.Plan({12.5, 1.5, M_PI}, {1.5, 4.5, -M_PI});
    ASSERT_TRUE(result.ok()) << result.message;
    EXPECT_THAT(result.doors_crossed, ElementsAre("B", "A"));
    ExpectCollisionFree(planner, result.path);
  }
}

TEST_F(BasePlannerTest, ClosedDoorMeansNoPath) {
  costmap_.SetDoorLeafAngle("A", 0.0);
  const PlanResult result = MakePlanner().Plan({1.5, 4.5, 0.0}, {12.5, 1.5, 0.0});
  EXPECT_EQ(result.status, PlanStatus::kGoalUnreachable);
  EXPECT_THAT(result.message, HasSubstr("closed door"));
  EXPECT_TRUE(result.path.empty());
}

TEST_F(BasePlannerTest, BadRequestsGetClearStatuses) {
  const BasePlanner planner = MakePlanner();
  PlanResult result = planner.Plan({std::nan(""), 1.0, 0.0}, {12.5, 1.5, 0.0});
  EXPECT_EQ(result.status, PlanStatus::kInvalidRequest);
  result = planner.Plan({1.5, 4.5, 0.0}, {20.0, 1.5, 0.0});
  EXPECT_EQ(result.status, PlanStatus::kInvalidRequest);
  EXPECT_THAT(result.message, HasSubstr("goal (20, 1.5) is outside the map"));
  result = planner.Plan({5.0, 1.0, 0.0}, {12.5, 1.5, 0.0});  // inside the wall
  EXPECT_EQ(result.status, PlanStatus::kStartInCollision);
  result = planner.Plan({1.5, 4.5, 0.0}, {2.5, 1.2, 0.0});  // on the table
  EXPECT_EQ(result.status, PlanStatus::kGoalInCollision);
  BasePlannerConfig config;
  config.planner = "AStar";
  EXPECT_THROW(BasePlanner(costmap_, nullptr, config), InvalidArgument);
}

TEST_F(BasePlannerTest, OctomapObstaclesTheLaserMissesAreAvoided) {
  // A table top at 0.7 m in the first room, invisible to the costmap.
  auto octree = std::make_shared<octomap::OcTree>(0.05);
  for (double x = 2.8; x <= 3.8; x += 0.05) {
    for (double y = 2.2; y <= 4.2; y += 0.05)
      octree->updateNode(x, y, 0.7, true);
  }
  octree->updateInnerOccupancy();
  const BasePlanner planner = MakePlanner(octree);
  EXPECT_TRUE(costmap_.IsFree({3.3, 3.2}));
  EXPECT_FALSE(planner.IsValid({3.3, 3.2, 0.0}));
  const PlanResult result = planner.Plan({1.5, 3.0, 0.0}, {12.5, 1.5, 0.0});
  ASSERT_TRUE(result.ok()) << result.message;
  for (std::size_t i = 1; i < result.path.size(); ++i) {
    const Eigen::Vector2d a = result.path[i - 1].translation(), b = result.path[i].translation();
    for (int k = 0; k <= 50; ++k)
      EXPECT_TRUE(planner.IsValid({(a + (b - a) * k / 50.0).x(), (a + (b - a) * k / 50.0).y(), 0}));
  }
}

TEST_F(BasePlannerTest, TheRobotsOwnOutlineDecidesUnderOverhangs) {
  // A shelf board at 0.8 m whose edge is at x = 3.0 (it reaches over x 3.0..3.6).
  auto octree = std::make_shared<octomap::OcTree>(0.05);
  for (double x = 3.0; x <= 3.6; x += 0.05) {
    for (double y = 2.2; y <= 4.2; y += 0.05)
      octree->updateNode(x, y, 0.8, true);
  }
  octree->updateInnerOccupancy();
  BasePlanner planner = MakePlanner(octree);
  const RobotModel model = RobotModel::LoadDefault();
  const auto tucked = model.CalcCollisionShapesInBase(
      {{"arm_roll_joint", -M_PI / 2}, {"wrist_flex_joint", -M_PI / 2}});
  // A payload carried in front at the shelf's height, 0.45 m ahead of the base's centre.
  auto carrying = tucked;
  CollisionShape bottle;
  bottle.name = "payload";
  bottle.kind = CollisionShape::Kind::kCylinder;
  bottle.size = {0.04, 0.04, 0.22};
  carrying.push_back({bottle, Pose3(Eigen::Vector3d(0.45, 0.0, 0.8))});

  // Base centre 0.3 m short of the edge, facing it: the default cylinder and the tucked robot
  // clear the board; the payload held out in front does not, unless the robot faces away.
  const Pose2 facing{2.7, 3.2, 0.0}, away{2.7, 3.2, M_PI};
  EXPECT_TRUE(planner.IsValid(facing));
  planner.SetBodyShapes(tucked);
  EXPECT_TRUE(planner.IsValid(facing));
  EXPECT_FALSE(planner.IsValid({3.3, 3.2, 0.0})) << "the torso and head reach the board";
  planner.SetBodyShapes(carrying);
  EXPECT_FALSE(planner.IsValid(facing));
  EXPECT_TRUE(planner.IsValid(away));
  // Far from the board the bounding check alone passes.
  EXPECT_TRUE(planner.IsValid({1.5, 3.0, 0.0}));
  planner.SetBodyShapes({});
  EXPECT_TRUE(planner.IsValid(facing)) << "an empty body falls back to the cylinder";

  auto broken = tucked;
  broken[0].shape.size.x() = std::nan("");
  EXPECT_THROW(planner.SetBodyShapes(broken), InvalidArgument);
}

TEST_F(BasePlannerTest, AnUpdatedCostmapInvalidatesThePathForReplanning) {
  const BasePlanner planner = MakePlanner();
  const PlanResult result = planner.Plan({6.0, 4.0, 0.0}, {8.0, 4.0, 0.0});
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(planner.IsPathValid(result.path));
  costmap_.SetProjectedObstacles({{7.0, 4.0}, {7.0, 4.05}, {7.0, 3.95}, {7.0, 4.1}, {7.0, 3.9}});
  EXPECT_FALSE(planner.IsPathValid(result.path));
  const PlanResult again = planner.Plan({6.0, 4.0, 0.0}, {8.0, 4.0, 0.0});
  ASSERT_TRUE(again.ok()) << again.message;
  EXPECT_TRUE(planner.IsPathValid(again.path));
}

TEST_F(BasePlannerTest, OptimizingPlannersByName) {
  for (const char* name : {"RRTstar", "InformedRRTstar", "PRMstar", "BITstar"}) {
    BasePlannerConfig config;
    config.planner = name;
    config.time_budget = 0.2;
    config.costmap_cost_weight = std::string(name) == "RRTstar" ? 0.5 : 0.0;
    const PlanResult result = MakePlanner(nullptr, config).Plan({6.0, 4.5, 0.0}, {8.0, 2.0, 0.0});
    ASSERT_TRUE(result.ok()) << name << ": " << result.message;
    EXPECT_LT(result.length, 4.0) << name;
  }
}

// A 6 m x 3 m room (walls 0.1 m thick) with a 1 m box standing out from the south wall in its
// middle; `gap` [m] is left between the box and the north wall.
Costmap2D RoomWithBox(double gap) {
  std::vector<Box2> boxes = {{{3.0, -0.05, 0.0}, {6.2, 0.1}},
                             {{3.0, 3.05, 0.0}, {6.2, 0.1}},
                             {{-0.05, 1.5, 0.0}, {0.1, 3.2}},
                             {{6.05, 1.5, 0.0}, {0.1, 3.2}}};
  const double height = 3.0 - gap;
  boxes.push_back({{3.0, height / 2, 0.0}, {1.0, height}});
  return Costmap2D(OccupancyGrid::FromBoxes(boxes, {-0.5, -0.5}, {6.5, 3.5}, 0.05));
}

// Closest distance of the path (sampled at 1 cm) to the box's corner region: the box spans
// x 2.5..3.5, y 0..top.
double ClosestToBox(const std::vector<Pose2>& path, double top) {
  double closest = 1e9;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
    const int steps = std::max(1, int((b - a).norm() / 0.01));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (double(k) / steps);
      const Eigen::Vector2d q(std::clamp(p.x(), 2.5, 3.5), std::clamp(p.y(), 0.0, top));
      closest = std::min(closest, (p - q).norm());
    }
  }
  return closest;
}

TEST(BasePlannerClearanceTest, TheGridPathKeepsItsMarginRoundCornersWhereThereIsRoom) {
  const Costmap2D costmap = RoomWithBox(1.5);
  BasePlannerConfig config;
  config.deterministic = true;
  config.clearance_weight = 4.0;
  const Pose2 start{1.0, 0.5, 0.0}, goal{5.0, 0.5, 0.0};
  const PlanResult kept = BasePlanner(costmap, nullptr, config).Plan(start, goal);
  ASSERT_TRUE(kept.ok()) << kept.message;
  // The margin beyond the footprint, less a cell of rasterization.
  EXPECT_GE(ClosestToBox(kept.path, 1.5), config.footprint_radius + config.clearance_margin - 0.05);
  // Without it the path is string-pulled on validity alone and grazes the corner.
  config.clearance_weight = 0.0;
  const PlanResult grazing = BasePlanner(costmap, nullptr, config).Plan(start, goal);
  ASSERT_TRUE(grazing.ok()) << grazing.message;
  EXPECT_LT(ClosestToBox(grazing.path, 1.5), config.footprint_radius + 0.05);
  EXPECT_LT(grazing.length, kept.length);
}

TEST(BasePlannerClearanceTest, APassageNarrowerThanTheMarginIsStillPassed) {
  // 0.55 m between the box and the wall: room for the 0.43 m footprint, not for the margin.
  const Costmap2D costmap = RoomWithBox(0.55);
  BasePlannerConfig config;
  config.deterministic = true;
  config.clearance_weight = 4.0;
  const PlanResult result =
      BasePlanner(costmap, nullptr, config).Plan({1.0, 2.7, 0.0}, {5.0, 2.7, 0.0});
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_GT(ClosestToBox(result.path, 2.45), config.footprint_radius - 0.05);
}

// Closest distance of the path (sampled at 1 cm) to p [m].
double ClosestTo(const std::vector<Pose2>& path, const Eigen::Vector2d& p) {
  double closest = 1e9;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
    const int steps = std::max(1, int((b - a).norm() / 0.01));
    for (int k = 0; k <= steps; ++k)
      closest = std::min(closest, (a + (b - a) * (double(k) / steps) - p).norm());
  }
  return closest;
}

// Someone standing in an open room on the straight line between start and goal: the path goes
// round their personal space where there is room, and straight past them without the layer.
TEST(BasePlannerPersonalSpaceTest, ThePathGoesRoundSomeonesPersonalSpaceWhereThereIsRoom) {
  Costmap2D costmap(OccupancyGrid::FromBoxes({}, {0, 0}, {8, 6}, 0.05));
  const Eigen::Vector2d p_MP(4.0, 3.0);
  // The person's body is not in the master grid here (the laser would mark it): the layer alone.
  costmap.SetPersonalSpaces({{p_MP, 0.9, 1.7, 1.0}});
  BasePlannerConfig config;
  config.deterministic = true;
  const Pose2 start{1.0, 3.0, 0.0}, goal{7.0, 3.0, 0.0};
  const PlanResult round = BasePlanner(costmap, nullptr, config).Plan(start, goal);
  ASSERT_TRUE(round.ok()) << round.message;
  // Outside the full-cost disc (less a cell), and shortcutting did not cut back in.
  EXPECT_GE(ClosestTo(round.path, p_MP), 0.9 - 0.05);
  config.personal_space_weight = 0.0;
  const PlanResult straight = BasePlanner(costmap, nullptr, config).Plan(start, goal);
  ASSERT_TRUE(straight.ok()) << straight.message;
  EXPECT_LT(ClosestTo(straight.path, p_MP), 0.05);
  EXPECT_LT(straight.length, round.length);
}

// Personal space steers, it never blocks: someone standing in the only passage is passed.
TEST(BasePlannerPersonalSpaceTest, SomeoneInTheOnlyPassageDoesNotBlockIt) {
  const Costmap2D room = RoomWithBox(0.8);
  Costmap2D costmap = room;
  costmap.SetPersonalSpaces({{{3.0, 2.6}, 0.9, 1.7, 1.0}});
  BasePlannerConfig config;
  config.deterministic = true;
  const PlanResult result =
      BasePlanner(costmap, nullptr, config).Plan({1.0, 2.6, 0.0}, {5.0, 2.6, 0.0});
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_GT(ClosestToBox(result.path, 2.2), config.footprint_radius - 0.05);
}

TEST(BasePlannerPersonalSpaceTest, ABadWeightIsRefused) {
  BasePlannerConfig config;
  config.personal_space_weight = -1.0;
  EXPECT_THAT([&] { config.Validate(); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("personal_space_weight")));
  config.personal_space_weight = std::nan("");
  EXPECT_THROW(config.Validate(), InvalidArgument);
  Costmap2D costmap(OccupancyGrid::FromBoxes({}, {0, 0}, {2, 2}, 0.05));
  EXPECT_THAT(
      [&] {
        GridCheapestPath(costmap, {0.5, 0.5}, {1.5, 1.5}, {.personal_space_weight = -1});
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("personal_space_weight")));
}

// A corridor (x 0..10, y 0..2) with a room south of it through a doorway in its south wall
// (x 4.5..5.5 at y = 0).
Costmap2D CorridorWithSideDoor() {
  const std::vector<Box2> boxes = {
      {{10.0 / 2, 2.05, 0.0}, {10.2, 0.1}}, {{2.25, -0.05, 0.0}, {4.5, 0.1}},
      {{7.75, -0.05, 0.0}, {4.5, 0.1}},     {{-0.05, 0.0, 0.0}, {0.1, 4.2}},
      {{10.05, 0.0, 0.0}, {0.1, 4.2}},      {{5.0, -2.05, 0.0}, {10.2, 0.1}}};
  return Costmap2D(OccupancyGrid::FromBoxes(boxes, {-0.5, -2.5}, {11.0, 5.0}, 0.05));
}
const PlannerDoor kSideDoor{"side", {4.5, 0.0}, {5.5, 0.0}};

// How far [m] the path (sampled at 1 cm) runs within `depth` of the side door's line across its
// opening widened by `widen`.
double LengthInSideDoorway(const std::vector<Pose2>& path, double depth, double widen) {
  double inside = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
    const int steps = std::max(1, int((b - a).norm() / 0.01));
    for (int k = 1; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (double(k) / steps);
      if (std::abs(p.x() - 5.0) <= 0.5 + widen && std::abs(p.y()) <= depth)
        inside += (b - a).norm() / steps;
    }
  }
  return inside;
}

// Along a corridor past a door in its wall, from and to spots by that wall: the path leaves the
// wall to pass the doorway, instead of running through it lengthwise.
TEST(BasePlannerDoorwayTest, APathAlongTheWallKeepsOutOfADoorwayItDoesNotUse) {
  const Costmap2D costmap = CorridorWithSideDoor();
  BasePlannerConfig config;
  config.deterministic = true;
  const Pose2 start{1.0, 0.4, 0.0}, goal{9.0, 0.4, 0.0};
  BasePlanner planner(costmap, nullptr, config);
  planner.AddDoor(kSideDoor);
  const PlanResult kept = planner.Plan(start, goal);
  ASSERT_TRUE(kept.ok()) << kept.message;
  EXPECT_TRUE(kept.doors_crossed.empty());
  // Out of the doorway (less a cell of rasterization), shortcutting included.
  EXPECT_EQ(
      LengthInSideDoorway(kept.path, config.door_standoff - 0.05, config.footprint_radius - 0.05),
      0.0);
  // Without the weight the path runs straight along the wall through the doorway.
  config.doorway_weight = 0.0;
  BasePlanner plain(costmap, nullptr, config);
  plain.AddDoor(kSideDoor);
  const PlanResult straight = plain.Plan(start, goal);
  ASSERT_TRUE(straight.ok()) << straight.message;
  EXPECT_GT(LengthInSideDoorway(straight.path, config.door_standoff, config.footprint_radius), 1.0);
  EXPECT_LT(straight.length, kept.length);
}

// The doorway weighs against running along a door, never against using it: through the door
// from the room, the path crosses it on its centreline, and from a start inside the doorway the
// path leaves it.
TEST(BasePlannerDoorwayTest, ADoorOnTheWayIsStillTakenAndADoorwayIsLeftStraight) {
  const Costmap2D costmap = CorridorWithSideDoor();
  BasePlannerConfig config;
  config.deterministic = true;
  BasePlanner planner(costmap, nullptr, config);
  planner.AddDoor(kSideDoor);
  const PlanResult through = planner.Plan({5.0, -1.5, M_PI / 2}, {9.0, 1.0, 0.0});
  ASSERT_TRUE(through.ok()) << through.message;
  EXPECT_THAT(through.doors_crossed, ElementsAre("side"));
  // From inside the doorway (0.3 m past the line) along the corridor: it runs no further in
  // the doorway than straight out of it would (0.3 m), plus a cell.
  const PlanResult out = planner.Plan({5.0, 0.3, 0.0}, {9.0, 0.4, 0.0});
  ASSERT_TRUE(out.ok()) << out.message;
  EXPECT_LT(LengthInSideDoorway(out.path, config.door_standoff - 0.05, 0.5), 0.3 + 0.1);
}

TEST(BasePlannerDoorwayTest, ABadWeightIsRefused) {
  BasePlannerConfig config;
  config.doorway_weight = -1.0;
  EXPECT_THAT([&] { config.Validate(); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("doorway_weight")));
  config.doorway_weight = std::nan("");
  EXPECT_THROW(config.Validate(), InvalidArgument);
  const Costmap2D costmap(OccupancyGrid::FromBoxes({}, {0, 0}, {2, 2}, 0.05));
  const std::vector<std::uint8_t> too_few(10, 0);
  EXPECT_THAT(
      [&] {
        GridCheapestPath(costmap, {0.5, 0.5}, {1.5, 1.5},
                         {.doorway = &too_few, .doorway_weight = 1.0});
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("doorway cells")));
}

TEST(BasePlannerClearanceTest, ABadMarginIsRefused) {
  BasePlannerConfig config;
  config.clearance_margin = -0.1;
  EXPECT_THROW(config.Validate(), InvalidArgument);
  config.clearance_margin = 0.1;
  config.clearance_weight = std::nan("");
  EXPECT_THROW(config.Validate(), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
