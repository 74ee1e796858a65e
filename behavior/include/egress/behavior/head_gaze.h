#pragma once
/// @file
/// HeadGaze: where the head camera looks, decided each control step from the belief. The base
/// laser sees all round; the head camera (58 deg) only where it points, and it is the sensor that
/// confirms people and reads doors' far sides. So the head looks, in this order:
///   1. at a tracked person coming towards the robot from outside the camera's view (a glance
///      of `glance_time`, then not at the same person again for `glance_cooldown`);
///   2. through a door ahead of the robot (its centre within 90 deg of the heading: not one it
///      has passed) that it is near while that door is open or opening: at the point
///      `door_look_beyond` past the doorway's centre, on its far side, where people wait for it
///      and come through from;
///   3. straight ahead (pan 0, tilt 0), the paper's fixed gaze.
/// Only the pan moves; the tilt stays level (the detector and the grasps are tuned for it).
/// Pan angles are of head_pan_joint: 0 ahead along the base's x, + to the left.

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
  double min_change_deg{3.0};      ///< A new target nearer than this to the last is not sent.
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// What the head looks at, and why (for the run log).
enum class GazeReason { kAhead, kDoor, kPerson };

class HeadGaze {
 public:
  explicit HeadGaze(HeadGazeConfig config = {});

  /// The head command to send this step, if the target changed (nullopt: keep the last one, or
  /// disabled). `pan_now` is the measured head_pan_joint angle [rad], if known.
  std::optional<HeadCommand> Update(const Belief& belief, std::optional<double> pan_now);
  GazeReason reason() const { return reason_; }
  /// The pan last commanded [rad] (0 before any).
  double commanded_pan() const { return commanded_pan_; }
  const HeadGazeConfig& config() const { return config_; }

 private:
  /// The pan that points the camera at p_M from the base at X_MB, clamped [rad].
  double PanTowards(const Pose2& X_MB, const Eigen::Vector2d& p_M) const;

  HeadGazeConfig config_;
  GazeReason reason_{GazeReason::kAhead};
  double commanded_pan_{0.0};
  bool sent_{false};
  int glance_id_{-1};
  Time glance_until_{};
  std::map<int, Time> glanced_at_;  ///< Track id -> when its glance began.
};

}  // namespace egress::behavior
