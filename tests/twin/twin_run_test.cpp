#include "egress/twin/twin_run.h"

#include <gtest/gtest.h>

#include "twin_test_util.h"

namespace egress::twin {
namespace {

TEST(RunScenarioTest, RunsForTheDurationCallsTheControllerAt10HzAndReportsProgress) {
  const Scenario s = LoadScenario(testing::WorldsDir() / "lab/lab_push_button.yaml");
  TwinWorld world(s, LoadSdfWorld(s.world_file), 1, testing::Hsr());
  TwinRobot robot(&world);
  int calls = 0;
  std::vector<double> progress;
  RunOptions options;
  options.duration = 3.0;
  options.on_progress = [&](double f) { progress.push_back(f); };
  const RunResult r = RunScenario(
      robot,
      [&](RobotPort& port) {
        ++calls;
        port.Sense();
        port.SendBaseVelocity({0.0, 0.0, 0.3});
        return true;
      },
      options);
  EXPECT_NEAR(r.simulated_time, 3.0, 1e-6);
  EXPECT_EQ(calls, 30);
  ASSERT_FALSE(progress.empty());
  EXPECT_DOUBLE_EQ(progress.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  ASSERT_TRUE(r.trace.has_value());
  EXPECT_EQ(r.trace->sample_count(), 61u);
  EXPECT_GT(world.robot_pose().yaw, 0.5);  // it turned
  EXPECT_FALSE(r.verdict.success);         // it never pressed the button nor reached the goal
}

TEST(RunScenarioTest, AControllerEndsTheRunEarlyAndDefaultsToTheTimeLimit) {
  const Scenario s = LoadScenario(testing::WorldsDir() / "lab/lab_push_button.yaml");
  TwinWorld world(s, LoadSdfWorld(s.world_file), 1, testing::Hsr());
  TwinRobot robot(&world);
  int calls = 0;
  const RunResult r = RunScenario(robot, [&](RobotPort&) { return ++calls < 5; });
  EXPECT_NEAR(r.simulated_time, 0.5, 1e-6);
  EXPECT_NEAR(r.verdict.metrics.end_time, 0.5, 1e-6);
  const auto short_run =
      testing::LoadText("world: lab.sdf\ntime_limit: 2.5\nrobot: {start: {x: 0, y: 0}}\n",
                        testing::WorldsDir() / "lab");
  TwinWorld other(short_run.scenario, short_run.world, 1, testing::Hsr());
  TwinRobot idle(&other);
  RunOptions no_trace;
  no_trace.record_trace = false;
  const RunResult full = RunScenario(idle, IdleController(), no_trace);
  EXPECT_NEAR(full.simulated_time, 2.5, 1e-6);
  EXPECT_TRUE(full.verdict.success);  // no predicates but the time limit
  EXPECT_FALSE(full.trace.has_value());
}

}  // namespace
}  // namespace egress::twin
