#include "egress/twin/door_operator.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::twin {

std::string_view ToString(DoorPhase phase) {
  switch (phase) {
    case DoorPhase::kClosed:
      return "closed";
    case DoorPhase::kOpening:
      return "opening";
    case DoorPhase::kHeldOpen:
      return "held_open";
    case DoorPhase::kClosing:
      return "closing";
  }
  return "unknown";
}

AdaDoorOperator::AdaDoorOperator(const DoorTiming& timing, double max_open_angle)
    : timing_(timing),
      open_angle_(std::min(timing.open_angle_deg * M_PI / 180.0, max_open_angle)),
      // A156.19 times: 0 → open angle in open_time; 90° → 10° in close_time; 10° → 0 in latch.
      opening_rate_(timing.open_angle_deg * M_PI / 180.0 / timing.open_time_s),
      closing_rate_((80.0 * M_PI / 180.0) / timing.close_time_s),
      latch_rate_(kLatchAngle / timing.latch_time_s) {
  ThrowUnless(timing.open_time_s > 0 && timing.close_time_s > 0 && timing.latch_time_s > 0,
              "door timing: times must be positive");
  ThrowUnless(open_angle_ > kLatchAngle, "door timing: open angle must exceed 10 degrees");
}

void AdaDoorOperator::Trigger(double now) {
  pending_trigger_ = true;
  trigger_time_ = now;
}

void AdaDoorOperator::CloseNow() {
  pending_trigger_ = false;
  if (phase_ == DoorPhase::kOpening || phase_ == DoorPhase::kHeldOpen) phase_ = DoorPhase::kClosing;
}

double AdaDoorOperator::Update(double now, double angle) {
  if (pending_trigger_) {
    pending_trigger_ = false;
    if (phase_ == DoorPhase::kHeldOpen) {
      held_since_ = trigger_time_;  // a press while open restarts the hold window
    } else if (phase_ != DoorPhase::kOpening) {
      phase_ = DoorPhase::kOpening;
    }
  }
  switch (phase_) {
    case DoorPhase::kClosed:
      // Pushed open by hand without a trigger: the operator's closer brings the leaf back at
      // the closing speeds.
      if (angle <= 2.0 * kClosedAngle) return 0.0;
      return angle > kLatchAngle ? -closing_rate_ : -latch_rate_;
    case DoorPhase::kOpening:
      if (angle >= open_angle_ - 1e-3) {
        phase_ = DoorPhase::kHeldOpen;
        held_since_ = now;
        return 0.0;
      }
      // Slow down over the last few degrees (back-check) instead of slamming the stop.
      return std::min(opening_rate_, 4.0 * (open_angle_ - angle) + 0.05);
    case DoorPhase::kHeldOpen:
      if (now - held_since_ >= timing_.hold_open_s) {
        phase_ = DoorPhase::kClosing;
        return -closing_rate_;
      }
      // Hold the leaf at the open angle against small disturbances.
      return std::clamp(2.0 * (open_angle_ - angle), -opening_rate_, opening_rate_);
    case DoorPhase::kClosing:
      if (angle <= kClosedAngle) {
        phase_ = DoorPhase::kClosed;
        return 0.0;
      }
      return angle > kLatchAngle ? -closing_rate_ : -std::max(latch_rate_, 0.0);
  }
  return 0.0;
}

}  // namespace egress::twin
