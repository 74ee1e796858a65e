#include "egress/planning/ik_solver.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

using ::testing::HasSubstr;

class IkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { model_ = new RobotModel(RobotModel::LoadDefault()); }
  static void TearDownTestSuite() { delete model_; }
  static const RobotModel& model() { return *model_; }
  static WholeBodyVector Tucked() {
    WholeBodyVector q = WholeBodyVector::Zero();
    q[kArmLift] = 0.01;
    q[kArmFlex] = -0.01;
    return q;
  }

 private:
  static inline RobotModel* model_ = nullptr;
};

TEST_F(IkTest, ConvergesToReachableTargetsWithinTolerance) {
  DlsIkSolver solver(model());
  std::mt19937 random(5);
  std::uniform_real_distribution<double> x(0.5, 0.8), y(-0.2, 0.3),
      z(0.8, 1.2);  // ADA button heights
  int converged = 0;
  for (int i = 0; i < 100; ++i) {
    const IkTarget target{{x(random), y(random), z(random)}, std::nullopt};
    const IkResult result = solver.Solve(target, Tucked());
    if (!result.converged) continue;
    ++converged;
    EXPECT_LT((model().CalcPalmPose(result.q).translation() - target.p_MT).norm(), 1e-3);
    EXPECT_TRUE(model().IsWithinLimits(result.q));
    EXPECT_DOUBLE_EQ(result.q[kBaseYaw], 0.0);  // yaw is held
  }
  EXPECT_GE(converged, 99);
}

TEST_F(IkTest, ReportsFailureForUnreachableTargets) {
  IkConfig arm_only;
  arm_only.use_base = false;
  DlsIkSolver solver(model(), arm_only);
  const IkResult far = solver.Solve({{3.0, 0.0, 1.0}, std::nullopt}, Tucked());
  EXPECT_FALSE(far.converged);
  EXPECT_LE(far.iterations, 200);  // a stall ends the adaptive schedule early
  EXPECT_GT(far.position_error, 1.0);
  arm_only.method = IkMethod::kPaperDls;
  const IkResult paper =
      DlsIkSolver(model(), arm_only).Solve({{3.0, 0.0, 1.0}, std::nullopt}, Tucked());
  EXPECT_FALSE(paper.converged);
  EXPECT_EQ(paper.iterations, 200);  // the paper's schedule spends its whole budget
  const IkResult high =
      DlsIkSolver(model()).Solve({{0.6, 0.0, 2.5}, std::nullopt}, Tucked());  // above max lift
  EXPECT_FALSE(high.converged);
  EXPECT_THROW(solver.Solve({{std::nan(""), 0, 0}, std::nullopt}, Tucked()), InvalidArgument);
}

TEST_F(IkTest, WarmStartNeedsFewerIterations) {
  for (const IkMethod method : {IkMethod::kPaperDls, IkMethod::kAdaptiveDls}) {
    IkConfig config;
    config.method = method;
    DlsIkSolver solver(model(), config);
    const IkResult cold = solver.Solve({{0.65, 0.05, 1.0}, std::nullopt}, Tucked());
    ASSERT_TRUE(cold.converged);
    const IkResult warm =
        solver.Solve({{0.66, 0.05, 1.01}, std::nullopt}, cold.q);  // the next target, 1.4 cm on
    ASSERT_TRUE(warm.converged);
    EXPECT_LE(2 * warm.iterations, cold.iterations)
        << int(method) << ": " << cold.iterations << " vs " << warm.iterations;
  }
}

// The same targets under both schedules: both converge; the adaptive one in far fewer
// iterations and to a configuration close to the paper's.
TEST_F(IkTest, AdaptiveScheduleConvergesWhereThePapersDoesInFewerIterations) {
  IkConfig paper_config;
  paper_config.method = IkMethod::kPaperDls;
  const DlsIkSolver paper(model(), paper_config), adaptive(model());
  std::mt19937 random(11);
  std::uniform_real_distribution<double> x(0.5, 0.8), y(-0.2, 0.3), z(0.86, 1.22);
  int paper_iterations = 0, adaptive_iterations = 0;
  for (int i = 0; i < 50; ++i) {
    const IkTarget target{{x(random), y(random), z(random)}, std::nullopt};
    const IkResult a = paper.Solve(target, Tucked());
    const IkResult b = adaptive.Solve(target, Tucked());
    ASSERT_TRUE(a.converged && b.converged) << i;
    EXPECT_LT((model().CalcPalmPose(b.q).translation() - target.p_MT).norm(), 1e-3);
    EXPECT_TRUE(model().IsWithinLimits(b.q));
    EXPECT_LT((a.q - b.q).cwiseAbs().maxCoeff(), 0.35) << i;  // the same family of solution
    paper_iterations += a.iterations;
    adaptive_iterations += b.iterations;
  }
  EXPECT_LT(5 * adaptive_iterations, paper_iterations);
}

// Table tops (0.40-0.86 m) from the tucked pose: the tucked, vertical arm is singular for
// targets below its palm and the paper's schedule stalls on many; the adaptive one does not.
TEST_F(IkTest, TableTopTargetsConvergeFromTheTuckedPose) {
  IkConfig paper_config;
  paper_config.method = IkMethod::kPaperDls;
  const DlsIkSolver paper(model(), paper_config), adaptive(model());
  std::mt19937 random(3);
  std::uniform_real_distribution<double> x(0.45, 0.75), y(-0.2, 0.2), z(0.40, 0.86);
  int paper_converged = 0;
  for (int i = 0; i < 60; ++i) {
    const IkTarget target{{x(random), y(random), z(random)}, std::nullopt};
    paper_converged += paper.Solve(target, Tucked()).converged;
    const IkResult r = adaptive.Solve(target, Tucked());
    ASSERT_TRUE(r.converged) << target.p_MT.transpose();
    EXPECT_LT((model().CalcPalmPose(r.q).translation() - target.p_MT).norm(), 1e-3);
  }
  EXPECT_LT(paper_converged, 60);
}

// Arm-only solves (the base where it stopped) of targets the arm reaches by construction: a
// run that stalls restarts from interior postures and finds more of them.
TEST_F(IkTest, ArmOnlyRestartsFindMoreReachableTargets) {
  IkConfig single_config, restarting_config;
  single_config.use_base = restarting_config.use_base = false;
  single_config.restarts = 0;
  const DlsIkSolver single(model(), single_config), restarting(model(), restarting_config);
  std::mt19937 random(2026);
  std::uniform_real_distribution<double> lift(0.0, 0.69), flex(-2.6, 0.0), roll(-0.5, 0.5),
      wflex(-1.5, 1.0), wroll(-1.0, 1.0);
  int single_converged = 0, restarting_converged = 0, targets = 0;
  while (targets < 600) {
    WholeBodyVector q = WholeBodyVector::Zero();
    q << 0, 0, 0, lift(random), flex(random), roll(random), wflex(random), wroll(random);
    const Eigen::Vector3d p = model().CalcPalmPose(q).translation();
    if (p.x() < 0.3 || p.z() < 0.4 || p.z() > 1.22) continue;
    ++targets;
    single_converged += single.Solve({p, std::nullopt}, Tucked()).converged;
    const IkResult r = restarting.Solve({p, std::nullopt}, Tucked());
    restarting_converged += r.converged;
    EXPECT_LE(r.iterations, 200);
  }
  EXPECT_GT(restarting_converged, single_converged);
  EXPECT_GE(restarting_converged, 597);  // 99.5 %
}

TEST_F(IkTest, ClampsEveryJointStep) {
  IkConfig config;
  config.step = 1.0;  // undamped step: large updates
  config.max_joint_step = 0.02;
  config.max_iterations = 1;
  DlsIkSolver solver(model(), config);
  const WholeBodyVector q0 = Tucked();
  const IkResult result = solver.Solve({{0.9, 0.4, 0.5}, std::nullopt}, q0);
  EXPECT_LE((result.q - q0).cwiseAbs().maxCoeff(), 0.02 + 1e-12);
}

TEST_F(IkTest, WristLevelingHoldsAndTheApproachAxisIsMet) {
  IkConfig level;
  level.wrist_leveling = true;
  DlsIkSolver leveled(model(), level);
  const IkResult carry = leveled.Solve({{0.6, 0.0, 0.75}, std::nullopt}, Tucked());
  ASSERT_TRUE(carry.converged);
  EXPECT_NEAR(carry.q[kWristFlex], -std::numbers::pi / 2 - carry.q[kArmFlex], 1e-12);
  // With roll 0 the leveled wrist keeps the palm's approach axis horizontal: a flat palm.
  EXPECT_LT(std::abs(model().CalcPalmPose(carry.q).rotation().col(2).z()), 0.05);

  IkConfig press;
  press.fingertip = true;
  DlsIkSolver solver(model(), press);
  const IkResult result = solver.Solve({{0.7, 0.1, 1.0}, Eigen::Vector3d::UnitX()}, Tucked());
  ASSERT_TRUE(result.converged);
  EXPECT_LT(result.orientation_error, 0.05);
  EXPECT_LT((model().CalcFingertipPosition(result.q) - Eigen::Vector3d(0.7, 0.1, 1.0)).norm(),
            1e-3);
}

TEST_F(IkTest, ButtonTargetsForBothTypes) {
  // A button on a wall facing -y (the robot is at smaller y), 1.0 m high.
  const Eigen::Vector3d button(0.5, 4.44, 1.0), normal(0, -1, 0);
  const ButtonTargets push = MakeButtonTargets(button, normal, ButtonType::kPushButton);
  EXPECT_NEAR(push.X_MB_standoff.y, 4.44 - 0.55, 1e-12);
  EXPECT_NEAR(push.X_MB_standoff.yaw, std::numbers::pi / 2, 1e-12);  // facing the wall
  EXPECT_NEAR(push.press.p_MT.y(), 4.446, 1e-12);                    // 6 mm past the surface
  EXPECT_NEAR(push.approach.p_MT.y(), 4.39, 1e-12);
  const ButtonTargets plate = MakeButtonTargets(button, normal, ButtonType::kProximityPlate);
  EXPECT_NEAR(plate.press.p_MT.y(), 4.32, 1e-12);  // no contact: within the 0.3 m range
  ButtonTargetsConfig out_of_range;
  out_of_range.wave_distance = 0.4;
  EXPECT_THROW(MakeButtonTargets(button, normal, ButtonType::kProximityPlate, out_of_range),
               InvalidArgument);
  EXPECT_THROW(MakeButtonTargets(button, {0, 0, 1}, ButtonType::kPushButton), InvalidArgument);
  // The press is reachable from the standoff.
  IkConfig config;
  config.fingertip = true;
  WholeBodyVector q = Tucked();
  q[kBaseX] = push.X_MB_standoff.x;
  q[kBaseY] = push.X_MB_standoff.y;
  q[kBaseYaw] = push.X_MB_standoff.yaw;
  const IkResult pre = DlsIkSolver(model(), config).Solve(push.approach, q);
  ASSERT_TRUE(pre.converged);
  EXPECT_TRUE(DlsIkSolver(model(), config).Solve(push.press, pre.q).converged);
}

TEST_F(IkTest, InvalidConfig) {
  IkConfig config;
  config.damping = -1;
  EXPECT_THROW(DlsIkSolver(model(), config), InvalidArgument);
  config = {};
  config.max_iterations = 0;
  EXPECT_THROW(DlsIkSolver(model(), config), InvalidArgument);
  config = {};
  config.max_adaptive_joint_step = 0.05;  // below the paper's clamp
  EXPECT_THROW(DlsIkSolver(model(), config), InvalidArgument);
  config = {};
  config.restarts = -1;
  EXPECT_THROW(DlsIkSolver(model(), config), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
