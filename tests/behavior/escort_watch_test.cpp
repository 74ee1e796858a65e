// What the escort sees round a door it holds (behavior/src/escort_watch.h): who is near, and
// whether anyone is coming.

#include <cmath>

#include <gtest/gtest.h>

#include "escort_watch.h"

namespace egress::behavior::detail {
namespace {

// The door's opening centred at the origin, the robot's side towards +x.
DoorPass Pass() {
  DoorPass pass;
  pass.centre = Eigen::Vector2d::Zero();
  pass.n_M = Eigen::Vector2d::UnitX();
  pass.width = 0.9;
  return pass;
}

// Measured at Time{}, the belief's default now.
perception::TrackedPersonWithIntent Person(int id, const Eigen::Vector2d& rest,
                                           const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
  perception::TrackedPersonWithIntent entry;
  entry.person.id = id;
  entry.person.p_MRest = rest;
  entry.person.p_MP = p;
  entry.person.v_MP = v;
  return entry;
}

constexpr double kWatchM = 6.0, kNearDoorM = 5.0;

TEST(EscortWatchTest, WatchTurnIsTheLeastTurnBringingBothBearingsWithinReach) {
  constexpr double kWithin = M_PI / 2;
  EXPECT_DOUBLE_EQ(WatchTurn(0.3, -1.2, kWithin), 0.0);  // both within already
  // One point: as far as brings it within reach.
  EXPECT_NEAR(WatchTurn(2.5, 2.5, kWithin), 2.5 - kWithin, 1e-12);
  EXPECT_NEAR(WatchTurn(-2.5, -2.5, kWithin), -2.5 + kWithin, 1e-12);
  // Two: the farther one brought to the edge, the other stays within.
  EXPECT_NEAR(WatchTurn(-M_PI / 2, -2.55, kWithin), -2.55 + kWithin, 1e-12);
  // Across the back: -3.0 is 0.28 rad on round from 3.0, and it is brought to the edge.
  EXPECT_NEAR(WatchTurn(3.0, -3.0, kWithin), (-3.0 + 2 * M_PI) - kWithin, 1e-12);
  // Too far apart for both (2.38 rad the short way round, across the back): centred.
  EXPECT_NEAR(WatchTurn(-2.0, 1.9, 0.5), 0.5 * (-2.0 + (1.9 - 2 * M_PI)), 1e-12);
}

TEST(EscortWatchTest, NobodyAboutIsNeitherNearNorMoving) {
  Belief belief;
  const Surroundings s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_FALSE(s.near);
  EXPECT_FALSE(s.moving);
}

// Someone is coming once they walk (faster than kMovingMps) and have walked off kWalkedOffM from
// where they stood; a tracker's wobble (fast, but where they stood) and a slow shuffle are not.
TEST(EscortWatchTest, SomeoneWalkingOffIsComingAWobbleIsNot) {
  Belief belief;
  belief.world.people = {Person(1, {3.0, 0.5}, {3.1, 0.5}, {-0.6, 0.0}),
                         Person(2, {3.0, -0.5}, {2.0, -0.5}, {-0.1, 0.0})};
  Surroundings s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  EXPECT_FALSE(s.moving);
  belief.world.people.push_back(Person(3, {3.6, 0.0}, {3.2, 0.0}, {-1.0, 0.0}));
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.moving);
  EXPECT_NE(s.mover.find("person 3"), std::string::npos) << s.mover;
}

// A track the sensors lost (at the edge of the laser's view, behind someone) coasts on its last
// velocity: after a spike of a step's worth, a standing person's track walks off on its own. Only
// a person measured within kSeenMovingWithinSec is seen coming.
TEST(EscortWatchTest, ATrackCoastingOutOfViewIsNotSomeoneComing) {
  Belief belief;
  belief.now = Time{} + SecondsToDuration(100.0);
  perception::TrackedPersonWithIntent coasting = Person(1, {3.0, 0.5}, {2.5, 0.5}, {-0.6, 0.0});
  coasting.person.last_seen = belief.now - SecondsToDuration(2 * kSeenMovingWithinSec);
  belief.world.people = {coasting};
  Surroundings s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  EXPECT_FALSE(s.moving);
  belief.world.people[0].person.last_seen =
      belief.now - SecondsToDuration(0.5 * kSeenMovingWithinSec);
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.moving);
}

// A leaf on the move is drawn in the costmap where the door estimate last put it, behind the leaf
// itself: its returns land off the map, and move. Returns where a moving leaf sweeps are not
// someone near, nor someone coming (two wards seed 7: door_e's leaf, opening towards the robot,
// kept the hold of a door everyone had passed from running out). The same returns with the leaf
// at rest, and any outside its sweep, are; a stale leaf's (not measured for a while) are not.
TEST(EscortWatchTest, ReturnsOfALeafOnTheMoveAreNotSomeone) {
  perception::TrackedDoor door;
  door.model.id = "d";
  door.model.p_MHinge = {0.0, -0.45};
  door.model.p_MLatch = {0.0, 0.45};
  door.model.swing_sign = -1.0;  // opens towards +x, the robot's side
  ASSERT_GT(door.model.SwingSide().x(), 0.9);
  door.state.observed = true;
  door.state.motion = perception::DoorMotion::kOpening;
  Belief belief;
  belief.world.doors = {door};
  const Eigen::Vector2d on_leaf{0.6, -0.1};
  ASSERT_TRUE(door.model.InSweep(on_leaf, 0.0));
  belief.off_map_returns = {on_leaf};
  belief.moving_returns = {on_leaf};
  Surroundings s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_FALSE(s.near);
  EXPECT_FALSE(s.moving);
  belief.world.doors[0].state.motion = perception::DoorMotion::kClosing;
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_FALSE(s.near);
  EXPECT_FALSE(s.moving);
  belief.world.doors[0].state.motion = perception::DoorMotion::kHeldOpen;  // at rest
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  EXPECT_TRUE(s.moving);
  // Stale (not measured for a while): the leaf may be anywhere on its sweep (random building
  // seed 7: seen again shut 12 s after it was last seen held open).
  belief.world.doors[0].stale = true;
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_FALSE(s.near);
  EXPECT_FALSE(s.moving);
  belief.off_map_returns = {{2.0, 0.0}};  // beyond the leaf's reach
  belief.moving_returns = {{2.0, 0.0}};
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  belief.world.doors[0].stale = false;
  belief.world.doors[0].state.motion = perception::DoorMotion::kOpening;
  belief.moving_returns = {{2.0, 0.0}};
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  EXPECT_TRUE(s.moving);
}

// People through the door (beyond kThroughM on the far side) or beyond the watch radius are not
// near; laser returns that moved near the door are someone coming.
TEST(EscortWatchTest, OnlyThisSideWithinReachCounts) {
  Belief belief;
  belief.world.people = {Person(1, {-2.0, 0.0}, {-2.0, 0.0}, {0.0, 0.0}),
                         Person(2, {8.0, 0.0}, {7.0, 0.0}, {-1.0, 0.0})};
  Surroundings s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_FALSE(s.near);
  EXPECT_FALSE(s.moving);
  belief.off_map_returns = {{2.0, 0.3}};
  belief.moving_returns = {{2.0, 0.3}};
  s = LookAround(belief, Pass(), kWatchM, kNearDoorM);
  EXPECT_TRUE(s.near);
  EXPECT_TRUE(s.moving);
  EXPECT_NE(s.mover.find("laser returns"), std::string::npos) << s.mover;
}

// Someone walking up to the doorway comes nearer it; a standing person's track that creeps (fast
// enough, and off where it stood, for seconds on end) stays by them (office seed 45). Only a walk
// that closes kComingCloserM on the doorway counts, from its farthest; a walk broken off for over
// kStirGapSec starts afresh.
TEST(EscortWatchTest, ApproachWatchCountsOnlyAWalkThatClosesOnTheDoorway) {
  Belief belief;
  ApproachWatch watch;
  const auto tick = [&](double t, const Eigen::Vector2d& p) {
    belief.now = Time{} + SecondsToDuration(t);
    perception::TrackedPersonWithIntent walker = Person(7, {4.0, 0.0}, p, {-0.4, 0.0});
    walker.person.last_seen = belief.now;
    belief.world.people = {walker};
    return watch.Update(belief, Pass(), kWatchM);
  };
  // Creeping back and forth between 3.6 and 3.2 m for 4 s: never.
  for (int k = 0; k <= 40; ++k) {
    const double x = 3.4 + 0.2 * std::sin(k * 0.3);
    EXPECT_FALSE(tick(0.1 * k, {x, 0.0})) << k;
  }
  // Walking on from 3.6 m: coming once 0.6 m nearer than the farthest it was.
  EXPECT_FALSE(tick(4.1, {3.3, 0.0}));
  EXPECT_FALSE(tick(4.2, {3.1, 0.0}));
  EXPECT_TRUE(tick(4.3, {2.95, 0.0}));
  // A gap over kStirGapSec: a new walk, from where it is now.
  EXPECT_FALSE(tick(4.3 + 2 * kStirGapSec, {2.9, 0.0}));
  EXPECT_FALSE(tick(4.4 + 2 * kStirGapSec, {2.6, 0.0}));
  EXPECT_TRUE(tick(4.5 + 2 * kStirGapSec, {2.25, 0.0}));
  // Standing (not SeenWalking) is no walk; through the door is not this side.
  watch.Reset();
  belief.world.people = {Person(7, {2.0, 0.0}, {2.0, 0.0}, {0.0, 0.0})};
  EXPECT_FALSE(watch.Update(belief, Pass(), kWatchM));
}

}  // namespace
}  // namespace egress::behavior::detail
