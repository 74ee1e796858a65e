// The route nodes (route_nodes.cpp) on the lab: a wall across y = 3 with the lab door's 1 m
// doorway, places south and north of it.

#include <deque>
#include <memory>

#include "egress/planning/route_planner.h"
#include "task_node_fixture.h"

namespace egress::behavior::node_testing {
namespace {

using bt::NodeStatus;

class RouteNodesTest : public TaskNodeFixture {
 protected:
  RouteNodesTest() {
    map_.grid = perception::OccupancyGrid::FromBoxes(
        {{{-1.75, 3.0, 0.0}, {2.5, 0.1}}, {{1.75, 3.0, 0.0}, {2.5, 0.1}}}, {-3.0, -1.0}, {3.0, 7.0},
        0.05);
    map_.doorways[0].swing_sign = map_.doors[0].swing_sign;  // opens north, away from the start
    map_.places.push_back({"south", "room", {0.0, 1.0, M_PI / 2}, true});
    map_.places.push_back({"north", "room", {0.0, 5.0, 0.0}, false});
    belief_.X_MB = {0.0, 0.5, M_PI / 2};
  }
  std::string Notes() const {
    std::string all;
    for (const auto& note : log_.pending())
      all += note.text + "\n";
    return all;
  }
};

TEST_F(RouteNodesTest, PlanRouteFindsTheDoorAndWhereToWaitBeforeIt) {
  auto bb = bt::Blackboard::Create();
  bb->Set("goal", std::string("north"));
  bt::Tree tree = Tree(
      R"(<Sequence><PlanRoute goal="{goal}" doors="{doors}" route="{route}" destination="{dest}"/>
         <DoorApproachPose door="lab_door" route="{route}" pose="{approach}"/></Sequence>)",
      bb);
  ASSERT_EQ(tree.TickOnce(), NodeStatus::kSuccess) << Notes();
  const auto doors = bb->Get<bt::SharedQueue<std::string>>("doors");
  ASSERT_TRUE(doors.has_value());
  EXPECT_EQ(**doors, (std::deque<std::string>{"lab_door"}));
  const Pose2 approach = ParsePose2(*bb->Get<std::string>("approach"));
  EXPECT_NEAR(approach.x, 0.0, 1e-9);
  EXPECT_NEAR(approach.y, 1.8, 1e-9);  // 1.2 m before a leaf that opens away
  EXPECT_NEAR(approach.yaw, M_PI / 2, 1e-9);
  // "north" has no heading: reached facing the way from the start.
  const Pose2 dest = ParsePose2(*bb->Get<std::string>("dest"));
  EXPECT_NEAR(dest.y, 5.0, 1e-12);
  EXPECT_NEAR(dest.yaw, M_PI / 2, 1e-9);
}

TEST_F(RouteNodesTest, NoRouteFailsWithTheReason) {
  auto bb = bt::Blackboard::Create();
  bb->Set("goal", std::string("attic"));
  bt::Tree unknown =
      Tree(R"(<PlanRoute goal="{goal}" doors="{d}" route="{r}" destination="{x}"/>)", bb);
  EXPECT_EQ(unknown.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(Notes().find("goal 'attic' is neither a pose"), std::string::npos) << Notes();
  EXPECT_NE(Notes().find("places: south, north"), std::string::npos);
  bb->Set("goal", std::string("0;5;0"));
  bb->Set("blocked", std::string("lab_door"));
  bt::Tree avoided = Tree(
      R"(<PlanRoute goal="{goal}" avoid="{blocked}" doors="{d}" route="{r}" destination="{x}"/>)",
      bb);
  EXPECT_EQ(avoided.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(Notes().find("avoiding door(s) lab_door"), std::string::npos) << Notes();
}

TEST_F(RouteNodesTest, IsBeforeDoorOnlyInFrontAndNear) {
  auto bb = bt::Blackboard::Create();
  bb->Set("goal", std::string("north"));
  bt::Tree plan =
      Tree(R"(<PlanRoute goal="{goal}" doors="{d}" route="{route}" destination="{x}"/>)", bb);
  ASSERT_EQ(plan.TickOnce(), NodeStatus::kSuccess);
  bt::Tree before = Tree(R"(<IsBeforeDoor door="lab_door" route="{route}"/>)", bb);
  belief_.X_MB = {0.2, 1.5, M_PI / 2};
  EXPECT_EQ(before.TickOnce(), NodeStatus::kSuccess);
  belief_.X_MB = {-2.5, -0.5, 0.0};  // 4.3 m away
  EXPECT_EQ(before.TickOnce(), NodeStatus::kFailure);
  belief_.X_MB = {0.0, 4.0, 0.0};  // beyond the door
  EXPECT_EQ(before.TickOnce(), NodeStatus::kFailure);
}

TEST_F(RouteNodesTest, MarkDoorBlockedAddsToTheList) {
  auto bb = bt::Blackboard::Create();
  bb->Set("blocked", std::string("door_x"));
  bt::Tree mark = Tree(R"(<MarkDoorBlocked door="lab_door" blocked="{blocked}"/>)", bb);
  EXPECT_EQ(mark.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(*bb->Get<std::string>("blocked"), "door_x;lab_door");
}

}  // namespace
}  // namespace egress::behavior::node_testing
