// The grasp's leaves (behavior/src/grasp_nodes.cpp), ticked in one-node trees.

#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;

class GraspNodesTest : public node_testing::TaskNodeFixture {
 protected:
  // PlanGrasp's plan for a payload seen at `pose`, on blackboard_ (nullopt if it failed).
  std::optional<GraspPlan> PlanFor(const std::string& pose, const std::string& kind = "bottle") {
    bt::Tree tree = Tree("<PlanGrasp pose=\"" + pose + "\" kind=\"" + kind + "\"/>", blackboard_);
    if (tree.TickOnce() != NodeStatus::kSuccess) return std::nullopt;
    return blackboard_->Get<GraspPlan>("grasp");
  }
  bt::Blackboard::Ptr blackboard_ = bt::Blackboard::Create();
};

TEST_F(GraspNodesTest, PlanGraspRefusesWhatNoPostureReaches) {
  EXPECT_FALSE(PlanFor("0.5;2.5;2.6"));  // 2.6 m up
  EXPECT_NE(log_.pending().back().text.find("no whole-body reach"), std::string::npos);
  EXPECT_FALSE(blackboard_->Has("grasp"));
}

TEST_F(GraspNodesTest, PlanGraspPutsTheBaseWhereTheHandReachesItLevel) {
  belief_.X_MB = {0.0, 2.0, M_PI / 2};
  const auto plan = PlanFor("0.0;3.8;0.8");
  ASSERT_TRUE(plan);
  // Closer, facing the bottle, but not on top of it; the palm comes in level from the robot.
  const double d = (Eigen::Vector2d(0.0, 3.8) - plan->X_MB.translation()).norm();
  EXPECT_GT(d, 0.3);
  EXPECT_LT(d, 0.9);
  EXPECT_NEAR(plan->approach_M.z(), 0.0, 1e-9);
  EXPECT_GT(plan->approach_M.y(), 0.99);
  // The camera saw the near side: the centre is a radius further, at the seen height.
  EXPECT_GT(plan->p_MC.y(), 3.8);
  EXPECT_NEAR(plan->p_MC.z(), 0.8, 1e-9);
  EXPECT_NEAR(plan->surface_z, 0.8 - 0.105, 1e-9);  // an upright bottle's centre height
}

TEST_F(GraspNodesTest, PlanGraspTakesALowLyingPayloadFromAbove) {
  belief_.X_MB = {0.0, 2.0, M_PI / 2};
  const auto plan = PlanFor("0.0;3.0;0.76", "flashlight");  // 2 cm above its table
  ASSERT_TRUE(plan);
  EXPECT_LT(plan->approach_M.z(), -0.99);
  EXPECT_NE(log_.pending().back().text.find("from above"), std::string::npos);
}

TEST_F(GraspNodesTest, ALeafWithoutAPlanFailsSayingSo) {
  for (const char* leaf : {"DriveToGrasp", "ReachForPayload", "LiftPayload"}) {
    bt::Tree tree = Tree(std::string("<") + leaf + "/>");
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure) << leaf;
    EXPECT_NE(log_.pending().back().text.find("no grasp planned"), std::string::npos) << leaf;
  }
}

TEST_F(GraspNodesTest, DriveToGraspOpensTheGripperAndDrivesToThePlannedPose) {
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  belief_.now = At(1.0);
  const auto plan = PlanFor("0.0;3.8;0.8");
  ASSERT_TRUE(plan);
  bt::Tree tree = Tree("<DriveToGrasp/>", blackboard_);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  EXPECT_LT((motion_.path().back().translation() - plan->X_MB.translation()).norm(), 1e-6);
  const auto gripper = motion_.TakeGripperCommand();
  ASSERT_TRUE(gripper);
  EXPECT_EQ(gripper->mode, GripperCommand::Mode::kOpen);
}

TEST_F(GraspNodesTest, TheDriveAndTheReachKeepThePayloadInTheCamerasView) {
  HeadGaze gaze;
  services_.gaze = &gaze;
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  belief_.X_MC = Pose3(Eigen::Vector3d(0.0, 1.0, 1.0));
  belief_.now = At(1.0);
  const auto plan = PlanFor("0.0;3.8;0.8");
  ASSERT_TRUE(plan);
  bt::Tree drive = Tree("<DriveToGrasp/>", blackboard_);
  EXPECT_EQ(drive.TickOnce(), NodeStatus::kRunning);
  auto look = gaze.Update(belief_, 0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze.reason(), GazeReason::kTask);
  EXPECT_NEAR(look->pan, 0.0, 0.05);  // ahead, where the payload is
  EXPECT_LT(look->tilt, 0.0);         // below the camera
  // At the grasp pose, close to it, the reach looks further down.
  belief_.X_MB = plan->X_MB;
  belief_.X_MC =
      Pose3(Eigen::Vector3d(plan->X_MB.translation().x(), plan->X_MB.translation().y(), 1.0));
  bt::Tree reach = Tree("<ReachForPayload/>", blackboard_);
  belief_.now = At(2.0);
  EXPECT_EQ(reach.TickOnce(), NodeStatus::kRunning);
  const auto closer = gaze.Update(belief_, 0.0);
  ASSERT_TRUE(closer.has_value());
  EXPECT_EQ(gaze.reason(), GazeReason::kTask);
  EXPECT_LT(closer->tilt, look->tilt);
}

TEST_F(GraspNodesTest, ReachForPayloadSwingsTheArmToTheGraspAndRecordsIt) {
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  belief_.now = At(1.0);
  auto plan = PlanFor("0.0;3.8;0.8");
  ASSERT_TRUE(plan);
  belief_.X_MB = plan->X_MB;  // the base arrived
  bt::Tree tree = Tree("<ReachForPayload/>", blackboard_);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  const auto reached = blackboard_->Get<GraspPlan>("grasp");
  ASSERT_TRUE(reached);
  // The arm goes where the plan's arm-only solve put it, and the palm holds the grasp centre.
  for (std::size_t i = 0; i < reached->arm.size(); ++i)
    EXPECT_NEAR(motion_.arm_target()[i], reached->arm[i], 1e-9) << i;
  WholeBodyVector q = WholeBodyVector::Zero();
  q[kBaseX] = plan->X_MB.x;
  q[kBaseY] = plan->X_MB.y;
  q[kBaseYaw] = plan->X_MB.yaw;
  const Pose3 X_MG = model_.CalcPalmPose(WithArm(q, reached->arm));
  EXPECT_LT((X_MG.translation() + reached->approach_M * 0.07 - reached->p_MC).norm(), 0.01);
}

TEST_F(GraspNodesTest, CloseGripperWaitsForTheFingersToComeToRestOrTimesOut) {
  belief_.now = At(1.0);
  bt::Tree tree = Tree(R"(<CloseGripper timeout="2.0"/>)");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  const auto gripper = motion_.TakeGripperCommand();
  ASSERT_TRUE(gripper);
  EXPECT_EQ(gripper->mode, GripperCommand::Mode::kGrasp);
  belief_.now = At(2.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.gripper_at_rest = true;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);

  bt::Tree stuck = Tree(R"(<CloseGripper timeout="2.0"/>)");
  belief_.gripper_at_rest = false;
  EXPECT_EQ(stuck.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(4.5);
  EXPECT_EQ(stuck.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(log_.pending().back().text.find("did not come to rest"), std::string::npos);
}

TEST_F(GraspNodesTest, LiftPayloadSucceedsOnlyWithThePayloadInTheGripper) {
  belief_.X_MB = {0.0, 1.0, M_PI / 2};
  const auto plan = PlanFor("0.0;3.8;0.8");
  ASSERT_TRUE(plan);
  for (const bool holding : {true, false}) {
    belief_.now = At(1.0);
    bt::Tree tree = Tree("<LiftPayload/>", blackboard_);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
    // The hand rises 10 cm above the grasp, then folds at that height.
    EXPECT_NEAR(motion_.arm_target()[0],
                std::min(plan->arm[0] + 0.10, model_.limits(kArmLift).upper), 1e-9);
    belief_.now = At(30.0);  // long after the motion's end (no joint measurements here)
    belief_.holding_object = holding;
    EXPECT_EQ(tree.TickOnce(), holding ? NodeStatus::kSuccess : NodeStatus::kFailure);
  }
  EXPECT_NE(log_.pending().back().text.find("closed on nothing"), std::string::npos);
}

}  // namespace
}  // namespace egress::behavior
