// Who keeps an evacuee waiting at a doorway (the rule of DoorwayTaken for evacuees).

#include "doorway_way.h"

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

}  // namespace
}  // namespace egress::twin::world_detail
