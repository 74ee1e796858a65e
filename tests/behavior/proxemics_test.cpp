#include "egress/behavior/proxemics.h"

#include <cmath>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

constexpr double kRobotRadius = 0.215, kPersonRadius = 0.3;

perception::TrackedPersonWithIntent At(const Eigen::Vector2d& p_MP,
                                       const Eigen::Vector2d& v_MP = Eigen::Vector2d::Zero()) {
  perception::TrackedPersonWithIntent entry;
  entry.person.p_MP = p_MP;
  entry.person.v_MP = v_MP;
  return entry;
}

double Scale(const std::vector<perception::TrackedPersonWithIntent>& people,
             const Eigen::Vector2d& v_M = {0.2, 0.0}, const ProxemicsConfig& config = {}) {
  return ApproachSpeedScale({0.0, 0.0, 0.0}, v_M, std::nullopt, people, kRobotRadius, kPersonRadius,
                            config);
}

// Gaps are surface to surface: a person centred d ahead is d - 0.515 m from the robot's edge.
TEST(ProxemicsTest, HeadingTowardsSomeoneSlowsFromPersonalSpaceToAStop) {
  EXPECT_DOUBLE_EQ(Scale({}), 1.0);
  EXPECT_DOUBLE_EQ(Scale({At({0.515 + 1.3, 0.0})}), 1.0);     // beyond 1.2 m
  EXPECT_NEAR(Scale({At({0.515 + 0.825, 0.0})}), 0.5, 1e-9);  // half way
  EXPECT_DOUBLE_EQ(Scale({At({0.515 + 0.4, 0.0})}), 0.0);     // inside 0.45 m
  // Where they will be in a second counts: walking into the robot's way from 2 m ahead.
  EXPECT_LT(Scale({At({0.515 + 2.0, 0.0}, {-1.2, 0.0})}), 0.5);
  // The nearest sets the pace.
  EXPECT_DOUBLE_EQ(Scale({At({0.515 + 0.825, 0.0}), At({0.515 + 0.4, 0.1})}), 0.0);
}

TEST(ProxemicsTest, MovingAwayOrPastSomeoneIsNeverSlowed) {
  const auto behind = At({-0.515 - 0.2, 0.0});
  EXPECT_DOUBLE_EQ(Scale({behind}), 1.0);                              // retreating from them
  EXPECT_DOUBLE_EQ(Scale({At({0.0, 0.515 + 0.2})}), 1.0);              // beside, going past
  EXPECT_DOUBLE_EQ(Scale({At({0.515 + 0.2, 0.0})}, {0.0, 0.0}), 1.0);  // standing
  ProxemicsConfig off;
  off.slow_near_people = false;
  EXPECT_DOUBLE_EQ(Scale({At({0.515 + 0.2, 0.0})}, {0.2, 0.0}, off), 1.0);
}

// Going by someone ahead of abeam, outside the cone, slows for them as heading at them would when
// the straight way passes them within pass_gap (surface to surface); with room to spare it does
// not (atrium seed 71).
TEST(ProxemicsTest, GoingBySomeoneWithinThePassGapSlows) {
  const auto grazed = At({0.3, 0.6});  // 63 degrees off, passed 0.6 - 0.515 = 0.085 m off
  EXPECT_DOUBLE_EQ(Scale({grazed}), 0.0);
  EXPECT_DOUBLE_EQ(Scale({At({0.3, 0.8})}), 1.0);  // passed 0.285 m off
  ProxemicsConfig no_pass;
  no_pass.pass_gap = 0.0;
  EXPECT_DOUBLE_EQ(Scale({grazed}, {0.2, 0.0}, no_pass), 1.0);
  // Abeam or behind, going away: never (a retreat must be quick).
  EXPECT_DOUBLE_EQ(Scale({At({-0.1, 0.6})}), 1.0);
}

TEST(ProxemicsTest, PassedOnTheWayIsBesideTheWayNotAtItsEnds) {
  const Eigen::Vector2d p_MB(0.0, 0.0), p_MGoal(2.0, 0.0);
  EXPECT_TRUE(IsPassedOnTheWay({1.0, 0.5}, p_MB, p_MGoal, 0.6));
  EXPECT_FALSE(IsPassedOnTheWay({1.0, 0.7}, p_MB, p_MGoal, 0.6));   // beyond reach
  EXPECT_FALSE(IsPassedOnTheWay({2.3, 0.1}, p_MB, p_MGoal, 0.6));   // beyond the end
  EXPECT_FALSE(IsPassedOnTheWay({-0.3, 0.1}, p_MB, p_MGoal, 0.6));  // behind the start
  EXPECT_FALSE(IsPassedOnTheWay({1.0, 0.5}, p_MB, p_MB, 0.6));      // no way at all
}

// Near the path's end and no nearer than it, but walking, or beside the way there: not whom the
// robot goes to (atrium seed 71: a step making room ended 0.5 m past a resident walking up).
TEST(ProxemicsTest, SomeoneWalkingUpOrPassedOnTheWayIsNotWhomTheRobotGoesTo) {
  const Eigen::Vector2d end(0.3, 0.0);
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, end, {At({0.915, 0.0})},
                                      kRobotRadius, kPersonRadius, {}),
                   1.0);  // standing beyond the end: whom it goes to
  EXPECT_DOUBLE_EQ(
      ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, end, {At({0.915, 0.0}, {-0.5, 0.0})},
                         kRobotRadius, kPersonRadius, {}),
      0.0);  // walking up
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, Eigen::Vector2d(0.6, 0.0),
                                      {At({0.5, 0.6})}, kRobotRadius, kPersonRadius, {}),
                   0.0);  // standing beside the way, 0.085 m from the robot's edge as it passes
}

// Going to someone on purpose (a hand-over: the path ends at reach of the responder).
TEST(ProxemicsTest, SomeoneWhereThePathEndsIsWhomTheRobotGoesTo) {
  const std::vector people = {At({0.515 + 0.4, 0.0})};
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, Eigen::Vector2d(0.3, 0.0),
                                      people, kRobotRadius, kPersonRadius, {}),
                   1.0);
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, Eigen::Vector2d(-3.0, 0.0),
                                      people, kRobotRadius, kPersonRadius, {}),
                   0.0);
}

// Someone near where the path ends but between the robot and the end is in its way, not whom it
// goes to: a resident queueing by the button the robot drives to (the path ends 1.3 m ahead, the
// resident stands 0.9 m ahead, 0.4 m from the robot's edge).
TEST(ProxemicsTest, SomeoneOnTheRobotsSideOfThePathsEndIsInItsWay) {
  const std::vector people = {At({0.515 + 0.4, 0.0})};
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, Eigen::Vector2d(1.3, 0.0),
                                      people, kRobotRadius, kPersonRadius, {}),
                   0.0);
  // The same person with the path ending before them: whom the robot goes to.
  EXPECT_DOUBLE_EQ(ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, Eigen::Vector2d(0.9, 0.0),
                                      people, kRobotRadius, kPersonRadius, {}),
                   1.0);
}

TEST(ProxemicsTest, WhomTheRobotGoesToIsNearThePathsEndAndBeyondIt) {
  const Eigen::Vector2d p_MB(0.0, 0.0), p_MGoal(2.0, 0.0);
  EXPECT_TRUE(IsWhomTheRobotGoesTo({2.6, 0.2}, p_MB, p_MGoal, 1.5));   // beyond the end
  EXPECT_TRUE(IsWhomTheRobotGoesTo({2.0, 1.0}, p_MB, p_MGoal, 1.5));   // beside it
  EXPECT_FALSE(IsWhomTheRobotGoesTo({1.5, 0.0}, p_MB, p_MGoal, 1.5));  // on the robot's side
  EXPECT_FALSE(IsWhomTheRobotGoesTo({4.0, 0.0}, p_MB, p_MGoal, 1.5));  // too far beyond
}

// Oncoming: walking towards the robot and passing within the gap (0.8 m) within the horizon.
TEST(ProxemicsTest, SomeoneWalkingAtTheRobotIsOncomingUntilTheyPass) {
  const auto pass = [](const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
    return OncomingPassTime(At(p, v).person, {0.0, 0.0}, kRobotRadius, kPersonRadius, 0.8, 4.0,
                            0.3);
  };
  // Head-on from 3 m at 1 m/s: nearest in 3 s.
  ASSERT_TRUE(pass({3.0, 0.2}, {-1.0, 0.0}).has_value());
  EXPECT_NEAR(*pass({3.0, 0.2}, {-1.0, 0.0}), 3.0, 1e-9);
  // Still coming from 6 m: 4 s on they are 2 m off, within the gap of the robot's edge? No:
  // 2 - 0.515 > 0.8. From 5 m: 1 m off, 0.485 m from its edge: coming (passing in 5 s).
  EXPECT_FALSE(pass({6.0, 0.0}, {-1.0, 0.0}).has_value());
  ASSERT_TRUE(pass({5.0, 0.0}, {-1.0, 0.0}).has_value());
  EXPECT_NEAR(*pass({5.0, 0.0}, {-1.0, 0.0}), 5.0, 1e-9);
  // Passing 1.5 m to the side (edge gap 0.985 m), walking away, or standing: not coming.
  EXPECT_FALSE(pass({3.0, 1.5}, {-1.0, 0.0}).has_value());
  EXPECT_FALSE(pass({-1.0, 0.2}, {-1.0, 0.0}).has_value());
  EXPECT_FALSE(pass({1.0, 0.0}, {-0.2, 0.0}).has_value());
  EXPECT_FALSE(pass({1.0, 0.0}, {std::nan(""), 0.0}).has_value());
}

TEST(ProxemicsTest, BadConfigsAreRefusedNamingTheField) {
  ProxemicsConfig c;
  c.stop_gap = 2.0;  // beyond slow_gap
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.cone_deg = 0.0;
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.horizon = -1.0;
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.squeeze_gap = c.stop_gap;  // must be below it
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.patience_s = std::nan("");
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.standing_speed = -0.1;
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.pass_gap = -0.1;
  EXPECT_THROW(c.Validate(), InvalidArgument);
  c = {};
  c.patience_s = -1.0;
  EXPECT_THROW(ApproachPace{c}, InvalidArgument);
}

// Edging past: someone standing 0.3 m from the robot's edge ahead holds it still; with `squeeze`
// it goes on at a crawl down to squeeze_gap (0.2 m), and someone it goes by (abeam-ahead, out
// of the 60-degree cone) slows it too. Someone walking is never squeezed past.
TEST(ProxemicsTest, SqueezingPastSomeoneStandingCrawlsDownToTheSqueezeGap) {
  const ProxemicsConfig c;
  const auto scale = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& v, bool squeeze) {
    return ApproachSpeedScale({0.0, 0.0, 0.0}, {0.2, 0.0}, std::nullopt, {At(p, v)}, kRobotRadius,
                              kPersonRadius, c, squeeze);
  };
  const Eigen::Vector2d still = Eigen::Vector2d::Zero();
  EXPECT_DOUBLE_EQ(scale({0.515 + 0.3, 0.0}, still, false), 0.0);
  EXPECT_NEAR(scale({0.515 + 0.3, 0.0}, still, true), (0.3 - 0.2) / (0.45 - 0.2), 1e-9);
  EXPECT_DOUBLE_EQ(scale({0.515 + 0.15, 0.0}, still, true), 0.0);  // inside the squeeze gap
  // Going by, 70 degrees off the way at 0.25 m: not slowed at all, unless squeezing.
  const Eigen::Vector2d beside = (0.515 + 0.25) * Eigen::Vector2d(std::cos(1.22), std::sin(1.22));
  EXPECT_DOUBLE_EQ(scale(beside, still, false), 1.0);
  EXPECT_NEAR(scale(beside, still, true), (0.25 - 0.2) / (0.45 - 0.2), 1e-9);
  // Behind abeam: going away, never slowed.
  EXPECT_DOUBLE_EQ(scale({-0.1, 0.515 + 0.25}, still, true), 1.0);
  // Walking (0.5 m/s across, faster than standing_speed): the normal rule, squeeze or not.
  EXPECT_DOUBLE_EQ(scale({0.515 + 0.3, 0.0}, {0.0, 0.5}, true),
                   scale({0.515 + 0.3, 0.0}, {0.0, 0.5}, false));
}

// Patience: held to a crawl by someone standing for patience_s (5 s) in a row, the robot edges
// past; a spell with no path longer than kHeldGapSec, or someone walking, starts it afresh.
TEST(ProxemicsTest, ApproachPaceEdgesPastSomeoneStandingOnlyOncePatienceIsSpent) {
  ApproachPace pace{ProxemicsConfig{}};
  const std::vector standing = {At({0.515 + 0.3, 0.0})};
  const Eigen::Vector2d v(0.2, 0.0), none = Eigen::Vector2d::Zero();
  const auto update = [&](double t, const Eigen::Vector2d& v_M,
                          const std::vector<perception::TrackedPersonWithIntent>& people) {
    return pace.Update(t, {0.0, 0.0, 0.0}, v_M, std::nullopt, people, kRobotRadius, kPersonRadius);
  };
  const double edging = (0.3 - 0.2) / (0.45 - 0.2);
  double t = 0.0;
  for (; t < 4.95; t += 0.1) {
    EXPECT_DOUBLE_EQ(update(t, v, standing), 0.0) << t;
    // Steps where the planned pace is nil (held at a path's start) do not break the patience.
    EXPECT_DOUBLE_EQ(update(t + 0.05, none, standing), 1.0);
  }
  EXPECT_FALSE(pace.squeezing());
  EXPECT_NEAR(update(5.0, v, standing), edging, 1e-9);
  EXPECT_TRUE(pace.squeezing());
  EXPECT_NEAR(update(5.1, v, standing), edging, 1e-9);
  // Past them (nobody near): no longer held, and the patience is spent again next time.
  EXPECT_DOUBLE_EQ(update(5.2, v, {}), 1.0);
  EXPECT_FALSE(pace.squeezing());
  EXPECT_DOUBLE_EQ(update(5.3, v, standing), 0.0);
  // No path for 2 s (longer than kHeldGapSec), then held again: patience afresh.
  ApproachPace paused{ProxemicsConfig{}};
  for (double s = 0.0; s < 4.0; s += 0.1)
    paused.Update(s, {0.0, 0.0, 0.0}, v, std::nullopt, standing, kRobotRadius, kPersonRadius);
  EXPECT_DOUBLE_EQ(
      paused.Update(6.0, {0.0, 0.0, 0.0}, v, std::nullopt, standing, kRobotRadius, kPersonRadius),
      0.0);
  EXPECT_FALSE(paused.squeezing());
  // Someone walking at the robot holds it however long: they will be gone.
  ApproachPace walking{ProxemicsConfig{}};
  const std::vector coming = {At({0.515 + 1.0, 0.0}, {-0.5, 0.0})};
  for (double s = 0.0; s < 20.0; s += 0.1)
    walking.Update(s, {0.0, 0.0, 0.0}, v, std::nullopt, coming, kRobotRadius, kPersonRadius);
  EXPECT_FALSE(walking.squeezing());
  // patience_s 0: it waits for them however long.
  ProxemicsConfig never;
  never.patience_s = 0.0;
  ApproachPace waits{never};
  for (double s = 0.0; s < 20.0; s += 0.1)
    EXPECT_DOUBLE_EQ(
        waits.Update(s, {0.0, 0.0, 0.0}, v, std::nullopt, standing, kRobotRadius, kPersonRadius),
        0.0);
}

// A door 1 m wide on the x axis, hinge at x = -0.5: its doorway spans |x| < 0.5 + the
// footprint, within doorway_depth (0.6 m) of the line y = 0 on either side.
perception::DoorModel DoorOnTheXAxis() {
  perception::DoorModel door;
  door.id = "door";
  door.p_MHinge = {-0.5, 0.0};
  door.p_MLatch = {0.5, 0.0};
  return door;
}

TEST(ProxemicsTest, LeavingADoorwayIsGoingAwayFromItsLineBetweenItsJambs) {
  const std::vector doors = {DoorOnTheXAxis()};
  const double depth = ProxemicsConfig{}.doorway_depth;
  const auto leaving = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
    return IsLeavingDoorway({p.x(), p.y(), 0.0}, v, doors, depth, kRobotRadius);
  };
  EXPECT_TRUE(leaving({0.0, 0.3}, {0.0, 0.4}));    // past the line, going on
  EXPECT_TRUE(leaving({0.0, -0.3}, {0.0, -0.4}));  // either side
  EXPECT_FALSE(leaving({0.0, -0.3}, {0.0, 0.4}));  // coming to the line
  EXPECT_FALSE(leaving({0.0, 0.7}, {0.0, 0.4}));   // out of it already
  EXPECT_FALSE(leaving({0.8, 0.3}, {0.0, 0.4}));   // beside the jamb
  EXPECT_TRUE(leaving({0.6, 0.3}, {0.0, 0.4}));    // the footprint overlaps the opening
  EXPECT_FALSE(leaving({0.0, 0.3}, {0.0, 0.0}));   // standing
  EXPECT_FALSE(leaving({0.0, 0.3}, {0.4, 0.0}));   // along the line
  EXPECT_FALSE(IsLeavingDoorway({0.0, 0.3, 0.0}, {0.0, 0.4}, doors, 0.0, kRobotRadius));
}

// Two wards seed 24: out of a doorway into a corridor, a resident walking the corridor towards
// the robot's way held it to a stop 0.46 m past the line, in the way of whoever came through.
TEST(ProxemicsTest, LeavingADoorwayTheRobotCrawlsOutUnlessSomeoneIsWithinTheSqueezeGap) {
  const ProxemicsConfig config;
  const Eigen::Vector2d v(0.0, 0.4);
  const Pose2 X_MB{0.0, 0.4, M_PI / 2};
  // Walking across ahead, 0.35 m from the robot's edge now (inside stop_gap: a stop).
  const std::vector coming = {
      At({0.0 + 0.9 * std::cos(1.0), 0.4 + 0.9 * std::sin(1.0)}, {-0.3, 0.0})};
  const auto update = [&](ApproachPace* pace,
                          const std::vector<perception::TrackedPersonWithIntent>& people,
                          bool leaving) {
    return pace->Update(0.0, X_MB, v, std::nullopt, people, kRobotRadius, kPersonRadius, leaving);
  };
  ApproachPace held{config}, out{config};
  EXPECT_DOUBLE_EQ(update(&held, coming, false), 0.0);
  EXPECT_DOUBLE_EQ(update(&out, coming, true), ApproachPace::kHeldScale);
  // Nobody near: the planned pace, doorway or not.
  EXPECT_DOUBLE_EQ(update(&out, {}, true), 1.0);
  // Someone within the squeeze gap ahead stops it even there.
  const std::vector touching = {At({0.0, 0.4 + kRobotRadius + kPersonRadius + 0.1})};
  EXPECT_DOUBLE_EQ(update(&out, touching, true), 0.0);
  // Just beyond the squeeze gap: slower than a crawl, not stopped.
  const std::vector close = {At({0.0, 0.4 + kRobotRadius + kPersonRadius + 0.22})};
  EXPECT_NEAR(update(&out, close, true), (0.22 - 0.2) / (0.45 - 0.2), 1e-9);
}

}  // namespace
}  // namespace egress::behavior
