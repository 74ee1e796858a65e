#pragma once
/// @file
/// HeadGaze: where the head camera looks, decided each control step from the belief. The base
/// laser sees all round; the head camera (58 deg) only where it points, and it is the sensor that
/// confirms people and reads doors' far sides. So the head looks, in this order:
///   1. at a tracked person coming towards the robot from outside the camera's view (a glance
///      of `glance_time`, then not at the same person again for `glance_cooldown`);
///   2. at what the current task asks for (RequestLook: the payload it is finding or
///      grasping), with pan and tilt, while the request lasts;
///   3. through a door ahead of the robot (its centre within 90 deg of the heading: not one it
///      has passed) that it is near while that door is open or opening: at the point
///      `door_look_beyond` past the doorway's centre, on its far side, where people wait for it
///      and come through from;
///   4. straight ahead (pan 0, tilt 0), the paper's fixed gaze.
/// The tilt moves only for a task's request (a payload on a table below the camera, near the
/// robot, is below a level camera's view); people and doors are looked at level. Pan angles are
/// of head_pan_joint: 0 ahead along the base's x, + to the left; tilt of head_tilt_joint: 0
/// level, - down.

#include <map>
#include <optional>

#include "egress/behavior/belief.h"
#include "egress/hsr_interface/command_types.h"

namespace egress::behavior {

struct HeadGazeConfig {
  /// False: the head stays where it is (the fixed gaze of the paper).
  bool enabled{true};
  double camera_hfov_deg{58.0};    ///< The head camera's horizontal field of view.
  double glance_range{4.0};        ///< People nearer than this may get a glance [m].
  double approach_speed{0.3};      ///< Coming towards the robot at least this fast [m/s].
  double glance_time{1.0};         ///< [s]
  double glance_cooldown{3.0};     ///< [s] before the same person gets another glance.
  double door_look_range{3.0};     ///< Doors whose centre is nearer than this [m].
  double door_look_beyond{1.5};    ///< The point looked at past the doorway's centre [m].
  double door_open_fraction{0.1};  ///< A door at least this open (or opening) is looked through.
  double max_pan_deg{110.0};       ///< The head never turns further from ahead.
  double max_tilt_down_deg{60.0};  ///< The head never tilts further down than this.
  double max_tilt_up_deg{25.0};    ///< ... nor further up.
  double min_change_deg{3.0};      ///< A new target nearer than this to the last is not sent.
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// What the head looks at, and why (for the run log).
enum class GazeReason { kAhead, kDoor, kPerson, kTask };

class HeadGaze {
 public:
  explicit HeadGaze(HeadGazeConfig config = {});

  /// The head command to send this step, if the target changed (nullopt: keep the last one, or
  /// disabled). `pan_now` is the measured head_pan_joint angle [rad], if known.
  std::optional<HeadCommand> Update(const Belief& belief, std::optional<double> pan_now);
  /// A task's request: look at p_M (in M) until `until` (the robot clock); a node that needs
  /// the view renews it each tick. A later request replaces an earlier one.
  void RequestLook(const Eigen::Vector3d& p_M, Time until);
  GazeReason reason() const { return reason_; }
  /// The pan last commanded [rad] (0 before any).
  double commanded_pan() const { return commanded_pan_; }
  /// The tilt last commanded [rad] (0 before any).
  double commanded_tilt() const { return commanded_tilt_; }
  const HeadGazeConfig& config() const { return config_; }

 private:
  /// The pan that points the camera at p_M from the base at X_MB, clamped [rad].
  double PanTowards(const Pose2& X_MB, const Eigen::Vector2d& p_M) const;
  /// The tilt that points the camera (at X_MC) at p_M, clamped [rad].
  double TiltTowards(const Pose3& X_MC, const Eigen::Vector3d& p_M) const;

  HeadGazeConfig config_;
  GazeReason reason_{GazeReason::kAhead};
  double commanded_pan_{0.0};
  double commanded_tilt_{0.0};
  std::optional<Eigen::Vector3d> requested_;  ///< RequestLook's point, until requested_until_.
  Time requested_until_{};
  bool sent_{false};
  int glance_id_{-1};
  Time glance_until_{};
  std::map<int, Time> glanced_at_;  ///< Track id -> when its glance began.
};

}  // namespace egress::behavior
