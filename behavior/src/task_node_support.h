#pragma once
// Internal to behavior/src: what the task-node families share — the TaskNode base, motion and
// path helpers, arm IK at a fixed base, the door constants — and each family's registration.
// Not installed; the public face is egress/behavior/task_nodes.h.

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "egress/behavior/door_rules.h"
#include "egress/behavior/task_nodes.h"
#include "egress/behavior/task_services.h"
#include "egress/bt/factory.h"
#include "egress/hsr_interface/error.h"

namespace egress::behavior::detail {

using bt::InputPort;
using bt::NodeConfig;
using bt::NodeStatus;
using bt::OutputPort;
using bt::PortsList;
using NoteFn = std::function<void(const std::string&)>;
using EventNoteFn = std::function<void(const std::string&, DecisionEvent)>;

inline constexpr double kArmTolerance = 0.02;        ///< [rad or m] the arm counts as at a pose
inline constexpr double kPathLookahead = 1.5;        ///< [m] of the path ahead checked for blockage
inline constexpr double kDoorSeenRecentlySec = 0.5;  // [s] a door estimate this fresh is "now"
// [s] A node's look request lasts this long: the node renews it each tick while it needs the view.
inline constexpr double kLookRequestSec = 0.5;
inline constexpr double kLeafClearance = 0.15;  // [m] kept between the footprint and a leaf's sweep
// [s] A low-energy ADA operator takes at least this long to open (ANSI A156.19: >= 3 s to the
// back check), and at most about the second: the hold window starts in between.
inline constexpr double kOperatorMinOpeningTime = 3.0;
inline constexpr double kOperatorOpeningTime = 4.0;
// [rad/s] The fastest a low-energy operator may close its door (A156.19: no less than 3 s from
// 90° to 10°).
inline constexpr double kOperatorMaxClosingRate = (80.0 * M_PI / 180.0) / 3.0;
// [s] From the end of its hold to latched, about: A156.19 allows no less than 3 s from 90° to 10°,
// then the latch check (the twin's operator: 3.5 s + 1.5 s).
inline constexpr double kOperatorClosingTime = 5.0;

bool ArmAt(const ArmPose& a, const ArmPose& b);
/// "x, y" rounded to centimetres: for notes people read.
std::string PoseText(const Pose2& X);
/// "x;y;yaw" in full precision: for a pose port (ParsePose2 reads it back exactly).
std::string PosePortText(const Pose2& X);

// Base for the nodes: the read-only belief, the services, typed inputs that fail the node
// loudly, and the door visit shared with the other door nodes on the `visit` port.
template <typename Base>
class TaskNode : public Base {
 public:
  TaskNode(const std::string& name, NodeConfig config, const TaskServices* services)
      : Base(name, std::move(config)), task_(*services), belief_(*services->belief) {}

 protected:
  template <typename T>
  T Input(std::string_view port) const {
    auto value = this->template GetInput<T>(port);
    if (!value) throw InvalidArgument(value.error());
    return *value;
  }
  /// A port's value, or nullopt when it names a blackboard entry nobody has written yet (state
  /// another node leaves, e.g. a visit or a retreat). Any other problem fails loudly.
  template <typename T>
  std::optional<T> Shared(std::string_view port) const {
    const std::optional<std::string> text = this->PortText(port);
    if (text) {
      if (const auto key = bt::BlackboardKeyOf(*text, port);
          key && !this->config().blackboard->Has(*key)) {
        return std::nullopt;
      }
    }
    return Input<T>(port);
  }
  std::string Door() const { return Input<std::string>("door"); }
  /// Asks the head to look at p_M (in M) for the next kLookRequestSec (HeadGaze::RequestLook).
  void LookAt(const Eigen::Vector3d& p_M) const {
    if (task_.gaze != nullptr)
      task_.gaze->RequestLook(p_M, belief_.now + SecondsToDuration(kLookRequestSec));
  }
  /// At a door's actuator (driving to it, squaring up, operating it): facing the wall there, the
  /// laser's blind sector is the room people come from, and the head may watch it for the next
  /// kLookRequestSec (HeadGaze::WatchBehind, rule 4).
  void WatchBehind() const {
    if (task_.gaze != nullptr)
      task_.gaze->WatchBehind(belief_.now + SecondsToDuration(kLookRequestSec), Door());
  }
  /// The visit to this node's door on the `visit` port; a new one if there is none yet or the
  /// port holds a visit to another door.
  DoorVisit Visit() const {
    const std::string door = Door();
    std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    if (visit && visit->door == door) return *visit;
    DoorVisit fresh;
    fresh.door = door;
    return fresh;
  }
  void Remember(DoorVisit visit) { this->SetOutput("visit", std::move(visit)); }
  void Note(const std::string& text, DecisionEvent event = DecisionEvent::kNote) const {
    task_.log->Record(
        event, StrCat(this->name().empty() ? this->registration_id() : this->name(), ": ", text));
  }
  /// A note function for helpers that record typed events too.
  EventNoteFn EventNoter() const {
    return [this](const std::string& t, DecisionEvent e) { Note(t, e); };
  }
  const TaskServices& task_;
  const Belief& belief_;  ///< Refreshed by the executive before every tick.
};

/// The `visit` port of the door nodes (see DoorVisit): read by conditions, read and written by
/// the actions.
inline std::pair<std::string, bt::PortInfo> VisitPort(bt::PortDirection direction) {
  auto port = bt::BidirectionalPort<DoorVisit>(
      "visit",
      "the robot's dealings with this door (approach side, button plan, when it operated it), "
      "shared by the door nodes",
      "{door_visit}");
  port.second.direction = direction;
  return port;
}

/// The `retreating` port: RetractToSafe writes whether its retreat is under way, IsPathClear
/// reads it (a retreat is finished before the robot resumes).
inline std::pair<std::string, bt::PortInfo> RetreatingPort(bt::PortDirection direction) {
  auto port = bt::BidirectionalPort<bool>(
      "retreating", "a standby retreat to the last safe waypoint is under way", "{retreating}");
  port.second.direction = direction;
  return port;
}

/// How the base's heading goes along a path StartPath starts.
enum class PathHeading {
  /// From the start yaw to the goal's evenly along the path (the base is holonomic).
  kEvenTurn,
  /// Facing the way it drives on a path longer than kFaceTravelBeyondM (turning on the spot
  /// first when that way is more than kFaceTravelTurnFirstRad off), ending facing along the
  /// last segment, not the goal's yaw: the laser's blind sector is behind the robot, and a
  /// long drive backwards meets whoever stands in its way unseen (two-wards seed 12). Shorter
  /// paths: as kEvenTurn.
  kAlongTravel,
  /// As kAlongTravel, but facing square to the way it drives (to the side nearer its heading at
  /// the start, the same side all the way): the laser's 270 degrees then see ahead along the way
  /// and back along it, the blind sector facing the side. Driving ahead of people who walk the
  /// same way faster (residents after the robot along a corridor), one who came up behind it was
  /// never seen, under kAlongTravel, until they touched it (two wards seed 3).
  kAcrossTravel,
};
/// Paths at least this long are driven facing the way of travel (or square to it) under
/// PathHeading::kAlongTravel (kAcrossTravel).
inline constexpr double kFaceTravelBeyondM = 2.0;
/// Under those, a start heading more than this off the first segment's is
/// turned on the spot before driving (within it, the turn is spread along the first segment).
inline constexpr double kFaceTravelTurnFirstRad = M_PI / 3;

/// A way is seen when the base laser sweeps, from the pose at each end of a segment, the point
/// this far ahead of the footprint along it [m] (IsInLaserSweep): where the base drives next.
inline constexpr double kBlindLookAheadM = 0.3;
/// A path whose yaws (any PathHeading) would drive more than this into the laser's blind sector
/// (backwards, or sideways past the sweep's edge) is driven facing the way of travel instead
/// (FaceTravel) [m]: someone standing behind the robot is never seen there, and it drove into
/// residents standing round it as an evacuation began (random buildings of
/// worlds/tools/make_random_building.py, 6 of 18: an approach to the button behind the robot,
/// planned through the group it stood in, backed into one of them at 0.06 m/s). Less than this
/// (a square-up, an escape step) is driven as planned.
inline constexpr double kBlindTravelToleranceM = 0.3;
/// Metres of `path` (the robot's pose first, yaws as it will drive them) on which the way ahead
/// is not in the base laser's sweep (kBlindLookAheadM).
double BlindTravel(const TaskServices& task, const std::vector<Pose2>& path);
/// Re-heads `path` to face along each segment (turning on the spot first where a segment turns
/// more than kFaceTravelTurnFirstRad from the heading before it), then on the spot at its end to
/// `goal_yaw`. Yaws stay continuous (no wrap between poses).
void FaceTravel(std::vector<Pose2>* path, double goal_yaw);

/// Plans from the robot to `goal` on the costmap and starts following the path; `door_speed`
/// runs every segment at the door speed (a door approach inside the hold window); `heading`:
/// how the base turns along it. RUNNING while the base moves, SUCCESS if already there, FAILURE
/// (noted) without a path.
NodeStatus StartPath(const TaskServices& task, const Pose2& goal, const std::string& what,
                     const NoteFn& note, bool door_speed = false,
                     PathHeading heading = PathHeading::kEvenTurn);
/// The base motion under way: RUNNING, SUCCESS when it ended, FAILURE (noted) when the
/// watchdog stopped it.
NodeStatus BaseMotionStatus(const TaskServices& task, const NoteFn& note);
/// The arm motion under way: RUNNING while the joints travel, FAILURE (the joint that stopped
/// short, noted) when they did not arrive in time, SUCCESS once they are at the target.
NodeStatus ArmMotionStatus(const TaskServices& task, const NoteFn& note);
/// The next kPathLookahead metres of the path being followed cross lethal or inscribed cost.
bool IsPathAheadBlocked(const TaskServices& task);
/// BaseMotionStatus for a planned drive that plans again when the path ahead becomes blocked.
NodeStatus DriveStatus(const TaskServices& task, const NoteFn& note, bool door_speed = false);
/// Arm-only IK at a fixed base pose; `accept_error` [m] accepts a solve that ends this close.
/// Where the arm cannot also hold the target's approach axis, the position alone is solved (a
/// press at a slant), unless `allow_slant` is false: then nullopt.
std::optional<ArmPose> SolveArm(const TaskServices& task, const Pose2& X_MB,
                                const planning::IkTarget& target, const ArmPose& from,
                                bool fingertip, double accept_error = 0.0, bool allow_slant = true);
/// Arm-only IK for `steps` points evenly along the straight line from `from_target` (where the
/// arm `from` already is) to `to_target`, each solved warm from the one before: knots that keep
/// a press on the button's normal instead of the curve a joint-space move would draw. nullopt
/// if a point is out of reach.
std::optional<std::vector<ArmPose>> SolveArmLine(const TaskServices& task, const Pose2& X_MB,
                                                 const planning::IkTarget& from_target,
                                                 const planning::IkTarget& to_target,
                                                 const ArmPose& from, bool fingertip, int steps);
/// The belief's estimate of `door`, or nullptr if the world model has none.
const perception::TrackedDoor* FindTrackedDoor(const perception::WorldState& world,
                                               const std::string& door);
/// Far enough past the door line that the closing leaf cannot reach the footprint [m].
double ExitDistance(const TaskServices& task, const std::string& door);
/// The middle of `door`'s clear opening [M], between its latch jamb and its leaf at the angle
/// last estimated (a leaf never seen: square to the door line): the way through an open door.
Eigen::Vector2d ClearOpeningCentre(const TaskServices& task, const std::string& door);
/// How far the localizer may be unsure of the robot's position [m, one standard deviation] for a
/// drive through `door`: a 3σ error across its clear opening (the leaf fully open) still leaves
/// the footprint inside it; never tighter than config.precise_pose_sigma. A 0.9 m door and the
/// HSR's 0.215 m footprint radius give about 7 cm. (Held to the press's 2 cm, the pass waited
/// 3 s after the press, standing, for a pose that stood at 20-23 mm north of the clinic's
/// door_e, and then found the door's window too short: two wards seed 10 failed it 8 times.)
double DoorPassPoseSigma(const TaskServices& task, const std::string& door);
/// How far before the door line the robot lines up and waits [m].
double EntryDistance(const TaskServices& task, const std::string& door, const DoorPass& pass);
/// The robot's way from X_MB_from onto `door`'s axis, at EntryDistance, facing through it:
/// straight, or, on the side the leaf opens into from nearer the door line than that, out
/// beyond the leaf's sweep first and then across (a straight line from beside the hinge, a
/// button's standoff, would cut the opening leaf). Starts with X_MB_from.
std::vector<Pose2> LineUpPath(const TaskServices& task, const std::string& door,
                              const DoorPass& pass, const Pose2& X_MB_from);
/// How long the trajectories take along `path` at the door speed, turns included [s].
double DoorPathDuration(const TaskServices& task, const std::vector<Pose2>& path);

/// A person's body (centre and radius) or a scan return off the map (radius 0), in M, now or
/// predicted `t` seconds ahead.
struct Occupant {
  Eigen::Vector2d p_M{Eigen::Vector2d::Zero()};
  double radius{0.0};  ///< [m]
  double t{0.0};       ///< how far ahead [s]; 0: now (scan returns are always now)
  Eigen::Vector2d v_M{Eigen::Vector2d::Zero()};  ///< a person's predicted velocity [m/s]
};
/// Where the people near `at` (within `look` [m]) are and will be: each tracked person now and
/// at their velocity every `step` [s] up to `horizon` [s] (a way predicted into a wall ends
/// there), and the latest scan's returns off the map.
std::vector<Occupant> PeopleAround(const TaskServices& task, const Eigen::Vector2d& at, double look,
                                   double horizon, double step);
/// [m] People this near a door's opening may go through it (ThroughDoorWays).
inline constexpr double kThroughDoorRadiusM = 3.0;
/// [m] People on the robot's side walking at a door's opening this near it may go through it
/// (ThroughDoorWays): as far as people round the robot count (PeopleRoom::kPeopleLookM; P1's
/// walker, coming up behind the robot at the button, was 3.0 m from the opening when the robot
/// chose where to make way).
inline constexpr double kIntoDoorRadiusM = 5.0;
/// The ways of the people near `door`'s opening (not holding it aside) who may go through it:
/// within kThroughDoorRadiusM on its far side from the robot, or in its zone, unless walking away
/// from the opening faster than PeopleRoom::kSidestepMinMps, to the robot's side; within
/// kIntoDoorRadiusM on the robot's side out of the zone, walking at the opening at least that
/// fast, to the far side. Each walks
/// through the middle of the opening and on straight along the door's normal, at their speed or
/// kWalkingMps if faster: every PeopleRoom::kPeopleStepSec up to `horizon` [s], from the first
/// step on (where they are now is their tracked way's). People walk through a doorway's middle,
/// not along the line they happen to walk on (S2: a crosser tracked 0.27 m off the axis passed
/// 0.12 m off it).
/// @throws InvalidArgument for an unknown door.
std::vector<Occupant> ThroughDoorWays(const TaskServices& task, const std::string& door,
                                      double horizon);
/// Appends to `near` the way of someone at p_MP walking at v_MP, as PeopleAround predicts it:
/// every `step` [s] from `first_step` up to `horizon` [s], kept where within `look` of `at`.
void AppendPredictedWay(const TaskServices& task, const Eigen::Vector2d& at, double look,
                        double horizon, double step, int first_step, Eigen::Vector2d p_MP,
                        Eigen::Vector2d v_MP, std::vector<Occupant>& near);
/// The distance from `q` to the nearest edge among `near` (infinity for none) [m].
double RoomAt(const std::vector<Occupant>& near, const Eigen::Vector2d& q);

/// p_M is inside the base laser's sweep (less PeopleRoom::kSweepMarginRad each side) with the
/// base at X_MB, or under the robot; true without a scan (nothing to tell).
bool IsInLaserSweep(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_M);

/// p_M is in the base laser's sight with the base at X_MB: inside its sweep (IsInLaserSweep) and
/// with no wall, furniture or door leaf of the map (Costmap2D::IsNearMappedObstacle) on the
/// straight line from the laser to within kSightShortM of p_M (what stands at p_M is not in the
/// way). True without a costmap. A clear view of a place is what lets "nobody is there" be
/// counted: a table between the robot and a doorway hides whoever waits there.
inline constexpr double kSightShortM = 0.3;
bool IsInLaserSight(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_M);

/// The straight way from p_MFrom to p_MTo keeps `clearance` [m] beyond the footprint, where it
/// leaves the laser's sweep (base at X_MB), from what the laser marked there off the map (the
/// costmap's obstacle layer, kept where no ray clears it; Costmap2D::IsNearUnmappedMark): the
/// latest scan's returns, all else a step is judged on, cannot see there. Not the walls' marks:
/// walls are the map's (counted too, atrium seed 46's cornered robot found only a step across a
/// resident's way). True without a costmap.
bool IsBlindWayClear(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_MFrom,
                     const Eigen::Vector2d& p_MTo, double clearance);

/// The nearest point to p_MFrom of the grid p_MFrom + a * along + b * out (a in [0, max_along],
/// b in [0, max_out], both every `step` [m]; `along`, `out`: unit vectors, M) at least
/// `min_distance` [m] from it for which `ok` holds; nullopt if none. Ties: the smaller a, then b.
std::optional<Eigen::Vector2d> NearestOnGrid(const Eigen::Vector2d& p_MFrom,
                                             const Eigen::Vector2d& along, double max_along,
                                             const Eigen::Vector2d& out, double max_out,
                                             double step, double min_distance,
                                             const std::function<bool(const Eigen::Vector2d&)>& ok);

/// What people may do beyond walking on at their tracked velocity.
struct PeopleHypotheses {
  /// People walking past step round the robot (TaskConfig::person_sidestep): each predicted
  /// position is a short segment across the walk, and the room a spot leaves a person is from
  /// its far end. Not on a way through a doorway's middle (through_door): that is where they
  /// must go (P1: judged to step round the robot beside the opening, a walker passed it
  /// 0.64 m off).
  bool sidestep{false};
  /// Anyone walking within PeopleRoom::kHeadOnRadiusM and coming nearer may also walk on straight
  /// through the robot's place, at their speed: a velocity tracked while they veer round the robot
  /// points off their way (H12 seed 2086: someone through the door, tracked heading east as
  /// they skirted the halted robot, went on west; the retreat chose a spot 1 m west, across
  /// their way, and the robot drove into them).
  bool head_on{false};
  /// A door's id (empty: none): anyone near it who may go through it may also walk through its
  /// middle (ThroughDoorWays), either way: someone dawdling in a doorway as the leaf
  /// opens reads as standing until they stride out (S2: the crosser read 0.2-0.3 m/s in the
  /// doorway for 1.5 s, then passed the waiting robot 0.69 m off).
  std::string through_door{};
};

/// People's room round the robot, for choosing where to stand out of their way (a standby's
/// retreat, a give-way in a corridor): where the tracked people (and the latest scan's returns
/// off the map) are now and will be over `horizon` [s], and which straight ways pass them.
class PeopleRoom {
 public:
  PeopleRoom(const TaskServices& task, double horizon, PeopleHypotheses hypotheses = {});
  /// The distance from `q` to the nearest person's edge, now or predicted at any time [m].
  double Predicted(const Eigen::Vector2d& q) const;
  /// The least room people's predicted bodies leave the base while it drives `corners` (the
  /// robot's position first) as the motion executor would at retreat_speed: a quintic from rest
  /// to rest on each leg, then standing at the last corner; each predicted position of a person
  /// is compared with where the base is at that time, a scan return off the map with the spot
  /// [m]. A far spot reached too late for a fast walker scores as the place the robot still is
  /// when they pass (a 1.5 m retreat is a 3.75 s quintic, 7 % of its way after 0.8 s).
  double RoomOnTheWay(const std::vector<Eigen::Vector2d>& corners) const;
  /// The worth of the way through `corners` to the spot it ends at [m]: the least of the spot's
  /// predicted room (at any time: the robot will stand there) and RoomOnTheWay, capped at the
  /// footprint plus the comfort distance (beyond that all spots are as good), plus
  /// kSpotRoomTieBreak times the spot's room (ways that share a pass no way avoids — the walker
  /// is on the robot before it has moved — differ in where they end), less kWayCostPerM per
  /// metre from the robot to the spot.
  double Score(const std::vector<Eigen::Vector2d>& corners) const;
  /// The straight lines through `corners` pass nobody (where they stand now) nearer than the
  /// footprint and kPassMarginM, and stay inside the base laser's sweep (behind the robot, in
  /// its blind sector, nobody is seen: P1 seed 2000 backed into someone waiting there) or where
  /// the base has just driven facing that way (Belief::swept_p_MB).
  bool IsWayClear(const std::vector<Eigen::Vector2d>& corners) const;
  /// The heading nearest the robot's (in kLookTurnStepRad steps) from which the straight lines
  /// through `corners` are all inside the base laser's sweep: where to turn to see a way that
  /// is behind it. nullopt without a scan.
  std::optional<double> YawSeeing(const std::vector<Eigen::Vector2d>& corners) const;
  /// Of the spots round the robot (kSpotRadiiM x kSpotHeadings, at its heading) outside every
  /// door's zone, at least kSpotWallClearanceM beyond the footprint from every mapped wall,
  /// reachable from `way` (the robot's pose first) by a clear straight line the planner finds
  /// valid, and whose way the pace lets the robot drive (IsWayHeldBack): the best-scoring one,
  /// if it scores above `beat`.
  std::optional<Pose2> BestSpotAround(const std::vector<Pose2>& way, double beat) const;
  /// Whether the executive's pace (ApproachSpeedScale, TaskServices::proxemics) would hold the
  /// robot to a crawl from its first step along the straight lines through `corners` (the
  /// robot's position first): it heads at someone near, or where they will be. A retreat
  /// aside that way stands still (H12, P5: the runner from behind the leaf came through the
  /// doorway at the robot waiting on its axis; the spot chosen was on the side they were
  /// heading for, the pace stopped the robot after 3 cm, and they squeezed past at 5 cm).
  bool IsWayHeldBack(const std::vector<Eigen::Vector2d>& corners) const;

  static constexpr double kSpotRadiiM[] = {0.6, 1.0, 1.5};
  static constexpr int kSpotHeadings = 16;
  static constexpr double kPeopleStepSec = 0.2;      ///< predictions sampled every [s]
  static constexpr double kPeopleLookM = 5.0;        ///< people this far round count [m]
  static constexpr double kWayCostPerM = 0.2;        ///< a nearer spot wins a tie [m of room per m]
  static constexpr double kSpotRoomTieBreak = 0.05;  ///< see Score
  static constexpr double kPassMarginM = 0.1;        ///< beyond the footprint [m]
  /// A spot's gap to the walls [m]: the planner's pose check passes a footprint 3 mm off a wall
  /// (its inscribed cost, in 5 cm cells), and the base, turning there to watch, drifts that much
  /// (room A seed 29: stepped aside to 0.218 m from a wall, it touched it turning on the spot).
  static constexpr double kSpotWallClearanceM = 0.05;
  static constexpr double kPathSampleM = 0.05;  ///< ways checked this often [m]
  static constexpr double kSweepMarginRad = 10.0 * M_PI / 180.0;
  static constexpr double kLookTurnStepRad = 5.0 * M_PI / 180.0;  ///< see YawSeeing
  static constexpr double kSidestepSampleM = 0.05;  ///< sidesteps checked against walls this often
  static constexpr double kSidestepMinMps = 0.3;    ///< slower people are standing, not passing
  static constexpr double kHeadOnRadiusM = 1.5;     ///< see Hypotheses::head_on

 private:
  /// p is inside the laser's sweep with the base at X_MB (IsInLaserSweep), or where the base
  /// has just driven facing that way (Belief::swept_p_MB).
  bool IsSeenFrom(const Pose2& X_MB, const Eigen::Vector2d& p) const;
  /// Calls `f` on the points the straight lines through `corners` are checked at, the first
  /// corner excluded, until it returns false; false then.
  bool AllAlong(const std::vector<Eigen::Vector2d>& corners,
                const std::function<bool(const Eigen::Vector2d&)>& f) const;
  /// The room predicted_[i] leaves the base at p_MB [m].
  double RoomFrom(std::size_t i, const Eigen::Vector2d& p_MB) const;
  const TaskServices& task_;
  Eigen::Vector2d at_;
  std::vector<Occupant> predicted_;
  /// predicted_[i]'s sidestep: the two ends of the segment it may step across (both p_M
  /// without sidestep).
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> sidesteps_;
  std::vector<Occupant> now_;
};

/// [m/s] The base slower than this has stopped, as far as turning back goes: a step aside or a
/// retreat may start (from rest, where the base is), since the base stops from it within
/// ~0.1 s and 1 cm at its 1 m/s². Waiting for a standstill cost the reversal ~0.2 s more (a
/// stop, a BT tick, a new path's slow start), standing in a doorway beside a resident; [s] it is
/// given this long to stop before a step aside or a retreat starts anyway (a path begun at speed
/// the other way leaves the reference behind and trips the watchdog).
inline constexpr double kStoppedMps = 0.15;
inline constexpr double kStopWithinSec = 1.5;
/// [m/s] People slower than this are standing, not walking (a laser-tracked person standing
/// still reads 0.3-0.4 m/s now and then: the legs' midpoint jitters; the slowest walkers with a
/// frame go 0.6).
inline constexpr double kWalkingMps = 0.5;

/// Whether the executive's pace (ApproachSpeedScale with TaskServices::proxemics) would hold the
/// robot to a crawl heading along v_M [m/s] to p_MGoal: it heads at someone near, or where they
/// will be. False without a pace.
bool IsHeldBackByPace(const TaskServices& task, const Eigen::Vector2d& v_M,
                      const Eigen::Vector2d& p_MGoal);

/// The base has stopped (kStoppedMps), or has had kStopWithinSec since `since` to.
bool StoppedOrStopTimedOut(const TaskServices& task, Time since);

/// Making way for people on the move (NavigateTo's give-way; HoldForResidents letting people
/// walking up behind pass): the spot round the robot where they leave it the most room
/// (PeopleRoom::BestSpotAround, with sidesteps), their ways predicted twice the give-way horizon
/// — on past the robot: to the horizon alone they may stop short of it, and every spot would
/// look as good as standing in their way — if it leaves `min_gain` [m] more room than standing.
/// `hypotheses` beyond the sidestep (always on). With `stepping_to` (a step aside under way ends
/// there), the spot must leave that much more room than going on to it: the step is re-aimed.
std::optional<Pose2> MakeWaySpot(const TaskServices& task, double min_gain,
                                 PeopleHypotheses hypotheses = {},
                                 const std::optional<Eigen::Vector2d>& stepping_to = std::nullopt);
/// Starts the step to `spot` at retreat_speed, the arm held where it is going.
void StepAsideTo(const TaskServices& task, const Pose2& spot);

/// Making way for people walking at the robot (TaskConfig::give_way), for a node that drives:
/// Begin when someone is coming (PeopleComing) stops the base; once it has stopped, Update steps
/// to MakeWaySpot (or stands still if no spot leaves more room), and reports SUCCESS
/// give_way_clear_for after the last person seen coming has passed (by their last prediction,
/// at most kMaxPassSec ahead: a person the camera loses behind another is still coming), or
/// after `patience` [s]; RUNNING until then.
class WayGiver {
 public:
  /// [s] A slow walker far off is not waited for longer than this.
  static constexpr double kMaxPassSec = 15.0;
  /// True (and the base stopped, the person noted) if someone is coming; false otherwise.
  /// `goal`: whom the robot goes to, there, is not made way for (PeopleComing).
  /// `hypotheses`: what people may do beyond walking on, kept for Update (MakeWaySpot's); with
  /// a `through_door`, people walking through that door are coming too (PeopleComing's).
  bool Begin(const TaskServices& task, const std::optional<Pose2>& goal, const NoteFn& note,
             PeopleHypotheses hypotheses = {});
  NodeStatus Update(const TaskServices& task, const std::optional<Pose2>& goal, double patience,
                    const NoteFn& note);
  bool active() const { return since_.has_value(); }
  void Reset() { since_.reset(); }

 private:
  std::optional<Time> since_;
  Time until_{};                 ///< when the last person seen coming will have passed
  bool chosen_{false};           ///< the spot is chosen (once the base has stopped)
  PeopleHypotheses hypotheses_;  ///< Begin's
};
/// [m] The hand keeps this far off mapped walls on a step: its palm block's half-size and a
/// margin. Out at an actuator it reaches past the round footprint every step is checked with
/// (atrium west seeds 5 and 36: an operation broken off, a step towards the wall the robot
/// faced brushed it with the hand as the arm tucked).
inline constexpr double kHandWallClearanceM = 0.08;
/// Whether the hand (the palm) stays kHandWallClearanceM off every mapped wall (and leaf) along
/// the straight step of the base from `from` to `to` (its yaw kept), the arm where it is going
/// now (MotionExecutor::arm_target) or tucked anywhere on the way (a step tucks it, and the base
/// may be there before the arm): checked every 5 cm past the start. True without a costmap, a robot
/// model or a motion executor, and when the hand is that near a wall already at the start (a step
/// cannot be judged by it then).
bool HandClearOfWalls(const TaskServices& task, const Pose2& from, const Eigen::Vector2d& to);
/// [m] A spot aside must give this much more room than standing where the robot is.
inline constexpr double kMakeWayMinGainM = 0.1;
/// [s] A step aside under way is re-aimed (someone now comes at where it ends) only this long
/// after it began: a step starts from rest, and one re-aimed every tick hardly moves the robot.
inline constexpr double kReAimAfterSec = 1.0;
/// [m] Someone this near the robot's goal is whom it goes to, not someone to make way for (as
/// ProxemicsConfig::goal_radius).
inline constexpr double kGoalPersonRadiusM = 1.5;
/// The people the robot standing where it is should make way for (TaskConfig::give_way): walking
/// at it to pass within comfort_distance within give_way_horizon (OncomingPassTime), or, given
/// `through_door` (a door's id; empty: none), walking (PeopleRoom::kSidestepMinMps or faster) on
/// a way through its opening's middle (ThroughDoorWays) that passes within comfort_distance
/// within give_way_horizon; each with when they pass nearest [s from now] (on the way through
/// the door, its first point that near); whom the robot goes to (IsWhomTheRobotGoesTo, within
/// kGoalPersonRadiusM of `goal`) excepted.
/// @throws InvalidArgument for an unknown door.
std::vector<std::pair<const perception::TrackedPerson*, double>> PeopleComing(
    const TaskServices& task, const std::optional<Pose2>& goal,
    const std::string& through_door = {});

/// Whom the robot standing where it is should make way for, for the notes: "someone coming"
/// (PeopleComing), or "whoever comes through the doorway" if a way through `door`'s middle
/// (ThroughDoorWays over MakeWaySpot's horizon; empty door: none) passes within comfort_distance
/// of it; nullopt if neither.
/// @throws InvalidArgument for an unknown door.
std::optional<std::string> WhomToMakeWayFor(const TaskServices& task, const std::string& door);

/// The localizer's position standard deviation: the square root of the largest eigenvalue of
/// the xy block of the belief's covariance [m].
double PositionSigma(const TaskServices& task);

/// Holds a precise act until the pose is certain enough: when PositionSigma exceeds the act's
/// limit (config.precise_pose_sigma unless the act names its own), the base stands still while the
/// localizer corrects on scans of the walls and door around it, until it is below again or
/// config.relocalize_timeout passed.
class RelocalizeGate {
 public:
  /// A new act: forget any earlier wait.
  void Reset() {
    waiting_since_.reset();
    gave_up_ = false;
  }
  /// RUNNING while re-localizing; SUCCESS when the pose is good enough (or the wait timed out,
  /// noted: then SUCCESS until the next Reset, as another wait would end the same way). Each wait
  /// is noted as a DecisionEvent::kRelocalizing (the executive counts them).
  NodeStatus Check(const TaskServices& task, const std::string& act, const EventNoteFn& note,
                   std::optional<double> limit = std::nullopt);

 private:
  std::optional<Time> waiting_since_;
  bool gave_up_{false};  // a wait timed out in this act
};

/// Registers node type T under `id` with its ports; its nodes act through `services`.
template <typename T>
void Register(bt::BehaviorTreeFactory& factory, const std::string& id,
              const TaskServices* services) {
  bt::NodeManifest manifest;
  manifest.id = id;
  if constexpr (std::is_base_of_v<bt::ConditionNode, T>) {
    manifest.kind = bt::NodeKind::kCondition;
  } else {
    manifest.kind = bt::NodeKind::kAction;
  }
  manifest.ports = T::ProvidedPorts();
  factory.RegisterBuilder(std::move(manifest), [services](const std::string& name, NodeConfig c) {
    return std::make_unique<T>(name, std::move(c), services);
  });
}

// Each family registers its own nodes (condition_nodes.cpp, navigation_nodes.cpp,
// door_nodes.cpp, manipulation_nodes.cpp, grasp_nodes.cpp, release_nodes.cpp, route_nodes.cpp,
// escort_nodes.cpp).
void RegisterConditionNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterNavigationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterDoorNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
/// TraverseDoor (traverse_door.cpp), registered by RegisterDoorNodes.
void RegisterTraverseDoor(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterManipulationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterGraspNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterReleaseNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterRouteNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
void RegisterEscortNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
/// PlanSweep, FeederApproachPose, WatchDoorway (sweep_nodes.cpp): the escort's sweep.
void RegisterSweepNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);
/// IsNobodyComing (escort_guard.cpp), registered by RegisterEscortNodes.
void RegisterEscortGuard(bt::BehaviorTreeFactory& factory, const TaskServices* services);

}  // namespace egress::behavior::detail
