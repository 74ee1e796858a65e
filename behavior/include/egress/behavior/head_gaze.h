#pragma once
/// @file
/// HeadGaze: where the head camera looks, decided each control step from the belief. The base
/// laser sees all round; the head camera (58 deg) only where it points, and it is the sensor that
/// confirms people and reads doors' far sides. So the head looks, in this order:
///   1. at a tracked person coming towards the robot from outside the camera's view, or in the
///      base laser's blind sector (where the camera alone measures them): a glance of
///      `glance_time`, kept on while they are still in the blind sector and coming, up to
///      `max_blind_glance`; then not at the same person for `glance_cooldown`;
///   2. at what the current task asks for (RequestLook: the payload it is finding or
///      grasping), with pan and tilt, while the request lasts;
///   3. through a door ahead of the robot (its centre within 90 deg of the heading: not one it
///      has passed) that it is near while that door is open or opening, or while the robot
///      operates its actuator (ExpectOpening; unless someone tracked is in the laser's blind
///      sector: they are watched until the leaf really moves, and while a task watches behind,
///      rule 4, as long as they are there): at the point `door_look_beyond`
///      past the doorway's centre, on its far side, where people wait for it and come through;
///   4. while a task asks (WatchBehind: at a door's actuator) and a wall is close ahead (every
///      laser return in the camera's view straight ahead nearer than `wall_ahead_range`), over
///      the laser's blind sector behind the base: ahead the camera would see only the wall, and
///      people walking up behind the robot to the door are in neither sensor's view (only on a
///      task's word: at a table, the default look ahead finds the payload). At the nearest
///      person tracked there (within `glance_range`: rule 3 leaves the door to them while the
///      task watches behind); else, given the door, at the point `approach_look_range` out from
///      its centre on the robot's side, where people walk up to it from, kept within the blind
///      sector (the laser sees the rest); else at `blind_look_pan_deg`;
///   5. straight ahead (pan 0, tilt 0), the paper's fixed gaze.
/// The tilt moves only for a task's request (a payload on a table below the camera, near the
/// robot, is below a level camera's view); people and doors are looked at level. Pan angles are
/// of head_pan_joint: 0 ahead along the base's x, + to the left; tilt of head_tilt_joint: 0
/// level, - down.

#include <map>
#include <optional>
#include <string>

#include "egress/behavior/belief.h"
#include "egress/hsr_interface/command_types.h"

namespace egress::behavior {

struct HeadGazeConfig {
  /// False: the head stays where it is (the fixed gaze of the paper).
  bool enabled{true};
  double camera_hfov_deg{58.0};  ///< The head camera's horizontal field of view.
  double glance_range{4.0};      ///< People nearer than this may get a glance [m].
  double approach_speed{0.3};    ///< Coming towards the robot at least this fast [m/s].
  double glance_time{1.0};       ///< [s]
  double glance_cooldown{3.0};   ///< [s] before the same person gets another glance.
  /// [s] A glance at someone still coming in the base laser's blind sector lasts while they
  /// are there, up to this long.
  double max_blind_glance{4.0};
  double door_look_range{3.0};     ///< Doors whose centre is nearer than this [m].
  double door_look_beyond{1.5};    ///< The point looked at past the doorway's centre [m].
  double door_open_fraction{0.1};  ///< A door at least this open (or opening) is looked through.
  /// The pan's range, head_pan_joint's limits on the HSR (-3.84 to 1.75 rad): the head turns
  /// right round past straight behind, to the left only to the side. A bearing is looked at
  /// the way round the range allows, the shorter from where the head is when both do.
  double min_pan_deg{-220.0};
  double max_pan_deg{100.0};
  double max_tilt_down_deg{60.0};  ///< The head never tilts further down than this.
  double max_tilt_up_deg{25.0};    ///< ... nor further up.
  double min_change_deg{3.0};      ///< A new target nearer than this to the last is not sent.
  /// [m] A wall this close ahead (rule 4) turns the head to the blind sector; 0: never.
  double wall_ahead_range{1.0};
  /// The pan of rule 4's look behind (within [min_pan_deg, max_pan_deg]) when no door is given
  /// or no scan says where the blind sector is.
  double blind_look_pan_deg{-180.0};
  /// [m] Rule 4 with a door: the point looked at out from the doorway's centre on the robot's
  /// side. Straight behind, the camera missed by 2 deg someone waiting 3.4 m back from the lab
  /// door to go through it (P4 seed 2073).
  double approach_look_range{3.0};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// What the head looks at, and why (for the run log).
enum class GazeReason { kAhead, kDoor, kPerson, kTask, kBehind };

class HeadGaze {
 public:
  explicit HeadGaze(HeadGazeConfig config = {});

  /// The head command to send this step, if the target changed (nullopt: keep the last one, or
  /// disabled). `pan_now` is the measured head_pan_joint angle [rad], if known.
  std::optional<HeadCommand> Update(const Belief& belief, std::optional<double> pan_now);
  /// A task's request: look at p_M (in M) until `until` (the robot clock); a node that needs
  /// the view renews it each tick. A later request replaces an earlier one.
  void RequestLook(const Eigen::Vector3d& p_M, Time until);
  /// The robot is operating `door`'s actuator: rule 3 takes the door as opening until `until`
  /// (the robot clock), so the head is turned through it by the time the leaf swings (from a
  /// look behind, the head takes 4 s to come round). Renewed each tick by the operating node.
  void ExpectOpening(const std::string& door, Time until);
  /// A task at `door`'s actuator: rule 4 may look behind until `until`, towards where people
  /// walk up to that door (empty, or a door not in the belief: straight behind). Renewed each
  /// tick.
  void WatchBehind(Time until, std::string door = {}) {
    watch_behind_until_ = until;
    watch_behind_door_ = std::move(door);
  }
  GazeReason reason() const { return reason_; }
  /// The pan last commanded [rad] (0 before any).
  double commanded_pan() const { return commanded_pan_; }
  /// The tilt last commanded [rad] (0 before any).
  double commanded_tilt() const { return commanded_tilt_; }
  const HeadGazeConfig& config() const { return config_; }

 private:
  /// The pan that points the camera at p_M from the base at X_MB [rad]: of the angles for that
  /// bearing within the pan's range, the nearest to `looking`; none, the nearer limit.
  double PanTowards(const Pose2& X_MB, const Eigen::Vector2d& p_M, double looking) const;
  /// True if every valid laser return within the camera's half view of straight ahead is
  /// nearer than wall_ahead_range (and there is at least one).
  bool WallAhead(const Belief& belief) const;
  /// The nearest tracked person within glance_range in the laser's blind sector, if any.
  std::optional<Eigen::Vector2d> NearestBehind(const Belief& belief) const;
  /// Rule 4's pan [rad]: at NearestBehind, else towards watch_behind_door_'s approach, within
  /// the blind sector.
  double BehindPan(const Belief& belief, double looking) const;
  /// True if p_M is outside the latest laser scan's angular range (no scan: false).
  bool InLaserBlindSector(const Belief& belief, const Eigen::Vector2d& p_M) const;
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
  Time glance_began_{};
  std::map<int, Time> glance_ended_;  ///< Track id -> when its last glance ended (or ends).
  Time watch_behind_until_{};
  std::string watch_behind_door_;
  std::map<std::string, Time> expected_opening_;  ///< ExpectOpening: door -> until.
};

}  // namespace egress::behavior
