// What the escort sees round a door it holds (behavior/src/escort_watch.h): who is near, and
// whether anyone is coming.

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

}  // namespace
}  // namespace egress::behavior::detail
