// People's predicted ways (PeopleAround) and the room they leave a spot (PeopleRoom), from
// behavior/src/task_node_support.h: walls turn a way along them but never back, and people walking
// past may step round the robot as far as the walls let them.

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "egress/behavior/proxemics.h"
#include "task_node_fixture.h"
#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

// A corridor along x, its walls' faces at y = 0 and y = 2, closed at x = 0 (a dead end).
perception::OccupancyGrid DeadEndCorridor() {
  using perception::Box2;
  return perception::OccupancyGrid::FromBoxes(
      {Box2{{5.0, -0.1, 0.0}, {12.0, 0.2}}, Box2{{5.0, 2.1, 0.0}, {12.0, 0.2}},
       Box2{{-0.1, 1.0, 0.0}, {0.2, 2.4}}},
      {-1.0, -1.0}, {11.0, 3.0}, 0.05);
}

perception::TrackedPersonWithIntent Walker(const Eigen::Vector2d& p_MP,
                                           const Eigen::Vector2d& v_MP) {
  perception::TrackedPersonWithIntent entry;
  entry.person.p_MP = p_MP;
  entry.person.v_MP = v_MP;
  return entry;
}

// The lab door's map (door line y = 3, the middle at (0, 3)) and a belief with the robot at
// X_MB, wired into task services.
struct AtTheLabDoor {
  explicit AtTheLabDoor(const Pose2& X_MB) {
    belief.X_MB = X_MB;
    task.map = &map;
    task.belief = &belief;
  }
  const MissionMap map = node_testing::LabDoor();
  Belief belief;
  TaskServices task;
};

class PeopleRoomTest : public ::testing::Test {
 protected:
  PeopleRoomTest() : costmap_(DeadEndCorridor()) {
    belief_.world.costmap = &costmap_;
    task_.belief = &belief_;
  }
  // What choosing and starting a step needs beyond the belief: the robot, its motion executor,
  // a planner on the corridor and a map with no doors, wired into task_.
  struct Stepping {
    explicit Stepping(PeopleRoomTest& test)
        : model(RobotModel::LoadDefault()), motion(model), planner(test.costmap_, nullptr) {
      test.task_.model = &model;
      test.task_.motion = &motion;
      test.task_.planner = &planner;
      test.task_.map = &map;
    }
    const RobotModel model;
    MotionExecutor motion;
    const planning::BasePlanner planner;
    MissionMap map;
  };
  perception::Costmap2D costmap_;
  Belief belief_;
  TaskServices task_;
};

// Walking to the corridor's dead end: the way stops at the end wall; it neither goes through it
// nor turns back along the walls (a group walking to the end was predicted back onto the robot).
TEST_F(PeopleRoomTest, AWayIntoADeadEndStopsThereAndNeverTurnsBack) {
  belief_.world.people = {Walker({3.0, 1.0}, {-1.2, 0.0})};
  const std::vector<Occupant> way = PeopleAround(task_, {3.0, 1.0}, 10.0, 8.0, 0.2);
  ASSERT_EQ(way.size(), 41u) << "every step of the horizon: they are still there";
  double x_before = 3.0 + 1e-9;
  for (const Occupant& o : way) {
    EXPECT_LE(o.p_M.x(), x_before) << "at t = " << o.t;
    EXPECT_GT(o.p_M.x(), 0.05) << "into the wall (its face at x = 0)";
    x_before = o.p_M.x();
  }
  EXPECT_LT(way.back().p_M.x(), 0.6);
  EXPECT_LT(way.back().v_M.norm(), 1e-9) << "standing at the end";
}

// A way a few degrees askew along the corridor turns along the wall and walks on.
TEST_F(PeopleRoomTest, AWayAskewIntoAWallTurnsAlongIt) {
  belief_.world.people = {Walker({9.0, 0.4}, {-1.0, -0.15})};
  const std::vector<Occupant> way = PeopleAround(task_, {9.0, 1.0}, 10.0, 4.0, 0.2);
  ASSERT_FALSE(way.empty());
  for (const Occupant& o : way)
    EXPECT_GT(o.p_M.y(), 0.05) << "into the wall (its face at y = 0)";
  EXPECT_LT(way.back().p_M.x(), 9.0 - 3.0) << "on along the wall, not stopped at it";
}

// Someone walking down the middle: a spot in the middle leaves them only a sidestep's room, a
// spot at the wall the corridor's other side. Without sidestep both are on their straight line's
// distance; with it, near-term predictions (no time to step aside) stay straight.
TEST_F(PeopleRoomTest, PeopleWalkingPastStepRoundTheRobotAsFarAsTheWallsLet) {
  belief_.world.people = {Walker({9.0, 1.0}, {-1.0, 0.0})};
  belief_.X_MB = {5.0, 1.0, 0.0};
  task_.config.person_sidestep = 0.6;
  const PeopleRoom straight(task_, 8.0);
  const PeopleRoom sidestep(task_, 8.0, {.sidestep = true});
  const double body = task_.config.person_radius;
  const Eigen::Vector2d middle(5.0, 1.0), at_wall(5.0, 0.3);
  EXPECT_LT(straight.Predicted(middle), 0.0) << "on their line";
  EXPECT_NEAR(straight.Predicted(at_wall), 0.7 - body, 0.02);
  // Sidestep 0.6 m at most: from the middle, its far end is 0.6 m off (either side is free).
  EXPECT_NEAR(sidestep.Predicted(middle), 0.6 - body, 0.03);
  // At the wall they step to y = 1.6: 1.3 m from the spot.
  EXPECT_NEAR(sidestep.Predicted(at_wall), 1.3 - body, 0.03);
  EXPECT_GT(sidestep.Predicted(at_wall), sidestep.Predicted(middle) + 0.5);
  // Next to the walker now, 0.1 s ahead of them: no time to step round.
  EXPECT_NEAR(sidestep.Predicted({8.9, 1.0}), straight.Predicted({8.9, 1.0}), 1e-9);

  // Squeezed between a wall and the far side: a sidestep stops where the body meets the wall.
  task_.config.person_sidestep = 2.0;
  task_.config.person_sidestep_speed = 10.0;
  const PeopleRoom far(task_, 8.0, {.sidestep = true});
  EXPECT_NEAR(far.Predicted({5.0, 0.3}), (2.0 - body - 0.3) - body, 0.06);
}

// Two walking abreast down the corridor at a robot standing in its middle (P2): the best spot is
// at a wall, leaving them the rest of the corridor. On straight lines every spot aside is in one
// of their lanes, and the robot stood where they squeezed past it on both sides.
TEST_F(PeopleRoomTest, TwoAbreastAreLeftTheCorridorBySteppingToAWall) {
  Stepping stepping(*this);
  const planning::BasePlanner& planner = stepping.planner;
  belief_.X_MB = {3.0, 0.95, 0.0};
  belief_.world.people = {Walker({8.0, 0.6}, {-1.1, 0.0}), Walker({8.0, 1.35}, {-1.1, 0.0})};
  const auto spot_for = [&](bool sidestep) {
    const PeopleRoom room(task_, 8.0, {.sidestep = sidestep});
    const Eigen::Vector2d at = belief_.X_MB.translation();
    return room.BestSpotAround({belief_.X_MB}, room.Score({at}) + 0.1);
  };
  const std::optional<Pose2> spot = spot_for(true);
  ASSERT_TRUE(spot.has_value());
  const double wall_gap = std::min(spot->y, 2.0 - spot->y);
  EXPECT_LT(wall_gap, task_.config.footprint_radius + 0.25) << "at a wall: y = " << spot->y;
  EXPECT_TRUE(planner.IsValid(*spot));
  // But not against it: the base turns there, and the planner's pose check passes a footprint
  // millimetres off a wall. The gap is measured to the wall's cells' centres, half a cell in.
  const double half_cell = costmap_.geometry().resolution / 2;
  EXPECT_GT(wall_gap + half_cell,
            task_.config.footprint_radius + PeopleRoom::kSpotWallClearanceM - 1e-9)
      << "y = " << spot->y;

  // MakeWaySpot (NavigateTo's give-way, HoldForResidents letting people pass) is this spot, the
  // ways predicted twice the give-way horizon; asking for more room than any spot gains, none.
  task_.config.give_way_horizon = 4.0;
  const std::optional<Pose2> made_way = MakeWaySpot(task_, 0.1);
  ASSERT_TRUE(made_way.has_value());
  EXPECT_NEAR(made_way->x, spot->x, 1e-9);
  EXPECT_NEAR(made_way->y, spot->y, 1e-9);
  EXPECT_FALSE(MakeWaySpot(task_, 100.0).has_value());
  // StepAsideTo starts the step there at retreat speed.
  StepAsideTo(task_, *made_way);
  EXPECT_TRUE(stepping.motion.base_moving());
}

// A spot the robot steps to keeps kSpotWallClearanceM off the walls: the base turns there to
// watch, and one 3 mm off a wall touched it (room A seed 29). Two walk abreast down the
// corridor's other side, and the robot stands anywhere from 0.45 to 0.95 m off the wall: the
// spots that leave them the most room are at the wall, some within what the planner passes.
TEST_F(PeopleRoomTest, ASpotToStepToKeepsClearOfTheWalls) {
  Stepping stepping(*this);
  const planning::BasePlanner& planner = stepping.planner;
  const double footprint = task_.config.footprint_radius;
  ASSERT_TRUE(planner.IsValid({3.0, footprint + 0.01, 0.0})) << "the planner's limit";
  belief_.world.people = {Walker({8.0, 1.2}, {-1.1, 0.0}), Walker({8.0, 1.7}, {-1.1, 0.0})};
  int spots = 0;
  for (double y = 0.45; y <= 0.95; y += 0.01) {
    belief_.X_MB = {3.0, y, 0.0};
    const PeopleRoom room(task_, 8.0, {.sidestep = true});
    const std::optional<Pose2> spot =
        room.BestSpotAround({belief_.X_MB}, room.Score({belief_.X_MB.translation()}));
    if (!spot) continue;
    ++spots;
    EXPECT_FALSE(costmap_.IsNearMappedObstacle(spot->translation(),
                                               footprint + PeopleRoom::kSpotWallClearanceM))
        << "from y = " << y << " to " << spot->x << ", " << spot->y;
  }
  EXPECT_GT(spots, 40);
}

// A step with the arm out (an operation broken off) must not put the hand into the wall the
// robot faces: the footprint's checks pass it, the hand reaches past them (atrium west seeds 5
// and 36). The robot faces the corridor's south wall (its face at y = 0), the arm held straight
// out ahead, the hand 0.2 m off the wall.
TEST_F(PeopleRoomTest, AStepKeepsTheHandOffTheWallTheRobotFaces) {
  Stepping stepping(*this);
  const RobotModel& model = stepping.model;
  MotionExecutor& motion = stepping.motion;
  const ArmPose out = {0.3, -M_PI / 2, 0.0, 0.0, 0.0};  // arm forward, level
  motion.MoveArm({{1.0, out}}, belief_.now);
  ASSERT_EQ(motion.arm_target(), out);
  WholeBodyVector q = WithArm(WholeBodyVector::Zero(), out);
  q[kBaseYaw] = -M_PI / 2;
  const Eigen::Vector2d p_BH_M = model.CalcPalmPose(q).translation().head<2>();
  ASSERT_LT(p_BH_M.y(), -(task_.config.footprint_radius + 0.1)) << "the hand out ahead";
  const Pose2 from{5.0, 0.2 - p_BH_M.y(), -M_PI / 2};
  // Along the wall, and back from it: clear.
  EXPECT_TRUE(HandClearOfWalls(task_, from, from.translation() + Eigen::Vector2d(0.6, 0.0)));
  EXPECT_TRUE(HandClearOfWalls(task_, from, from.translation() + Eigen::Vector2d(0.0, 0.6)));
  // 0.1 m nearer: the hand 0.1 m off, clear; 0.17 m nearer, 3 cm off: not.
  EXPECT_TRUE(HandClearOfWalls(task_, from, from.translation() + Eigen::Vector2d(0.3, -0.1)));
  EXPECT_FALSE(HandClearOfWalls(task_, from, from.translation() + Eigen::Vector2d(0.3, -0.17)));
  // The base's own footprint is nowhere near the wall on that step.
  EXPECT_FALSE(costmap_.IsNearMappedObstacle(from.translation() + Eigen::Vector2d(0.3, -0.17),
                                             task_.config.footprint_radius + 0.3));
  // Tucked, the hand stays over the base: the same step is clear.
  motion.MoveArm({{1.0, TuckedArm(model)}}, belief_.now);
  EXPECT_TRUE(HandClearOfWalls(task_, from, from.translation() + Eigen::Vector2d(0.3, -0.17)));
}

// Someone near, coming nearer while veering (their tracked velocity points at the wall, as when
// skirting the robot): with head_on they may also walk on straight through the robot's place,
// so a spot beyond the robot on that line is in their way; the velocity alone takes them to the
// wall and along it, clear of it. Anyone walking away, or farther than kHeadOnRadiusM, is
// predicted as before.
TEST_F(PeopleRoomTest, SomeoneNearComingNearerMayWalkStraightThroughTheRobotsPlace) {
  belief_.X_MB = {5.0, 1.0, 0.0};
  const Eigen::Vector2d beyond(4.0, 1.0);  // on the line from them through the robot
  const auto predicted = [&](bool head_on, const Eigen::Vector2d& q) {
    return PeopleRoom(task_, 3.0, {.head_on = head_on}).Predicted(q);
  };
  belief_.world.people = {Walker({6.2, 1.0}, {-0.3, -1.0})};
  EXPECT_LT(predicted(true, beyond), 0.0) << "their straight way passes through it";
  EXPECT_GT(predicted(false, beyond), 0.3) << "their tracked way keeps clear of it";
  // Their tracked way is still predicted too: a hypothesis only takes room.
  EXPECT_LT(predicted(true, {5.9, 0.3}), 0.1) << "where the tracked way meets the wall";
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(5.9, 0.3), Eigen::Vector2d(5.0, 0.3)})
    EXPECT_LE(predicted(true, q), predicted(false, q));

  for (const auto& walker : {Walker({6.2, 1.0}, {0.3, -1.0}),  // walking away from the robot
                             Walker({5.0 + PeopleRoom::kHeadOnRadiusM + 0.1, 1.0}, {-1.0, -0.3}),
                             Walker({6.2, 1.0}, {-0.1, -0.1})}) {  // standing (slower than 0.3)
    belief_.world.people = {walker};
    for (const Eigen::Vector2d& q :
         {beyond, Eigen::Vector2d(3.0, 1.0), Eigen::Vector2d(5.0, 0.3), Eigen::Vector2d(7.0, 1.5)})
      EXPECT_DOUBLE_EQ(predicted(true, q), predicted(false, q))
          << "at (" << q.transpose() << ") for a walker at (" << walker.person.p_MP.transpose()
          << ") moving (" << walker.person.v_MP.transpose() << ")";
  }
}

// People near a door's far side (or in its zone) may walk through the middle of its opening and
// on to the robot's side: the way goes through the opening's middle whatever line they walk on
// now, then along the normal, at their speed (or a walker's, if they dawdle). Nobody walking
// away from the opening, or farther than kThroughDoorRadiusM, has such a way.
TEST(ThroughDoorWaysTest, PeopleNearADoorsFarSideWalkThroughTheMiddleOfItsOpening) {
  AtTheLabDoor at({1.0, 2.4, M_PI / 2});  // beside the opening, on its south side
  Belief& belief = at.belief;
  TaskServices& task = at.task;
  const auto ways_of = [&](const Eigen::Vector2d& p_MP, const Eigen::Vector2d& v_MP) {
    auto entry = node_testing::Person(p_MP, perception::PersonIntent::kUnknown);
    entry.person.v_MP = v_MP;
    belief.world.people = {entry};
    return ThroughDoorWays(task, "lab_door", 4.0);
  };

  // Off the axis, walking south at 0.8 m/s: through (0, 3), then down x = 0.
  const std::vector<Occupant> way = ways_of({-0.3, 4.5}, {0.0, -0.8});
  ASSERT_FALSE(way.empty());
  const double to_middle = std::hypot(0.3, 1.5);
  double t_before = 0.0, nearest_middle = 1e9;
  for (const Occupant& o : way) {
    EXPECT_GT(o.t, t_before);
    t_before = o.t;
    nearest_middle = std::min(nearest_middle, (o.p_M - Eigen::Vector2d(0.0, 3.0)).norm());
    if (o.t > to_middle / 0.8 + 1e-9) {
      EXPECT_NEAR(o.p_M.x(), 0.0, 1e-9) << "along the normal after the middle";
      EXPECT_NEAR(o.p_M.y(), 3.0 - 0.8 * (o.t - to_middle / 0.8), 1e-9) << "at t = " << o.t;
    }
  }
  EXPECT_LT(nearest_middle, 0.8 * PeopleRoom::kPeopleStepSec);
  EXPECT_NEAR(way.back().t, 4.0, PeopleRoom::kPeopleStepSec);
  EXPECT_NEAR(RoomAt(way, belief.X_MB.translation()), 1.0 - task.config.person_radius, 0.01)
      << "the way passes 1 m from the robot beside the opening (sampled every 0.16 m)";

  // Standing in the doorway: as if walking at kWalkingMps.
  const std::vector<Occupant> dawdling = ways_of({0.0, 3.2}, {0.0, -0.1});
  ASSERT_FALSE(dawdling.empty());
  EXPECT_NEAR(dawdling.back().p_M.y(), 3.2 - kWalkingMps * dawdling.back().t, 1e-9);

  EXPECT_TRUE(ways_of({-0.3, 4.5}, {0.0, 0.8}).empty()) << "walking away from the opening";
  EXPECT_TRUE(ways_of({0.0, 3.0 + kThroughDoorRadiusM + 0.2}, {0.0, -1.0}).empty()) << "far";

  // On the robot's side, off the zone: only someone walking at the opening goes through it, and
  // on to the far side (P1: walking up behind the robot at the button, into the doorway).
  const std::vector<Occupant> inward = ways_of({1.5, 1.0}, {0.0, 0.8});
  ASSERT_FALSE(inward.empty());
  const double to_opening = std::hypot(1.5, 2.0);
  for (const Occupant& o : inward)
    if (o.t > to_opening / 0.8 + 1e-9) {
      EXPECT_NEAR(o.p_M.x(), 0.0, 1e-9) << "along the normal after the middle";
      EXPECT_NEAR(o.p_M.y(), 3.0 + 0.8 * (o.t - to_opening / 0.8), 1e-9) << "to the far side";
    }
  EXPECT_GT(inward.back().p_M.y(), 3.0 + 0.5);
  EXPECT_TRUE(ways_of({1.5, 1.0}, {0.8, 0.0}).empty()) << "walking along, not at the opening";
  EXPECT_TRUE(ways_of({1.5, 1.0}, {0.0, 0.2}).empty()) << "slower than kSidestepMinMps";
  EXPECT_TRUE(ways_of({0.0, 3.0 - kIntoDoorRadiusM - 0.2}, {0.0, 1.0}).empty()) << "far";
  EXPECT_FALSE(ways_of({0.0, 3.0 - kIntoDoorRadiusM + 0.2}, {0.0, 1.0}).empty());
  EXPECT_THROW(ThroughDoorWays(task, "no_such_door", 4.0), InvalidArgument);
}

// Someone coming round the leaf towards the opening's middle (walking along the door line as
// well as at it) walks on through it with that drift, not straight down the normal: H12 and P5's
// runner went on the way they were drifting, and a spot aside on that side was in their way.
TEST(ThroughDoorWaysTest, ThroughTheOpeningTheyKeepTheirDriftAlongTheDoorLine) {
  AtTheLabDoor at({0.0, 2.3, M_PI / 2});  // on the axis, at the entry
  Belief& belief = at.belief;
  TaskServices& task = at.task;
  auto entry = node_testing::Person({0.3, 4.4}, perception::PersonIntent::kUnknown);
  entry.person.v_MP = {-0.6, -0.8};  // 1 m/s, towards -x and the door
  belief.world.people = {entry};
  const std::vector<Occupant> way = ThroughDoorWays(task, "lab_door", 4.0);
  ASSERT_FALSE(way.empty());
  const double t_middle = std::hypot(0.3, 1.4) / 1.0;
  int after = 0;
  for (const Occupant& o : way) {
    if (o.t <= t_middle + 1e-9) continue;
    ++after;
    // From (0, 3) along the normal at their speed (0, -1) bent by their drift (-0.6, 0), at
    // their speed.
    const Eigen::Vector2d v = Eigen::Vector2d(-0.6, -1.0).normalized();
    EXPECT_NEAR(o.p_M.x(), v.x() * (o.t - t_middle), 1e-6) << "at t = " << o.t;
    EXPECT_NEAR(o.p_M.y(), 3.0 + v.y() * (o.t - t_middle), 1e-6) << "at t = " << o.t;
  }
  EXPECT_GT(after, 3);
  // So a spot on the side they drift to has less room than its mirror image.
  const PeopleRoom room(task, 4.0, {.through_door = "lab_door"});
  EXPECT_LT(room.Predicted({-1.0, 2.3}), room.Predicted({1.0, 2.3}) - 0.2);
}

// Someone walking at the door the robot stands beside, read slow (a track that has just set off
// from standing and coasts out of the laser's view: P1, 0.46 m/s read for 1.3 m/s): not coming
// by their tracked line and speed, but coming by their way through the opening's middle at a
// walker's pace. Nobody standing, nor walking away from the door, counts so.
TEST(PeopleComingTest, SomeoneWalkingThroughTheDoorTheRobotStandsBesideIsComing) {
  AtTheLabDoor at({1.15, 2.43, M_PI / 2});  // at the button, beside the opening
  Belief& belief = at.belief;
  TaskServices& task = at.task;
  const auto coming_with = [&](const Eigen::Vector2d& v_MP, const std::string& door) {
    auto entry = node_testing::Person({1.5, 0.8}, perception::PersonIntent::kUnknown);
    entry.person.v_MP = v_MP;
    belief.world.people = {entry};
    return PeopleComing(task, std::nullopt, door);
  };
  const Eigen::Vector2d at_the_door =
      0.46 * (Eigen::Vector2d(0.0, 3.0) - Eigen::Vector2d(1.5, 0.8)).normalized();
  EXPECT_TRUE(coming_with(at_the_door, "").empty()) << "slower than a walker";
  const auto coming = coming_with(at_the_door, "lab_door");
  ASSERT_EQ(coming.size(), 1u);
  EXPECT_GT(coming.front().second, 0.0);
  EXPECT_LT(coming.front().second, task.config.give_way_horizon);
  EXPECT_TRUE(coming_with({0.1, 0.1}, "lab_door").empty()) << "standing";
  EXPECT_TRUE(coming_with(-at_the_door, "lab_door").empty()) << "walking away from the door";
  EXPECT_THROW(coming_with(at_the_door, "no_such_door"), InvalidArgument);
}

// Whom the robot beside a door's opening makes way for: someone walking at it, or whoever may
// come through the doorway past it within comfort_distance (someone dawdling in it); nobody
// else, and nobody through a door it was not given.
TEST(WhomToMakeWayForTest, SomeoneComingOrWhoeverComesThroughTheDoorway) {
  AtTheLabDoor at({1.0, 2.4, M_PI / 2});
  Belief& belief = at.belief;
  TaskServices& task = at.task;
  const auto whom_with = [&](const Eigen::Vector2d& p_MP, const Eigen::Vector2d& v_MP,
                             const std::string& door) {
    auto entry = node_testing::Person(p_MP, perception::PersonIntent::kUnknown);
    entry.person.v_MP = v_MP;
    belief.world.people = {entry};
    return WhomToMakeWayFor(task, door);
  };
  EXPECT_EQ(whom_with({1.0, -1.0}, {0.0, 1.2}, ""), "someone coming");
  EXPECT_EQ(whom_with({0.0, 3.2}, {0.0, -0.1}, "lab_door"), "whoever comes through the doorway");
  EXPECT_FALSE(whom_with({0.0, 3.2}, {0.0, -0.1}, "").has_value()) << "no door given";
  EXPECT_FALSE(whom_with({-2.5, 0.0}, {0.0, 0.0}, "lab_door").has_value()) << "standing aside";
  EXPECT_THROW(whom_with({0.0, 3.2}, {0.0, -0.1}, "no_such_door"), InvalidArgument);
}

// A way through a doorway's middle is where they must go: PeopleRoom grants it no sidestep (P1:
// the robot beside the opening judged a walker coming up behind it would step round it, stood,
// and was passed 0.64 m off). Their tracked way keeps its sidestep.
TEST_F(PeopleRoomTest, AWayThroughADoorwaysMiddleHasNoRoomToStepOff) {
  Stepping stepping(*this);
  stepping.map = node_testing::LabDoor();  // door line y = 3, the middle at (0, 3)
  belief_.world.costmap = nullptr;         // the lab door's open floor, not the corridor
  belief_.X_MB = {1.0, 2.4, M_PI / 2};
  // Dawdling in the doorway: through the middle and down x = 0 at a walker's pace.
  belief_.world.people = {Walker({0.0, 3.2}, {0.0, -0.1})};
  const Eigen::Vector2d on_the_way(0.0, 2.0);
  const PeopleRoom through(task_, 4.0, {.sidestep = true, .through_door = "lab_door"});
  const PeopleRoom tracked(task_, 4.0, {.sidestep = true});
  EXPECT_LT(through.Predicted(on_the_way), 0.0) << "no step off the way through the middle";
  EXPECT_GT(tracked.Predicted(on_the_way), 0.3) << "the tracked way stops short of it";
  // Walking down x = 0 at 1 m/s, tracked: they may step round a spot on their way.
  belief_.world.people = {Walker({0.0, 4.5}, {0.0, -1.0})};
  const PeopleRoom walking(task_, 4.0, {.sidestep = true, .through_door = "lab_door"});
  const PeopleRoom straight(task_, 4.0, {.through_door = "lab_door"});
  EXPECT_LT(walking.Predicted(on_the_way), 0.0) << "the way through the middle is on it";
  EXPECT_NEAR(walking.Predicted(on_the_way), straight.Predicted(on_the_way), 1e-9);
}

// The base has stopped below kStoppedMps, or is given kStopWithinSec to.
// A way aside the executive's pace would hold to a crawl (it heads at someone near, or where
// they will be within its horizon) is no way aside: the robot would stand still on it (H12, P5:
// chosen on a first glimpse, it stopped after 3 cm and the runner squeezed past at 5 cm).
TEST_F(PeopleRoomTest, AWayThePaceHoldsBackIsNoWayAside) {
  Stepping stepping(*this);
  const ProxemicsConfig proxemics;
  belief_.X_MB = {5.0, 1.0, 0.0};
  // Walking down the corridor at the robot, 1.5 m off: in a second, 0.3 m from it.
  belief_.world.people = {Walker({6.5, 1.0}, {-1.2, 0.0})};
  const Eigen::Vector2d at = belief_.X_MB.translation();
  const std::vector<Eigen::Vector2d> towards{at, {5.8, 1.4}}, away{at, {4.0, 1.0}};
  {
    const PeopleRoom room(task_, 3.0);
    EXPECT_FALSE(room.IsWayHeldBack(towards)) << "without a pace nothing holds it back";
  }
  task_.proxemics = &proxemics;
  const PeopleRoom room(task_, 3.0);
  EXPECT_TRUE(room.IsWayHeldBack(towards));
  EXPECT_FALSE(room.IsWayHeldBack(away));
  EXPECT_FALSE(room.IsWayHeldBack({at})) << "no way";
  // No spot chosen aside is one the pace holds back.
  const std::optional<Pose2> spot = room.BestSpotAround({belief_.X_MB}, -1e9);
  ASSERT_TRUE(spot.has_value());
  EXPECT_FALSE(room.IsWayHeldBack({at, spot->translation()}))
      << "to " << spot->x << ", " << spot->y;
  // Without the pace, one of the spots most to the side, ahead, is held back.
  ProxemicsConfig none = proxemics;
  none.slow_near_people = false;
  task_.proxemics = &none;
  EXPECT_FALSE(PeopleRoom(task_, 3.0).IsWayHeldBack(towards));
}

TEST_F(PeopleRoomTest, StoppedOnceSlowOrOnceTheStopTimeHasRunOut) {
  belief_.now = SecondsToDuration(10.0);
  belief_.V_B = {0.3, 0.0, 0.0};
  EXPECT_FALSE(StoppedOrStopTimedOut(task_, SecondsToDuration(9.0)));
  EXPECT_TRUE(StoppedOrStopTimedOut(task_, SecondsToDuration(10.0 - kStopWithinSec)));
  belief_.V_B = {0.03, 0.04, 0.5};  // 0.05 m/s: turning on the spot counts as stopped
  EXPECT_TRUE(StoppedOrStopTimedOut(task_, SecondsToDuration(10.0)));
}

}  // namespace
}  // namespace egress::behavior::detail
