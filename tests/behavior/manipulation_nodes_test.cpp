// The manipulation nodes (behavior/src/manipulation_nodes.cpp), ticked in one-node trees.

#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

using bt::NodeStatus;
using node_testing::At;
using ManipulationNodesTest = node_testing::TaskNodeFixture;

perception::TrackedObject Seen(const std::string& label, const Eigen::Vector3d& p_MO) {
  perception::TrackedObject object;
  object.label = label;
  object.p_MO = p_MO;
  return object;
}

TEST_F(ManipulationNodesTest, DetectPayloadWritesTheNearestOfItsKind) {
  auto blackboard = bt::Blackboard::Create();
  bt::Tree tree = Tree(R"(<DetectPayload kind="bottle" pose="{where}"/>)", blackboard);
  belief_.world.payloads = {Seen("flashlight", {0.5, 2.5, 0.75}), Seen("bottle", {2.0, 2.0, 0.8}),
                            Seen("bottle", {0.6, 2.2, 0.8})};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  const auto where = blackboard->Get<std::string>("where");
  ASSERT_TRUE(where.has_value());
  const Pose2 p = ParsePose2(*where);  // x;y;z
  EXPECT_NEAR(p.x, 0.6, 1e-9);
  EXPECT_NEAR(p.y, 2.2, 1e-9);
  EXPECT_NEAR(p.yaw, 0.8, 1e-9);
}

TEST_F(ManipulationNodesTest, DetectPayloadLooksUntilItsTimeout) {
  bt::Tree tree = Tree(R"(<DetectPayload kind="bottle" pose="{where}" timeout="2.0"/>)");
  belief_.world.payloads = {Seen("flashlight", {0.5, 2.5, 0.75})};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(2.5);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  belief_.now = At(3.5);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
}

TEST_F(ManipulationNodesTest, GraspPayloadRefusesWhatNoPostureReaches) {
  bt::Tree tree = Tree(R"(<GraspPayload kind="bottle" pose="0.5;2.5;2.6"/>)");  // 2.6 m up
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kFailure);
  EXPECT_NE(log_.pending().back().text.find("no whole-body reach"), std::string::npos);
  EXPECT_FALSE(motion_.base_moving());
}

TEST_F(ManipulationNodesTest, GraspPayloadDrivesToWhereTheHandReachesIt) {
  bt::Tree tree = Tree(R"(<GraspPayload kind="bottle" pose="0.0;3.8;0.8"/>)");
  belief_.X_MB = {0.0, 2.0, M_PI / 2};
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  ASSERT_GE(motion_.path().size(), 2u);
  const Pose2& grasp = motion_.path().back();
  // Closer, facing the bottle, but not on top of it.
  const double d = (Eigen::Vector2d(0.0, 3.8) - grasp.translation()).norm();
  EXPECT_GT(d, 0.3);
  EXPECT_LT(d, 0.9);
}

}  // namespace
}  // namespace egress::behavior
