// RelocalizeGate (behavior/src/task_node_support.h): precise acts wait, standing, for an
// uncertain pose to settle, and go on anyway after the timeout.

#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

Time At(double t) {
  return Time{} + SecondsToDuration(t);
}

TEST(RelocalizeGateTest, AnUncertainPoseIsSettledBeforeTheAct) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  Belief belief;
  TaskServices ctx;
  ctx.motion = &motion;
  ctx.belief = &belief;
  std::vector<std::string> notes;
  int relocalizations = 0;  // as the executive counts them: by event
  const EventNoteFn note = [&](const std::string& t, DecisionEvent e) {
    notes.push_back(t);
    if (e == DecisionEvent::kRelocalizing) ++relocalizations;
  };
  RelocalizeGate gate;

  // Certain enough (sigma 1 cm against the 2 cm default): act at once, nothing counted.
  belief.world.X_MB_covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  EXPECT_NEAR(PositionSigma(ctx), 0.01, 1e-12);
  EXPECT_EQ(gate.Check(ctx, "pressing", note), bt::NodeStatus::kSuccess);
  EXPECT_EQ(relocalizations, 0);

  // 5 cm along y (the largest eigenvalue counts, whatever the axis): wait.
  belief.world.X_MB_covariance(1, 1) = 0.05 * 0.05;
  belief.now = At(1.0);
  EXPECT_EQ(gate.Check(ctx, "pressing", note), bt::NodeStatus::kRunning);
  EXPECT_EQ(relocalizations, 1);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("re-localizing before pressing"), std::string::npos) << notes.back();
  belief.now = At(2.0);
  EXPECT_EQ(gate.Check(ctx, "pressing", note), bt::NodeStatus::kRunning);
  // The scans pinned it: go on.
  belief.world.X_MB_covariance(1, 1) = 1e-4;
  belief.now = At(2.5);
  EXPECT_EQ(gate.Check(ctx, "pressing", note), bt::NodeStatus::kSuccess);
  EXPECT_EQ(relocalizations, 1);

  // It never settles: after relocalize_timeout (3 s) the act goes on, noted.
  belief.world.X_MB_covariance(0, 0) = 0.04 * 0.04;
  belief.now = At(10.0);
  EXPECT_EQ(gate.Check(ctx, "grasping", note), bt::NodeStatus::kRunning);
  belief.now = At(12.9);
  EXPECT_EQ(gate.Check(ctx, "grasping", note), bt::NodeStatus::kRunning);
  belief.now = At(13.1);
  EXPECT_EQ(gate.Check(ctx, "grasping", note), bt::NodeStatus::kSuccess);
  EXPECT_NE(notes.back().find("grasping anyway"), std::string::npos) << notes.back();
  EXPECT_EQ(relocalizations, 2);
  // Checked again in the same act (its other conditions held it a tick): no new wait — one
  // would end the same way, and a traversal waited 3 s a time until the door's window had gone
  // (random building seed 12).
  belief.now = At(13.2);
  EXPECT_EQ(gate.Check(ctx, "grasping", note), bt::NodeStatus::kSuccess);
  EXPECT_EQ(relocalizations, 2);
  // A new act waits again.
  gate.Reset();
  belief.now = At(14.0);
  EXPECT_EQ(gate.Check(ctx, "grasping", note), bt::NodeStatus::kRunning);
  EXPECT_EQ(relocalizations, 3);
}

TEST(RelocalizeGateTest, AnActWithItsOwnLimitWaitsOnlyAboveIt) {
  const RobotModel model = RobotModel::LoadDefault();
  MotionExecutor motion(model);
  Belief belief;
  TaskServices ctx;
  ctx.motion = &motion;
  ctx.belief = &belief;
  int relocalizations = 0;
  const EventNoteFn note = [&](const std::string&, DecisionEvent e) {
    if (e == DecisionEvent::kRelocalizing) ++relocalizations;
  };
  RelocalizeGate gate;
  // 5 cm: within a 7 cm limit the act goes on; under the 2 cm default it waits.
  belief.world.X_MB_covariance = Eigen::Vector3d(0.05 * 0.05, 1e-4, 1e-4).asDiagonal();
  EXPECT_EQ(gate.Check(ctx, "driving through the door", note, 0.07), bt::NodeStatus::kSuccess);
  EXPECT_EQ(relocalizations, 0);
  EXPECT_EQ(gate.Check(ctx, "driving through the door", note, 0.04), bt::NodeStatus::kRunning);
  EXPECT_EQ(relocalizations, 1);
  gate.Reset();
  EXPECT_EQ(gate.Check(ctx, "pressing", note), bt::NodeStatus::kRunning);
  EXPECT_EQ(relocalizations, 2);
}

TEST(RelocalizeGateTest, ADoorPassToleratesWhatItsClearOpeningLeavesTheFootprint) {
  MissionMap map;
  map.doors.push_back({"wide", {0.0, 0.0}, {0.9, 0.0}, 1.0, std::numbers::pi / 2});
  map.doors.push_back({"narrow", {0.0, 2.0}, {0.5, 2.0}, 1.0, std::numbers::pi / 2});
  Belief belief;
  TaskServices ctx;
  ctx.belief = &belief;
  ctx.map = &map;
  // 0.9 m: 0.87 m clear past the open leaf, 0.44 m left beside the 0.43 m footprint, 0.22 m a
  // side: 3 sigma of it.
  const double wide = (0.87 - 2 * ctx.config.footprint_radius) / 2 / 3;
  EXPECT_NEAR(DoorPassPoseSigma(ctx, "wide"), wide, 1e-12);
  EXPECT_GT(DoorPassPoseSigma(ctx, "wide"), 0.07);
  // A door barely wider than the robot (2 cm a side): never looser than the precise acts' limit.
  EXPECT_DOUBLE_EQ(DoorPassPoseSigma(ctx, "narrow"), ctx.config.precise_pose_sigma);
  // The limit follows the footprint.
  ctx.config.footprint_radius = 0.3;
  EXPECT_NEAR(DoorPassPoseSigma(ctx, "wide"), (0.87 - 0.6) / 2 / 3, 1e-12);
}

}  // namespace
}  // namespace egress::behavior::detail
