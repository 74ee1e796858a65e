#pragma once
/// @file
/// What a task node works with, handed to its constructor: TaskServices (the robot model, the
/// building map, the planner, the motion executor, the decision log and the read-only Belief)
/// and TaskConfig, the nodes' parameters. What nodes hand each other (a button plan, the side a
/// door is approached from, when the robot operated it, a retreat under way) is not here: it
/// travels on blackboard ports (DoorVisit, `retreating`), where the tree and Groot2 see it.

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "egress/behavior/belief.h"
#include "egress/behavior/head_gaze.h"
#include "egress/behavior/mission_map.h"
#include "egress/behavior/motion_executor.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/perception/world_state.h"
#include "egress/planning/base_planner.h"
#include "egress/planning/ik_solver.h"
#include "egress/planning/route_planner.h"

namespace egress::behavior {

struct TaskConfig {
  double footprint_radius{0.215};   ///< The HSR's round base [m].
  double door_entry_distance{0.7};  ///< Entry pose this far before the door line [m].
  double door_exit_distance{1.0};   ///< Exit pose at least this far past the door line [m]
                                    ///< (and beyond the leaf's sweep).
  /// Coming to a door that opens away from it from beside its lane (a button's standoff, from
  /// where the wall and the opening leaf hide the far side), the robot first stops at the lane's
  /// edge on the entry line, looking through the opening, until the leaf has stopped opening and
  /// it has looked this long; only then does it slide onto the axis. People waiting for the door
  /// on the far side set off as it opens, and a robot already in the lane meets them there. 0:
  /// straight onto the axis [s].
  double door_peek_time{0.5};
  /// ... and stops there turned this far from facing through the door towards the lane (the way
  /// it goes). The laser, at the base's front, then stands nearer the lane and sees more of the
  /// far side past the jamb: someone stepping out from behind the opening leaf is seen sooner.
  /// Measured over 100 trials each against square (0): 10th percentile of the closest approach
  /// H12 0.63 -> 0.73 m, P5 0.59 -> 0.71 m, worst H2 0.59 -> 0.80 m, nothing worse; 10 deg
  /// changed little, 25 about the same, 45 stretched the legs (the turn within
  /// TrajectoryConfig::max_yaw_rate) past what the hold window leaves for the stop. The slide
  /// onto the axis turns it back. 0: square [deg].
  double door_peek_turn_deg{20.0};
  /// How long an ADA operator holds its door open (the paper's ~10 s auto-close window): a held
  /// door is passed only if the robot can clear the leaf's sweep within it [s].
  double door_hold_window{10.0};
  /// A door still steady this long past the window is held by someone out of sight (the
  /// holder often stands behind the jamb) [s].
  double door_hold_margin{2.0};
  /// Before driving through a door the robot waits at its entry pose (outside the doorway)
  /// while someone would come within this of the opening's middle during the pass, at the
  /// velocity they are tracked at: a robot driving through then stood in the doorway beside
  /// people walking past it (the doorway rule of the evacuation study, a resident within 2 m).
  /// 0: no wait [m].
  double passage_clearance{2.0};
  /// ... and until nobody has been within passage_clearance of the opening's middle for this
  /// long: from the entry the robot sees a metre or so either way along the passage beyond, and
  /// someone walking it comes into view a second before the doorway; people seen passing it
  /// lately are the sign of a stream still walking by (two wards seed 35) [s] ...
  double passage_quiet_time{5.0};
  /// ... for at most this long; then it goes (the reactive door-zone check still stops it for
  /// anyone stepping into the zone) [s].
  double passage_max_wait{10.0};
  double zone_depth{1.0};     ///< People-free zone each side of a door line [m].
  double person_radius{0.3};  ///< [m]
  /// A person the tracker classifies as crossing a door (their straight path goes through its
  /// opening within IntentConfig::crossing_horizon, 2 s) occupies its zone already: the robot
  /// yields before they arrive, not when they are 0.8 s away (the paper's forecast).
  bool yield_to_crossing{true};
  /// Right of way at a door that has just opened: someone on its far side within this of the
  /// doorway's centre, not walking away, was waiting for it and comes through first [m] ...
  double right_of_way_radius{2.5};
  /// ... while the opening is younger than this; someone still standing there after it is
  /// not coming, and the robot goes [s]. 0 (the default): no right of way. (Also tried: after
  /// its own press, the robot waiting beside the door this long past the operator's opening
  /// time, for people it cannot see from there; the wait ate the hold window, and a re-press on
  /// a door the robot could not see open from the actuator left too little of it: S2 seeds
  /// 2000-2003, 4/4 -> 0/4 with 2 s. Removed.)
  double right_of_way_time{0.0};
  /// Before lining up from beside a door's lane (its actuator's standoff), the robot watches
  /// anyone for the door on its side within this of the doorway's centre (TraverseDoor's
  /// SomeoneForTheDoor: standing in front of the doorway, or walking at its opening; not holding
  /// the door aside), the head turned to them: someone standing there may have waited for the
  /// door and sets off as it opens, walking up behind the robot (P4 seed 2073: seen standing
  /// 3.4 m back while the robot pressed, they set off as it drove to the lane's edge, out of
  /// view, and passed it 0.39 m off). It first steps along the door line away from the lane,
  /// clear of their straight way in (comfort_distance, at most 0.6 m), makes way if they come,
  /// and lines up after near_waiter_time if they stay. For someone standing, only when the hold
  /// window leaves time for the watch, the line-up and the pass. 0: no watch [m] ...
  double near_waiter_radius{4.0};
  /// ... [s], from the line-up's start; 0: no watch.
  double near_waiter_time{2.0};
  /// The gap the robot keeps from people where it can (surface to surface; personal space is
  /// 0.45-1.2 m): a standby retreat goes where people will stay at least this far [m].
  double comfort_distance{0.8};
  /// A standby retreat's speed: a quintic from rest at the paper's 0.2 m/s covers 4 cm in its
  /// first second [m/s].
  double retreat_speed{0.4};
  /// Making way on the move (NavigateTo): someone walking towards the robot who would pass
  /// within comfort_distance of it within give_way_horizon [s] stops the drive; the robot steps
  /// to where they will leave it the most room (out of their way, e.g. to a corridor's wall)
  /// or stands still, and goes on once nobody has been coming for give_way_clear_for [s]. A
  /// robot that stops in the middle of a 2 m corridor is walked into (P2).
  bool give_way{true};
  double give_way_horizon{4.0};
  double give_way_clear_for{1.0};
  /// Where the robot stands aside for people walking past (a give-way), they step round it
  /// too: a predicted position may move sideways (across the walk) by up to
  /// person_sidestep_speed [m/s] times how far ahead it is, at most person_sidestep [m], as far
  /// as the walls leave room. A spot at a corridor's wall then leaves the group the corridor; a
  /// spot in its middle leaves a squeeze on each side (P2: every spot aside read as worse than
  /// the middle on the straight lines, and the group walked into the robot). 0: straight lines.
  double person_sidestep{1.0};
  double person_sidestep_speed{0.4};
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
  /// The building-scale route (PlanRoute): clearance, where to wait before doors.
  planning::RoutePlannerConfig route;
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
  kRelocalizing,      ///< A precise act waits for the pose to settle (re-localizes) first.
};

/// One note of a node: its event and its text.
struct NodeNote {
  DecisionEvent event{DecisionEvent::kNote};
  std::string text;
};

/// The decisions the nodes record, drained by the executive each tick into the run's log.
class DecisionLog {
 public:
  void Record(DecisionEvent event, std::string text) { notes_.push_back({event, std::move(text)}); }
  /// What was recorded since the last Take, oldest first; the log is empty afterwards.
  std::vector<NodeNote> Take() { return std::exchange(notes_, {}); }
  /// What was recorded since the last Take (tests read it).
  const std::vector<NodeNote>& pending() const { return notes_; }

 private:
  std::vector<NodeNote> notes_;
};

/// The robot's dealings with one door, shared by the door nodes on a blackboard port (`visit`,
/// default key `{door_visit}`): each DoorTraversal subtree instance has its own blackboard, so a
/// traversal starts with a fresh visit and keeps it across its retries after a yield.
struct DoorVisit {
  std::string door;  ///< The door the visit is to; a node at another door starts a new visit.
  /// The unit normal of the door line pointing to the side the robot came from: fixed when it
  /// first works at the door, so a robot caught mid-doorway still knows which way is forward;
  /// cleared once it is through, so it can come back the other way.
  std::optional<Eigen::Vector2d> approach_side;
  std::optional<ButtonPlan> button_plan;  ///< ApproachButton's, for PressButton / WaveAtPlate.
  /// When the robot's hand reached the actuator to press or wave (the operator's hold window
  /// starts soon after, whether or not the door is seen opening).
  std::optional<Time> operated_at;
  /// Set when a press or wave found the door already open: the operator restarted its hold
  /// window when the hand reached the actuator (operated_at).
  std::optional<Time> window_restarted_at;
  /// Since when the robot has waited at the entry for people passing the doorway
  /// (TaskConfig::passage_max_wait counts from here, across a retry's new press: a wait that
  /// outlasted one opening would otherwise begin again with the next, clinic family seed 2005).
  std::optional<Time> passage_wait_began;
  /// When ApproachButton last turned to look at an actuator's standoff it found blocked (what
  /// blocked it may have gone out of sight: it looks again only so often).
  std::optional<Time> standoff_looked_at;
};

/// A grasp, planned by PlanGrasp and carried out by the grasp leaves after it (DriveToGrasp,
/// ReachForPayload, CloseGripper, LiftPayload; behavior/trees/grasp.xml) on a blackboard port
/// (`grasp`, default `{grasp}`).
struct GraspPlan {
  Eigen::Vector3d p_MC{Eigen::Vector3d::Zero()};  ///< Grasp centre in M [m]; refined on the way.
  /// Unit axis in M the palm comes in along: horizontal, or straight down for a low payload.
  Eigen::Vector3d approach_M{Eigen::Vector3d::UnitX()};
  double surface_z{0.0};  ///< Height of what the payload rests on [m].
  std::string kind;       ///< bottle, flashlight, ... (how it stands)
  Pose2 X_MB;             ///< Where the base stands for the grasp (whole-body IK).
  /// The arm there (whole-body IK); once ReachForPayload has solved it from where the base
  /// stopped, the arm at the grasp.
  ArmPose arm{};
  /// The pre-grasp stands this far short of p_MC along approach_M [m]: beyond the default, in
  /// front of something low before the payload, so that the hand, swinging up into it, does
  /// not come up through that (it then goes in level, over it).
  double pre_offset{0.12};
};

/// A release of the held payload (placing it, or handing it over), planned by PlanPlacement or
/// PlanHandOver and carried out by the release leaves after it (DriveToRelease, ReachToRelease,
/// WaitForRecipient, OpenGripper, WithdrawArm; behavior/trees/release.xml) on a blackboard port
/// (`release`, default `{release}`).
struct ReleasePlan {
  Eigen::Vector3d p_MC{Eigen::Vector3d::Zero()};  ///< Where the payload's centre goes, in M [m].
  Eigen::Vector3d approach_M{Eigen::Vector3d::UnitX()};  ///< Unit horizontal approach in M.
  ArmPose arm{};      ///< The arm at the release (whole-body IK; DriveToRelease).
  ArmPose pre_arm{};  ///< The arm short of it, which the hand withdraws through (ReachToRelease).
  /// How far the release point may come back along approach_M when the base pose whole-body IK
  /// gives for it is not free (a hand-over: the responder's own laser returns, inflated, can
  /// cover it); 0 for a placement, whose point is where the payload must land [m].
  double give{0.0};
};

struct ProxemicsConfig;

/// What the task nodes act through, handed to each at construction. The executive owns every
/// piece and keeps them alive as long as its trees.
struct TaskServices {
  const RobotModel* model{nullptr};
  const MissionMap* map{nullptr};
  TaskConfig config;
  MotionExecutor* motion{nullptr};
  const planning::BasePlanner* planner{nullptr};
  DecisionLog* log{nullptr};
  /// Where the head looks; nodes ask it for a view they need (RequestLook). May be null (no
  /// head control, e.g. in node tests).
  HeadGaze* gaze{nullptr};
  /// The robot's belief, refreshed by the executive before every tick; read-only to the nodes.
  const Belief* belief{nullptr};
  /// How the executive slows the base near people (ApproachPace): a step aside it would hold
  /// to a crawl is no step aside. May be null (no pace, e.g. in node tests).
  const ProxemicsConfig* proxemics{nullptr};
};

}  // namespace egress::behavior
