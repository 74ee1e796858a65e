// SolveArmLine (behavior/src/task_node_support.h): arm knots along a straight line, each solved
// warm from the one before, so a press travels the button's normal.

#include <cmath>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/planning/ik_solver.h"
#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

TEST(SolveArmLineTest, KnotsLieEvenlyOnTheLineFromTheStartToTheEnd) {
  const RobotModel model = RobotModel::LoadDefault();
  TaskServices ctx;
  ctx.model = &model;
  const Pose2 X_MB{0.0, 0.0, 0.0};
  // A press 5.6 cm forward at button height, in front of the robot.
  const planning::IkTarget from{{0.55, 0.0, 1.0}, Eigen::Vector3d::UnitX()};
  const planning::IkTarget to{{0.606, 0.0, 1.0}, std::nullopt};
  const auto start = SolveArm(ctx, X_MB, from, TuckedArm(model), true);
  ASSERT_TRUE(start.has_value());
  const auto knots = SolveArmLine(ctx, X_MB, from, to, *start, true, 4);
  ASSERT_TRUE(knots.has_value());
  ASSERT_EQ(knots->size(), 4u);
  for (int i = 0; i < 4; ++i) {
    WholeBodyVector q = WithArm(WholeBodyVector::Zero(), (*knots)[std::size_t(i)]);
    const Eigen::Vector3d tip = model.CalcFingertipPosition(q);
    const Eigen::Vector3d expected = from.p_MT + (i + 1) / 4.0 * (to.p_MT - from.p_MT);
    EXPECT_LT((tip - expected).norm(), 1e-3) << "knot " << i;
  }
  // Neighbouring knots stay close in joint space: no flip between solutions.
  ArmPose previous = *start;
  for (const ArmPose& arm : *knots) {
    for (std::size_t j = 0; j < arm.size(); ++j)
      EXPECT_LT(std::abs(arm[j] - previous[j]), 0.2);
    previous = arm;
  }
}

TEST(SolveArmLineTest, APointOutOfReachFailsTheLineAndBadStepsAreAnError) {
  const RobotModel model = RobotModel::LoadDefault();
  TaskServices ctx;
  ctx.model = &model;
  const Pose2 X_MB{0.0, 0.0, 0.0};
  const planning::IkTarget from{{0.55, 0.0, 1.0}, std::nullopt};
  const planning::IkTarget far{{2.0, 0.0, 1.0}, std::nullopt};  // beyond the arm from here
  EXPECT_FALSE(SolveArmLine(ctx, X_MB, from, far, TuckedArm(model), true, 4).has_value());
  EXPECT_THROW(SolveArmLine(ctx, X_MB, from, far, TuckedArm(model), true, 0), InvalidArgument);
}

// A button pressed along +x: from where whole-body IK stands the base the arm alone holds the
// approach axis; from 20 cm to the side, square on, it reaches the button only at a slant, which
// a standoff choice that wants the axis held must be told (room A seed 6: pressed at a slant
// from 20 cm along the wall, the hand touched the wall beside the button).
TEST(SolveArmTest, WithoutSlantAnArmThatCannotHoldTheApproachAxisIsNone) {
  const RobotModel model = RobotModel::LoadDefault();
  TaskServices ctx;
  ctx.model = &model;
  const planning::IkTarget button{{0.55, 0.0, 1.0}, Eigen::Vector3d::UnitX()};
  planning::IkConfig ik;
  ik.fingertip = true;
  ik.use_base = true;
  const planning::IkResult whole = planning::DlsIkSolver(model, ik).Solve(
      button, WithArm(WholeBodyVector::Zero(), TuckedArm(model)));
  ASSERT_TRUE(whole.converged);
  const Pose2 X_MB{whole.q[kBaseX], whole.q[kBaseY], whole.q[kBaseYaw]};
  const auto square = SolveArm(ctx, X_MB, button, ArmOf(whole.q), true, 0.0, false);
  ASSERT_TRUE(square.has_value());
  EXPECT_EQ(*square, *SolveArm(ctx, X_MB, button, ArmOf(whole.q), true));
  const Pose2 aside{X_MB.x, X_MB.y - 0.2, X_MB.yaw};
  const auto slant = SolveArm(ctx, aside, button, ArmOf(whole.q), true);
  ASSERT_TRUE(slant.has_value());
  WholeBodyVector q = WithArm(WholeBodyVector::Zero(), *slant);
  q[kBaseX] = aside.x;
  q[kBaseY] = aside.y;
  q[kBaseYaw] = aside.yaw;
  EXPECT_LT((model.CalcFingertipPosition(q) - button.p_MT).norm(), 2e-3);
  EXPECT_FALSE(SolveArm(ctx, aside, button, ArmOf(whole.q), true, 0.0, false).has_value());
}

}  // namespace
}  // namespace egress::behavior::detail
