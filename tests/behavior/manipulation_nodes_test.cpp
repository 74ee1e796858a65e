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

TEST_F(ManipulationNodesTest, DetectPayloadLooksLowerAheadThenToEitherSide) {
  HeadGaze gaze;
  services_.gaze = &gaze;
  belief_.X_MC = Pose3(Eigen::Vector3d(0.0, 2.0, 1.0));
  bt::Tree tree = Tree(R"(<DetectPayload kind="bottle" pose="{where}" timeout="4.0"/>)");
  // The first second: level ahead, no request.
  belief_.now = At(1.0);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  gaze.Update(belief_, 0.0);
  EXPECT_EQ(gaze.reason(), GazeReason::kAhead);
  // Then lower, ahead; then to the left; then to the right.
  std::vector<std::pair<double, double>> looks;
  for (double t : {2.2, 3.2, 4.2}) {
    belief_.now = At(t);
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
    const auto look = gaze.Update(belief_, 0.0);
    ASSERT_TRUE(look.has_value()) << t;
    EXPECT_EQ(gaze.reason(), GazeReason::kTask);
    EXPECT_LT(look->tilt, -0.2) << t;
    looks.emplace_back(look->pan, look->tilt);
  }
  EXPECT_NEAR(looks[0].first, 0.0, 1e-9);
  EXPECT_GT(looks[1].first, 0.3);
  EXPECT_LT(looks[2].first, -0.3);
  // Found: done, and no more requests.
  belief_.world.payloads = {Seen("bottle", {0.8, 2.8, 0.4})};
  belief_.now = At(4.3);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  belief_.now = At(4.9);
  gaze.Update(belief_, 0.0);
  EXPECT_EQ(gaze.reason(), GazeReason::kAhead);
}

}  // namespace
}  // namespace egress::behavior
