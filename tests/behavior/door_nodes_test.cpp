// The door nodes (behavior/src/door_nodes.cpp), ticked in one-node trees.

#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;
using DoorNodesTest = node_testing::TaskNodeFixture;

TEST_F(DoorNodesTest, ButtonTypeWritesTheActuatorKindOfThisSide) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<ButtonType door="lab_door" type="{kind}"/>)", blackboard);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(blackboard->Get<std::string>("kind"), "push_button");
  // From the far side there is no actuator.
  belief_.X_MB = {0.0, 4.0, -M_PI / 2};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(DoorNodesTest, ApproachButtonDrivesToAStandoffFacingTheButton) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<ApproachButton door="lab_door"/>)", blackboard);
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  // The plan travels to PressButton on the blackboard, in the door's visit, with the side the
  // robot came from (south: -y).
  const auto visit = blackboard->Get<DoorVisit>("door_visit");
  ASSERT_TRUE(visit.has_value());
  EXPECT_EQ(visit->door, "lab_door");
  ASSERT_TRUE(visit->approach_side.has_value());
  EXPECT_NEAR(visit->approach_side->y(), -1.0, 1e-9);
  ASSERT_TRUE(visit->button_plan.has_value());
  const ButtonPlan& plan = *visit->button_plan;
  EXPECT_EQ(plan.actuator, "lab_button");
  // In front of the button (south of its wall), facing it (+y), within the arm's reach.
  EXPECT_NEAR(plan.X_MB_standoff.yaw, M_PI / 2, 1e-6);
  const double standoff = 2.93 - plan.X_MB_standoff.y;
  EXPECT_GT(standoff, 0.3);
  EXPECT_LT(standoff, 0.8);
  EXPECT_NEAR(plan.X_MB_standoff.x, 1.075, 0.25);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - plan.X_MB_standoff.translation()).norm(), 1e-6);
  EXPECT_TRUE(motion_.base_moving());
}

TEST_F(DoorNodesTest, PressButtonNeedsTheApproachFirst) {
  bt::Tree tree = Tree(R"(<PressButton door="lab_door"/>)");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(log_.pending().back().text.find("ApproachButton must run first"), std::string::npos);
}

TEST_F(DoorNodesTest, APressRecordsWhenTheHandReachesTheButtonAndForgetsAnEarlierRestart) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree approach = Tree(R"(<ApproachButton door="lab_door"/>)", blackboard);
  belief_.now = At(1.0);
  ASSERT_EQ(approach.TickOnce(), NodeStatus::kRunning);
  DoorVisit visit = *blackboard->Get<DoorVisit>("door_visit");
  ASSERT_TRUE(visit.button_plan.has_value());
  // An earlier press found the door open and restarted its window; this one starts afresh.
  visit.window_restarted_at = At(0.5);
  blackboard->Set("door_visit", bt::Any(visit));
  belief_.X_MB = visit.button_plan->X_MB_standoff;  // standing at the standoff
  belief_.now = At(20.0);
  bt::Tree press = factory_.CreateTreeFromText(
      R"(<root BTCPP_format="4"><BehaviorTree ID="press"><PressButton door="lab_door"/></BehaviorTree></root>)",
      "press", blackboard);
  EXPECT_EQ(press.TickOnce(), NodeStatus::kRunning);
  EXPECT_TRUE(motion_.arm_moving(belief_.now));
  const DoorVisit after = *blackboard->Get<DoorVisit>("door_visit");
  ASSERT_TRUE(after.operated_at.has_value());
  // The hand reaches the button press_reach_time after the press starts.
  EXPECT_NEAR(ToSeconds(*after.operated_at - At(20.0)), services_.config.press_reach_time, 1e-9);
  EXPECT_FALSE(after.window_restarted_at.has_value());
  EXPECT_TRUE(after.button_plan.has_value());  // the plan stays with the visit
}

TEST_F(DoorNodesTest, TraverseDoorLinesUpOnTheDoorsAxisBeforeGoing) {
  bt::Tree tree = Tree(R"(<TraverseDoor door="lab_door"/>)");
  belief_.X_MB = {1.0, 2.2, M_PI / 2};  // beside the axis, before the door
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  // The line-up pose is on the door's axis (x = 0), before the door line, facing through it.
  const Pose2& entry = motion_.path().back();
  EXPECT_NEAR(entry.x, 0.0, 1e-6);
  EXPECT_LT(entry.y, 3.0);
  EXPECT_NEAR(entry.yaw, M_PI / 2, 1e-6);
}

}  // namespace
}  // namespace egress::behavior
