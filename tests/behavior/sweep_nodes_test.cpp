// The escort's sweep nodes (sweep_nodes.cpp) in a small ward: a corridor (x 0-12, y 0-2) with an
// exit door at its east end (x = 12) to the outside, room A north of it (x 1-5) and room D north
// of it (x 6-10), each with a push button on the corridor side of its door; room B south of the
// corridor (x 2-6) with a button only inside; room E north of room A (y 6-9), reached only
// through room A. PlanSweep, FeederApproachPose and WatchDoorway at the lab door for the watch.

#include <deque>
#include <memory>
#include <string>

#include "egress/planning/route_planner.h"
#include "task_node_fixture.h"

namespace egress::behavior::node_testing {
namespace {

using bt::NodeStatus;

// A door of the ward: its doorway from `hinge` to `latch`, the leaf opening into the corridor.
void AddDoor(MissionMap& map, const std::string& id, const Eigen::Vector2d& hinge,
             const Eigen::Vector2d& latch) {
  perception::Doorway doorway;
  doorway.id = id;
  doorway.p_MHinge = hinge;
  doorway.p_MLatch = latch;
  map.doorways.push_back(doorway);
  perception::DoorModel door;
  door.id = id;
  door.p_MHinge = hinge;
  door.p_MLatch = latch;
  map.doors.push_back(door);
}

void AddButton(MissionMap& map, const std::string& door, const Eigen::Vector3d& p_M,
               const Eigen::Vector3d& n_M) {
  MapActuator button;
  button.id = door + "_button_" + std::to_string(map.actuators.size());
  button.door = door;
  button.type = planning::ButtonType::kPushButton;
  button.p_M = p_M;
  button.n_M = n_M;
  button.protrusion = 0.02;
  map.actuators.push_back(button);
}

MissionMap Ward() {
  MissionMap map;
  const double t = 0.1;  // wall thickness
  std::vector<perception::Box2> walls{
      // Corridor south wall (y = 0) with room B's doorway x 3.5-4.5.
      {{1.75, 0.0, 0.0}, {3.5, t}},
      {{8.25, 0.0, 0.0}, {7.5, t}},
      // Corridor north wall (y = 2) with doorways x 2.5-3.5 (A) and x 7.5-8.5 (D).
      {{1.25, 2.0, 0.0}, {2.5, t}},
      {{5.5, 2.0, 0.0}, {4.0, t}},
      {{10.25, 2.0, 0.0}, {3.5, t}},
      // The west end, and the east end with the exit's doorway y 0.5-1.5.
      {{0.0, 4.5, 0.0}, {t, 9.0}},
      {{12.0, 0.0, 0.0}, {t, 1.0}},
      {{12.0, 2.0, 0.0}, {t, 1.0}},
      // Rooms A and D: side walls and their north walls (A's with room E's doorway x 2.5-3.5).
      {{5.5, 4.0, 0.0}, {t, 4.0}},
      {{10.0, 4.0, 0.0}, {t, 4.0}},
      {{1.25, 6.0, 0.0}, {2.5, t}},
      {{4.5, 6.0, 0.0}, {2.0, t}},
      {{7.75, 6.0, 0.0}, {4.5, t}},
      // Room E's walls.
      {{2.75, 9.0, 0.0}, {5.5, t}},
      {{5.5, 7.5, 0.0}, {t, 3.0}},
      // Room B's walls (y -4 to 0).
      {{2.0, -2.0, 0.0}, {t, 4.0}},
      {{6.0, -2.0, 0.0}, {t, 4.0}},
      {{4.0, -4.0, 0.0}, {4.0, t}},
      // The outside: a yard x 12-14 closed round.
      {{13.0, -0.5, 0.0}, {2.0, t}},
      {{13.0, 2.5, 0.0}, {2.0, t}},
      {{14.0, 1.0, 0.0}, {t, 3.0}},
  };
  map.grid = perception::OccupancyGrid::FromBoxes(walls, {-0.5, -4.5}, {14.5, 9.5}, 0.05);
  AddDoor(map, "door_a", {2.5, 2.0}, {3.5, 2.0});
  AddDoor(map, "door_d", {7.5, 2.0}, {8.5, 2.0});
  AddDoor(map, "door_b", {3.5, 0.0}, {4.5, 0.0});
  AddDoor(map, "door_e", {2.5, 6.0}, {3.5, 6.0});
  AddDoor(map, "exit_door", {12.0, 0.5}, {12.0, 1.5});
  AddButton(map, "door_a", {3.9, 1.93, 1.0}, {0.0, -1.0, 0.0});   // corridor side
  AddButton(map, "door_d", {8.9, 1.93, 1.0}, {0.0, -1.0, 0.0});   // corridor side
  AddButton(map, "door_b", {4.9, -0.07, 1.0}, {0.0, -1.0, 0.0});  // inside room B only
  AddButton(map, "door_e", {3.9, 5.93, 1.0}, {0.0, -1.0, 0.0});   // room A's side
  AddButton(map, "exit_door", {11.93, 1.9, 1.0}, {-1.0, 0.0, 0.0});
  return map;
}

class SweepNodesTest : public TaskNodeFixture {
 protected:
  SweepNodesTest() {
    map_ = Ward();
    belief_.X_MB = {11.0, 1.0, 0.0};  // before the exit door, facing it
    bb_ = bt::Blackboard::Create();
    bb_->Set("goal", std::string("13;1;0"));
  }
  // PlanRoute from where the robot is to the yard.
  void PlanTheRoute() {
    bt::Tree plan = Tree(
        R"(<PlanRoute goal="{goal}" doors="{route_doors}" route="{route}" destination="{d}"/>)",
        bb_);
    ASSERT_EQ(plan.TickOnce(), NodeStatus::kSuccess) << Notes();
  }
  std::string Notes() const {
    std::string all;
    for (const auto& note : log_.pending())
      all += note.text + "\n";
    return all;
  }
  bt::Blackboard::Ptr bb_;
};

TEST_F(SweepNodesTest, TheRoomsWhoseWayOutLeavesByTheLastDoorAreSweptFarthestFirst) {
  PlanTheRoute();
  bt::Tree sweep = Tree(
      R"(<PlanSweep door="exit_door" route="{route}" goal="{goal}" doors="{sweep_doors}"/>)", bb_);
  ASSERT_EQ(sweep.TickOnce(), NodeStatus::kSuccess) << Notes();
  const auto doors = bb_->Get<bt::SharedQueue<std::string>>("sweep_doors");
  ASSERT_TRUE(doors.has_value());
  // Room E (through room A), A, then D; not room B (no button on the corridor side).
  EXPECT_EQ(**doors, (std::deque<std::string>{"door_e", "door_a", "door_d"})) << Notes();
  EXPECT_NE(Notes().find("no actuator on this side of door_b"), std::string::npos) << Notes();

  // Each room once: the loop popped door_e and door_a and stopped (someone came out); door_d is
  // still to sweep.
  (*doors)->pop_front();
  (*doors)->pop_front();
  ASSERT_EQ(sweep.TickOnce(), NodeStatus::kSuccess) << Notes();
  EXPECT_EQ(**bb_->Get<bt::SharedQueue<std::string>>("sweep_doors"),
            (std::deque<std::string>{"door_d"}));
  (**bb_->Get<bt::SharedQueue<std::string>>("sweep_doors")).pop_front();
  EXPECT_EQ(sweep.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(Notes().find("nothing to sweep"), std::string::npos) << Notes();
}

TEST_F(SweepNodesTest, NoSweepAtAnyOtherDoorOrWhenItIsOff) {
  belief_.X_MB = {3.0, 4.0, -M_PI / 2};  // in room A
  PlanTheRoute();
  const auto route_doors = bb_->Get<bt::SharedQueue<std::string>>("route_doors");
  ASSERT_EQ(**route_doors, (std::deque<std::string>{"door_a", "exit_door"}));
  bt::Tree at_a = Tree(
      R"(<PlanSweep door="door_a" route="{route}" goal="{goal}" doors="{sweep_doors}"/>)", bb_);
  EXPECT_EQ(at_a.TickOnce(), NodeStatus::kFailure);
  bt::Tree off = Tree(
      R"(<PlanSweep door="exit_door" route="{route}" goal="{goal}" sweep="false"
                    doors="{sweep_doors}"/>)",
      bb_);
  EXPECT_EQ(off.TickOnce(), NodeStatus::kFailure);
  EXPECT_FALSE(bb_->Get<bt::SharedQueue<std::string>>("sweep_doors").has_value());
  // On at the last door: room A was on the route (escorted from), so D (farther from room A)
  // and E only.
  bt::Tree on = Tree(
      R"(<PlanSweep door="exit_door" route="{route}" goal="{goal}" doors="{sweep_doors}"/>)", bb_);
  ASSERT_EQ(on.TickOnce(), NodeStatus::kSuccess) << Notes();
  EXPECT_EQ(**bb_->Get<bt::SharedQueue<std::string>>("sweep_doors"),
            (std::deque<std::string>{"door_d", "door_e"}));
}

TEST_F(SweepNodesTest, TheRobotWaitsBeforeASweptDoorOnTheRouteSide) {
  PlanTheRoute();
  bt::Tree approach = Tree(
      R"(<FeederApproachPose door="door_a" route="{route}" goal="{goal}" pose="{pose}"/>)", bb_);
  ASSERT_EQ(approach.TickOnce(), NodeStatus::kSuccess) << Notes();
  const Pose2 pose = ParsePose2(*bb_->Get<std::string>("pose"));
  EXPECT_LT(pose.y, 2.0 - 0.24);  // in the corridor, before door_a
  EXPECT_GT(pose.y, 0.24);
  EXPECT_NEAR(pose.x, 3.0, 0.6);
  EXPECT_GT(std::sin(pose.yaw), 0.7);  // facing north, at the door
  bt::Tree unknown = Tree(
      R"(<FeederApproachPose door="door_z" route="{route}" goal="{goal}" pose="{pose}"/>)", bb_);
  EXPECT_EQ(unknown.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(Notes().find("no door 'door_z'"), std::string::npos) << Notes();
}

class WatchDoorwayTest : public TaskNodeFixture {
 protected:
  WatchDoorwayTest() {
    belief_.now = At(1.0);
    bb_ = bt::Blackboard::Create();
  }
  bt::Blackboard::Ptr bb_;
};

TEST_F(WatchDoorwayTest, NobodyComingEndsTheWatchAfterWaitFor) {
  bt::Tree watch = Tree(R"(<WatchDoorway door="lab_door" wait_for="4" came="{came}"/>)", bb_);
  for (double t = 1.0; t < 5.0 - 1e-9; t += 0.1) {
    belief_.now = At(t);
    ASSERT_EQ(watch.TickOnce(), NodeStatus::kRunning) << t;
  }
  belief_.now = At(5.0);
  EXPECT_EQ(watch.TickOnce(), NodeStatus::kSuccess);
  EXPECT_FALSE(*bb_->Get<bool>("came"));
}

TEST_F(WatchDoorwayTest, SomeoneComingThroughIsWatchedUntilClearFor) {
  bt::Tree watch =
      Tree(R"(<WatchDoorway door="lab_door" wait_for="4" clear_for="3" came="{came}"/>)", bb_);
  EXPECT_EQ(watch.TickOnce(), NodeStatus::kRunning);
  // Someone comes through from the room beyond (y > 3) from 2 s to 8 s, past wait_for.
  for (double t = 2.0; t <= 8.0 + 1e-9; t += 0.1) {
    belief_.now = At(t);
    See({Person({0.0, 4.5 - (t - 2.0) * 0.5}, perception::PersonIntent::kCrossing)});
    ASSERT_EQ(watch.TickOnce(), NodeStatus::kRunning) << t;
  }
  See({});
  for (double t = 8.1; t < 11.0 - 1e-9; t += 0.1) {
    belief_.now = At(t);
    ASSERT_EQ(watch.TickOnce(), NodeStatus::kRunning) << t;
  }
  belief_.now = At(11.0);
  EXPECT_EQ(watch.TickOnce(), NodeStatus::kSuccess);
  EXPECT_TRUE(*bb_->Get<bool>("came"));
}

TEST_F(WatchDoorwayTest, BadParametersFailWithANote) {
  bt::Tree negative = Tree(R"(<WatchDoorway door="lab_door" clear_for="-1" came="{came}"/>)", bb_);
  EXPECT_EQ(negative.TickOnce(), NodeStatus::kFailure);
  bt::Tree unknown = Tree(R"(<WatchDoorway door="door_z" came="{came}"/>)", bb_);
  EXPECT_EQ(unknown.TickOnce(), NodeStatus::kFailure);
  bool noted = false;
  for (const auto& note : log_.pending())
    noted = noted || note.text.find("unknown door 'door_z'") != std::string::npos;
  EXPECT_TRUE(noted);
}

}  // namespace
}  // namespace egress::behavior::node_testing
