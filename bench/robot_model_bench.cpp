// Cost of the robot model's kinematics, which the DLS IK solver calls up to 200 times a solve.

#include <benchmark/benchmark.h>

#include "egress/hsr_interface/robot_model.h"

namespace {

egress::WholeBodyVector SomeConfiguration() {
  egress::WholeBodyVector q;
  q << 0.4, -0.2, 0.3, 0.25, -1.1, 0.2, -0.6, 0.4;
  return q;
}

void BM_PalmForwardKinematics(benchmark::State& state) {
  const auto model = egress::RobotModel::LoadDefault();
  const auto q = SomeConfiguration();
  for (auto _ : state)
    benchmark::DoNotOptimize(model.CalcPalmPose(q));
}
BENCHMARK(BM_PalmForwardKinematics);

void BM_FingertipJacobian(benchmark::State& state) {
  const auto model = egress::RobotModel::LoadDefault();
  const auto q = SomeConfiguration();
  for (auto _ : state)
    benchmark::DoNotOptimize(model.CalcFingertipJacobian(q));
}
BENCHMARK(BM_FingertipJacobian);

void BM_LoadUrdf(benchmark::State& state) {
  for (auto _ : state)
    benchmark::DoNotOptimize(egress::RobotModel::LoadDefault());
}
BENCHMARK(BM_LoadUrdf)->Unit(benchmark::kMillisecond);

}  // namespace
