// The condition nodes (behavior/src/condition_nodes.cpp), ticked as a tree ticks them: one
// node per tree, built by the factory from XML, on task services and a belief set up by hand.

#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;

using node_testing::At;
using node_testing::Person;
using ConditionNodesTest = node_testing::TaskNodeFixture;

TEST_F(ConditionNodesTest, IsPathClearFailsWhileAPersonIsInTheZoneAndHoldsOffAfterward) {
  bt::Tree tree = Tree(R"(<IsPathClear door="lab_door" clear_for="1.0"/>)");
  belief_.now = At(10.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_TRUE(log_.pending().empty());

  // Someone stands in the doorway: FAILURE, and the decision is a typed event.
  belief_.now = At(10.1);
  See({Person({0.0, 3.3}, perception::PersonIntent::kStationary)});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  ASSERT_EQ(log_.pending().size(), 1u);
  EXPECT_EQ(log_.pending().back().event, DecisionEvent::kPersonInDoorZone);
  // Still there: no second event for the same occupation.
  belief_.now = At(10.2);
  See(belief_.world.people);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  EXPECT_EQ(log_.pending().size(), 1u);

  // Gone: still FAILURE for the hysteresis (1 s since last seen), then SUCCESS and the event.
  belief_.now = At(10.3);
  See({});
  belief_.now = At(10.8);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  belief_.now = At(11.3);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  ASSERT_EQ(log_.pending().size(), 2u);
  EXPECT_EQ(log_.pending().back().event, DecisionEvent::kDoorZoneClear);
}

TEST_F(ConditionNodesTest, IsPathClearTimesTheHysteresisFromTheBeliefNotFromItsOwnTicks) {
  // The zone was last occupied while the condition was not being ticked (a retreat under way):
  // the belief has it, and the hysteresis runs from then.
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<IsPathClear door="lab_door" clear_for="1.0"/>)", blackboard);
  belief_.now = At(5.0);
  See({Person({0.0, 3.3}, perception::PersonIntent::kStationary)});
  belief_.now = At(5.5);
  See({});
  belief_.now = At(5.8);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);  // 0.8 s since last seen occupied
  belief_.now = At(6.1);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);  // 1.1 s
  // A retreat under way (RetractToSafe's entry on the blackboard): FAILURE until it ends.
  blackboard->Set("retreating", bt::Any(true));
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  blackboard->Set("retreating", bt::Any(false));
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(ConditionNodesTest, IsPathClearSeesAPersonWalkingIntoTheZone) {
  bt::Tree tree = Tree(R"(<IsPathClear door="lab_door"/>)");
  auto walking_in = Person({0.0, 5.0}, perception::PersonIntent::kApproaching);
  belief_.world.people = {walking_in};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);  // far, and no forecast into the zone
  walking_in.person.forecast = {{0.0, 4.6}, {0.0, 4.2}};
  belief_.world.people = {walking_in};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ConditionNodesTest, IsDoorOpenNeedsTheClearanceAndTimeLeftInTheWindow) {
  bt::Tree tree = Tree(R"(<IsDoorOpen door="lab_door" margin="0.1"/>)");
  belief_.now = At(50.0);
  // Not seen: not open.
  perception::TrackedDoor unseen;
  unseen.model = map_.doors[0];
  belief_.world.doors = {unseen};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  // Ajar at 20°: too narrow for the base.
  DoorSeenOpen(20.0, 1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  // Wide open, held (no press of ours) for 1 s: go.
  DoorSeenOpen(85.0, 1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  // Closing: never.
  belief_.world.doors[0].state.motion = perception::DoorMotion::kClosing;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ConditionNodesTest, AWindowRestartedByAPressIsTimedFromThePressNotFromFirstSight) {
  // The robot pressed the open door 6 s ago (restarting its hold window) but, beside the
  // actuator, saw the leaf open only 1 s ago: 6 s of the window are gone, and the 5.8 s drive
  // clear of the leaf does not fit in the 4 left.
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<IsDoorOpen door="lab_door" margin="0.1"/>)", blackboard);
  belief_.now = At(50.0);
  DoorSeenOpen(85.0, 1.0);
  DoorVisit visit;
  visit.door = "lab_door";
  visit.operated_at = At(44.0);
  blackboard->Set("door_visit", bt::Any(visit));
  // Without the restart the same press is read as the door's own opening (at the earliest 3 s
  // after it): passable.
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  visit.window_restarted_at = visit.operated_at;
  blackboard->Set("door_visit", bt::Any(visit));
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ConditionNodesTest, IsPersonHoldingDoorWantsAStillHolderBesideAnOpenLeaf) {
  bt::Tree tree = Tree(R"(<IsPersonHoldingDoor door="lab_door"/>)");
  belief_.now = At(50.0);
  DoorSeenOpen(85.0, 1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);  // nobody there
  // Standing still beside the hinge jamb on the far side, out of the lane: holding it.
  belief_.world.people = {Person({0.55, 3.45}, perception::PersonIntent::kHoldingDoor)};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  // The same person in the middle of the doorway holds nothing for the robot.
  belief_.world.people = {Person({0.0, 3.1}, perception::PersonIntent::kHoldingDoor)};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ConditionNodesTest, IsThroughDoorOnlyPastTheLineOutOfTheSweepAndEndsTheVisit) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<IsThroughDoor door="lab_door"/>)", blackboard);
  // No visit yet (the robot has not approached this door): not through, wherever it stands.
  belief_.X_MB = {0.0, 4.6, M_PI / 2};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  DoorVisit visit;
  visit.door = "lab_door";
  visit.approach_side = Eigen::Vector2d(0.0, -1.0);  // came from the south
  const auto with_visit = [&] { blackboard->Set("door_visit", bt::Any(visit)); };
  // Before the line; in the doorway; past the line but where the leaf (opening north) sweeps;
  // far beside the opening: not through.
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.0, 2.0), Eigen::Vector2d(0.0, 3.2),
                                   Eigen::Vector2d(0.0, 3.7), Eigen::Vector2d(3.0, 3.7)}) {
    with_visit();
    belief_.X_MB = {p.x(), p.y(), M_PI / 2};
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure) << p.transpose();
  }
  // Past the sweep in front of the opening: through, and the visit's side is forgotten (a later
  // traversal may come back the other way).
  with_visit();
  belief_.X_MB = {0.0, 4.6, M_PI / 2};
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  ASSERT_TRUE(blackboard->Get<DoorVisit>("door_visit").has_value());
  EXPECT_FALSE(blackboard->Get<DoorVisit>("door_visit")->approach_side.has_value());
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  // Coming from the north, the same spot is before the door.
  visit.approach_side = Eigen::Vector2d(0.0, 1.0);
  with_visit();
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ConditionNodesTest, IsHoldingPayloadReadsTheGripsBelief) {
  bt::Tree tree = Tree(R"(<IsHoldingPayload payload="bottle"/>)");
  belief_.holding_object = false;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  belief_.holding_object = true;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(ConditionNodesTest, AnUnknownDoorIsAClearError) {
  bt::Tree tree = Tree(R"(<IsPathClear door="door_z"/>)");
  EXPECT_THROW(tree.TickOnce(), InvalidArgument);
  // A visit to a door the map does not have (a mistyped id in a tree) is an error too, not a
  // crash.
  auto blackboard = bt::Blackboard::Create();
  DoorVisit visit;
  visit.door = "door_z";
  visit.approach_side = Eigen::Vector2d(0.0, -1.0);
  blackboard->Set("door_visit", bt::Any(visit));
  bt::Tree through = Tree(R"(<IsThroughDoor door="door_z"/>)", blackboard);
  EXPECT_THROW(through.TickOnce(), InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
