#include "egress/twin/twin_run.h"

#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::twin {

RunResult RunScenario(TwinRobot& robot, const Controller& controller, const RunOptions& options) {
  ThrowUnless(options.control_period > 0, "run: control_period must be positive");
  TwinWorld& world = robot.world();
  const double duration = options.duration > 0 ? options.duration : world.scenario().time_limit;
  const double end = world.time() + duration;
  RunResult result;
  if (options.record_trace) result.trace.emplace(options.trace_rate_hz);
  ScenarioJudge judge;
  judge.Observe(world);
  if (result.trace) result.trace->Observe(world);
  int last_percent = -1;
  bool running = true;
  while (running && world.time() < end - 1e-9) {
    running = controller(robot);
    const double period_end = std::min(end, world.time() + options.control_period);
    while (world.time() < period_end - 1e-9) {
      robot.Advance(world.step_size());
      judge.Observe(world);
      if (result.trace) {
        if (options.annotate && result.trace->SampleDue(world)) {
          const TraceAnnotation note = options.annotate();
          result.trace->Observe(world, &note);
        } else {
          result.trace->Observe(world);
        }
      }
    }
    const int percent = int(std::floor(100.0 * (1.0 - (end - world.time()) / duration)));
    if (options.on_progress && percent != last_percent) {
      last_percent = percent;
      options.on_progress(std::min(1.0, percent / 100.0));
    }
  }
  result.verdict = judge.Finish(world);
  result.simulated_time = world.time();
  return result;
}

Controller IdleController() {
  return [](RobotPort&) { return true; };
}

}  // namespace egress::twin
