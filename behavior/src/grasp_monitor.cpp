#include "egress/behavior/grasp_monitor.h"

#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {

void GraspMonitorConfig::Validate() const {
  ThrowUnless(std::isfinite(closed_position), "GraspMonitorConfig: closed_position must be finite");
  ThrowUnless(min_opening > 0 && std::isfinite(min_opening),
              "GraspMonitorConfig: min_opening must be > 0");
  ThrowUnless(min_effort >= 0 && std::isfinite(min_effort),
              "GraspMonitorConfig: min_effort must be >= 0");
  ThrowUnless(settle_time >= 0 && settle_rate > 0,
              "GraspMonitorConfig: settle_time must be >= 0 and settle_rate > 0");
}

GraspMonitor::GraspMonitor(GraspMonitorConfig config) : config_(config) {
  config_.Validate();
}

void GraspMonitor::OnCommand(const GripperCommand& command) {
  grasping_ = command.mode == GripperCommand::Mode::kGrasp;
  moved_since_command_ = false;
  if (!grasping_) holding_ = false;
}

void GraspMonitor::Update(const GripperState& state) {
  state.Validate();
  if (last_) {
    ThrowUnless(state.stamp >= last_->stamp, "GraspMonitor: gripper reading at ",
                ToSeconds(state.stamp), " s is older than the last one (", ToSeconds(last_->stamp),
                " s)");
    const double dt = ToSeconds(state.stamp - last_->stamp);
    const double moved = std::abs(state.hand_motor_position - last_->hand_motor_position);
    if (dt > 0 && moved > config_.settle_rate * dt) {
      steady_since_ = state.stamp;
      moved_since_command_ = true;
    }
  } else {
    steady_since_ = state.stamp;
  }
  last_ = state;
  const bool settled = ToSeconds(state.stamp - steady_since_) >= config_.settle_time;
  settled_ = settled;
  const bool short_of_closed =
      state.hand_motor_position >= config_.closed_position + config_.min_opening;
  if (!grasping_ || !short_of_closed || state.effort < config_.min_effort) {
    holding_ = false;
  } else if (settled) {
    holding_ = true;
  }
}

}  // namespace egress::behavior
