#pragma once
/// @file
/// The ADA low-energy door operator as a state machine, independent of physics: closed →
/// opening → held open → closing → closed; a trigger while opening restarts nothing, while held
/// open restarts the hold, and while closing re-opens. It commands the leaf's angular velocity;
/// the physics (a hinge motor whose torque is capped by the stall force) decides whether the
/// leaf actually moves, so a blocked leaf simply stops.

#include <string_view>

#include "egress/twin/scenario.h"

namespace egress::twin {

enum class DoorPhase { kClosed, kOpening, kHeldOpen, kClosing };
std::string_view ToString(DoorPhase phase);

class AdaDoorOperator {
 public:
  /// Angle below which the leaf counts as closed (and the 10° latch-speed boundary).
  static constexpr double kClosedAngle = 0.5 * M_PI / 180.0;
  static constexpr double kLatchAngle = 10.0 * M_PI / 180.0;

  /// `max_open_angle` [rad] is the hinge's limit; the operator never opens beyond it.
  AdaDoorOperator(const DoorTiming& timing, double max_open_angle);

  /// A press or a wave at time `now` [s].
  void Trigger(double now);
  /// Starts closing now if opening or held open (a fault: the operator cuts its hold short).
  /// A later trigger re-opens it as usual.
  void CloseNow();
  /// Advances the state machine to `now` [s] given the measured opening angle [rad]; returns
  /// the commanded opening rate [rad/s] (positive opens).
  double Update(double now, double angle);

  DoorPhase phase() const { return phase_; }
  double open_angle() const { return open_angle_; }
  /// Opening speed [rad/s] and closing speeds above/below the latch angle [rad/s].
  double opening_rate() const { return opening_rate_; }
  double closing_rate() const { return closing_rate_; }
  double latch_rate() const { return latch_rate_; }

 private:
  DoorTiming timing_;
  double open_angle_;
  double opening_rate_;
  double closing_rate_;
  double latch_rate_;
  DoorPhase phase_{DoorPhase::kClosed};
  double held_since_{0.0};
  bool pending_trigger_{false};
  double trigger_time_{0.0};
};

}  // namespace egress::twin
