// The release's leaves (behavior/src/release_nodes.cpp), ticked in one-node trees.

#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;
using node_testing::Person;

class ReleaseNodesTest : public node_testing::TaskNodeFixture {
 protected:
  ReleaseNodesTest() {
    belief_.X_MB = {0.0, 1.0, M_PI / 2};
    belief_.now = At(1.0);
    belief_.holding_object = true;
  }
  // Ticks `xml` once on blackboard_ (the tree goes: a running node is halted).
  NodeStatus TickOnce(const std::string& xml) { return Tree(xml, blackboard_).TickOnce(); }
  std::optional<ReleasePlan> Plan() const { return blackboard_->Get<ReleasePlan>("release"); }
  bool LastNoteSays(const std::string& text) const {
    return !log_.pending().empty() && log_.pending().back().text.find(text) != std::string::npos;
  }
  bt::Blackboard::Ptr blackboard_ = bt::Blackboard::Create();
};

TEST_F(ReleaseNodesTest, PlanningNeedsSomethingInTheHand) {
  belief_.holding_object = false;
  EXPECT_EQ(TickOnce(R"(<PlanPlacement pose="0.0;2.5;0.8"/>)"), NodeStatus::kFailure);
  EXPECT_TRUE(LastNoteSays("not holding a payload"));
  EXPECT_EQ(TickOnce(R"(<PlanHandOver pose="0.0;2.5"/>)"), NodeStatus::kFailure);
  EXPECT_FALSE(Plan());
}

TEST_F(ReleaseNodesTest, PlanPlacementPutsTheCentreAtThePoseApproachedLevel) {
  ASSERT_EQ(TickOnce(R"(<PlanPlacement pose="0.0;2.5;0.8"/>)"), NodeStatus::kSuccess);
  const auto plan = Plan();
  ASSERT_TRUE(plan);
  EXPECT_LT((plan->p_MC - Eigen::Vector3d(0.0, 2.5, 0.8)).norm(), 1e-9);
  EXPECT_LT((plan->approach_M - Eigen::Vector3d::UnitY()).norm(), 1e-9);
}

TEST_F(ReleaseNodesTest, PlanHandOverHoldsItOutTowardTheNearestResponder) {
  EXPECT_EQ(TickOnce(R"(<PlanHandOver pose="0.0;3.0"/>)"), NodeStatus::kFailure);
  EXPECT_TRUE(LastNoteSays("no responder in sight"));
  See({Person({0.2, 3.0}, perception::PersonIntent::kStationary),
       Person({2.5, 3.0}, perception::PersonIntent::kStationary)});
  ASSERT_EQ(TickOnce(R"(<PlanHandOver pose="0.0;3.0" hand_height="0.95"/>)"), NodeStatus::kSuccess);
  const auto plan = Plan();
  ASSERT_TRUE(plan);
  // 0.3 m from the nearer person, on the robot's side, at hand height.
  EXPECT_NEAR((plan->p_MC.head<2>() - Eigen::Vector2d(0.2, 3.0)).norm(), 0.3, 1e-9);
  EXPECT_LT(plan->p_MC.y(), 3.0);
  EXPECT_NEAR(plan->p_MC.z(), 0.95, 1e-9);
}

TEST_F(ReleaseNodesTest, ALeafWithoutAPlanFailsSayingSo) {
  for (const char* leaf : {"DriveToRelease", "ReachToRelease", "WithdrawArm"}) {
    EXPECT_EQ(TickOnce(std::string("<") + leaf + "/>"), NodeStatus::kFailure) << leaf;
    EXPECT_TRUE(LastNoteSays("no release planned")) << leaf;
  }
}

TEST_F(ReleaseNodesTest, DriveThenReachCarryThePayloadToTheReleasePoint) {
  ASSERT_EQ(TickOnce(R"(<PlanPlacement pose="0.0;2.6;0.8"/>)"), NodeStatus::kSuccess);
  bt::Tree drive = Tree("<DriveToRelease/>", blackboard_);  // alive: a halt stops the base
  EXPECT_EQ(drive.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2 stop = motion_.path().back();
  // From too far the arm does not reach (a retry drives again) ...
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  EXPECT_EQ(TickOnce("<ReachToRelease/>"), NodeStatus::kFailure);
  EXPECT_TRUE(LastNoteSays("out of the arm's reach"));
  // ... from where the drive ends it does, and the palm ends at the release point.
  belief_.X_MB = stop;
  bt::Tree reach = Tree("<ReachToRelease/>", blackboard_);
  EXPECT_EQ(reach.TickOnce(), NodeStatus::kRunning);
  const auto plan = Plan();
  ASSERT_TRUE(plan);
  WholeBodyVector q = WholeBodyVector::Zero();
  q[kBaseX] = stop.x;
  q[kBaseY] = stop.y;
  q[kBaseYaw] = stop.yaw;
  const Pose3 X_MG = model_.CalcPalmPose(WithArm(q, motion_.arm_target()));
  EXPECT_LT((X_MG.translation() + plan->approach_M * 0.07 - plan->p_MC).norm(), 0.01);
  // The withdrawal passes through the pre-release posture, short of and above the point.
  const Pose3 X_MPre = model_.CalcPalmPose(WithArm(q, plan->pre_arm));
  EXPECT_LT(X_MPre.translation().y(), X_MG.translation().y() - 0.05);
  EXPECT_GT(X_MPre.translation().z(), X_MG.translation().z() + 0.02);
}

// The responder's own returns, inflated, can cover the base's pose for the offer point: the
// point comes back towards the robot until the pose is free. A placement's point does not move.
TEST_F(ReleaseNodesTest, AHandOverHoldsItOutNearerWhenTheBasePoseForItIsNotFree) {
  See({Person({0.0, 3.0}, perception::PersonIntent::kStationary)});
  ASSERT_EQ(TickOnce(R"(<PlanHandOver pose="0.0;3.0"/>)"), NodeStatus::kSuccess);
  const Eigen::Vector3d offered = Plan()->p_MC;
  Pose2 free_stop;
  {
    bt::Tree drive = Tree("<DriveToRelease/>", blackboard_);  // a halt clears the path
    ASSERT_EQ(drive.TickOnce(), NodeStatus::kRunning);
    free_stop = motion_.path().back();
  }
  // Something 0.15 m ahead of that pose: the base there would touch it.
  costmap_.SetProjectedObstacles({free_stop.translation() + Eigen::Vector2d(0.0, 0.15)});
  ASSERT_FALSE(planner_.IsValid(free_stop));
  ASSERT_EQ(TickOnce(R"(<PlanHandOver pose="0.0;3.0"/>)"), NodeStatus::kSuccess);
  {
    bt::Tree drive = Tree("<DriveToRelease/>", blackboard_);
    ASSERT_EQ(drive.TickOnce(), NodeStatus::kRunning);
    ASSERT_FALSE(motion_.path().empty());
    EXPECT_TRUE(planner_.IsValid(motion_.path().back()));
  }
  const Eigen::Vector3d nearer = Plan()->p_MC;
  EXPECT_LT(nearer.y(), offered.y() - 0.04);
  EXPECT_LE(offered.y() - nearer.y(), 0.3 + 1e-9);
  EXPECT_TRUE(NotedText("cm nearer the robot"));
  // A placement at the first offer point keeps its point: the drive fails, saying why.
  ASSERT_EQ(TickOnce(StrCat(R"(<PlanPlacement pose=")", offered.x(), ";", offered.y(), ";",
                            offered.z(), R"("/>)")),
            NodeStatus::kSuccess);
  const Eigen::Vector3d placed = Plan()->p_MC;
  bt::Tree drive = Tree("<DriveToRelease/>", blackboard_);
  EXPECT_EQ(drive.TickOnce(), NodeStatus::kFailure);
  EXPECT_EQ(Plan()->p_MC, placed);
  EXPECT_TRUE(NotedText("in collision"));
}

TEST_F(ReleaseNodesTest, WaitForRecipientLetsGoWhenTheyStandWithinReach) {
  ASSERT_EQ(TickOnce(R"(<PlanPlacement pose="0.0;2.5;0.9"/>)"), NodeStatus::kSuccess);
  See({Person({0.0, 4.0}, perception::PersonIntent::kStationary)});
  bt::Tree tree = Tree(R"(<WaitForRecipient pose="0.0;4.0" timeout="5.0"/>)", blackboard_);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);  // 1.5 m from the payload
  belief_.now = At(3.0);
  See({Person({0.0, 3.1}, perception::PersonIntent::kStationary)});
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_TRUE(Noted(DecisionEvent::kResponderInReach));

  bt::Tree nobody = Tree(R"(<WaitForRecipient pose="0.0;4.0" timeout="5.0"/>)", blackboard_);
  See({});
  EXPECT_EQ(nobody.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(8.5);
  EXPECT_EQ(nobody.TickOnce(), NodeStatus::kFailure);
  EXPECT_TRUE(LastNoteSays("nobody took the payload"));
}

TEST_F(ReleaseNodesTest, OpenGripperOpensAndWaitsForTheFingers) {
  bt::Tree tree = Tree("<OpenGripper/>");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  const auto gripper = motion_.TakeGripperCommand();
  ASSERT_TRUE(gripper);
  EXPECT_EQ(gripper->mode, GripperCommand::Mode::kOpen);
  belief_.gripper_at_rest = true;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(ReleaseNodesTest, WithdrawArmTucksAndSucceedsOnlyWithAnEmptyGripper) {
  ASSERT_EQ(TickOnce(R"(<PlanPlacement pose="0.0;2.5;0.8"/>)"), NodeStatus::kSuccess);
  for (const bool holding : {true, false}) {
    belief_.now = At(1.0);
    bt::Tree tree = Tree("<WithdrawArm/>", blackboard_);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
    for (std::size_t i = 0; i < motion_.arm_target().size(); ++i)
      EXPECT_NEAR(motion_.arm_target()[i], TuckedArm(model_)[i], 1e-9);
    belief_.now = At(30.0);  // long after the motion's end (no joint measurements here)
    belief_.holding_object = holding;
    EXPECT_EQ(tree.TickOnce(), holding ? NodeStatus::kFailure : NodeStatus::kSuccess);
    EXPECT_TRUE(LastNoteSays(holding ? "still in the gripper" : "let go of the payload"));
  }
}

}  // namespace
}  // namespace egress::behavior
