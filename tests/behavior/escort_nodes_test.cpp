// The escort's nodes (behavior/src/escort_nodes.cpp), ticked in one-node trees at the fixture's
// lab door (wall y = 3, opening north; its push button south of it at x = 1.075).

#include "task_node_fixture.h"

#include "escort_watch.h"
#include "task_node_support.h"

#include "egress/behavior/head_gaze.h"
#include "egress/planning/ik_solver.h"

#include <functional>
#include <limits>
#include <optional>
#include <utility>

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;
using EscortNodesTest = node_testing::TaskNodeFixture;

// Where the robot stands to press the lab button, and the spot beside it the hold uses (1.5 m
// further along the wall, away from the doorway).
Pose2 Standoff() {
  TaskConfig config;
  return planning::MakeButtonTargets({1.075, 2.93, 1.0}, {0.0, -1.0, 0.0},
                                     planning::ButtonType::kPushButton, config.buttons)
      .X_MB_standoff;
}

// The lab wall (y = 3) either side of the doorway, as a costmap: the fixture's grid has no
// walls (its planner lets steps through them; the making-room rules read the belief's costmap).
perception::Costmap2D LabWalls() {
  return perception::Costmap2D(perception::OccupancyGrid::FromBoxes(
      {{{1.75, 3.0, 0.0}, {2.5, 0.1}}, {{-1.75, 3.0, 0.0}, {2.5, 0.1}}}, {-3.0, -1.0}, {3.0, 7.0},
      0.05));
}

class HoldForResidentsTest : public EscortNodesTest {
 protected:
  HoldForResidentsTest() {
    belief_.X_MB = Standoff();
    belief_.now = At(1.0);
  }
  // The robot operated the button `ago` seconds before now.
  void OperatedAgo(double ago) {
    DoorVisit visit;
    visit.door = "lab_door";
    visit.operated_at = belief_.now - SecondsToDuration(ago);
    blackboard_->Set("door_visit", bt::Any(visit));
  }
  // The hold's first tick operates (the spot is planned, the laser sweeping); then its spot is
  // blocked (something marked there in the costmap): the planner finds no path to it. Returns it.
  Pose2 OperateThenBlockTheSpot() {
    belief_.scan = node_testing::SweepScan();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
    const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
    OperatedAgo(0.0);
    blocked_costmap_.emplace(perception::OccupancyGrid::FromBoxes(
        {{{spot.x, spot.y, 0.0}, {0.3, 0.3}}}, {-3.0, -1.0}, {3.0, 7.0}, 0.05));
    blocked_planner_.emplace(*blocked_costmap_, nullptr);
    services_.planner = &*blocked_planner_;
    return spot;
  }
  std::optional<perception::Costmap2D> blocked_costmap_;
  std::optional<planning::BasePlanner> blocked_planner_;
  // The hold begins with the robot at the far end of the room (6, 0.5) and the door shut (the
  // robot's last operation long past).
  void BeginFarFromAShutDoor() {
    belief_.X_MB = {6.0, 0.5, 0.0};
    tree_.TickOnce();
    OperatedAgo(12.0);
  }
  // Ticks every kTickSec from `from` until someone has been on the move kComingForSec on end
  // (as `moving_returns` now says), each tick RUNNING; returns the time of the last tick.
  double ComeFrom(double from) {
    double t = from;
    for (; t <= from + detail::kComingForSec + 1e-9; t += kTickSec) {
      belief_.now = At(t);
      EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
    }
    return t - kTickSec;
  }
  // The hold's first tick, no operation due at 2 s, and residents coming by the doorway from
  // then until they are seen coming, gone by the next tick. Returns the time of their last tick.
  double ResidentsCame() {
    tree_.TickOnce();
    OperatedAgo(1.0);
    belief_.moving_returns = {{-0.5, 1.5}};
    belief_.off_map_returns = belief_.moving_returns;
    const double came = ComeFrom(2.0);
    belief_.moving_returns.clear();
    belief_.off_map_returns.clear();
    return came;
  }
  // A hold from `from` through which residents came (laser returns moving by the doorway for
  // kComingForSec), to its end once they are through. Returns the time of its last tick.
  double HoldThroughWhichResidentsCame(double from) {
    belief_.moving_returns = {{-0.5, 1.5}};
    belief_.off_map_returns = belief_.moving_returns;
    double t = ComeFrom(from);
    belief_.moving_returns.clear();
    belief_.off_map_returns.clear();
    NodeStatus status = NodeStatus::kRunning;
    const double until = t + 20.0;
    while (status == NodeStatus::kRunning && t < until) {
      t += 0.5;
      belief_.now = At(t);
      motion_.StopBase();
      OperatedAgo(0.5);
      status = tree_.TickOnce();
    }
    EXPECT_EQ(status, NodeStatus::kFailure);
    EXPECT_TRUE(NotedText("everyone is through"));
    return t;
  }
  // The robot comes from the far end of the room to a shut door; someone stands still by the
  // doorway (0.6 m from the standoff) from the start. At 6.5 s they have waited long enough: the
  // tick's status (SUCCESS: it goes to open the door for them).
  NodeStatus OpenForSomeoneFoundWaiting() {
    BeginFarFromAShutDoor();
    belief_.off_map_returns = {{0.5, 2.2}};
    belief_.now = At(6.5);
    motion_.StopBase();
    return tree_.TickOnce();
  }
  // With residents coming and no operation due, the robot sets off to its spot at 2 s, from
  // `from(spot)`. Returns the spot.
  Pose2 DriveToTheSpotFrom(const std::function<Pose2(const Pose2&)>& from) {
    BeginFarFromAShutDoor();
    OperatedAgo(1.0);  // not due
    const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
    belief_.X_MB = from(spot);
    belief_.now = At(2.0);
    belief_.moving_returns = {{-0.5, 1.5}};  // they come
    belief_.off_map_returns = belief_.moving_returns;
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    EXPECT_TRUE(NotedText("driving to the spot beside the door"));
    log_.Take();
    return spot;
  }
  // `people` stand where they are from `from`, a tick a second for `seconds`, the robot at
  // rest: the time it goes to the actuator (SUCCESS), or -1 if it does not.
  double TimeItGoesForThoseStanding(std::vector<perception::TrackedPersonWithIntent> people,
                                    double from, double seconds) {
    See(std::move(people));
    for (double t = from; t < from + seconds; t += 1.0) {
      belief_.now = At(t);
      motion_.StopBase();
      const NodeStatus status = tree_.TickOnce();
      if (status == NodeStatus::kSuccess) return t;  // to the actuator
      EXPECT_EQ(status, NodeStatus::kRunning) << "at " << t;
    }
    return -1.0;
  }
  // A tick at `t` with `returns` off the map (residents coming: moving returns by the doorway)
  // sets the robot off on a path that ends at `spot`.
  void ExpectSetsOffFor(const Pose2& spot, double t, std::vector<Eigen::Vector2d> returns) {
    belief_.now = At(t);
    belief_.moving_returns = {{-0.5, 1.5}};  // they come
    belief_.off_map_returns = std::move(returns);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    EXPECT_TRUE(NotedText("driving to the spot beside the door"));
    ASSERT_GE(motion_.path().size(), 2u);
    EXPECT_LT((motion_.path().back().translation() - spot.translation()).norm(), 1e-6);
  }
  // The robot stopped, a tick at `t` with `returns` off the map does not set it off.
  void ExpectStaysWith(double t, std::vector<Eigen::Vector2d> returns) {
    motion_.StopBase();
    log_.Take();
    belief_.now = At(t);
    belief_.off_map_returns = std::move(returns);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    EXPECT_FALSE(NotedText("driving to the spot"));
  }
  static constexpr double kTickSec = 0.25;  // under kStirGapSec
  bool NotedText(const std::string& text) const {
    for (const auto& note : log_.pending())
      if (note.text.find(text) != std::string::npos) return true;
    return false;
  }
  bt::Blackboard::Ptr blackboard_ = bt::Blackboard::Create();
  bt::Tree tree_ =
      Tree(R"(<HoldForResidents door="lab_door" clear_for="3.0" wait_for="10.0"/>)", blackboard_);
};

TEST_F(HoldForResidentsTest, OperatesFirstAndWritesTheSpotBesideTheDoor) {
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // not operated in this hold yet
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  EXPECT_NEAR(spot.x, Standoff().x + 1.5, 1e-6);  // away from the doorway (x = 0)
  EXPECT_NEAR(spot.y, Standoff().y, 1e-6);
}

TEST(NearestOnGridTest, FindsTheNearestAcceptedPointAtLeastTheDistanceAway) {
  const Eigen::Vector2d from(1.0, 2.0), along(1.0, 0.0), out(0.0, -1.0);
  // Everything accepted: the nearest grid point 0.25 m away or more is two steps each way.
  auto p = detail::NearestOnGrid(from, along, 1.0, out, 1.0, 0.1, 0.25,
                                 [](const Eigen::Vector2d&) { return true; });
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(p->isApprox(Eigen::Vector2d(1.2, 1.8), 1e-9)) << p->transpose();
  // Nothing past x = 1.15 (a wall): the nearest is out from `from`, still 0.25 m away.
  p = detail::NearestOnGrid(from, along, 1.0, out, 1.0, 0.1, 0.25,
                            [](const Eigen::Vector2d& q) { return q.x() < 1.15; });
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(p->isApprox(Eigen::Vector2d(1.0, 1.7), 1e-9)) << p->transpose();
  // Nothing accepted, or nothing of the grid far enough: none.
  EXPECT_FALSE(detail::NearestOnGrid(from, along, 1.0, out, 1.0, 0.1, 0.0,
                                     [](const Eigen::Vector2d&) { return false; }));
  EXPECT_FALSE(detail::NearestOnGrid(from, along, 0.2, out, 0.2, 0.1, 0.5,
                                     [](const Eigen::Vector2d&) { return true; }));
}

// Where the actuator's wall runs into the room's corner within a footprint of the standoff, no
// spot along the wall is free: the robot waits beside the lane, out from the wall, leaving room
// for a resident at the actuator, and waits there, not at the standoff, before anyone comes
// (random building seed 31: waiting at the standoff, in the way in, it was walked into by the
// first resident making for the button).
TEST_F(HoldForResidentsTest, WithTheWallsCornerBesideTheActuatorItWaitsBesideTheLane) {
  constexpr double kPartitionX = 1.55;  // a wall running south from the lab wall's corner
  map_.grid = perception::OccupancyGrid::FromBoxes({{{1.75, 3.0, 0.0}, {2.5, 0.1}},
                                                    {{-1.75, 3.0, 0.0}, {2.5, 0.1}},
                                                    {{kPartitionX, 1.5, 0.0}, {0.1, 3.0}}},
                                                   {-3.0, -1.0}, {3.0, 7.0}, 0.05);
  const perception::Costmap2D cornered(map_.grid);
  planning::BasePlanner planner(cornered, nullptr);
  services_.planner = &planner;
  belief_.world.costmap = &cornered;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // not operated in this hold yet
  ASSERT_TRUE(NotedText("waiting beside the lane"));
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  const TaskConfig config;
  EXPECT_LT(spot.x, kPartitionX - 0.05 - config.footprint_radius + 1e-9);  // this side of it
  const double lane = 0.475 + config.footprint_radius + config.person_radius;
  EXPECT_GT(std::abs(spot.x), lane);  // beside the way in
  EXPECT_GE((spot.translation() - Standoff().translation()).norm(),
            config.footprint_radius + 2 * config.person_radius - 1e-9);
  EXPECT_LT(spot.y, Standoff().y);  // out from the wall, into the room
  // Operated, nobody about: it goes to wait at the spot.
  OperatedAgo(1.0);
  log_.Take();
  belief_.now = At(2.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - spot.translation()).norm(), 1e-6);
}

// Boxed in at the actuator — no way to its spot — with residents who came standing about the shut
// door, someone by its doorway, the robot operates from where it stands: they wait for the door,
// and it stands where they would operate it (random building seed 8: nine residents and the robot
// waited at the exit door for 340 s). Not for a group yet to set off, who have not moved (seed 28:
// they set off as it reached for the button among them). With its spot to go to, it goes there.
TEST_F(HoldForResidentsTest, BoxedInAtTheActuatorItOperatesForThoseWhoCameAndWait) {
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operate; the spot is planned
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  OperatedAgo(0.0);  // in this hold
  // By the doorway and across the room, within `reach`: a group, not one waiting.
  belief_.off_map_returns = {{0.2, 2.1}, {-0.6, 1.4}, {0.7, 1.0}};
  const auto first_operation = [&](double from, double until) {
    for (double t = from; t <= until; t += 0.5) {
      belief_.now = At(t);
      for (auto& entry : belief_.world.people)
        entry.person.last_seen = belief_.now;
      motion_.StopBase();
      const NodeStatus status = tree_.TickOnce();
      if (status == NodeStatus::kSuccess) return t;
      EXPECT_EQ(status, NodeStatus::kRunning) << "at " << t;
    }
    return -1.0;
  };
  {
    // Its spot free: it drives there, and does not operate for the group.
    SCOPED_TRACE("spot free");
    belief_.now = At(1.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  }
  // Its spot blocked (what stood there marked in the costmap): no path.
  const perception::Costmap2D blocked(perception::OccupancyGrid::FromBoxes(
      {{{spot.x, spot.y, 0.0}, {0.3, 0.3}}}, {-3.0, -1.0}, {3.0, 7.0}, 0.05));
  planning::BasePlanner planner(blocked, nullptr);
  services_.planner = &planner;
  motion_.StopBase();
  belief_.X_MB = Standoff();
  log_.Take();
  // Nobody has walked — a group yet to set off, stirring (moving returns for a tick) — nor ever
  // will it operate for them (seed 28).
  EXPECT_LT(first_operation(2.0, 7.5), 0.0);
  belief_.moving_returns = {{0.2, 2.1}};
  belief_.now = At(8.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  belief_.moving_returns.clear();
  EXPECT_LT(first_operation(8.5, 16.0), 0.0);
  // Someone walks (kComingForSec and more) along the doorway's front, 1.2 m out — about the
  // door, not nearer it: not residents coming — and stands there. Once all have stood
  // kStillForSec, it operates (due: a hold window since the last operation).
  constexpr double kOutM = 1.2, kSpeedMps = 0.5, kWalkFrom = 16.5, kWalkTo = 20.5;
  const auto on_arc = [&](double t) {
    const double a = -2.8 + kSpeedMps / kOutM * (t - kWalkFrom);
    return Eigen::Vector2d(kOutM * std::cos(a), 3.0 + kOutM * std::sin(a));
  };
  auto walker = node_testing::Person(on_arc(kWalkFrom), perception::PersonIntent::kUnknown);
  walker.person.p_MRest = on_arc(kWalkFrom);
  for (double t = kWalkFrom; t < kWalkTo; t += kTickSec) {
    belief_.now = At(t);
    walker.person.p_MP = on_arc(t);
    walker.person.v_MP = (on_arc(t + 0.01) - on_arc(t)) / 0.01;
    walker.person.last_seen = belief_.now;
    See({walker});
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  EXPECT_FALSE(NotedText("residents coming"));
  walker.person.v_MP.setZero();
  walker.person.p_MRest = walker.person.p_MP;
  See({walker});
  const double operated = first_operation(kWalkTo, kWalkTo + 10.0);
  EXPECT_GT(operated, kWalkTo - kTickSec + detail::kStillForSec);
  EXPECT_LE(operated, kWalkTo + detail::kStillForSec + 1.0);
  int no_path_notes = 0;
  for (const auto& note : log_.pending())
    no_path_notes += note.text.find("no path to the spot") != std::string::npos;
  EXPECT_EQ(no_path_notes, 1);  // noted once, not every tick
}

// With no path to its spot and the spot out of the laser's sight, the robot turns until it is in
// sight: what blocks it may be marks of someone long gone, behind it, that only a ray clears
// (seed 8: the spot stayed "in collision" for 340 s, in the laser's blind sector).
TEST_F(HoldForResidentsTest, WithNoPathToItsSpotItTurnsToSeeIt) {
  const Pose2 spot = OperateThenBlockTheSpot();
  // Its back to the spot (the way in 55 degrees off ahead: no turn to watch it), someone waiting.
  const Eigen::Vector2d to_spot = spot.translation() - Standoff().translation();
  belief_.X_MB = Standoff();
  belief_.X_MB.yaw = std::atan2(to_spot.y(), to_spot.x()) + M_PI;
  belief_.off_map_returns = {{-0.6, 1.4}};
  for (const double t : {1.5, 2.0}) {
    belief_.now = At(t);
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2 turned = motion_.path().back();
  EXPECT_LT((turned.translation() - Standoff().translation()).norm(), 1e-6);  // on the spot
  const double bearing =
      std::remainder(std::atan2(to_spot.y(), to_spot.x()) - turned.yaw, 2 * M_PI);
  EXPECT_LE(std::abs(bearing), M_PI / 2 + 1e-6);  // in the sweep now
}

// A drive to its spot that found no path is planned again only kReplanNoPathSec later: a
// search that finds none covers the whole map, and tried every tick it was a fifth of the crowd
// bench's instructions. Once the way is free it sets off at the next try.
TEST_F(HoldForResidentsTest, ADriveThatFoundNoPathIsPlannedAgainOnlyAfterAPause) {
  const planning::BasePlanner* free_planner = services_.planner;
  OperateThenBlockTheSpot();
  belief_.X_MB = Standoff();
  belief_.off_map_returns = {{-0.6, 1.4}};  // someone waiting: it waits at its spot
  log_.Take();
  const auto tick_at = [&](double t) {
    belief_.now = At(t);
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  };
  tick_at(1.5);
  EXPECT_TRUE(NotedText("no path to the spot"));
  services_.planner = free_planner;  // the way frees
  log_.Take();
  tick_at(1.6);
  tick_at(1.9);
  EXPECT_FALSE(NotedText("driving to the spot beside the door")) << "planned again too soon";
  tick_at(1.5 + detail::kReplanNoPathSec);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
}

TEST_F(HoldForResidentsTest, ResidentsComingSendTheRobotAsideAndItLetsThemPass) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  belief_.now = At(2.0);
  belief_.moving_returns = {{-0.5, 1.5}};  // walking towards the door, on the robot's side
  belief_.off_map_returns = belief_.moving_returns;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_NEAR(motion_.path().back().x, Standoff().x + 1.5, 1e-6);
  // Its operation due again, with people still on the move near the door: it stays aside.
  belief_.X_MB = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  motion_.StopBase();
  OperatedAgo(8.0);
  for (double t = 2.25; t < 2.0 + detail::kComingForSec - 0.1; t += kTickSec) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  }
  EXPECT_FALSE(NotedText("residents coming"));  // not on the move kComingForSec yet
  belief_.now = At(2.0 + detail::kComingForSec);
  belief_.moving_returns = {{0.3, 2.3}};
  belief_.off_map_returns = belief_.moving_returns;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("residents coming"));
  // Through: the clear time counts while it watches; past clear_for the hold is over.
  belief_.moving_returns.clear();
  belief_.off_map_returns = {{0.2, 4.5}};  // beyond the door: not near on its side
  const double through = 2.5 + detail::kComingForSec;
  for (double t = through; t < through + 2.9; t += 0.5) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.now = At(through + 3.1);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("everyone is through"));
}

TEST_F(HoldForResidentsTest, WaitingAtTheActuatorItTurnsTheWayTheResidentsComeIntoView) {
  // Pressed, with nobody about: it waits at the actuator, but turned from the wall until the
  // way the residents come is 90 degrees off ahead (the laser's blind sector, behind it, would
  // otherwise be the room; a whole turn there and back takes too long between presses).
  HeadGaze gaze;
  services_.gaze = &gaze;
  tree_.TickOnce();
  belief_.now = At(2.0);
  OperatedAgo(1.0);  // in this hold: not due again
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2 to = motion_.path().back();
  // The head looks the rest of the way: at the way in.
  const auto head = gaze.Update(belief_, std::nullopt);
  ASSERT_TRUE(head.has_value());
  EXPECT_EQ(gaze.reason(), GazeReason::kTask);
  EXPECT_LT((to.translation() - Standoff().translation()).norm(), 1e-6);  // turns in place
  // 2 m out from the doorway (0, 3) on the robot's side: a right angle off ahead, on the side
  // the robot turned to (the shorter way round from the wall).
  const Eigen::Vector2d look = (Eigen::Vector2d(0.0, 1.0) - to.translation()).normalized();
  const Eigen::Vector2d ahead(std::cos(to.yaw), std::sin(to.yaw));
  EXPECT_NEAR(look.dot(ahead), 0.0, 1e-6);
  const double turned = std::remainder(to.yaw - Standoff().yaw, 2 * M_PI);
  const double full = std::remainder(std::atan2(look.y(), look.x()) - Standoff().yaw, 2 * M_PI);
  EXPECT_GT(turned * full, 0.0) << "towards the way in";
  EXPECT_NEAR(std::abs(full) - std::abs(turned), M_PI / 2, 1e-6);
}

TEST_F(HoldForResidentsTest, NeverGoesToTheActuatorWithSomeoneStandingByIt) {
  tree_.TickOnce();
  OperatedAgo(7.0);  // due
  belief_.now = At(2.0);
  belief_.off_map_returns = {{1.6, 1.8}};  // standing 0.7 m from the standoff
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  // Still there, never moving, 2 m from the doorway: standing in the room (they may set off
  // any moment), not waiting at the door.
  belief_.now = At(7.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  belief_.off_map_returns.clear();
  belief_.now = At(7.5);
  motion_.StopBase();  // done turning to face the way they come
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(HoldForResidentsTest, OpensTheDoorForSomeoneLeftWaitingAtIt) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  belief_.moving_returns = {{-0.5, 1.5}};  // they come
  belief_.off_map_returns = belief_.moving_returns;
  const double came = ComeFrom(2.0);
  motion_.StopBase();
  belief_.moving_returns.clear();
  belief_.off_map_returns.clear();
  // One stays, still, 1.5 m from the standoff (a wheelchair user who cannot press the button).
  See({node_testing::Person({0.0, 1.9}, perception::PersonIntent::kStationary)});
  OperatedAgo(12.0);  // the door has closed
  belief_.now = At(came + 2.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // still a moment ago: may set off
  belief_.X_MB = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());  // aside now
  motion_.StopBase();
  belief_.now = At(came + 4.5);
  See(belief_.world.people);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // waiting: the robot opens it
}

TEST_F(HoldForResidentsTest, OpensTheDoorForSomeoneFoundWaitingAtIt) {
  // The robot comes from the far end of the room; someone who cannot press the button has
  // been waiting by the doorway all along (0.4 m from the standoff), and never moves.
  BeginFarFromAShutDoor();
  belief_.off_map_returns = {{0.7, 2.2}};
  belief_.now = At(2.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // still only a moment: may set off
  belief_.now = At(6.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // right at the standoff: not yet clear
  belief_.off_map_returns = {{0.5, 2.2}};             // 0.6 m off it, still by the doorway
  belief_.now = At(6.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // waiting: the robot goes to open it
}

// ... also after a stir nearby too short to be people coming, once it has been still for a while
// (two wards seed 7: a resident waiting alone at door_e was left behind, the robot watching from
// 8 m while others walked through: no one "came" for it, and the stir barred "found waiting").
TEST_F(HoldForResidentsTest, OpensTheDoorForSomeoneFoundWaitingAfterAStirNearby) {
  BeginFarFromAShutDoor();
  belief_.off_map_returns = {{0.5, 2.2}};  // waiting by the doorway, 0.6 m off the standoff
  belief_.moving_returns = {{-1.5, 1.5}};  // a stir on this side, half a second
  for (const double t : {2.0, 2.25, 2.5}) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  }
  belief_.moving_returns.clear();
  belief_.now = At(6.0);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // still only 3.5 s since
  belief_.now = At(7.0);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // waiting: the robot goes to open it
}

TEST_F(HoldForResidentsTest, OpensTheDoorForSomeoneWaitingBesideTheWayToTheActuator) {
  // As the clinic's 2 m corridor: the robot comes from 6 m along the wall; the one waiting by
  // the doorway stands 0.7 m short of the standoff, right on the straight line there. Only the
  // standoff itself must be free: the way is the planner's, round them (asking the line's last
  // metre to be clear too kept the robot away for good: clinic seeds 13, 60).
  belief_.X_MB = {-5.0, 2.0, 0.0};
  tree_.TickOnce();
  OperatedAgo(12.0);
  const Eigen::Vector2d standoff = Standoff().translation();
  const Eigen::Vector2d waiting =
      standoff + 0.7 * (belief_.X_MB.translation() - standoff).normalized();
  belief_.off_map_returns = {waiting};
  belief_.now = At(2.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // still only a moment: may set off
  belief_.now = At(6.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // waiting: the robot goes to open it
  // Someone at the standoff itself: not yet.
  tree_.HaltTree();
  belief_.off_map_returns = {waiting, standoff + Eigen::Vector2d(0.3, 0.0)};
  belief_.now = At(12.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
}

TEST_F(HoldForResidentsTest, BetweenOperationsForSomeoneWaitingItWaitsAsideNotAtTheActuator) {
  // Operated at the start of the hold; someone waits by the doorway (a wheelchair user who
  // cannot press), still, for longer than kStillForSec: the robot may go to the actuator for
  // them, but between operations it waits at the spot aside, not at the standoff beside their
  // way in (the open leaf and the robot there left a wide resident no way through: clinic
  // seed 13, 80 s of presses to the time limit).
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operates first
  belief_.now = At(1.5);
  OperatedAgo(0.0);  // in this hold: not due again for `every` seconds
  belief_.off_map_returns = {{0.5, 2.2}};
  // Not again after `every` (6 s) but after the operator's hold window (10 s): the press and the
  // tuck after it take most of 6 s, and the robot would never leave the actuator.
  for (double t = 2.0; t < 11.5; t += 0.5) {
    belief_.now = At(t);
    belief_.X_MB = Standoff();  // back at the standoff after each tick
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
    ASSERT_GE(motion_.path().size(), 2u) << "at " << t;
    EXPECT_NEAR(motion_.path().back().x, Standoff().x + 1.5, 1e-6) << "at " << t;
  }
  belief_.now = At(11.6);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
}

// Once it has opened for someone found waiting, it waits aside, not at the actuator, even with
// them out of view (behind it as it faces the button: clinic escort seed 26, where door_e's
// standoff is before the doorway and the resident could not pass the robot waiting there).
TEST_F(HoldForResidentsTest, AfterOpeningForSomeoneWaitingItWaitsAsideWithThemOutOfView) {
  ASSERT_EQ(OpenForSomeoneFoundWaiting(), NodeStatus::kSuccess);
  // Pressed; facing the wall, the robot no longer sees them.
  belief_.X_MB = Standoff();
  belief_.off_map_returns.clear();
  belief_.now = At(12.0);
  OperatedAgo(0.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_NEAR(motion_.path().back().x, Standoff().x + 1.5, 1e-6);
}

// The door open and someone near, the robot still at the actuator in their way in steps sideways
// along the door line away from the opening, up to the wall (kSqueezeMaxM, 0.4 m), facing the way
// they come, and waits there while the door stands open if its way to the spot is taken (two
// wards seed 54, clinic seed 19: door_e's leaf opens towards those waiting, and its free edge
// ended 0.55 m from the robot at the standoff; a wheelchair needs 0.66 m). Residents as wide as
// a wheelchair (0.4 m) put the lab's standoff, 1.075 m from the doorway's middle, in their lane.
TEST_F(HoldForResidentsTest, InTheWayInToTheOpenDoorItStepsAsideAlongTheDoorLine) {
  services_.config.person_radius = 0.4;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operates first
  // Pressed: the door open, someone by the doorway, the robot at the standoff.
  belief_.now = At(3.0);
  OperatedAgo(1.0);
  DoorSeenOpen(90.0, 1.0);
  belief_.off_map_returns = {{0.2, 2.2}};
  belief_.X_MB = Standoff();
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("squeezing aside"));
  ASSERT_EQ(motion_.path().size(), 2u);
  const Pose2 aside = motion_.path().back();
  EXPECT_NEAR(aside.x, Standoff().x + 0.4, 1e-6);  // away from the doorway, along its line
  EXPECT_NEAR(aside.y, Standoff().y, 1e-6);
  // Facing the way they come (the watch point, 2 m out from the doorway's middle).
  const Eigen::Vector2d look =
      detail::WatchPoint(CalcDoorPass(map_, "lab_door", aside)) - aside.translation();
  EXPECT_NEAR(aside.yaw, std::atan2(look.y(), look.x()), 1e-6);
  // There, with someone on its way to the spot, it stays while the door stands open.
  belief_.X_MB = aside;
  motion_.StopBase();
  log_.Take();
  belief_.off_map_returns = {{0.2, 2.2}, {2.3, 2.4}};
  belief_.now = At(4.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(motion_.base_moving());
  EXPECT_FALSE(NotedText("squeezing aside"));
  EXPECT_FALSE(NotedText("driving to the spot"));
  // The way there clear, it goes on to the spot.
  belief_.off_map_returns = {{0.2, 2.2}};
  belief_.now = At(4.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
}

// ... but not with the door shut: at the standoff beside someone waiting, it goes to its spot.
TEST_F(HoldForResidentsTest, WithTheDoorShutItDoesNotStepAsideAlongTheDoorLine) {
  services_.config.person_radius = 0.4;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
  belief_.now = At(3.0);
  OperatedAgo(1.0);
  belief_.off_map_returns = {{0.2, 2.2}};
  belief_.X_MB = Standoff();
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("squeezing aside"));
}

// Standing in the residents' way in, it sets off for its spot with someone standing 0.7 m from
// the way there: staying holds them up more (clinic escort seed 26: a resident beside the way
// kept the robot before door_e's doorway, and themselves behind it, through two openings). Out
// of the way in, the same person keeps it where it is.
TEST_F(HoldForResidentsTest, InTheirWayInItLeavesPastSomeoneStandingNearTheWayOut) {
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
  belief_.now = At(1.5);
  OperatedAgo(0.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.moving_returns = {{-1.5, 0.5}};
  belief_.off_map_returns = belief_.moving_returns;
  const double came = ComeFrom(2.0);  // they came
  belief_.moving_returns.clear();
  // Someone standing 0.7 m below the last metre of the way from before the doorway to the
  // spot, more than a metre from the spot itself.
  const Eigen::Vector2d in_lane(0.3, 2.4);
  const Eigen::Vector2d last_metre =
      spot.translation() + (in_lane - spot.translation()).normalized();
  const Eigen::Vector2d standing = last_metre + Eigen::Vector2d(0.0, -0.7);
  ASSERT_GT((standing - spot.translation()).norm(), 1.0);
  belief_.off_map_returns = {standing};
  belief_.X_MB = {in_lane.x(), in_lane.y(), 0.0};
  belief_.now = At(came + 0.5);
  motion_.StopBase();
  log_.Take();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  // From beside the actuator, out of the lane, on the same line: it stays.
  tree_.HaltTree();
  log_.Take();
  const Eigen::Vector2d out_of_lane =
      spot.translation() + 1.3 * (in_lane - spot.translation()).normalized();
  belief_.X_MB = {out_of_lane.x(), out_of_lane.y(), 0.0};
  ASSERT_GT(out_of_lane.x(), 1.1);  // beyond the lane's half width (1.02 m)
  belief_.now = At(came + 1.0);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("driving to the spot"));
}

// Having opened for someone found waiting, who then went through: it does not operate again for
// nobody, and the hold is over once nobody has been near for clear_for (clinic escort seed 26:
// two more presses at door_e after the resident it had opened for went through, and the robot
// reached the exit door, where they waited, after the time limit).
TEST_F(HoldForResidentsTest, OnceWhoeverItOpenedForWentThroughItReleasesTheDoor) {
  ASSERT_EQ(OpenForSomeoneFoundWaiting(), NodeStatus::kSuccess);
  // Pressed at 7 s; they went through; the robot watches from its spot, facing the way in.
  belief_.now = At(7.0);
  OperatedAgo(0.0);
  belief_.off_map_returns.clear();
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  const Eigen::Vector2d way_in = Eigen::Vector2d(0.0, 2.0) - spot.translation();
  belief_.X_MB = {spot.x, spot.y, std::atan2(way_in.y(), way_in.x())};
  NodeStatus status = NodeStatus::kRunning;
  double t = 7.0;
  // Past `every` (6 s) and the door shut: it would operate again before the wait_for (10 s) of
  // a hold nobody came to ran out.
  while (status == NodeStatus::kRunning && t < 20.0) {
    t += 0.5;
    belief_.now = At(t);
    motion_.StopBase();
    status = tree_.TickOnce();
  }
  EXPECT_EQ(status, NodeStatus::kFailure) << "at " << t;
  EXPECT_TRUE(NotedText("everyone is through"));
  EXPECT_LT(t, 7.0 + 6.0);
}

TEST_F(HoldForResidentsTest, GoesAsideForSomeoneWaitingBesideTheWayThere) {
  // Someone came, and stopped 0.6 m beside the way from the actuator to the spot, waiting (a
  // wheelchair user held up there): past someone standing still, the robot's room is enough (a
  // metre's clearance kept it at the actuator beside them: clinic seed 13).
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
  belief_.now = At(1.5);
  OperatedAgo(0.0);
  const Eigen::Vector2d beside = Standoff().translation() + Eigen::Vector2d(1.2, -0.6);
  belief_.moving_returns = {beside + Eigen::Vector2d(0.0, -0.5)};
  belief_.off_map_returns = belief_.moving_returns;
  const double came = ComeFrom(2.0);  // they come
  belief_.X_MB = Standoff();
  belief_.moving_returns.clear();
  belief_.off_map_returns = {beside};
  belief_.now = At(came + 4.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_NEAR(motion_.path().back().x, Standoff().x + 1.5, 1e-6);
}

TEST_F(HoldForResidentsTest, SomeoneWhoStayedWhileTheDoorStoodOpenIsNotWaitingForIt) {
  // As OpensTheDoorForSomeoneFoundWaitingAtIt, but the door stood open before them for 5 s in
  // this hold and they did not go through: not waiting for the door.
  BeginFarFromAShutDoor();
  belief_.off_map_returns = {{0.5, 2.2}};
  belief_.door_open_since["lab_door"] = At(1.0);
  belief_.now = At(6.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  belief_.door_open_since.clear();  // shut again: still not taken for someone waiting
  belief_.now = At(12.0);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
}

// Once the evacuation is under way (people came to a door the robot held), someone who stayed
// while the door stood open is still waiting for it: held up by others, or by the robot (clinic
// seed 19: a wheelchair user at door_e, held up by the robot through two windows, was never
// opened for again).
TEST_F(HoldForResidentsTest, OnceUnderWaySomeoneWhoStayedWhileTheDoorStoodOpenIsWaiting) {
  // A hold through which residents came, to its end.
  tree_.TickOnce();
  OperatedAgo(1.0);
  const double t = HoldThroughWhichResidentsCame(2.0);
  // The next hold: as SomeoneWhoStayedWhileTheDoorStoodOpenIsNotWaitingForIt.
  BeginFarFromAShutDoor();
  belief_.off_map_returns = {{0.5, 2.2}};
  belief_.door_open_since["lab_door"] = At(t);
  belief_.now = At(t + 5.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // it goes to keep it open for them
}

TEST_F(HoldForResidentsTest, DoesNotTakeAGroupYetToSetOffForSomeoneWaiting) {
  // The same as above, with others of the group standing further out in the room near the
  // actuator: they have not set off yet, and may as the robot presses with its back to them.
  BeginFarFromAShutDoor();
  belief_.off_map_returns = {{0.5, 2.2}, {0.3, 0.9}};  // the second 2.1 m from the doorway
  for (double t = 2.0; t < 20.0; t += 1.0) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.off_map_returns = {{0.5, 2.2}};  // only the one by the doorway now
  belief_.now = At(20.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
}

// Before anyone came, a group standing out in the room within `reach` (6 m) of the standoff,
// beyond keep_clear (3.5 m), keeps the robot from the actuator: they may set off while it is
// there, and it would drive back to its spot through them (two wards seeds 3, 16, 22: a group
// 3.6 m from the standoff; the robot pressed every hold window and was at the button when the
// alarm set them off).
TEST_F(HoldForResidentsTest, DoesNotGoToTheActuatorWithAGroupStandingWithinReach) {
  const std::vector<Eigen::Vector2d> group = {{-0.5, -1.3}, {0.5, -1.3}};
  for (const Eigen::Vector2d& p : group)
    ASSERT_GT((p - Standoff().translation()).norm(), 3.5);
  belief_.off_map_returns = group;
  for (double t = 1.0; t < 15.0; t += 1.0) {
    belief_.now = At(t);
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.off_map_returns.clear();  // they went another way
  belief_.now = At(15.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
}

// ... but laser returns hugging a wall are the wall's, seen a little off from afar, not people:
// a jamb 4.7 m from the standoff, read as a group, kept the robot from the button while a
// resident waited at the door (atrium seed 26).
TEST_F(HoldForResidentsTest, ReturnsHuggingAWallAreNotAGroupWithinReach) {
  const perception::Costmap2D walls = LabWalls();
  belief_.world.costmap = &walls;
  const Eigen::Vector2d by_wall{-2.8, 2.8};  // 0.15 m off the west wall's face
  const Eigen::Vector2d off_wall{-2.8, 2.4};
  for (const Eigen::Vector2d& p : {by_wall, off_wall}) {
    ASSERT_GT((p - Standoff().translation()).norm(), 3.5);
    ASSERT_LT((p - Standoff().translation()).norm(), 6.0);
  }
  belief_.off_map_returns = {off_wall};
  for (double t = 1.0; t < 5.0; t += 1.0) {
    belief_.now = At(t);
    motion_.StopBase();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.off_map_returns = {by_wall};
  belief_.now = At(5.5);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
}

// Once the evacuation is under way (people came to a door the robot held), those standing at the
// next door with someone by its doorway are waiting for it, however many stand further out
// (office seed 14: two who could not wave at door_b's plate queued there, the second 1.9 m from
// the doorway, and were left there). Before, the same people are a group yet to set off.
TEST_F(HoldForResidentsTest, OnceTheEvacuationIsUnderWayAQueueAtTheDoorIsWaitingForIt) {
  const Eigen::Vector2d front{0.3, 2.0}, second{0.3, 0.8};
  ASSERT_LT((front - Eigen::Vector2d(0.0, 3.0)).norm(), 1.5);
  ASSERT_GT((second - Eigen::Vector2d(0.0, 3.0)).norm(), 2.0);
  const auto stationary = perception::PersonIntent::kStationary;
  const auto queue_stands_from = [&](double from) {
    return TimeItGoesForThoseStanding(
        {node_testing::Person(front, stationary), node_testing::Person(second, stationary)}, from,
        6.0);
  };
  // Before anyone came: a group standing about, never operated for.
  BeginFarFromAShutDoor();
  EXPECT_EQ(queue_stands_from(2.0), -1.0);
  // A hold through which residents came, to its end ...
  See({});
  const double t = HoldThroughWhichResidentsCame(9.0);
  // ... and the next hold finds the same two standing at the door: it goes to open it for them.
  BeginFarFromAShutDoor();
  const double went = queue_stands_from(t + 1.0);
  EXPECT_GT(went, t + detail::kStillForSec) << "went before they stood still kStillForSec";
  EXPECT_TRUE(NotedText("releasing")) << "the first hold's end";
}

// ... and so is someone standing alone, still, near the door but not by its doorway: a
// wheelchair user who cannot operate it, who made way for whoever would (the twin's residents
// wait across a lane to the actuator). Read as not waiting, they kept the robot from the
// actuator (clinic seed 37: left behind at the time limit).
TEST_F(HoldForResidentsTest, OnceUnderWaySomeoneStandingStillNearTheDoorIsWaitingForIt) {
  const Eigen::Vector2d aside{0.3, 0.8};
  ASSERT_GT((aside - Eigen::Vector2d(0.0, 3.0)).norm(), 1.5);  // not by the doorway
  ASSERT_LT((aside - Standoff().translation()).norm(), 3.5);   // within keep_clear
  tree_.TickOnce();
  OperatedAgo(1.0);
  const double t = HoldThroughWhichResidentsCame(2.0);
  BeginFarFromAShutDoor();
  const double went = TimeItGoesForThoseStanding(
      {node_testing::Person(aside, perception::PersonIntent::kStationary)}, t + 1.0, 8.0);
  EXPECT_GT(went, t + detail::kStillForSec) << "went before they stood still kStillForSec";
}

// People came once someone near was on the move kComingForSec on end: a stir of a few tenths
// of a second in a group standing about (a track hopping between neighbours who hide one
// another) is not residents coming (two wards seed 16: taken for it 4.9 s into the hold, a
// minute before the alarm, the robot then pressed for the group as if they waited at the door).
TEST_F(HoldForResidentsTest, AStirInAGroupStandingAboutIsNotResidentsComing) {
  tree_.TickOnce();
  belief_.off_map_returns = {{-0.5, -1.3}, {0.5, -1.3}};
  belief_.moving_returns = {{0.5, -1.3}};
  double t = 2.0;
  for (; t < 2.0 + detail::kComingForSec - 0.1; t += kTickSec) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  }
  belief_.moving_returns.clear();  // a gap longer than kStirGapSec
  belief_.now = At(t + detail::kStirGapSec);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  belief_.moving_returns = {{0.5, -1.3}};  // a stir again: counted afresh
  const double again = t + detail::kStirGapSec + kTickSec;
  for (t = again; t < again + detail::kComingForSec - 0.1; t += kTickSec) {
    belief_.now = At(t);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  }
  EXPECT_FALSE(NotedText("residents coming"));
  belief_.now = At(again + detail::kComingForSec);  // on the move kComingForSec on end
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("residents coming"));
}

TEST_F(HoldForResidentsTest, SomeoneWaitingIsOneBodyWhoseOutlineReachesFurtherOut) {
  // A wheelchair user waiting by the doorway, off to the side away from the actuator: the
  // laser's returns on their outline run from 0.9 m to 1.6 m from the doorway's centre (office
  // seed 34: one such was left behind).
  BeginFarFromAShutDoor();
  std::vector<Eigen::Vector2d> outline;
  for (double x = -0.6; x > -1.42; x -= 0.04)
    outline.push_back({x, 2.3});
  belief_.off_map_returns = outline;
  belief_.now = At(6.0);
  motion_.StopBase();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
  // Someone else 0.3 m beyond them (a gap between two bodies): a group, not one waiting.
  tree_.TickOnce();
  OperatedAgo(12.0);
  belief_.off_map_returns = outline;
  belief_.off_map_returns.push_back({-1.7, 2.3});
  belief_.now = At(7.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  // Only the one beside the lane: nobody waits at the door.
  belief_.off_map_returns = {{-1.7, 2.3}};
  belief_.now = At(8.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
}

TEST_F(HoldForResidentsTest, GoesToItsSpotPastSomeoneFarFromItOnTheStraightLine) {
  // From the far end of the room, residents coming: someone standing on the straight line to
  // its spot but 1.2 m short of the line's last metre does not keep it from the spot (it will
  // pass them on its path, yielding as everywhere); someone at the spot does.
  BeginFarFromAShutDoor();
  OperatedAgo(1.0);                 // not due
  belief_.X_MB = {2.7, -0.7, 0.0};  // the room's far corner, 3.1 m from the spot
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  const Eigen::Vector2d robot = belief_.X_MB.translation();
  const Eigen::Vector2d on_the_line = robot + 0.3 * (spot.translation() - robot);
  ExpectSetsOffFor(spot, 2.0, {{-0.5, 1.5}, on_the_line});
  // Someone standing 0.5 m from the spot: it waits where it is.
  belief_.moving_returns.clear();
  ExpectStaysWith(2.5, {{spot.x - 0.5, spot.y}});
}

// Someone standing behind it as it sets off for its spot does not keep it where it stands: the
// drive takes it away from them. Stopped 0.9 m in front of a group yet to set off, between them
// and the door, the robot counted the nearest as on its way and stood in their way in until
// they walked past it at 0.09 m (office escort seed 3). Someone as near ahead, on the way, does.
TEST_F(HoldForResidentsTest, SetsOffForItsSpotAwayFromSomeoneStandingBehindIt) {
  BeginFarFromAShutDoor();
  OperatedAgo(1.0);  // not due
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = {spot.x - 0.15, spot.y - 0.85, M_PI / 2};  // into the room, out of the lane
  const Eigen::Vector2d at = belief_.X_MB.translation();
  const Eigen::Vector2d to_spot = (spot.translation() - at).normalized();
  ExpectSetsOffFor(spot, 2.0, {{-0.5, 1.5}, at - 0.8 * to_spot});
  // The same person as near ahead, on its way there: it stays.
  ExpectStaysWith(2.5, {{-0.5, 1.5}, at + 0.8 * to_spot});
}

// From far off, it drives to its spot square to the way it goes, the same side all the way, so
// the laser (270 degrees) sees ahead along the way and back along it: its blind sector behind it,
// facing the way the residents come it drove backwards 14 m into someone queued on its way
// (two-wards seed 12); facing the way it went, a resident who came up behind it was not seen
// until they walked into it (two-wards seed 3). It turns on the spot first when it faces well
// away; the watch turns it at the spot.
TEST_F(HoldForResidentsTest, DrivesToItsSpotSquareToTheWayItGoes) {
  BeginFarFromAShutDoor();
  OperatedAgo(1.0);                       // not due
  belief_.X_MB = {2.7, -0.7, -M_PI / 2};  // facing away from the spot, 3.1 m off
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.now = At(2.0);
  belief_.moving_returns = {{-0.5, 1.5}};  // they come
  belief_.off_map_returns = belief_.moving_returns;
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  const std::vector<Pose2>& path = motion_.path();
  ASSERT_GE(path.size(), 3u);
  EXPECT_LT((path.back().translation() - spot.translation()).norm(), 1e-6);
  // A turn on the spot first, to face square to the first leg.
  EXPECT_LT((path[1].translation() - belief_.X_MB.translation()).norm(), 1e-9);
  std::optional<double> side;  // +pi/2: facing left of the way, -pi/2: right
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d leg = path[i + 1].translation() - path[i].translation();
    if (leg.norm() < 0.01) continue;
    const double off = std::remainder(path[i].yaw - std::atan2(leg.y(), leg.x()), 2 * M_PI);
    EXPECT_NEAR(std::abs(off), M_PI / 2, 1e-9) << "waypoint " << i << " square to its leg";
    if (side) {
      EXPECT_NEAR(off, *side, 1e-9) << "waypoint " << i << " on the same side";
    }
    side = off;
  }
  ASSERT_TRUE(side.has_value());
  const Eigen::Vector2d last = path.back().translation() - path[path.size() - 2].translation();
  EXPECT_NEAR(std::remainder(path.back().yaw - std::atan2(last.y(), last.x()), 2 * M_PI), *side,
              1e-9);
  // A short way (under kFaceTravelBeyondM) turns evenly to the watching yaw, as before.
  motion_.StopBase();
  log_.Take();
  belief_.X_MB = {spot.x, spot.y - 1.0, M_PI};
  belief_.now = At(3.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
  ASSERT_EQ(motion_.path().size(), 2u);
  const Eigen::Vector2d look =
      Eigen::Vector2d(0.0, 1.0) - motion_.path().back().translation();  // 2 m out from the door
  EXPECT_NEAR(std::remainder(motion_.path().back().yaw - std::atan2(look.y(), look.x()), 2 * M_PI),
              0.0, 1e-6);
}

// Driving to its spot, someone walking up behind it (from there on in the laser's blind sector)
// makes it stop and stand aside; it drives on once nobody has walked up behind for a while.
// Someone behind it walking away does not (two wards seed 3: a resident followed the robot along
// the corridor into the blind sector and walked into its back).
TEST_F(HoldForResidentsTest, LetsSomeoneWalkingUpBehindItPassBeforeDrivingOn) {
  BeginFarFromAShutDoor();
  OperatedAgo(1.0);  // not due
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = {spot.x, 1.3, M_PI / 2};  // south of its spot, facing it
  belief_.now = At(2.0);
  belief_.moving_returns = {{-0.5, 1.5}};  // they come
  belief_.off_map_returns = belief_.moving_returns;
  ASSERT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("driving to the spot beside the door"));
  ASSERT_TRUE(motion_.base_moving());
  const auto walking = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
    auto entry = node_testing::Person(p, perception::PersonIntent::kApproaching);
    entry.person.v_MP = v;
    return entry;
  };
  const Eigen::Vector2d at = belief_.X_MB.translation();
  // Behind it, walking away: it drives on.
  log_.Take();
  belief_.now = At(2.1);
  See({walking(at + Eigen::Vector2d(0.0, -1.0), {0.0, -1.0})});
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("walking up behind"));
  EXPECT_TRUE(motion_.base_moving());
  // Behind it, walking up: it stops and steps aside, out of their way. (Slow and far enough
  // that making room, for someone about to touch it, has nothing to do yet.)
  belief_.now = At(2.2);
  See({walking(at + Eigen::Vector2d(0.0, -2.2), {0.0, 0.55})});
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("someone walking up behind: letting them pass"));
  ASSERT_TRUE(NotedText("stepping aside"));
  ASSERT_GE(motion_.path().size(), 2u);
  const Eigen::Vector2d aside = motion_.path().back().translation() - at;
  EXPECT_GT(std::abs(aside.x()), 0.3) << "off their way: " << aside.transpose();
  EXPECT_GE(aside.y(), 0.0) << "not back towards them: " << aside.transpose();
  // They have passed and the step has ended: it waits out kLetPassClearSec, then drives on.
  motion_.StopBase();
  See({});
  log_.Take();
  belief_.now = At(3.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("driving to the spot"));
  belief_.now = At(3.8);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("driving on"));
  EXPECT_TRUE(NotedText("driving to the spot beside the door"));
}

// Its spot taken while it drives there: it stops short (the drive's slowing near people spares
// whoever stands at its goal: two wards seed 10, a resident came to wait for door_e beside the
// spot and the robot crept on into them); someone near the way but not the spot does not stop it.
// door_speed (a round behind residents the robot let out on a sweep): to the same spot, every
// segment at the door speed.
class HoldForResidentsAtTheDoorSpeedTest : public HoldForResidentsTest {
 protected:
  HoldForResidentsAtTheDoorSpeedTest() {
    tree_ = Tree(R"(<HoldForResidents door="lab_door" clear_for="3.0" wait_for="10.0"
                                      door_speed="true"/>)",
                 blackboard_);
  }
};

TEST_F(HoldForResidentsAtTheDoorSpeedTest, ItDrivesToTheSpotAtTheDoorSpeed) {
  const Pose2 spot = DriveToTheSpotFrom([](const Pose2& spot) {
    return Pose2{spot.x, spot.y - 2.5, M_PI / 2};
  });
  const std::vector<Pose2> path = motion_.path();
  ASSERT_GE(path.size(), 2u);
  EXPECT_LT((path.back().translation() - spot.translation()).norm(), 1e-6);
  const planning::TrajectoryConfig& trajectory = motion_.trajectory_config();
  ASSERT_LT(trajectory.nominal_speed, trajectory.door_speed);
  double at_door_speed = 0.0, at_nominal_speed = 0.0;
  for (std::size_t k = 1; k < path.size(); ++k) {
    const double length = (path[k].translation() - path[k - 1].translation()).norm();
    const double turn = std::abs(std::remainder(path[k].yaw - path[k - 1].yaw, 2 * M_PI));
    at_door_speed += planning::SegmentDuration(length, turn, true, trajectory);
    at_nominal_speed += planning::SegmentDuration(length, turn, false, trajectory);
  }
  EXPECT_LT(at_door_speed, at_nominal_speed - 1.0);
  EXPECT_NEAR(motion_.base_duration(), at_door_speed, 1e-6);
}

TEST_F(HoldForResidentsTest, StopsShortWhenItsSpotIsTakenOnTheWay) {
  const Pose2 spot = DriveToTheSpotFrom([](const Pose2& spot) {
    return Pose2{spot.x, spot.y - 2.5, M_PI / 2};
  });
  // Someone 1.5 m beside the spot: it drives on.
  belief_.now = At(2.5);
  belief_.off_map_returns = {{-0.5, 1.5}, {spot.x + 1.5, spot.y}};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(motion_.base_moving());
  EXPECT_FALSE(NotedText("taken"));
  // Someone comes to stand 0.5 m from the spot: it stops short.
  belief_.now = At(3.0);
  belief_.off_map_returns = {{-0.5, 1.5}, {spot.x + 0.5, spot.y}};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("the spot is taken: stopping short"));
  EXPECT_FALSE(motion_.base_moving());
  // ... and does not set off for it again while they stand there.
  log_.Take();
  belief_.now = At(3.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("driving to the spot"));
}

// ... but not in the residents' way in (the lane before the doorway): stopped there, between the
// actuator and its spot, it held up a wheelchair user through two hold windows (clinic seed 19,
// door_e). It drives on until out of the lane, and stops short there.
TEST_F(HoldForResidentsTest, DoesNotStopShortInTheResidentsWayIn) {
  // From before the doorway (x = 0, y = 3).
  const Pose2 spot = DriveToTheSpotFrom([](const Pose2&) { return Pose2{0.3, 1.8, 0.0}; });
  // Someone comes to stand 0.5 m from the spot while it is still in the lane: it drives on.
  belief_.now = At(2.5);
  belief_.off_map_returns = {{-0.5, 1.5}, {spot.x + 0.5, spot.y}};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(motion_.base_moving());
  EXPECT_FALSE(NotedText("taken"));
  // Out of the lane (its half width: the opening's half, the robot and a resident, 1.02 m):
  // it stops short.
  belief_.X_MB = {1.3, 2.0, 0.0};
  ASSERT_GT((belief_.X_MB.translation() - spot.translation()).norm(), 0.3);
  belief_.now = At(3.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("the spot is taken: stopping short"));
  // Stopped (or turning where it stands, to watch the way in).
  EXPECT_TRUE(!motion_.base_moving() ||
              (motion_.path().back().translation() - belief_.X_MB.translation()).norm() < 0.05);
}

TEST_F(HoldForResidentsTest, MakesRoomForSomeoneWhoComesTooNear) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = spot;
  belief_.now = At(2.0);
  // Someone 0.4 m from the robot's centre, on the doorway's side of it.
  const Eigen::Vector2d them{spot.x - 0.4, spot.y};
  belief_.off_map_returns = {them};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("making room"));
  ASSERT_GE(motion_.path().size(), 2u);
  const Eigen::Vector2d to = motion_.path().back().translation();
  EXPECT_GT((to - them).norm(), 0.4 + 0.1);  // farther from them by a real step
  EXPECT_TRUE(planner_.IsPathValid(motion_.path()));
  // Someone at arm's length (a metre) is not too near: no step.
  motion_.StopBase();
  log_.Take();
  belief_.X_MB = spot;
  belief_.off_map_returns = {{spot.x - 1.0, spot.y}};
  belief_.now = At(2.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("making room"));
}

TEST_F(HoldForResidentsTest, MakesRoomToTheSideOfSomeoneWalkingAtIt) {
  // Someone 1.5 m away walking straight at the robot at 1 m/s: it steps out of their path, to
  // the side, not ahead of them along it (where they catch up with a robot stepping at 0.4 m/s).
  tree_.TickOnce();
  OperatedAgo(1.0);
  belief_.X_MB = {-1.8, 1.0, 0.0};
  belief_.now = At(2.0);
  auto walker = node_testing::Person({-1.8, -0.5}, perception::PersonIntent::kApproaching);
  walker.person.v_MP = {0.0, 1.0};
  for (int k = 1; k <= 4; ++k)
    walker.person.forecast.push_back(walker.person.p_MP + walker.person.v_MP * (0.2 * k));
  See({walker});
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("making room"));
  ASSERT_GE(motion_.path().size(), 2u);
  const Eigen::Vector2d step = motion_.path().back().translation() - belief_.X_MB.translation();
  EXPECT_GT(std::abs(step.x()), std::abs(step.y())) << "step " << step.transpose();
  EXPECT_GT(std::abs(motion_.path().back().x - -1.8), 0.5) << "off their path";
}

// Someone running at the robot, too near for any step to take it out of their way in time: it
// keeps still, where they see it and go round, rather than start a step they run into (atrium
// seed 32: a metre's step, predicted to meet them anyway, reversed the robot into a resident
// pushed along by the crowd).
TEST_F(HoldForResidentsTest, KeepsStillForSomeoneTooNearForAnyStepToClear) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = spot;  // arrived
  motion_.StopBase();
  belief_.now = At(2.0);
  const auto walking_at_it = [&](double from, double speed) {
    auto walker =
        node_testing::Person({spot.x, spot.y - from}, perception::PersonIntent::kApproaching);
    walker.person.v_MP = {0.0, speed};
    for (int k = 1; k <= 4; ++k)
      walker.person.forecast.push_back(walker.person.p_MP + walker.person.v_MP * (0.2 * k));
    return walker;
  };
  // Running at 2 m/s from 1.2 m: on the robot in under half a second.
  See({walking_at_it(1.2, 2.0)});
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("making room"));
  // (It may turn where it stands, to watch them.)
  EXPECT_TRUE(!motion_.base_moving() ||
              (motion_.path().back().translation() - spot.translation()).norm() < 1e-9);
  // Walking at 1 m/s from 1.5 m, they leave the robot time for a step out of their way: it
  // takes it.
  See({walking_at_it(1.5, 1.0)});
  belief_.now = At(2.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(NotedText("making room"));
}

// A step under way is re-aimed when someone comes at where it ends: taking a 0.6 m step for
// one person, the robot did not look again for the seconds it took, while another walked 2 m
// at it (clinic seed 4, a contact).
TEST_F(HoldForResidentsTest, AStepUnderWayIsReAimedWhenSomeoneComesAtWhereItEnds) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = spot;
  belief_.now = At(2.0);
  belief_.off_map_returns = {{spot.x - 0.4, spot.y}};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("making room"));
  ASSERT_TRUE(motion_.base_moving());
  const Eigen::Vector2d first = motion_.path().back().translation();
  // Still on the way there: nobody new, the step goes on.
  log_.Take();
  belief_.now = At(2.2);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("making room"));
  // Someone 1.2 m beyond the step's end walking at it at 1 m/s: a new step, away from their way.
  const Eigen::Vector2d away = (first - spot.translation()).normalized();
  auto walker = node_testing::Person(first + away * 1.2, perception::PersonIntent::kApproaching);
  walker.person.v_MP = -away;
  for (int k = 1; k <= 4; ++k)
    walker.person.forecast.push_back(walker.person.p_MP + walker.person.v_MP * (0.2 * k));
  See({walker});
  // Not at once: a step starts from rest, and one re-aimed every tick would not move the robot.
  belief_.now = At(2.4);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("making room"));
  belief_.now = At(3.1);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("making room"));
  const Eigen::Vector2d second = motion_.path().back().translation();
  // Farther from where they will be over the next 2 s than the first step's end, which they
  // walk through.
  const auto nearest_pass = [&](const Eigen::Vector2d& q) {
    double d = std::numeric_limits<double>::infinity();
    for (double t = 0.0; t <= 2.0; t += 0.05)
      d = std::min(d, (walker.person.p_MP + walker.person.v_MP * t - q).norm());
    return d;
  };
  EXPECT_GT(nearest_pass(second), nearest_pass(first) + 0.3)
      << "first " << first.transpose() << " second " << second.transpose();
}

// A step to make room ends clear of the building's walls by a margin (a step's quintic settles
// a little past its end: clinic seed 62, a step ending 2.5 cm from the corridor's wall touched
// it), even where the most room from people lies along the wall.
TEST_F(HoldForResidentsTest, AStepToMakeRoomEndsClearOfTheWall) {
  const perception::Costmap2D walls = LabWalls();
  belief_.world.costmap = &walls;
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = spot;
  belief_.now = At(2.0);
  belief_.off_map_returns = {{spot.x, spot.y - 0.4}};  // someone just south of it
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("making room"));
  const Pose2 to = motion_.path().back();
  constexpr double kWallFaceY = 2.95;  // the lab wall's south face
  EXPECT_LE(to.y, kWallFaceY - TaskConfig{}.footprint_radius - 0.1 + 1e-9) << to.x << ", " << to.y;
  EXPECT_GT((to.translation() - Eigen::Vector2d(spot.x, spot.y - 0.4)).norm(), 0.4 + 0.1);
}

// A step planned from rest but begun moving runs past its end by about the braking distance
// (two wards seed 53: begun at 0.45 m/s, it ended 0.105 m past its end, on the corridor's wall):
// its end keeps that much more from the walls, and where braking alone takes the robot up to a
// wall no step begins (the motion under way brakes at its own end).
TEST_F(HoldForResidentsTest, AStepBegunMovingKeepsItsBrakingDistanceMoreFromTheWalls) {
  const perception::Costmap2D walls = LabWalls();
  belief_.world.costmap = &walls;
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  constexpr double kWallFaceY = 2.95;  // the lab wall's south face
  const double footprint = TaskConfig{}.footprint_radius;
  // Where it steps from `at` moving at v_M (someone just south of it), if it steps.
  const auto step_from = [&](const Pose2& at, const Eigen::Vector2d& v_M) {
    const Eigen::Vector2d v_B = Eigen::Rotation2Dd(-at.yaw) * v_M;
    motion_.StopBase();
    belief_.X_MB = at;
    belief_.V_B = Twist2{v_B.x(), v_B.y(), 0.0};
    belief_.now = At(2.0);
    belief_.off_map_returns = {
        {at.x, at.y - 0.4}, {at.x - 0.5, at.y - 0.5}, {at.x + 0.5, at.y - 0.5}};  // a row south
    log_.Take();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    return NotedText("making room") ? std::optional(motion_.path().back()) : std::nullopt;
  };
  // 0.12 m beyond the footprint from the wall, with people just south: at rest the most room
  // lies along the wall, up to the usual margin from it.
  const Pose2 by_wall{1.6, kWallFaceY - footprint - 0.12, spot.yaw};  // room east along it
  const double braking = 0.18;  // at 0.6 m/s and the base's 1 m/s^2
  const std::optional<Pose2> at_rest = step_from(by_wall, {0.0, 0.0});
  ASSERT_TRUE(at_rest);
  EXPECT_GT(at_rest->y, kWallFaceY - footprint - 0.1 - braking) << "the case no longer tells";
  // Moving along the wall at 0.6 m/s: a step, if any, ends the braking distance farther off.
  if (const std::optional<Pose2> moving = step_from(by_wall, {0.6, 0.0})) {
    EXPECT_LE(moving->y, kWallFaceY - footprint - 0.1 - braking + 1e-9);
  }
  // Moving at the wall at 0.6 m/s it would brake to within 0.06 m of it: no step.
  EXPECT_FALSE(step_from(by_wall, {0.0, 0.6}));
}

// Not back into the laser's blind sector where it last saw someone (school seed 5: pressing the
// button, the robot had the residents standing behind it; making room for a wheelchair user
// beside it, it stepped straight back among them). The costmap's obstacle layer remembers them
// where no ray has cleared them since.
TEST_F(HoldForResidentsTest, AStepToMakeRoomDoesNotGoBackAmongThoseLastSeenBehindIt) {
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  // Facing the wall (north), someone just west of it (the doorway's side), too near.
  const Pose2 X_MB{spot.x, spot.y, M_PI / 2};
  const Eigen::Vector2d them{spot.x - 0.4, spot.y};
  // Where a step goes, with `behind` seen earlier south of the robot (from where it stands,
  // facing south) and out of the laser's view now.
  const auto step_with = [&](const std::vector<Eigen::Vector2d>& behind, double t) {
    perception::Costmap2D costmap = LabWalls();
    LaserScan earlier = node_testing::SweepScan();
    earlier.ranges.assign(earlier.ranges.size(), std::numeric_limits<float>::infinity());
    const Pose2 X_ML_earlier{spot.x, spot.y, -M_PI / 2};
    for (const Eigen::Vector2d& p : behind) {
      const Eigen::Vector2d p_L = X_ML_earlier.Inverse() * p;
      const auto i = std::size_t(std::lround((std::atan2(p_L.y(), p_L.x()) - earlier.angle_min) /
                                             earlier.angle_increment));
      earlier.ranges[i] = float(p_L.norm());
    }
    costmap.UpdateWithScan(earlier, X_ML_earlier);
    belief_.world.costmap = &costmap;
    belief_.scan = node_testing::SweepScan();
    belief_.X_MB = X_MB;
    belief_.off_map_returns = {them};
    belief_.now = At(t);
    motion_.StopBase();
    log_.Take();
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
    EXPECT_TRUE(NotedText("making room"));
    belief_.world.costmap = nullptr;
    return motion_.path().empty() ? X_MB.translation() : motion_.path().back().translation();
  };
  // With nothing seen behind it, it steps back, out of the laser's view.
  const Eigen::Vector2d clear = step_with({}, 2.0);
  EXPECT_LT(clear.y(), spot.y - 0.2) << clear.transpose();
  // With people seen standing there, it steps elsewhere, clear of them by a body.
  std::vector<Eigen::Vector2d> group;
  for (double x = spot.x - 1.2; x <= spot.x + 1.2; x += 0.3)
    group.emplace_back(x, spot.y - 0.8);
  const Eigen::Vector2d to = step_with(group, 3.0);
  for (const Eigen::Vector2d& p : group)
    EXPECT_GT((to - p).norm(), TaskConfig{}.footprint_radius + 0.25)
        << "step to " << to.transpose() << ", someone at " << p.transpose();
  EXPECT_GT((to - them).norm(), 0.4 + 0.1);
}

// Nor in another door's doorway, nor through it (two wards seed 24: past door_d, holding door_e,
// the robot stepped back into door_d's doorway, making room for residents walking along the
// corridor, as door_d closed).
TEST_F(HoldForResidentsTest, AStepToMakeRoomStaysOutOfEveryDoorway) {
  const perception::Costmap2D walls = LabWalls();  // the lab wall north of the robot
  belief_.world.costmap = &walls;
  tree_.TickOnce();
  OperatedAgo(1.0);
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  // A side door 0.5 m east of the spot, its line along y (x = spot.x + 0.5), 1 m wide.
  const double line_x = spot.x + 0.5;
  perception::Doorway side;
  side.id = "side_door";
  side.p_MHinge = {line_x, spot.y - 0.5};
  side.p_MLatch = {line_x, spot.y + 0.5};
  map_.doorways.push_back(side);
  perception::DoorModel door;
  door.id = side.id;
  door.p_MHinge = side.p_MHinge;
  door.p_MLatch = side.p_MLatch;
  door.swing_sign = -1.0;
  map_.doors.push_back(door);
  belief_.X_MB = spot;
  belief_.now = At(2.0);
  // People just west and south of the robot: the most room is east, through the side door (the
  // wall is north).
  belief_.off_map_returns = {
      {spot.x - 0.4, spot.y}, {spot.x, spot.y - 0.45}, {spot.x + 0.4, spot.y - 0.6}};
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_TRUE(NotedText("making room"));
  const Pose2 to = motion_.path().back();
  EXPECT_LT(to.x, line_x) << "through the side door: " << to.x << ", " << to.y;
  const bool across_opening = std::abs(to.y - spot.y) < 0.5 + TaskConfig{}.footprint_radius;
  EXPECT_FALSE(across_opening && line_x - to.x < 0.6) << "in its doorway: " << to.x << ", " << to.y;
}

// An operation it asked for that did not happen (the approach found no free standoff) is not
// asked for again at once: it was, every tick, for 340 s (two-wards seed 17).
TEST_F(HoldForResidentsTest, AnOperationThatDidNotHappenIsNotAskedForAgainAtOnce) {
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operate
  // The approach failed at once: no operation. The hold runs again.
  belief_.now = At(1.1);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  motion_.StopBase();  // the turn to watch the way in, done
  belief_.now = At(3.9);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  motion_.StopBase();
  belief_.now = At(4.1);  // kOperateRetrySec on
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);
  // Operated this time: due again only `every` seconds after the operation.
  OperatedAgo(0.0);
  belief_.now = At(4.2);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
}

// The clear time counts only while the way in is in the laser's sweep: with its back to the
// door (stepping aside, turning), nobody there is seen (two-wards seed 17).
TEST_F(HoldForResidentsTest, ClearTimeCountsOnlyWhileTheWayInIsInTheLasersSweep) {
  belief_.scan = node_testing::SweepScan();
  const double came = ResidentsCame();
  // Aside, facing away from the doorway's way in (x = 0, y = 2 from the spot's east): the
  // laser's blind sector behind it.
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  belief_.X_MB = {spot.x, spot.y, 0.0};
  for (double t = came + 0.5; t < 9.0; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();  // it would turn to watch: held facing away here
    OperatedAgo(0.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t << ": nothing seen yet";
  }
  // Facing the way in: clear_for (3 s) of watching, then the hold is over.
  belief_.X_MB.yaw = M_PI;
  for (double t = 9.0; t < 12.0; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    OperatedAgo(0.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.now = At(12.6);
  OperatedAgo(0.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("everyone is through"));
}

// Watching, it keeps both the watch point and the way in (where the clear time is counted) within
// a right angle of ahead: near the watch point their bearings part (two wards seed 56: a step to
// make room ended 0.4 m from door_e's watch point, a right angle off ahead; the way in was 129
// deg off, past the laser's sweep, the clear time never ran, and the robot held door_e until the
// time limit while the last resident waited at the exit door).
TEST_F(HoldForResidentsTest, WatchingItKeepsTheWayInInTheLasersSweepAsWellAsTheWatchPoint) {
  belief_.scan = node_testing::SweepScan();
  const double came = ResidentsCame();
  // Someone stands at its spot: it stays where it is, 0.41 m from the watch point (0, 1), which
  // is a right angle off ahead on its right; the way in (0, 2) is 146 deg off.
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  See({node_testing::Person(spot.translation(), perception::PersonIntent::kStationary)});
  const Eigen::Vector2d watch(0.0, 1.0), way_in(0.0, 2.0);
  belief_.X_MB = {0.4, 0.9, std::atan2(0.1, -0.4) + M_PI / 2};
  const auto off = [](const Pose2& X_MB, const Eigen::Vector2d& p_M) {
    const Eigen::Vector2d to = p_M - X_MB.translation();
    return std::remainder(std::atan2(to.y(), to.x()) - X_MB.yaw, 2 * M_PI);
  };
  ASSERT_NEAR(off(belief_.X_MB, watch), -M_PI / 2, 1e-9);
  ASSERT_LT(off(belief_.X_MB, way_in), -0.8 * M_PI);
  belief_.now = At(came + 0.5);
  motion_.StopBase();
  OperatedAgo(0.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2 to = motion_.path().back();
  EXPECT_LT((to.translation() - belief_.X_MB.translation()).norm(), 1e-6);  // turns in place
  for (const Eigen::Vector2d& p : {watch, way_in})
    EXPECT_LE(std::abs(off(to, p)), M_PI / 2 + 1e-6) << p.transpose();
  // The least turn: the way in a right angle off ahead.
  EXPECT_NEAR(off(to, way_in), -M_PI / 2, 1e-6);
}

// ... and only while nothing of the map stands between the laser and the way in: aside behind
// the office's table, the robot saw nobody at door_a for 5 s while a wheelchair user waited
// there, and left them behind (office seed 5).
TEST_F(HoldForResidentsTest, ClearTimeCountsOnlyWhileTheWayInIsInTheLasersSight) {
  belief_.scan = node_testing::SweepScan();
  const double came = ResidentsCame();
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  const Eigen::Vector2d way_in(0.0, 2.0);
  // A table halfway between the spot and the way in, facing which the robot watches.
  const Eigen::Vector2d table = 0.5 * (spot.translation() + way_in);
  const perception::Costmap2D with_table(
      perception::OccupancyGrid::FromBoxes({{{1.75, 3.0, 0.0}, {2.5, 0.1}},
                                            {{-1.75, 3.0, 0.0}, {2.5, 0.1}},
                                            {{table.x(), table.y(), 0.0}, {0.3, 0.6}}},
                                           {-3.0, -1.0}, {3.0, 7.0}, 0.05));
  const perception::Costmap2D walls = LabWalls();
  belief_.world.costmap = &with_table;
  const Eigen::Vector2d to_way_in = way_in - spot.translation();
  belief_.X_MB = {spot.x, spot.y, std::atan2(to_way_in.y(), to_way_in.x())};
  EXPECT_TRUE(detail::IsInLaserSweep(services_, belief_.X_MB, way_in));
  EXPECT_FALSE(detail::IsInLaserSight(services_, belief_.X_MB, way_in));
  for (double t = came + 0.5; t < 12.0; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    OperatedAgo(0.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t << ": the table hides it";
  }
  // The view clear (the table gone): clear_for (3 s) of watching, then the hold is over.
  belief_.world.costmap = &walls;
  EXPECT_TRUE(detail::IsInLaserSight(services_, belief_.X_MB, way_in));
  for (double t = 12.0; t < 15.0; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    OperatedAgo(0.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.now = At(15.6);
  OperatedAgo(0.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("everyone is through"));
}

// Once people came, an operation that falls due while the clear clock runs with nobody near
// waits: the hold runs out, or someone comes (random building seeds 7, 12: arriving at its spot
// after a drive longer than `every`, the robot went back to press before clear_for had run, for
// nobody, until the time limit). Someone by the doorway stops the clock, and it operates.
TEST_F(HoldForResidentsTest, OnceTheyCameItDoesNotOperateForNobodyWhileTheClearClockRuns) {
  const double came = ResidentsCame();
  const Pose2 spot = ParsePose2(blackboard_->Get<std::string>("hold_spot").value());
  const Eigen::Vector2d to_way_in = Eigen::Vector2d(0.0, 2.0) - spot.translation();
  belief_.X_MB = {spot.x, spot.y, std::atan2(to_way_in.y(), to_way_in.x())};
  double t = came + 0.5;
  for (; t < came + 2.5; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    OperatedAgo(20.0);  // long due
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t << ": for nobody";
  }
  // Someone by the doorway, still: the clock stops, and once they have stood 4 s (kStillForSec) the
  // robot opens for them.
  belief_.off_map_returns = {{0.3, 1.6}};
  NodeStatus status = NodeStatus::kRunning;
  for (const double until = t + 6.0; status == NodeStatus::kRunning && t < until; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    OperatedAgo(20.0);
    status = tree_.TickOnce();
  }
  EXPECT_EQ(status, NodeStatus::kSuccess);
  // Nobody near again: the clock runs out with no operation.
  belief_.off_map_returns.clear();
  status = NodeStatus::kRunning;
  for (const double until = t + 6.0; status == NodeStatus::kRunning && t < until; t += 0.5) {
    belief_.now = At(t);
    motion_.StopBase();
    belief_.X_MB = {spot.x, spot.y, std::atan2(to_way_in.y(), to_way_in.x())};
    OperatedAgo(20.0);
    status = tree_.TickOnce();
  }
  EXPECT_EQ(status, NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("everyone is through"));
}

TEST_F(HoldForResidentsTest, WithNobodyAboutTheHoldEndsAfterWaitFor) {
  tree_.TickOnce();
  OperatedAgo(0.5);
  for (double t = 1.5; t <= 10.5; t += 1.0) {
    belief_.now = At(t);
    OperatedAgo(0.5);  // kept open meanwhile
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  belief_.now = At(11.6);
  OperatedAgo(0.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("nobody about"));
}

// ... but only as far as the laser knows people: beyond its people range (driving to a door
// 17 m away) seeing nobody at the way in says nothing.
TEST_F(HoldForResidentsTest, NobodySeenBeyondThePeopleRangeIsNotNobodyAbout) {
  belief_.people_range = 0.5;  // the way in is 1.2 m from the standoff
  tree_.TickOnce();
  OperatedAgo(0.5);
  for (double t = 1.5; t <= 20.5; t += 1.0) {
    belief_.now = At(t);
    OperatedAgo(0.5);
    EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning) << "at " << t;
  }
  EXPECT_FALSE(NotedText("nobody about"));
}

// Holding a door nobody comes to, the robot operates every `every` (6) s and watches only in
// between: the time spent operating between two looks that found nobody counts towards
// wait_for too (it counted only the watching, a fifth of the time, and office door_b was held
// 100 s for a group long out).
TEST_F(HoldForResidentsTest, WithNobodyAboutTheTimeSpentOperatingCountsTowardsWaitFor) {
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operate (t = 1)
  // Operating until t = 7 (the hand at the button at 3), then watching.
  belief_.now = At(7.0);
  OperatedAgo(4.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  motion_.StopBase();  // turned to watch
  belief_.now = At(9.0);
  OperatedAgo(6.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // due again
  // Back from the next operation at t = 15: 14 s since it last saw anyone, over wait_for (10).
  belief_.now = At(15.0);
  OperatedAgo(4.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("nobody about"));
}

// ... wherever the robot faces as it comes back from the actuator: the way in behind it (in the
// laser's blind sector) at the first tick after an operation still counts the operation (atrium
// seed 5: only the seconds it watched between operations counted, and it pressed the button of a
// door everyone was past for 130 s), and the hold is over at its first look at the way in.
TEST_F(HoldForResidentsTest, TheTimeSpentOperatingCountsFacingAwayFromTheWayIn) {
  belief_.scan = node_testing::SweepScan();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operate (t = 1)
  const auto facing_away = [&] {
    // The doorway's way in at (0, 2): straight behind the robot.
    belief_.X_MB.yaw = std::atan2(2.0 - belief_.X_MB.y, 0.0 - belief_.X_MB.x) + M_PI;
  };
  belief_.now = At(7.0);
  OperatedAgo(4.0);
  facing_away();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  motion_.StopBase();
  belief_.now = At(9.0);
  OperatedAgo(6.0);
  facing_away();
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // due again; 6 s, none of it watched
  belief_.now = At(15.0);
  OperatedAgo(4.0);
  facing_away();
  // 12 s since it last saw anyone, but over only on a look at the way in (random building seed
  // 10: eight residents walked up behind it, unseen): it turns to watch first.
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);
  EXPECT_FALSE(NotedText("nobody about"));
  ASSERT_GE(motion_.path().size(), 2u);
  belief_.X_MB = motion_.path().back();  // turned
  motion_.StopBase();
  belief_.now = At(16.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(NotedText("nobody about"));
}

// ... but an operation that began with someone about does not count as clear (they may come
// while the robot faces the actuator).
TEST_F(HoldForResidentsTest, AnOperationBegunWithSomeoneAboutDoesNotCountAsClear) {
  // Standing 5 m from the doorway, beyond `reach` (6 m) of the standoff: about, and no bar to
  // operating.
  const Eigen::Vector2d about(-5.0, 2.7);
  ASSERT_LT((about - Eigen::Vector2d(0.0, 3.0)).norm(), 6.0);  // the watch radius
  ASSERT_GT((about - Standoff().translation()).norm(), 6.0);
  See({node_testing::Person(about, perception::PersonIntent::kStationary)});
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // operate (t = 1)
  See({});                                            // gone meanwhile
  belief_.now = At(7.0);
  OperatedAgo(4.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // clear from here: 0 s
  motion_.StopBase();                                 // turned to watch
  belief_.now = At(9.0);
  OperatedAgo(6.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kSuccess);  // 2 s
  belief_.now = At(15.0);
  OperatedAgo(4.0);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kRunning);  // 8 s (this operation began with nobody)
  motion_.StopBase();
  belief_.now = At(17.5);
  OperatedAgo(0.5);
  EXPECT_EQ(tree_.TickOnce(), NodeStatus::kFailure);  // 10.5 s
  EXPECT_TRUE(NotedText("nobody about"));
}

TEST_F(EscortNodesTest, IsNobodyComingFailsWhenSomeoneMovesNearTheDoorOnTheRobotsSide) {
  bt::Tree tree = Tree(R"(<IsNobodyComing door="lab_door"/>)");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  belief_.off_map_returns = {{-0.5, 1.5}};  // standing: not coming
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  belief_.moving_returns = {{0.3, 4.5}};  // walking, beyond the door
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  belief_.moving_returns = {{-0.5, 1.5}};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  belief_.moving_returns.clear();
  See({node_testing::Person({-1.0, 0.0}, perception::PersonIntent::kUnknown)});
  auto& person = belief_.world.people[0].person;
  // Tracked at walking pace, but where they stood: the tracker's wobble, not someone coming.
  person.v_MP = {0.2, 0.25};
  person.p_MRest = person.p_MP;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  person.v_MP = {0.5, 1.0};  // walking to the door, 0.45 m on from where they stood
  person.p_MRest = person.p_MP - Eigen::Vector2d(0.2, 0.4);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

}  // namespace
}  // namespace egress::behavior
