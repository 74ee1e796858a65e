#pragma once
/// @file
/// One twin run: steps a TwinRobot (and its world) in control periods, calls a controller each
/// period (the robot brain, or a baseline), watches with the judge and the trace recorder, and
/// returns the verdict. The controller sees only the RobotPort.

#include <functional>
#include <optional>

#include "egress/twin/scenario_judge.h"
#include "egress/twin/trace.h"
#include "egress/twin/twin_robot.h"

namespace egress::twin {

struct RunOptions {
  double duration{0.0};        ///< Simulated seconds; 0 = the scenario's time limit.
  double control_period{0.1};  ///< Controller period [s] (the paper's 10 Hz executive).
  bool record_trace{true};
  double trace_rate_hz{20.0};
  /// Called with the fraction done (0..1) about every 1 % of the run.
  std::function<void(double)> on_progress;
  /// Called when a trace sample is recorded: what the driver wants shown with it.
  std::function<TraceAnnotation()> annotate;
};

/// Called once per control period; return false to end the run early (e.g. the task is done).
using Controller = std::function<bool(RobotPort&)>;

struct RunResult {
  Verdict verdict;
  std::optional<TraceRecorder> trace;
  double simulated_time{0.0};  ///< [s]
};

/// Runs until the duration or until the controller returns false.
RunResult RunScenario(TwinRobot& robot, const Controller& controller,
                      const RunOptions& options = {});

/// A controller that never commands anything (the robot stands still).
Controller IdleController();

}  // namespace egress::twin
