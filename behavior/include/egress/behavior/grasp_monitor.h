#pragma once
/// @file
/// GraspMonitor: whether the hand holds something, from the gripper's own measurements, as on
/// the real HSR (whose gripper reports its hand_motor_joint angle and its effort, not what it
/// holds). After a grasp command the fingers close until they stop: on an object they stop
/// short of closed and keep squeezing; on nothing they close fully. A payload that slips out
/// lets the fingers close, and the monitor says so.

#include <optional>

#include "egress/hsr_interface/command_types.h"
#include "egress/hsr_interface/robot_state_types.h"
#include "egress/hsr_interface/time.h"

namespace egress::behavior {

struct GraspMonitorConfig {
  /// hand_motor_joint where the HSR's fingertips meet with nothing between them [rad].
  double closed_position{-0.3};
  /// Held when the fingers stopped at least this far short of closed [rad] (the 4 cm
  /// flashlight stops them ~0.45 rad short; the 6.6 cm bottle ~0.75 rad).
  double min_opening{0.1};
  /// ... while squeezing with at least this force [N].
  double min_effort{0.5};
  /// ... and the finger angle has moved less than settle_rate for this long [s].
  double settle_time{0.2};
  double settle_rate{0.05};  ///< [rad/s]
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

class GraspMonitor {
 public:
  explicit GraspMonitor(GraspMonitorConfig config = {});
  /// A command sent to the gripper (a grasp arms the monitor; open or position disarms it).
  void OnCommand(const GripperCommand& command);
  /// One gripper reading. @throws InvalidArgument for a reading older than the last one.
  void Update(const GripperState& state);
  /// The hand holds an object: a grasp is in force and the fingers rest, squeezing, short of
  /// closed.
  bool holding() const { return holding_; }
  /// The fingers moved after the last command and have come to rest since (on an object, or
  /// closed or open on nothing): the command is done, as the gripper measures it.
  bool at_rest() const { return moved_since_command_ && settled_; }

 private:
  GraspMonitorConfig config_;
  bool grasping_{false};
  bool holding_{false};
  bool moved_since_command_{false};
  bool settled_{false};
  std::optional<GripperState> last_;
  Time steady_since_{};
};

}  // namespace egress::behavior
