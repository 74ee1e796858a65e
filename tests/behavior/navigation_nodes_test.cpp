// The navigation nodes (behavior/src/navigation_nodes.cpp), ticked in one-node trees.

#include <optional>

#include "task_node_fixture.h"
#include "task_node_support.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;
using node_testing::Person;
using NavigationNodesTest = node_testing::TaskNodeFixture;

TEST_F(NavigationNodesTest, NavigateToPlansAndFollowsAPathToTheGoal) {
  bt::Tree tree = Tree(R"(<NavigateTo goal="1.5;1.0;0.0"/>)");
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(1.5, 1.0)).norm(), 1e-6);
  EXPECT_TRUE(motion_.base_moving());
  // Halted (a reactive condition failed): the base stops in the same tick.
  tree.HaltTree();
  EXPECT_FALSE(motion_.base_moving());
}

// door_speed: the same path, every segment at the door speed (a sweep to let residents out).
TEST_F(NavigationNodesTest, NavigateToAtTheDoorSpeedFollowsTheSamePathFaster) {
  const auto planned = [&](const std::string& xml) {
    motion_.StopBase();
    bt::Tree tree = Tree(xml);
    belief_.now = At(1.0);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning) << xml;
    return std::pair(motion_.path(), motion_.base_duration());
  };
  const auto [path, nominal] = planned(R"(<NavigateTo goal="1.5;1.0;0.0"/>)");
  const auto [same_path, default_too] =
      planned(R"(<NavigateTo goal="1.5;1.0;0.0" door_speed="false"/>)");
  const auto [fast_path, fast] = planned(R"(<NavigateTo goal="1.5;1.0;0.0" door_speed="true"/>)");
  ASSERT_EQ(fast_path.size(), path.size());
  for (std::size_t k = 0; k < path.size(); ++k)
    EXPECT_LT((fast_path[k].translation() - path[k].translation()).norm(), 1e-9) << k;
  EXPECT_DOUBLE_EQ(default_too, nominal);
  const planning::TrajectoryConfig& trajectory = motion_.trajectory_config();
  ASSERT_LT(trajectory.nominal_speed, trajectory.door_speed);
  // Each segment takes max(L / v, its floor): at twice the speed, at most what it took before
  // and less on the long ones.
  EXPECT_LT(fast, nominal - 1.0);
  double expected = 0.0;
  for (std::size_t k = 1; k < path.size(); ++k)
    expected += planning::SegmentDuration(
        (fast_path[k].translation() - fast_path[k - 1].translation()).norm(),
        std::abs(std::remainder(fast_path[k].yaw - fast_path[k - 1].yaw, 2 * M_PI)), true,
        trajectory);
  EXPECT_NEAR(fast, expected, 1e-6);
}

// A goal behind the robot, keeping its heading: the even turn would back the whole way into the
// base laser's blind sector, where someone standing behind it is never seen. It turns to face
// the way first, drives facing it and turns back to the goal's heading there.
TEST_F(NavigationNodesTest, NavigateToNeverBacksIntoTheLasersBlindSector) {
  belief_.scan = node_testing::SweepScan();
  belief_.X_MB = {0.0, 2.0, M_PI / 2};                                         // facing north
  bt::Tree tree = Tree(R"(<NavigateTo goal="0.0;0.0;1.5707963267948966"/>)");  // 2 m south
  belief_.now = At(1.0);
  ASSERT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  const std::vector<Pose2>& path = motion_.path();
  ASSERT_GE(path.size(), 3u);
  EXPECT_DOUBLE_EQ(detail::BlindTravel(services_, path), 0.0);
  // On the spot to face south, then along the way, then on the spot back to north.
  EXPECT_LT((path[1].translation() - path[0].translation()).norm(), 1e-9);
  EXPECT_NEAR(std::remainder(path[1].yaw + M_PI / 2, 2 * M_PI), 0.0, 0.2);
  EXPECT_LT((path.back().translation() - Eigen::Vector2d(0.0, 0.0)).norm(), 1e-6);
  EXPECT_NEAR(std::remainder(path.back().yaw - M_PI / 2, 2 * M_PI), 0.0, 1e-9);
  for (std::size_t i = 1; i < path.size(); ++i)  // no jump of a turn between poses
    EXPECT_LT(std::abs(path[i].yaw - path[i - 1].yaw), M_PI + 1e-9);
}

// A way the laser sees all along (to the side) is driven as planned: turning evenly to the
// goal's heading, no turn on the spot.
TEST_F(NavigationNodesTest, NavigateToASeenWayKeepsTheEvenTurn) {
  belief_.scan = node_testing::SweepScan();
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  bt::Tree tree = Tree(R"(<NavigateTo goal="2.0;1.0;1.5707963267948966"/>)");  // 2 m east
  belief_.now = At(1.0);
  ASSERT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  const std::vector<Pose2>& path = motion_.path();
  ASSERT_GE(path.size(), 2u);
  for (std::size_t i = 1; i < path.size(); ++i) {
    EXPECT_GT((path[i].translation() - path[i - 1].translation()).norm(), 1e-6);
    EXPECT_NEAR(path[i].yaw, M_PI / 2, 1e-9);
  }
  // The same way driven backwards (facing west) would be blind from its start.
  std::vector<Pose2> backwards = path;
  for (Pose2& p : backwards)
    p.yaw = M_PI;
  EXPECT_GT(detail::BlindTravel(services_, backwards), 1.5);
}

TEST_F(NavigationNodesTest, NavigateToAGoalWhereTheRobotStandsSucceedsAtOnce) {
  bt::Tree tree = Tree(R"(<NavigateTo goal="0.0;2.0;1.5707963267948966"/>)");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(NavigationNodesTest, NavigateToAnUnreachableGoalWaitsItsPatienceThenFails) {
  bt::Tree tree = Tree(R"(<NavigateTo goal="40.0;2.0;0.0" patience="1.0"/>)");  // off the map
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving());
  belief_.now = At(1.6);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(2.2);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(log_.pending().back().text.find("gave up"), std::string::npos);
}

// Someone walking at the robot stops the drive; once the base has stopped it steps out of
// their way, and goes on (a new plan to the goal) after they have passed.
TEST_F(NavigationNodesTest, NavigateToMakesWayForSomeoneComingAndGoesOnAfterThey) {
  bt::Tree tree = Tree(R"(<NavigateTo goal="2.5;0.5;0.0"/>)");
  belief_.X_MB = {-2.0, 0.5, 0.0};
  belief_.now = At(1.0);
  ASSERT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  auto walker = Person({0.4, 0.7}, perception::PersonIntent::kUnknown);
  walker.person.v_MP = {-1.2, 0.0};
  belief_.world.people = {walker};
  belief_.V_B = {0.2, 0.0, 0.0};
  belief_.now = At(1.1);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving()) << "stops first";
  EXPECT_TRUE(NotedText("making way"));
  belief_.V_B = {};
  belief_.now = At(1.2);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  const Eigen::Vector2d spot = motion_.path().back().translation();
  // Away from their way (y = 0.7), to the side (they step round it too: not a full metre).
  EXPECT_LT(spot.y(), 0.5 - 0.2) << "away from their way (y = 0.7), to the side";
  // Gone past (walking away): on once their pass time and give_way_clear_for are over.
  motion_.StopBase();
  belief_.X_MB = {spot.x(), spot.y(), 0.0};
  walker.person.p_MP = {-2.9, 0.7};
  belief_.world.people = {walker};
  belief_.now = At(2.5);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving()) << "they were to pass at 3.2 s: still waiting";
  belief_.now = At(4.3);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(2.5, 0.5)).norm(), 1e-6);
  EXPECT_TRUE(NotedText("going on"));
}

// Standing people, people walking elsewhere and whoever waits at the goal are not made way for;
// nor is anyone when give_way is off.
TEST_F(NavigationNodesTest, NavigateToMakesWayOnlyForPeopleComingAtTheRobot) {
  // Whether the robot made way for `person` (the log keeps every note: none before the last).
  auto makes_way_for = [&](const perception::TrackedPersonWithIntent& person, bool give_way) {
    services_.config.give_way = give_way;
    bt::Tree tree = Tree(R"(<NavigateTo goal="2.5;0.5;0.0"/>)");
    belief_.X_MB = {-2.5, 0.5, 0.0};
    belief_.world.people.clear();
    belief_.now = At(1.0);
    tree.TickOnce();
    belief_.world.people = {person};
    belief_.now = At(1.1);
    tree.TickOnce();
    return NotedText("making way");
  };
  auto standing = Person({-1.3, 0.5}, perception::PersonIntent::kStationary);
  EXPECT_FALSE(makes_way_for(standing, true));
  auto elsewhere = Person({-1.0, 2.5}, perception::PersonIntent::kUnknown);
  elsewhere.person.v_MP = {-1.2, 0.0};
  EXPECT_FALSE(makes_way_for(elsewhere, true));
  // Beyond where the path ends (IsWhomTheRobotGoesTo; proxemics_test has the near side).
  auto at_goal = Person({2.8, 0.6}, perception::PersonIntent::kUnknown);
  at_goal.person.v_MP = {-1.0, 0.0};
  EXPECT_FALSE(makes_way_for(at_goal, true)) << "whom the robot goes to";
  auto coming = Person({0.5, 0.6}, perception::PersonIntent::kUnknown);
  coming.person.v_MP = {-1.0, 0.0};
  EXPECT_FALSE(makes_way_for(coming, false));
  EXPECT_TRUE(makes_way_for(coming, true));
}

TEST_F(NavigationNodesTest, RetractToSafeBacksOffToTheLastSafeWaypoint) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.9, M_PI / 2};  // in the doorway
  belief_.last_safe = Pose2{0.0, 1.5, M_PI / 2};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  EXPECT_EQ(blackboard->Get<bool>("retreating"), true);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.5)).norm(), 1e-6);
  // Out of the doorway along its normal first: no waypoint beside the door line.
  for (const Pose2& p : motion_.path())
    EXPECT_LT(std::abs(p.x), 1e-6);
}

TEST_F(NavigationNodesTest, RetractToSafeWithNowhereToGoOnlyStops) {
  bt::Tree tree = Tree(R"(<RetractToSafe/>)");
  belief_.now = At(1.0);
  tree.TickOnce();
  EXPECT_FALSE(Noted(DecisionEvent::kRetreating));
  EXPECT_FALSE(motion_.base_moving());
}

TEST_F(NavigationNodesTest, WaitForClearWaitsForTheZoneAndGivesUpAfterItsTimeout) {
  // In the doorway's lane: with give_way it would step out of it (the next test).
  services_.config.give_way = false;
  bt::Tree tree = Tree(R"(<WaitForClear door="lab_door" timeout="4.0" clear_for="1.0"/>)");
  belief_.now = At(1.0);
  See({Person({0.0, 3.3}, perception::PersonIntent::kStationary)});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(2.0);
  See(belief_.world.people);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  // Gone, but the zone must stay clear for clear_for (as IsPathClear asks) before the retry.
  belief_.now = At(2.1);
  See({});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(3.1);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);

  belief_.now = At(10.0);
  See({Person({0.0, 3.3}, perception::PersonIntent::kStationary)});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(14.5);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

// Waiting beside the opening, 0.9 m off its axis, with someone dawdling in the doorway: they may
// stride through it any moment and pass the robot within comfort_distance, so it steps aside,
// farther off the axis, and does not report the zone clear while the step lasts (the retry's
// path would start at speed the other way). Nobody near the door, or give_way off: it stands.
TEST_F(NavigationNodesTest, WaitForClearStepsOutOfTheWayOfWhoeverMayComeThroughTheDoorway) {
  std::optional<bt::Tree> tree;
  const auto wait_with = [&](bool give_way,
                             const std::vector<perception::TrackedPersonWithIntent>& people) {
    services_.config.give_way = give_way;
    motion_.StopBase();
    log_.Take();
    belief_.zone_occupied_at.clear();
    belief_.X_MB = {0.9, 2.3, M_PI / 2};
    belief_.V_B = {};
    belief_.now = At(1.0);
    tree.emplace(Tree(R"(<WaitForClear door="lab_door" timeout="30" clear_for="1.0"/>)"));
    See(people);
    return tree->TickOnce();
  };
  auto dawdler = Person({-0.1, 3.4}, perception::PersonIntent::kUnknown);
  dawdler.person.v_MP = {0.0, -0.2};

  EXPECT_EQ(wait_with(true, {dawdler}), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  EXPECT_TRUE(NotedText("making way"));
  const Eigen::Vector2d spot = motion_.path().back().translation();
  EXPECT_GT(std::abs(spot.x()), 0.9 + 0.3) << "farther off the doorway's axis: " << spot.x();
  EXPECT_FALSE(IsInAnyDoorZone(services_, spot));
  // They went back; the zone is clear long enough, but the step is under way.
  belief_.now = At(1.1);
  See({});
  belief_.now = At(2.5);
  EXPECT_EQ(tree->TickOnce(), NodeStatus::kRunning);
  motion_.StopBase();
  belief_.X_MB = {spot.x(), spot.y(), M_PI / 2};
  belief_.now = At(2.6);
  EXPECT_EQ(tree->TickOnce(), NodeStatus::kSuccess);

  EXPECT_EQ(wait_with(false, {dawdler}), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving()) << "give_way off";
  auto far = Person({-0.1, 6.5}, perception::PersonIntent::kUnknown);
  far.person.v_MP = {0.0, -0.2};
  EXPECT_EQ(wait_with(true, {far}), NodeStatus::kSuccess) << "nobody near the door";
  EXPECT_FALSE(motion_.base_moving());
}

// A step aside under way is re-aimed when someone now walks at where it ends: not within a
// second of its start, and not when its end is still the best.
TEST_F(NavigationNodesTest, WaitForClearReAimsAStepAsideWhenSomeoneComesAtWhereItEnds) {
  services_.config.give_way = true;
  belief_.X_MB = {0.9, 2.3, M_PI / 2};
  belief_.now = At(1.0);
  bt::Tree tree = Tree(R"(<WaitForClear door="lab_door" timeout="30" clear_for="1.0"/>)");
  auto dawdler = Person({-0.1, 3.4}, perception::PersonIntent::kUnknown);
  dawdler.person.v_MP = {0.0, -0.2};
  See({dawdler});
  ASSERT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  const Eigen::Vector2d end = motion_.path().back().translation();
  const Eigen::Vector2d p_MB0 = belief_.X_MB.translation();
  // Half way there; someone walks straight at where the step ends.
  auto walker = Person(end + Eigen::Vector2d(1.8, 0.0), perception::PersonIntent::kUnknown);
  walker.person.v_MP = {-1.0, 0.0};
  const auto half_way = [&](double t) {
    belief_.X_MB = {0.5 * (p_MB0.x() + end.x()), 0.5 * (p_MB0.y() + end.y()), M_PI / 2};
    belief_.V_B = {0.2, 0.0, 0.0};
    belief_.now = At(t);
  };
  half_way(1.5);
  See({dawdler, walker});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_LT((motion_.path().back().translation() - end).norm(), 1e-9) << "too early to re-aim";
  half_way(2.1);
  See({dawdler});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_LT((motion_.path().back().translation() - end).norm(), 1e-9) << "nobody comes at it";
  EXPECT_FALSE(NotedText("re-aiming"));
  half_way(3.2);
  See({dawdler, walker});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(motion_.base_moving());
  EXPECT_TRUE(NotedText("re-aiming"));
  const Eigen::Vector2d re_aimed = motion_.path().back().translation();
  EXPECT_GT(std::abs(re_aimed.y() - end.y()), 0.4)
      << "off the walker's way (y = " << end.y() << "): " << re_aimed.transpose();
  EXPECT_FALSE(IsInAnyDoorZone(services_, re_aimed));
}

// A retreat begun while the base still rolls the other way would leave its reference behind
// and trip the watchdog (H2 seed 2002): it starts once the base has (all but) stopped — slow
// enough to stop within a centimetre, not at a standstill (waiting for that stood the robot in
// a doorway beside a resident ~0.2 s longer at every reversal).
TEST_F(NavigationNodesTest, RetractToSafeWaitsForTheBaseToStopBeforeBackingOff) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.9, M_PI / 2};
  belief_.last_safe = Pose2{0.0, 1.5, M_PI / 2};
  belief_.V_B = {0.4, 0.0, 0.0};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_EQ(blackboard->Get<bool>("retreating"), true);  // under way: IsPathClear keeps failing
  EXPECT_FALSE(motion_.base_moving());
  EXPECT_FALSE(Noted(DecisionEvent::kRetreating));
  belief_.now = At(1.2);
  belief_.V_B = {0.2, 0.0, 0.0};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving()) << "still braking";
  belief_.now = At(1.3);
  belief_.V_B = {0.1, 0.0, 0.0};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(motion_.base_moving());
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
}

TEST_F(NavigationNodesTest, RetractToSafeStepsOutOfAPersonsPredictedPath) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.4, M_PI / 2};
  belief_.last_safe = Pose2{0.0, 1.2, M_PI / 2};
  // Through the door towards the south-west, past the last safe pose within 3 s.
  auto crosser = Person({-0.1, 3.4}, perception::PersonIntent::kCrossing);
  crosser.person.v_MP = {-0.3, -1.3};
  belief_.world.people = {crosser};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Eigen::Vector2d spot = motion_.path().back().translation();
  EXPECT_GT(spot.x(), 0.4) << "away from the person's way, not back along the robot's own";
  EXPECT_FALSE(IsInAnyDoorZone(services_, spot));
  // Nobody near: back to the last safe pose as before.
  motion_.StopBase();
  belief_.world.people.clear();
  tree.HaltTree();
  belief_.now = At(5.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.2)).norm(), 1e-6);
}

// A fast walker coming straight at the robot: the spot is one it reaches in time, not the one
// with the most room once it gets there (a 1.5 m retreat is a 3.75 s quintic that has covered
// 7 % of its way when a 2 m/s walker 1.6 m off arrives: H2 seeds 2002 and 2012, H12 with laser
// people).
TEST_F(NavigationNodesTest, RetractToSafeStepsWhereItGetsBeforeAFastWalkerDoes) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.3, M_PI / 2};            // lining up, short of the door's entry distance
  belief_.last_safe = Pose2{0.0, 1.2, M_PI / 2};  // straight down the walker's way
  auto runner = Person({0.0, 3.9}, perception::PersonIntent::kCrossing);
  runner.person.v_MP = {0.0, -2.0};
  belief_.world.people = {runner};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Eigen::Vector2d spot = motion_.path().back().translation();
  EXPECT_GT(std::abs(spot.x()), 0.4) << "aside, out of the walker's way";
  EXPECT_LT((spot - belief_.X_MB.translation()).norm(), 1.2)
      << "a near spot it reaches in time, not one of the 1.5 m ring";
  // The retreat under way is not restarted as a make-way in place (that is for a standby with
  // nothing to back off to): the path stays.
  belief_.now = At(1.1);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("making way for"));
  EXPECT_LT((motion_.path().back().translation() - spot).norm(), 1e-9);
  // The same walker at a stroll, 1.6 m nearer in 3 s: they pass nowhere near the last safe pose,
  // which the robot backs off to.
  motion_.StopBase();
  tree.HaltTree();
  runner.person.p_MP = {0.0, 6.0};
  runner.person.v_MP = {0.0, -0.6};
  belief_.world.people = {runner};
  belief_.now = At(5.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.2)).norm(), 1e-6);
}

// Nobody is seen in the laser's blind sector behind the robot, nor may a retreat pass through
// someone it can see (P1 seed 2000: backed into a person waiting behind it).
TEST_F(NavigationNodesTest, RetractToSafeKeepsToWhereTheLaserSeesAndPassesNobody) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.4, M_PI / 2};
  belief_.last_safe = Pose2{0.0, 1.2, M_PI / 2};  // straight behind: the laser's blind sector
  belief_.scan = node_testing::SweepScan();
  belief_.X_BL = Pose2{};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  if (motion_.base_moving()) {
    const Eigen::Vector2d spot = motion_.path().back().translation();
    const Eigen::Vector2d d = spot - belief_.X_MB.translation();
    // In B the spot's bearing is within the sweep (less its margin), not straight back.
    const double bearing = std::remainder(std::atan2(d.y(), d.x()) - M_PI / 2, 2 * M_PI);
    EXPECT_LT(std::abs(bearing), 0.75 * M_PI);
  }
  // Someone standing beside the robot on the way to every spot but the far one: never passed.
  tree.HaltTree();
  motion_.StopBase();
  belief_.scan.reset();
  belief_.last_safe = Pose2{1.5, 2.4, M_PI / 2};
  belief_.world.people = {Person({0.75, 2.4}, perception::PersonIntent::kStationary)};
  belief_.now = At(3.0);
  tree.TickOnce();
  for (const Pose2& p : motion_.path())
    EXPECT_LT(p.x, 0.75 - 0.3 - 0.215) << "the way would pass through the person at x = 0.75";
}

// Halted in a doorway facing away from the way back (two-wards seed 12: it stood 7 s in the
// doorway beside residents passing, until the door shut on it): where it has just driven,
// facing that way, counts as seen; beyond that it turns on the spot only until the way back
// is inside the laser's sweep, then backs off.
TEST_F(NavigationNodesTest, RetractToSafeTurnsToSeeTheWayBackAndTrustsWhereItJustDrove) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 2.9, M_PI / 2};            // in the doorway, facing through it
  belief_.last_safe = Pose2{0.0, 1.2, M_PI / 2};  // straight behind: the laser's blind sector
  belief_.scan = node_testing::SweepScan();
  belief_.X_BL = Pose2{0.15, 0.0, 0.0};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(Noted(DecisionEvent::kRetreating));
  ASSERT_EQ(motion_.path().size(), 2u);
  const Pose2 turned = motion_.path().back();
  EXPECT_LT((turned.translation() - belief_.X_MB.translation()).norm(), 1e-9) << "on the spot";
  const double turn = std::abs(std::remainder(turned.yaw - belief_.X_MB.yaw, 2 * M_PI));
  EXPECT_GT(turn, 0.1);
  EXPECT_LT(turn, M_PI - 0.1) << "only as far as brings the way back into the sweep";
  // Turned and looked (past the dwell): the way back is seen and clear, so it backs off.
  motion_.StopBase();
  belief_.X_MB.yaw = turned.yaw;
  belief_.now = At(1.2);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(Noted(DecisionEvent::kRetreating)) << "still looking";
  belief_.now = At(2.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.2)).norm(), 1e-6);

  // The same, having just driven up that way facing it: it backs off at once, no turn.
  tree.HaltTree();
  motion_.StopBase();
  log_.Take();
  belief_.X_MB = {0.0, 2.9, M_PI / 2};
  belief_.now = At(10.0);
  belief_.swept_p_MB.clear();
  for (double y = 1.2; y < 2.9; y += kSweptSampleM)
    belief_.swept_p_MB.emplace_back(At(10.0 - (2.9 - y) / 0.4), Eigen::Vector2d(0.0, y));
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.2)).norm(), 1e-6);
  // Someone seen standing on that way: never passed, turn or no turn.
  tree.HaltTree();
  motion_.StopBase();
  log_.Take();
  belief_.world.people = {Person({0.0, 2.0}, perception::PersonIntent::kStationary)};
  belief_.now = At(11.0);
  tree.TickOnce();
  for (const Pose2& p : motion_.path())
    EXPECT_GT((p.translation() - Eigen::Vector2d(0.0, 2.0)).norm(), 0.3 + 0.215)
        << "the way would pass through the person";
}

// A blackboard whose door visit came to the lab door from the south (its wall is at y = 3).
bt::Blackboard::Ptr VisitFromTheSouth() {
  auto blackboard = bt::Blackboard::Create();
  DoorVisit visit;
  visit.door = "lab_door";
  visit.approach_side = Eigen::Vector2d(0.0, -1.0);
  blackboard->Set("door_visit", bt::Any(visit));
  return blackboard;
}

// Halted just past the door line, the way on to its last safe pose (beside the door, where the
// robot came from) in the laser's blind sector and the spots ahead taken: it backs out of the
// doorway along the way it has just driven, seen, rather than turn to look in the leaf's sweep
// (O2 seed 2005: it turned there while the memory of the way it drove ran out, and the closing
// leaf struck it).
TEST_F(NavigationNodesTest, RetractToSafeBacksOutOfTheDoorwayWhenTheWayOnIsUnseen) {
  auto blackboard = VisitFromTheSouth();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 3.12, M_PI / 2};            // just past the door line, facing north
  belief_.last_safe = Pose2{1.0, 2.38, M_PI / 2};  // beside the door: 132 deg off, unseen
  belief_.scan = node_testing::SweepScan();
  belief_.X_BL = Pose2{0.17, 0.0, 0.0};
  belief_.now = At(10.0);
  for (double y = 2.0; y < 3.12; y += kSweptSampleM)  // driven up the axis, facing north
    belief_.swept_p_MB.emplace_back(At(10.0 - (3.12 - y) / 0.4), Eigen::Vector2d(0.0, y));
  belief_.world.people = {Person({0.0, 4.3}, perception::PersonIntent::kStationary)};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  EXPECT_TRUE(NotedText("backing out of the doorway"));
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2 out = motion_.path().back();
  EXPECT_NEAR(out.x, 0.0, 1e-6) << "straight back along the door's normal";
  EXPECT_LT(out.y, 3.0 - 0.5) << "out of the doorway";
  // Someone seen standing on that way back too: it stays (it never passes them).
  tree.HaltTree();
  motion_.StopBase();
  log_.Take();
  belief_.world.people.push_back(Person({0.0, 2.6}, perception::PersonIntent::kStationary));
  belief_.now = At(10.1);
  tree.TickOnce();
  EXPECT_FALSE(Noted(DecisionEvent::kRetreating));
}

// Issue 17: with nowhere to back off, standing at the visited door's button beside the lane
// before its doorway (the robot blocks the way between the open leaf's edge and itself), it
// squeezes aside along the door line, away from the opening; with someone standing there it
// stays where it is.
TEST_F(NavigationNodesTest, RetractToSafeWithNowhereToBackOffSqueezesAsideOutOfTheLane) {
  const auto retreat_with = [&](std::vector<perception::TrackedPersonWithIntent> people) {
    log_.Take();
    motion_.StopBase();
    bt::Tree tree = Tree(R"(<RetractToSafe/>)", VisitFromTheSouth());
    belief_.X_MB = {0.75, 2.45, M_PI / 2};  // at the button, beside the lane, facing the wall
    belief_.last_safe = Pose2{0.75, 1.2, M_PI / 2};
    belief_.world.people = std::move(people);
    belief_.now = At(1.0);
    tree.TickOnce();
    return tree;  // kept: a tree destroyed halts its nodes, and the retreat stops the base
  };
  // Someone on the way back and someone waiting in the lane for the door.
  const auto behind = Person({0.75, 1.75}, perception::PersonIntent::kStationary);
  const auto waiting = Person({-0.1, 2.0}, perception::PersonIntent::kStationary);
  bt::Tree squeezing = retreat_with({behind, waiting});
  ASSERT_TRUE(NotedText("squeezing aside")) << log_.pending().back().text;
  ASSERT_TRUE(motion_.base_moving());
  const Pose2 aside = motion_.path().back();
  EXPECT_NEAR(aside.y, 2.45, 0.05) << "along the door line";
  EXPECT_GT(aside.x, 0.75 + 0.1) << "away from the opening";
  EXPECT_LE(aside.x, 0.75 + 0.4 + 1e-9) << "a step, not a walk";
  // Someone standing where the step would go: it does not step at them.
  squeezing.HaltTree();
  bt::Tree staying =
      retreat_with({behind, waiting, Person({1.15, 2.4}, perception::PersonIntent::kStationary)});
  EXPECT_TRUE(NotedText("standing still"));
  EXPECT_FALSE(motion_.base_moving());
}

// Nothing to back off to (the robot stands where it was last safe, at the button beside the
// lane): once stopped it steps out of the way of someone walking at it or through the visited
// door, as WaitForClear would after the 1.5 s tuck, by when they have passed (P1). A step out of
// someone's way already under way (TraverseDoor's, halted as they entered the door zone) it lets
// end; any other drive it stops. Nobody coming: it stands.
TEST_F(NavigationNodesTest, RetractToSafeInPlaceMakesWayAndLetsAStepOutOfTheWayEnd) {
  const Pose2 at_button{1.15, 2.43, M_PI / 2};
  const auto standby_with = [&](std::vector<perception::TrackedPersonWithIntent> people) {
    log_.Take();
    motion_.StopBase();
    bt::Tree tree = Tree(R"(<RetractToSafe/>)", VisitFromTheSouth());
    belief_.X_MB = at_button;
    belief_.last_safe = at_button;
    belief_.world.people = std::move(people);
    belief_.now = At(1.0);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
    belief_.now = At(1.1);
    tree.TickOnce();  // stopped: makes way, or (arm tucked, base idle) is done
    return tree;      // kept: a tree destroyed halts its nodes, and the standby stops the base
  };
  // From behind and to the right, heading for the doorway's middle (0, 3) at 1.2 m/s.
  auto walker = Person({1.9, 0.4}, perception::PersonIntent::kApproaching);
  walker.person.v_MP = 1.2 * (Eigen::Vector2d(0.0, 3.0) - walker.person.p_MP).normalized();
  bt::Tree making_way = standby_with({walker});
  EXPECT_TRUE(NotedText("making way for"));
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  ASSERT_TRUE(motion_.stepping_out_of_way());
  EXPECT_GT(motion_.path().back().x, at_button.x + 0.3) << "away from the lane";
  making_way.HaltTree();

  bt::Tree standing = standby_with({});
  EXPECT_FALSE(NotedText("making way for"));
  EXPECT_FALSE(motion_.base_moving());
  standing.HaltTree();

  // A step aside under way goes on; a drive that is not one is stopped.
  for (const bool brisk : {true, false}) {
    log_.Take();
    const Pose2 aside{1.9, 2.43, M_PI / 2};
    motion_.FollowPath({at_button, aside}, {false}, motion_.arm_target(), At(2.0),
                       services_.config.retreat_speed, brisk);
    bt::Tree tree = Tree(R"(<RetractToSafe/>)", VisitFromTheSouth());
    belief_.now = At(2.1);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
    EXPECT_EQ(motion_.base_moving(), brisk);
    EXPECT_EQ(NotedText("going on with the step"), brisk);
    if (brisk) {
      EXPECT_LT((motion_.path().back().translation() - aside.translation()).norm(), 1e-9);
    }
    tree.HaltTree();
  }
}

// Halted just past the door line, having left the door's zone on the far side before (its last
// safe pose is there): it goes on to that pose, never back through the doorway (clinic family
// seed 2007: it backed through door_b as the leaf closed on it).
TEST_F(NavigationNodesTest, RetractToSafePastTheDoorLineNeverBacksThroughTheDoorway) {
  auto blackboard = VisitFromTheSouth();
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  belief_.X_MB = {0.0, 3.3, M_PI / 2};
  belief_.last_safe = Pose2{0.0, 4.4, M_PI / 2};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(Noted(DecisionEvent::kRetreating));
  ASSERT_GE(motion_.path().size(), 2u);
  for (const Pose2& p : motion_.path())
    EXPECT_GT(p.y, 3.0) << "back through the doorway";
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 4.4)).norm(), 1e-6);
  // Still on the near side of the line, it backs out the way it came, as before.
  tree.HaltTree();
  motion_.StopBase();
  belief_.X_MB = {0.0, 2.9, M_PI / 2};
  belief_.last_safe = Pose2{0.0, 1.5, M_PI / 2};
  belief_.now = At(3.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 1.5)).norm(), 1e-6);
}

// Issue 17: halted a step past the door line, out of the leaf's reach, as someone walks past
// the doorway on that side: backing through it would stand the robot in the doorway beside
// them (two wards seed 14). It makes room on the side it is on; with nobody near the doorway it
// backs through to its last safe pose, as before.
TEST_F(NavigationNodesTest,
       RetractToSafePastTheDoorLineStaysOnThatSideWhileSomeonePassesTheDoorway) {
  auto blackboard = bt::Blackboard::Create();
  DoorVisit visit;
  visit.door = "lab_door";
  visit.approach_side = Eigen::Vector2d(0.0, 1.0);  // from the north, the side the leaf opens to
  blackboard->Set("door_visit", bt::Any(visit));
  bt::Tree tree = Tree(R"(<RetractToSafe/>)", blackboard);
  const auto halt_past_the_line = [&](double t) {
    tree.HaltTree();
    motion_.StopBase();
    log_.Take();
    belief_.X_MB = {0.0, 2.4, -M_PI / 2};  // 0.6 m past the line, facing south
    belief_.last_safe = Pose2{0.0, 4.4, -M_PI / 2};
    belief_.scan = node_testing::SweepScan();
    belief_.X_BL = Pose2{0.17, 0.0, 0.0};
    belief_.now = At(t);
    belief_.swept_p_MB.clear();
    for (double y = 4.4; y > 2.4; y -= kSweptSampleM)  // driven down the axis, facing south
      belief_.swept_p_MB.emplace_back(At(t - (y - 2.4) / 0.4), Eigen::Vector2d(0.0, y));
    return tree.TickOnce();
  };
  auto passer = Person({-2.0, 2.0}, perception::PersonIntent::kApproaching);
  passer.person.v_MP = {1.0, 0.0};  // along the passage south of the door, past its doorway
  belief_.world.people = {passer};
  ASSERT_TRUE(IsPassageBusy(services_, "lab_door", 3.0));
  EXPECT_EQ(halt_past_the_line(1.0), NodeStatus::kRunning);
  ASSERT_TRUE(Noted(DecisionEvent::kRetreating));
  ASSERT_GE(motion_.path().size(), 2u);
  for (const Pose2& p : motion_.path())
    EXPECT_LT(p.y, 3.0) << "back through the doorway";
  EXPECT_FALSE(IsInAnyDoorZone(services_, motion_.path().back().translation()))
      << "out of the door's way";
  // Nobody near the doorway: back through it to the last safe pose.
  belief_.world.people = {};
  EXPECT_EQ(halt_past_the_line(2.0), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - Eigen::Vector2d(0.0, 4.4)).norm(), 1e-6);
}

}  // namespace
}  // namespace egress::behavior
