// Who keeps an evacuee waiting at a doorway (the rule of DoorwayTaken for evacuees), and where
// someone who cannot operate a shut door waits clear of its actuator (ClearOfActuator's rule).

#include "doorway_way.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace egress::twin::world_detail {
namespace {

// A 0.95 m doorway in a wall along x at y = 2.05 (the clinic's door_a), the evacuee coming
// from the north (y > 2.05) to go south through it.
const DoorwayFrame kDoor{Eigen::Vector2d(4.0, 2.05), Eigen::Vector2d::UnitY(),
                         Eigen::Vector2d::UnitX(), 0.475};
const Eigen::Vector2d kEvacuee(4.1, 2.8);

TEST(KeepsEvacueeWaitingTest, NobodyOnTheEvacueesOwnSideDoes) {
  // Ahead of them in the queue, standing or even stepping back.
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.0, 2.4}, Eigen::Vector2d::Zero()));
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.0, 2.3}, {0.0, 0.5}));
}

TEST(KeepsEvacueeWaitingTest, SomeoneBeyondGoingOnTheirWayDoesNot) {
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.0, 1.6}, {0.0, -1.0}));
}

TEST(KeepsEvacueeWaitingTest, SomeoneBeyondComingBackTowardsTheDoorDoes) {
  EXPECT_TRUE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.0, 1.4}, {0.0, 0.8}));
  // ... even off to the side of the opening, coming at it.
  EXPECT_TRUE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.6, 1.3}, {-0.3, 0.5}));
}

TEST(KeepsEvacueeWaitingTest, SomeoneStandingInTheOpeningDoes) {
  EXPECT_TRUE(KeepsEvacueeWaiting(kDoor, kEvacuee, {4.2, 1.8}, Eigen::Vector2d::Zero()));
  EXPECT_TRUE(KeepsEvacueeWaiting(kDoor, kEvacuee, {3.6, 2.0}, {0.5, 0.0}));
}

// Two wards seed 2: just through door_a, a resident turned east along the corridor 0.66 m
// beyond its door line; the wheelchair user behind them waited until the door shut.
TEST(KeepsEvacueeWaitingTest, SomeoneBeyondWalkingAlongTheCorridorPastTheDoorDoesNot) {
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, {4.18, 2.70}, {3.95, 1.39}, {0.6, 0.0}));
  // Nor someone standing there, clear of the opening.
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, kEvacuee, {3.95, 1.39}, Eigen::Vector2d::Zero()));
  EXPECT_FALSE(KeepsEvacueeWaiting(kDoor, kEvacuee, {3.3, 1.8}, Eigen::Vector2d::Zero()));
}

TEST(KeepsEvacueeWaitingTest, TheRuleHoldsForEitherSideAndAnyDoorOrientation) {
  // The same doorway turned 90 degrees (its line along y at x = 4.0), the evacuee coming from
  // the west: the mirror of each case above.
  const DoorwayFrame door{Eigen::Vector2d(4.0, 2.0), -Eigen::Vector2d::UnitX(),
                          Eigen::Vector2d::UnitY(), 0.475};
  const Eigen::Vector2d evacuee(3.2, 2.1);
  EXPECT_TRUE(KeepsEvacueeWaiting(door, evacuee, {4.6, 2.0}, {-0.8, 0.0}));   // coming back
  EXPECT_TRUE(KeepsEvacueeWaiting(door, evacuee, {4.2, 2.1}, {0.0, 0.0}));    // in the opening
  EXPECT_FALSE(KeepsEvacueeWaiting(door, evacuee, {4.65, 1.9}, {0.0, 0.6}));  // along past it
  EXPECT_FALSE(KeepsEvacueeWaiting(door, evacuee, {4.6, 2.0}, {1.0, 0.0}));   // going on
  EXPECT_FALSE(KeepsEvacueeWaiting(door, evacuee, {3.6, 2.0}, {0.0, 0.0}));   // ahead in queue
}

// The same door with a push button on its wall 1 m east of the doorway's centre, the spot where
// one stands to press it 0.5 m out into the north room; a wheelchair user (0.35 m) who cannot
// press it waits on the north side: they keep the spot's disc (0.3 m, and a 0.15 m margin) and
// the way to it square to the door (0.6 m either side) clear. The leaf slides.
const Eigen::Vector2d kSpot(5.0, 2.55);
constexpr double kKeepM = 0.3 + 0.15 + 0.35;
constexpr double kLaneHalfM = 0.6 + 0.35;
const LeafSweep kSliding{};

double AlongFromSpot(const Eigen::Vector2d& p) {
  return std::abs(p.x() - kSpot.x());
}

TEST(WaitClearOfActuatorTest, SomeoneClearOfTheSpotAndItsWayStays) {
  EXPECT_FALSE(WaitClearOfActuator(kDoor, 1.0, kSpot, {3.0, 3.0}, kKeepM, kLaneHalfM, kSliding));
  // Along the wall beyond the spot's disc, on the far side from the doorway.
  EXPECT_FALSE(WaitClearOfActuator(kDoor, 1.0, kSpot, {5.9, 2.5}, kKeepM, kLaneHalfM, kSliding));
}

TEST(WaitClearOfActuatorTest, SomeoneOnTheWayToTheSpotWaitsAcrossItOnTheDoorwaysSide) {
  const auto to = WaitClearOfActuator(kDoor, 1.0, kSpot, {5.2, 3.4}, kKeepM, kLaneHalfM, kSliding);
  ASSERT_TRUE(to);
  EXPECT_NEAR(AlongFromSpot(*to), kLaneHalfM, 1e-9);
  EXPECT_LT(to->x(), kSpot.x());  // the doorway's side
  EXPECT_NEAR(to->y(), 3.4, 1e-9);
}

// Atrium west seed 36: shut out, a wheelchair user came to wait between the spot and the wall,
// 0.07 m from the spot. Straight away from it is into the wall, which held them there for good.
TEST(WaitClearOfActuatorTest, SomeoneBetweenTheSpotAndItsWallStepsAlongTheWallNotIntoIt) {
  const Eigen::Vector2d at(5.05, 2.49);
  const auto to = WaitClearOfActuator(kDoor, 1.0, kSpot, at, kKeepM, kLaneHalfM, kSliding);
  ASSERT_TRUE(to);
  EXPECT_GE(to->y(), at.y() - 1e-9) << "towards the wall: " << to->transpose();
  EXPECT_GT((*to - kSpot).norm(), kKeepM);
  EXPECT_NEAR(AlongFromSpot(*to), kLaneHalfM, 1e-9);
}

TEST(WaitClearOfActuatorTest, AcrossTheWayTheyKeepOutOfTheSweepOfALeafOpeningTowardsThem) {
  // Hinged at the doorway's east jamb, swinging north (a 0.95 m leaf).
  const LeafSweep leaf{{4.475, 2.05}, 1.0, 0.95 + 0.35 + 0.1};
  const auto to = WaitClearOfActuator(kDoor, 1.0, kSpot, {5.2, 2.9}, kKeepM, kLaneHalfM, leaf);
  ASSERT_TRUE(to);
  EXPECT_NEAR(AlongFromSpot(*to), kLaneHalfM, 1e-9);
  EXPECT_GE((*to - leaf.p_WH).norm(), leaf.clear_radius - 1e-9);
  // On the side it does not swing to, the leaf is no matter.
  const LeafSweep south{leaf.p_WH, -1.0, leaf.clear_radius};
  const auto level = WaitClearOfActuator(kDoor, 1.0, kSpot, {5.2, 2.9}, kKeepM, kLaneHalfM, south);
  ASSERT_TRUE(level);
  EXPECT_NEAR(level->y(), 2.9, 1e-9);
}

// The robot at the origin coming east to a spot 2 m ahead; someone 0.2 m north of its way, 1 m
// along; they keep 0.7 m from the way.
const Eigen::Vector2d kRobot(0.0, 0.0), kWaySpot(2.0, 0.0), kInTheWay(1.0, 0.2);
constexpr double kWayKeepM = 0.7;
const auto kNoWalls = [](const Eigen::Vector2d& q) { return q; };
const auto kNothingBetween = [](const Eigen::Vector2d&, const Eigen::Vector2d&) { return false; };

TEST(AsideOfRobotsWayTest, SomeoneInTheWayStepsAsideOnTheirSide) {
  const auto to =
      AsideOfRobotsWay(kInTheWay, kRobot, kWaySpot, kWayKeepM, kNoWalls, kNothingBetween);
  ASSERT_TRUE(to);
  EXPECT_NEAR(to->x(), 1.0, 1e-9);
  EXPECT_NEAR(to->y(), kWayKeepM, 1e-9);
}

TEST(AsideOfRobotsWayTest, SomeoneClearOfTheWayOrBehindTheRobotStays) {
  EXPECT_FALSE(
      AsideOfRobotsWay({1.0, 0.8}, kRobot, kWaySpot, kWayKeepM, kNoWalls, kNothingBetween));
  EXPECT_FALSE(
      AsideOfRobotsWay({-0.5, 0.1}, kRobot, kWaySpot, kWayKeepM, kNoWalls, kNothingBetween));
}

// A wall 0.4 m north of the way: cleared of it, their side's point comes out beyond it (a
// wall between). They stay on their side (the caller keeps them clear of the actuator's lane),
// not across the way, where they would stand in the way of the next one who comes to operate
// the door (office seed 71).
TEST(AsideOfRobotsWayTest, WithAWallOnTheirSideTheyStayOnItRatherThanCrossTheWay) {
  const auto beyond_wall = [](const Eigen::Vector2d& q) {
    return q.y() > 0.4 ? Eigen::Vector2d(q.x(), std::max(q.y(), 0.4 + 0.35)) : q;
  };
  const auto wall_between = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.y() - 0.4) * (b.y() - 0.4) < 0.0;
  };
  EXPECT_FALSE(AsideOfRobotsWay(kInTheWay, kRobot, kWaySpot, kWayKeepM, beyond_wall, wall_between));
}

// Their side's point, cleared of a wall, comes back within reach of the way (no wall between):
// they step aside on the other side.
TEST(AsideOfRobotsWayTest, WithNoRoomOnTheirSideTheyStepToTheOther) {
  const auto pushed_back = [](const Eigen::Vector2d& q) {
    return Eigen::Vector2d(q.x(), std::min(q.y(), 0.3));
  };
  const auto to =
      AsideOfRobotsWay(kInTheWay, kRobot, kWaySpot, kWayKeepM, pushed_back, kNothingBetween);
  ASSERT_TRUE(to);
  EXPECT_NEAR(to->y(), -kWayKeepM, 1e-9);
}

}  // namespace
}  // namespace egress::twin::world_detail
