#pragma once
/// @file
/// TaskContext: what the task nodes share — the robot's latest belief (pose, world state), the
/// building map, the planner and the motion executor — and TaskConfig, their parameters. The
/// executive owns one and refreshes it every control step; the nodes read it when ticked.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "egress/behavior/mission_map.h"
#include "egress/behavior/motion_executor.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/perception/world_state.h"
#include "egress/planning/base_planner.h"
#include "egress/planning/ik_solver.h"

namespace egress::behavior {

struct TaskConfig {
  double footprint_radius{0.215};   ///< The HSR's round base [m].
  double door_entry_distance{0.7};  ///< Entry pose this far before the door line [m].
  double door_exit_distance{1.0};   ///< Exit pose at least this far past the door line [m]
                                    ///< (and beyond the leaf's sweep).
  /// How long an ADA operator holds its door open (the paper's ~10 s auto-close window): a held
  /// door is passed only if the robot can clear the leaf's sweep within it [s].
  double door_hold_window{10.0};
  /// A door still steady this long past the window is held by someone out of sight (the
  /// holder often stands behind the jamb) [s].
  double door_hold_margin{2.0};
  double zone_depth{1.0};        ///< People-free zone each side of a door line [m].
  double person_radius{0.3};     ///< [m]
  double arm_tuck_time{1.5};     ///< [s]
  double press_reach_time{2.0};  ///< Tucked → pre-press [s].
  double press_time{1.0};        ///< Pre-press → press → pre-press, each way [s].
  double wave_hold_time{1.5};    ///< Palm held at the plate [s].
  /// Button targets. The press aims 20 mm past the cap's face, at the wall plane behind a
  /// surface-mounted button: the cap switches after 4 mm, and odometry leaves the base up to a
  /// centimetre or two off its planned pose after a few metres (no contact sensing in the loop).
  planning::ButtonTargetsConfig buttons = [] {
    planning::ButtonTargetsConfig c;
    c.press_stroke = 0.02;
    return c;
  }();
  planning::IkConfig ik;  ///< For button presses (fingertip for push buttons).
  /// Precise acts (pressing or waving, grasping, lining up on a door) start only when the
  /// localizer's position standard deviation is at most this; above it the robot stands and
  /// re-localizes first [m].
  double precise_pose_sigma{0.02};
  /// ... for at most this long, then acts anyway (noted) [s].
  double relocalize_timeout{3.0};
  void Validate() const;
};

/// A press worked out by ApproachButton for PressButton / WaveAtPlate.
struct ButtonPlan {
  std::string actuator;  ///< Id of the button or plate in the mission map.
  planning::ButtonType type{planning::ButtonType::kPushButton};
  planning::ButtonTargets targets;
  Pose2 X_MB_standoff;     ///< Where the base stands (from whole-body IK).
  ArmPose approach_arm{};  ///< The arm there (seed for the arm-only solves; tucked if none).
};

/// What a node's note records beyond its text. The executive and tests read the event, never
/// the text (which is for people and may be reworded).
enum class DecisionEvent {
  kNote,              ///< A reason for the run log only.
  kPersonInDoorZone,  ///< A person is in or entering a door zone: the robot yields.
  kDoorZoneClear,     ///< The door zone is clear again (after the hysteresis).
  kRetreating,        ///< A standby retreat to the last safe waypoint starts.
  kResponderInReach,  ///< A hand-over's responder is within the arm's reach.
};

/// One note of a node: its event and its text.
struct NodeNote {
  DecisionEvent event{DecisionEvent::kNote};
  std::string text;
};

struct TaskContext {
  const RobotModel* model{nullptr};
  const MissionMap* map{nullptr};
  TaskConfig config;
  MotionExecutor* motion{nullptr};
  const planning::BasePlanner* planner{nullptr};

  // Refreshed every control step by the executive.
  Time now{};
  Pose2 X_MB;  ///< Localized base pose.
  perception::WorldState world;
  bool holding_object{false};
  std::optional<LaserScan> scan;  ///< The latest laser scan.
  /// The latest head depth image, the camera in M when it was taken, and its intrinsics.
  std::optional<DepthImage> depth;
  Pose3 X_MC;
  CameraIntrinsics depth_intrinsics;
  Pose2 X_BL;  ///< The laser in the base frame.
  /// The last pose at which the robot stood outside every door zone.
  std::optional<Pose2> last_safe;

  // Kept by the nodes.
  std::map<std::string, ButtonPlan> button_plans;  ///< Per door.
  std::map<std::string, Time> zone_occupied_at;    ///< Per door: when a person last was in it.
  /// Per door: the unit normal of the door line pointing to the side the robot came from
  /// (fixed when it first works at the door, so a robot caught mid-doorway still knows which
  /// way is forward; forgotten once it is through, so it can come back the other way).
  std::map<std::string, Eigen::Vector2d> door_approach_side;
  /// Per door: since when it has been open enough to pass in its current opening (kept by the
  /// executive from the angle estimate; a press restarts it).
  std::map<std::string, Time> door_open_since;
  /// Per door: when the robot's hand last reached its actuator to press or wave (the operator's
  /// hold window starts soon after, whether or not the door is seen opening).
  std::map<std::string, Time> door_operated_at;
  /// How often a precise act waited for the pose to settle (re-localized) first.
  int relocalizations{0};
  /// A standby retreat is under way: it is finished before the robot resumes.
  bool retreating{false};
  std::vector<NodeNote> notes;  ///< The nodes' reasons and decision events, for the run log.

  double now_s() const { return ToSeconds(now); }
  void Note(std::string text, DecisionEvent event = DecisionEvent::kNote) {
    notes.push_back({event, std::move(text)});
  }
};

}  // namespace egress::behavior
