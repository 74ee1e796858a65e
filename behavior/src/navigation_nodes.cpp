#include "egress/behavior/proxemics.h"
#include "escort_room.h"
#include "escort_watch.h"
#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace egress::behavior::detail {
namespace {

// Plans and follows a path to `goal`. When the path ahead becomes blocked (an obstacle the map
// does not show), it plans again on the updated costmap; when the costmap has no way to the
// goal, it detours with the Bug2 local planner (round the obstacle's boundary by the laser).
// A goal someone stands on, or a detour that gives up, is planned again every `replan_period`
// for up to `patience` before the node fails. Someone coming towards the robot who would pass
// too near stops the drive: the robot makes way (TaskConfig::give_way), then plans again.
class NavigateTo final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("goal", "goal: a place of the building, or a pose x;y;yaw"),
            InputPort<double>("detour_speed", 0.2,
                              "speed of the Bug2 detour when the costmap has no path [m/s]"),
            InputPort<double>("patience", 15.0, "how long to keep re-planning a blocked goal [s]"),
            InputPort<bool>("door_speed", false,
                            "drive every segment at the door speed (TrajectoryConfig::door_speed): "
                            "a trip that cannot wait")};
  }
  NodeStatus OnStart() override {
    blocked_since_.reset();
    give_way_.Reset();
    detour_tried_ = false;
    goal_.reset();  // a place without a heading is resolved once, from where the robot starts
    return Start();
  }
  NodeStatus OnRunning() override {
    if (give_way_.active()) return GiveWay();
    if (task_.config.give_way && !task_.motion->bug_active() &&
        give_way_.Begin(task_, goal_, [this](const std::string& t) { Note(t); }))
      return GiveWay();
    if (blocked_since_) {
      if (ToSeconds(belief_.now - last_try_) < kReplanPeriod) return NodeStatus::kRunning;
      return Start();
    }
    if (!task_.motion->bug_active() && IsPathAheadBlocked(task_)) {
      task_.motion->StopBase();
      Note("the path ahead is blocked: planning again");
      return Start();
    }
    const NodeStatus s = BaseMotionStatus(task_, [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kFailure ? Blocked() : s;
  }
  void OnHalted() override {
    task_.motion->StopBase();
    give_way_.Reset();
  }

 private:
  static constexpr double kReplanPeriod = 0.5;  // [s]

  // Making way (WayGiver), then on to the goal.
  NodeStatus GiveWay() {
    const NodeStatus s = give_way_.Update(task_, goal_, Input<double>("patience"),
                                          [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kRunning ? s : Start();
  }

  NodeStatus Start() {
    last_try_ = belief_.now;
    if (!goal_) {
      try {
        goal_ = ResolveGoal(*task_.map, Input<std::string>("goal"), belief_.X_MB);
      } catch (const InvalidArgument& e) {
        Note(e.what());
        return NodeStatus::kFailure;
      }
    }
    const Pose2 goal = *goal_;
    // Quiet while re-planning: the first failure is noted, not every retry.
    const NodeStatus s = StartPath(
        task_, goal, "goal",
        [this](const std::string& t) {
          if (!blocked_since_) Note(t);
        },
        Input<bool>("door_speed"));
    if (s != NodeStatus::kFailure) {
      if (blocked_since_) Note("the way is free again");
      blocked_since_.reset();
      return s;
    }
    // No path on the costmap, though the goal itself is free: round the obstacle by the laser.
    if (!detour_tried_ && task_.planner->IsValid(goal)) {
      detour_tried_ = true;
      planning::BugConfig bug;
      bug.speed = Input<double>("detour_speed");
      bug.robot_radius = task_.config.footprint_radius;
      task_.motion->FollowBug(belief_.X_MB, goal.translation(), bug, belief_.now);
      Note("no path on the costmap: detouring round the obstacle (Bug2)");
      return NodeStatus::kRunning;
    }
    return Blocked();
  }
  NodeStatus Blocked() {
    if (!blocked_since_) {
      blocked_since_ = belief_.now;
      last_try_ = belief_.now;
      Note(StrCat("waiting up to ", Input<double>("patience"), " s for a way"));
    }
    if (ToSeconds(belief_.now - *blocked_since_) > Input<double>("patience")) {
      Note("gave up: the goal stayed blocked");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  std::optional<Time> blocked_since_;
  WayGiver give_way_;
  std::optional<Pose2> goal_;
  Time last_try_{};
  bool detour_tried_{false};
};

// The safe standby's retreat: the arm tucked and, with `back_off`, the base out of the door's
// way — to the last pose outside every door zone, unless people will come near it: then to
// where they will be farthest (out of their predicted path, not only back along its own; also
// out of a straight way through the robot's place for anyone near and coming nearer, and
// through the doorway for anyone near the visited door's far side or in its zone:
// PeopleHypotheses). The retreat starts once the base has stopped (a path begun at speed the
// other way leaves the reference behind and trips the watchdog).
class RetractToSafe final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<bool>("back_off", true, "also drive back out of the door's way"),
            VisitPort(bt::PortDirection::kInput), RetreatingPort(bt::PortDirection::kOutput)};
  }
  NodeStatus OnStart() override {
    failure_noted_ = false;
    looked_back_ = false;
    looking_back_until_.reset();
    retreat_to_.reset();
    rechoices_ = 0;
    started_ = belief_.now;
    pending_ = Input<bool>("back_off") && belief_.last_safe &&
               (belief_.last_safe->translation() - belief_.X_MB.translation()).norm() > 0.05;
    // With nothing to back off to, a step out of someone's way under way (TraverseDoor's, halted
    // as they entered the door zone) is let end: it is the standby's own making way.
    const bool stepping = !pending_ && task_.motion->stepping_out_of_way();
    make_way_pending_ = !pending_ && !stepping && task_.config.give_way;
    if (!stepping) task_.motion->StopBase();
    if (!ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model)) ||
        task_.motion->arm_moving(belief_.now)) {
      task_.motion->MoveArm({{task_.config.arm_tuck_time, TuckedArm(*task_.model)}}, belief_.now);
      Note("tucking the arm");
    }
    if (pending_) {
      this->SetOutput("retreating", true);
      StartRetreatOnceStopped();
    }
    if (stepping) {
      this->SetOutput("retreating", true);
      Note("going on with the step out of people's way");
    }
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (pending_) {
      StartRetreatOnceStopped();
      return NodeStatus::kRunning;
    }
    if (IsRetreatHeldBack()) {
      // Chosen on a first glimpse of someone (a track a few frames old, its velocity still that
      // of their turn round the leaf), the way now heads where they go: stop and choose again.
      ++rechoices_;
      retreat_to_.reset();
      task_.motion->StopBase();
      pending_ = true;
      looked_back_ = true;  // no turning to look: someone is coming now
      started_ = belief_.now;
      Note("the way back heads where someone is going: choosing again");
      return NodeStatus::kRunning;
    }
    if (make_way_pending_) {
      if (!StoppedOrStopTimedOut(task_, started_)) return NodeStatus::kRunning;
      make_way_pending_ = false;
      MakeWayInPlace();
    }
    if (task_.motion->base_failed() && !failure_noted_) {
      // Blocked: stay, arm tucked.
      failure_noted_ = true;
      task_.motion->StopBase();
      Note("the retreat stopped: " + task_.motion->base_failure());
    }
    const bool busy = task_.motion->arm_moving(belief_.now) || task_.motion->base_moving();
    if (!busy) this->SetOutput("retreating", false);
    return busy ? NodeStatus::kRunning : NodeStatus::kSuccess;
  }
  void OnHalted() override {
    task_.motion->StopBase();
    pending_ = false;
    make_way_pending_ = false;
    this->SetOutput("retreating", false);
  }

 private:
  // How far ahead people's paths are predicted [s].
  static constexpr double kPeopleHorizonSec = 3.0;

  // Nothing to back off to (the robot stands where it was last safe: at an actuator beside the
  // lane, say): while the arm tucks it makes way for anyone walking at it, or through the visited
  // door, as WaitForClear would after it — but the tuck takes 1.5 s, and a walker has passed by
  // then (P1: someone walking up behind the robot at the button to the door it opened; a step
  // aside under way as the door zone filled was stopped by this standby).
  void MakeWayInPlace() {
    const std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    PeopleHypotheses hypotheses;
    if (visit && task_.map->FindDoor(visit->door) != nullptr) hypotheses.through_door = visit->door;
    const std::optional<std::string> whom = WhomToMakeWayFor(task_, hypotheses.through_door);
    if (!whom) return;
    const auto spot = MakeWaySpot(task_, kMakeWayMinGainM, hypotheses);
    if (!spot) return;
    StepAsideTo(task_, *spot);
    this->SetOutput("retreating", true);
    Note(StrCat("making way for ", *whom, ": stepping aside to (", PoseText(*spot), ")"),
         DecisionEvent::kRetreating);
  }

  void StartRetreatOnceStopped() {
    if (!StoppedOrStopTimedOut(task_, started_)) return;
    if (looking_back_until_) {
      if (task_.motion->base_moving() || belief_.now < *looking_back_until_) return;
      looking_back_until_.reset();
    }
    pending_ = false;
    // Out of a doorway straight back along the door's normal first (a diagonal line would cut
    // the jamb or the leaf), then on.
    std::vector<Pose2> path{belief_.X_MB};
    const std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    bool stay_this_side = false;
    for (const auto& door : task_.map->doors) {
      const DoorPass pass = CalcKnownPass(task_, door.id, visit ? &*visit : nullptr);
      const Eigen::Vector2d offset = belief_.X_MB.translation() - pass.centre;
      const double along = offset.dot(pass.n_M);
      const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
      const double entry = EntryDistance(task_, door.id, pass);
      if (along < entry - 0.05 && along > -ExitDistance(task_, door.id) &&
          lateral < pass.width / 2 + 0.3) {
        // Past the door line, with the last safe pose beyond it too (it left the door's zone
        // on the far side, then halted back in it): on to that pose, not back through the
        // doorway (clinic family seed 2007: it backed through door_b as the leaf closed).
        if (along < 0.0 && (belief_.last_safe->translation() - pass.centre).dot(pass.n_M) < 0.0)
          break;
        // Past the door line, out of the leaf's reach, with someone near the doorway (walking
        // past it on this side): back through it would stand the robot in the doorway beside
        // them. It makes room on this side instead (two wards seed 14: halted a step into the
        // corridor, it backed into door_d's doorway as a resident hurried by, 3 s beside them).
        // In the leaf's sweep it backs out, as below: the leaf may be closing on it.
        if (along < 0.0 &&
            !door.InSweep(belief_.X_MB.translation(),
                          task_.config.footprint_radius + kLeafClearance) &&
            IsPassageBusy(task_, door.id, kPeopleHorizonSec)) {
          stay_this_side = true;
          break;
        }
        const Eigen::Vector2d out = belief_.X_MB.translation() + pass.n_M * (entry - along);
        path.push_back({out.x(), out.y(), belief_.X_MB.yaw});
        break;
      }
    }
    // Whoever is near the far side of the door it was passing, or in its zone, may come through.
    PeopleHypotheses hypotheses{.head_on = true};
    if (visit && task_.map->FindDoor(visit->door) != nullptr) hypotheses.through_door = visit->door;
    std::optional<std::pair<Pose2, bool>> chosen;
    if (stay_this_side) {
      if (const auto aside = PeopleRoom(task_, kPeopleHorizonSec, hypotheses)
                                 .BestSpotAround(path, -std::numeric_limits<double>::infinity()))
        chosen = std::pair{*aside, true};
    } else {
      chosen = ChooseSpot(path, hypotheses);
    }
    if (!chosen && !looked_back_ && !stay_this_side) {
      // The way back may only be unseen: it is behind the robot, in the laser's blind sector
      // (two-wards seed 12: driving through door_d, halted for residents crossing the doorway's
      // far side, the robot stood 7 s in the doorway beside them, then the door shut on it).
      // Turn on the spot until it is inside the laser's sweep (no further: the base turns at
      // ~0.3 rad/s on average, and a whole turn took 9 s, the door shutting on the robot
      // meanwhile), and choose again once the laser has seen it.
      looked_back_ = true;
      std::vector<Eigen::Vector2d> back;
      for (const Pose2& p : path)
        back.push_back(p.translation());
      back.push_back(belief_.last_safe->translation());
      const std::optional<double> yaw = PeopleRoom(task_, kPeopleHorizonSec).YawSeeing(back);
      if (yaw && std::abs(std::remainder(*yaw - belief_.X_MB.yaw, 2 * M_PI)) > 0.0) {
        task_.motion->FollowPath({belief_.X_MB, {belief_.X_MB.x, belief_.X_MB.y, *yaw}}, {false},
                                 TuckedArm(*task_.model), belief_.now);
        looking_back_until_ = belief_.now + SecondsToDuration(kLookBackDwellSec);
        pending_ = true;
        Note("turning to see the way back");
        return;
      }
    }
    if (!chosen) {
      // Nowhere to go, at the visited door's actuator beside the lane before its doorway: a step
      // sideways along the door line, away from the opening, up to the wall, leaves whoever waits
      // before the door the way through (the clinic, one wheelchair user coming to door_e after
      // the robot's hold had ended: the robot stood at the standoff beside the lane, the leaf
      // opening towards them, and for 550 s they could not get between its edge and the robot).
      if (visit && task_.map->FindDoor(visit->door) != nullptr) {
        const DoorPass pass = CalcKnownPass(task_, visit->door, &*visit);
        const std::optional<Pose2> aside = InTheLane(pass, belief_.X_MB.translation(), task_.config)
                                               ? SqueezeAsidePose(task_, pass, visit->door)
                                               : std::nullopt;
        // Not nearer anyone: the step keeps the footprint + 0.1 m from them, as the retreat does.
        const auto roomy = [&](const Eigen::Vector2d& q) {
          const double body = task_.config.footprint_radius + 0.1;
          for (const auto& entry : belief_.world.people)
            if ((entry.person.p_MP - q).norm() < body + task_.config.person_radius) return false;
          for (const Eigen::Vector2d& p : belief_.off_map_returns)
            if ((p - q).norm() < body) return false;
          return true;
        };
        if (aside && roomy(aside->translation())) {
          task_.motion->FollowPath({belief_.X_MB, *aside}, {false}, TuckedArm(*task_.model),
                                   belief_.now, task_.config.retreat_speed, /*brisk=*/true);
          this->SetOutput("retreating", true);
          Note(StrCat("nowhere to back off to without passing someone: squeezing aside to ",
                      PoseText(*aside), ", out of the way through ", visit->door));
          return;
        }
      }
      Note("nowhere to back off to without passing someone: standing still");
      return;
    }
    const auto [spot, aside] = *chosen;
    if ((path.back().translation() - spot.translation()).norm() > 0.05) path.push_back(spot);
    if (path.size() < 2) return;
    retreat_to_ = spot.translation();
    task_.motion->FollowPath(path, std::vector<bool>(path.size() - 1, false),
                             TuckedArm(*task_.model), belief_.now, task_.config.retreat_speed,
                             /*brisk=*/true);
    this->SetOutput("retreating", true);
    const bool out_of_doorway_only =
        !aside && (spot.translation() - belief_.last_safe->translation()).norm() > 0.05;
    Note(aside ? StrCat("stepping aside, out of people's way, to (", PoseText(spot), ")")
         : out_of_doorway_only
             ? StrCat("backing out of the doorway to (", PoseText(spot),
                      "): the way on is not clear yet")
             : StrCat("backing off to the last safe waypoint (", PoseText(spot), ")"),
         DecisionEvent::kRetreating);
  }

  // Where the retreat that begins with `way` (the robot's pose, maybe a point out of the
  // doorway) ends, people predicted with `hypotheses`: the last safe pose if people will stay
  // comfort_distance from it; else, of the spots round the robot out of every door's way and
  // reachable in a straight line, the one where they will be farthest (less kWayCostPerM per metre
  // of way), if that beats the last safe pose. No way may pass nearer anyone than the footprint and
  // kPassMarginM (people where they are now: a retreat into someone standing behind the robot, P1
  // seed 2000). nullopt: every way does, unless the way's first leg, out of a doorway, is clear:
  // then its end. Second: whether it is a spot aside.
  std::optional<std::pair<Pose2, bool>> ChooseSpot(const std::vector<Pose2>& way,
                                                   const PeopleHypotheses& hypotheses) const {
    const Pose2 safe = *belief_.last_safe;
    const PeopleRoom room(task_, kPeopleHorizonSec, hypotheses);
    const double comfortable = task_.config.footprint_radius + task_.config.comfort_distance;
    std::vector<Eigen::Vector2d> corners;
    for (const Pose2& p : way)
      corners.push_back(p.translation());
    corners.push_back(safe.translation());
    const bool safe_ok = room.IsWayClear(corners) && !room.IsWayHeldBack(corners);
    if (safe_ok && room.Predicted(safe.translation()) >= comfortable) return std::pair{safe, false};
    const double beat = safe_ok ? room.Score(corners) : -std::numeric_limits<double>::infinity();
    if (const auto aside = room.BestSpotAround(way, beat)) return std::pair{*aside, true};
    if (safe_ok) return std::pair{safe, false};
    // Out of the doorway at least, where the way out is clear: a leaf may close on a robot
    // standing in it. (O2 seed 2005: halted just past the door line, the way on to the last
    // safe pose was in the laser's blind sector and, while the robot turned to see it, the
    // memory of where it had just driven ran out; it turned on in the doorway, and the closing
    // leaf struck it.)
    if (way.size() >= 2) {
      corners.pop_back();
      if (room.IsWayClear(corners) && task_.planner->IsPathValid(way))
        return std::pair{way.back(), false};
    }
    return std::nullopt;
  }

  // After turning to see the way back: long enough for the laser's people tracks to confirm
  // whoever stands there [s].
  static constexpr double kLookBackDwellSec = 0.5;
  // A retreat held back by the pace is chosen again at most this often.
  static constexpr int kMaxRechoices = 2;

  // Whether the retreat under way heads at someone (where they are or will be) so that the
  // executive's pace (ApproachSpeedScale) holds it to a crawl.
  bool IsRetreatHeldBack() const {
    if (!retreat_to_ || rechoices_ >= kMaxRechoices || !task_.motion->base_moving()) return false;
    const Eigen::Vector2d v_M = task_.motion->planned_velocity();
    return v_M.norm() >= kStoppedMps && IsHeldBackByPace(task_, v_M, *retreat_to_);
  }

  bool pending_{false};
  bool make_way_pending_{false};  ///< MakeWayInPlace once the base has stopped
  bool failure_noted_{false};
  bool looked_back_{false};
  std::optional<Time> looking_back_until_;     ///< turning to see the way back until then, at least
  std::optional<Eigen::Vector2d> retreat_to_;  ///< where the retreat under way ends
  int rechoices_{0};                           ///< retreats chosen again, held back
  Time started_{};
};

// Waits until the door zone has been clear as long as IsPathClear asks (the same hysteresis,
// from the belief), so the retry after a standby finds the path clear. Meanwhile it makes way
// (TaskConfig::give_way) for anyone walking at the robot to pass within comfort_distance, and for
// anyone near the door's far side or in its zone who, walking through the doorway, would: a step to
// MakeWaySpot with that hypothesis. The retreat chose its spot on what it knew then, often a
// first glimpse through the opening door (S2: a track a few frames old, barely moving; the
// robot stood at the last safe pose and the crosser passed 0.69 m from it).
class WaitForClear final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose zone to watch"),
            InputPort<double>("clear_for", 1.0,
                              "seconds the zone must have been clear (hysteresis) [s]"),
            InputPort<double>("timeout", 30.0, "give up after [s]")};
  }
  NodeStatus OnStart() override {
    started_ = belief_.now;
    next_make_way_ = belief_.now;
    stepping_ = false;
    Note("waiting for the door zone to clear");
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    MakeWay();
    // Not while stepping aside: the retry's path would start at speed the other way.
    if (!stepping_ && IsDoorZoneClearFor(task_, Door(), Input<double>("clear_for")))
      return NodeStatus::kSuccess;
    if (ToSeconds(belief_.now - started_) > Input<double>("timeout")) {
      if (stepping_) task_.motion->StopBase();
      Note("gave up waiting");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {
    if (stepping_) task_.motion->StopBase();
    stepping_ = false;
  }

 private:
  // [s] After a step aside (or finding none better), who is coming is looked at again after this.
  static constexpr double kMakeWayPeriodSec = 1.0;

  // A step under way is re-aimed, kReAimAfterSec into it, when a spot now leaves more room than
  // where it ends: who comes is often seen only once the step has begun (as HoldForResidents'
  // steps). It is only as good as people's tracked velocities: two wards seed 25's resident,
  // catching the robot up along the corridor at a step's end, read a third of their speed
  // until FusedPersonTracker measured a track's velocity afresh after it coasted.
  void MakeWay() {
    if (stepping_) {
      if (task_.motion->base_failed()) task_.motion->StopBase();  // blocked: stay where it is
      if (!task_.motion->base_moving()) {
        stepping_ = false;
      } else if (ToSeconds(belief_.now - step_since_) < kReAimAfterSec) {
        return;
      }
    }
    if (!task_.config.give_way || belief_.now < next_make_way_) return;
    // Stepping, the way to where it ends is judged by MakeWaySpot, whoever comes.
    std::optional<std::string> whom;
    if (!stepping_) {
      whom = WhomToMakeWayFor(task_, Door());
      if (!whom || !StoppedOrStopTimedOut(task_, started_)) return;
    }
    next_make_way_ = belief_.now + SecondsToDuration(kMakeWayPeriodSec);
    const auto spot = MakeWaySpot(task_, kMakeWayMinGainM, {.through_door = Door()},
                                  stepping_ ? std::optional(step_to_) : std::nullopt);
    if (!spot) return;
    StepAsideTo(task_, *spot);
    Note(StrCat(stepping_ ? "making way: re-aiming the step aside"
                          : StrCat("making way for ", *whom, ": stepping aside"),
                " to (", PoseText(*spot), ")"));
    stepping_ = true;
    step_to_ = spot->translation();
    step_since_ = belief_.now;
  }

  Time started_{};
  Time next_make_way_{};
  bool stepping_{false};
  Eigen::Vector2d step_to_{Eigen::Vector2d::Zero()};  ///< where the step under way ends
  Time step_since_{};                                 ///< when it began
};

}  // namespace

void RegisterNavigationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<NavigateTo>(factory, "NavigateTo", services);
  Register<RetractToSafe>(factory, "RetractToSafe", services);
  Register<WaitForClear>(factory, "WaitForClear", services);
}

}  // namespace egress::behavior::detail
