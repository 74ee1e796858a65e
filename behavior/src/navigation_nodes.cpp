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
// for up to `patience` before the node fails.
class NavigateTo final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("goal", "goal: a place of the building, or a pose x;y;yaw"),
            InputPort<double>("detour_speed", 0.2,
                              "speed of the Bug2 detour when the costmap has no path [m/s]"),
            InputPort<double>("patience", 15.0, "how long to keep re-planning a blocked goal [s]")};
  }
  NodeStatus OnStart() override {
    blocked_since_.reset();
    detour_tried_ = false;
    goal_.reset();  // a place without a heading is resolved once, from where the robot starts
    return Start();
  }
  NodeStatus OnRunning() override {
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
  void OnHalted() override { task_.motion->StopBase(); }

 private:
  static constexpr double kReplanPeriod = 0.5;  // [s]

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
    const NodeStatus s = StartPath(task_, goal, "goal", [this](const std::string& t) {
      if (!blocked_since_) Note(t);
    });
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
  std::optional<Pose2> goal_;
  Time last_try_{};
  bool detour_tried_{false};
};

// The safe standby's retreat: the arm tucked and, with `back_off`, the base out of the door's
// way — to the last pose outside every door zone, unless people will come near it: then to
// where they will be farthest (out of their predicted path, not only back along its own).
// The retreat starts once the base has stopped (a path begun at speed the other way leaves
// the reference behind and trips the watchdog).
class RetractToSafe final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<bool>("back_off", true, "also drive back out of the door's way"),
            VisitPort(bt::PortDirection::kInput), RetreatingPort(bt::PortDirection::kOutput)};
  }
  NodeStatus OnStart() override {
    task_.motion->StopBase();
    failure_noted_ = false;
    started_ = belief_.now;
    if (!ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model)) ||
        task_.motion->arm_moving(belief_.now)) {
      task_.motion->MoveArm({{task_.config.arm_tuck_time, TuckedArm(*task_.model)}}, belief_.now);
      Note("tucking the arm");
    }
    pending_ = Input<bool>("back_off") && belief_.last_safe &&
               (belief_.last_safe->translation() - belief_.X_MB.translation()).norm() > 0.05;
    if (pending_) {
      this->SetOutput("retreating", true);
      StartRetreatOnceStopped();
    }
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (pending_) {
      StartRetreatOnceStopped();
      return NodeStatus::kRunning;
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
    this->SetOutput("retreating", false);
  }

 private:
  // [m/s] The base slower than this has stopped; [s] it is given this long to stop.
  static constexpr double kStoppedMps = 0.05;
  static constexpr double kStopWithinSec = 1.5;
  // Candidate spots round the robot [m] and headings; how far ahead people's paths are
  // predicted [s] and sampled [s]; how far round people count [m].
  static constexpr double kSpotRadiiM[] = {0.6, 1.0, 1.5};
  static constexpr int kSpotHeadings = 16;
  static constexpr double kPeopleHorizonSec = 3.0;
  static constexpr double kPeopleStepSec = 0.2;
  static constexpr double kPeopleLookM = 5.0;
  // [m] Each metre of extra way costs this much room: a nearer spot wins a tie.
  static constexpr double kWayCostPerM = 0.2;
  // [m] A retreat passes people's edges no nearer than the footprint and this; checked every
  // kPathSampleM along its way.
  static constexpr double kPassMarginM = 0.1;
  static constexpr double kPathSampleM = 0.05;
  static constexpr double kSweepMarginRad = 10.0 * M_PI / 180.0;

  void StartRetreatOnceStopped() {
    const double speed = std::hypot(belief_.V_B.vx, belief_.V_B.vy);
    if (speed > kStoppedMps && ToSeconds(belief_.now - started_) < kStopWithinSec) return;
    pending_ = false;
    // Out of a doorway straight back along the door's normal first (a diagonal line would cut
    // the jamb or the leaf), then on.
    std::vector<Pose2> path{belief_.X_MB};
    const std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    for (const auto& door : task_.map->doors) {
      const DoorPass pass = CalcKnownPass(task_, door.id, visit ? &*visit : nullptr);
      const Eigen::Vector2d offset = belief_.X_MB.translation() - pass.centre;
      const double along = offset.dot(pass.n_M);
      const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
      const double entry = EntryDistance(task_, door.id, pass);
      if (along < entry - 0.05 && along > -ExitDistance(task_, door.id) &&
          lateral < pass.width / 2 + 0.3) {
        const Eigen::Vector2d out = belief_.X_MB.translation() + pass.n_M * (entry - along);
        path.push_back({out.x(), out.y(), belief_.X_MB.yaw});
        break;
      }
    }
    const auto chosen = ChooseSpot(path);
    if (!chosen) {
      Note("nowhere to back off to without passing someone: standing still");
      return;
    }
    const auto [spot, aside] = *chosen;
    if ((path.back().translation() - spot.translation()).norm() > 0.05) path.push_back(spot);
    if (path.size() < 2) return;
    task_.motion->FollowPath(path, std::vector<bool>(path.size() - 1, false),
                             TuckedArm(*task_.model), belief_.now, task_.config.retreat_speed);
    this->SetOutput("retreating", true);
    Note(aside ? StrCat("stepping aside, out of people's way, to (", PoseText(spot), ")")
               : StrCat("backing off to the last safe waypoint (", PoseText(spot), ")"),
         DecisionEvent::kRetreating);
  }

  // Where the retreat that begins with `way` (the robot's pose, maybe a point out of the
  // doorway) ends: the last safe pose if people will stay comfort_distance from it; else, of the
  // spots round the robot out of every door's way and reachable in a straight line, the one
  // where they will be farthest (less kWayCostPerM per metre of way), if that beats the last
  // safe pose. No way may pass nearer anyone than the footprint and kPassMarginM (people where
  // they are now: a retreat into someone standing behind the robot, P1 seed 2000). nullopt:
  // every way does. Second: whether it is a spot aside.
  std::optional<std::pair<Pose2, bool>> ChooseSpot(const std::vector<Pose2>& way) const {
    const Pose2 safe = *belief_.last_safe;
    const Eigen::Vector2d at = belief_.X_MB.translation();
    const std::vector<Eigen::Vector2d> people =
        PeopleAround(task_, at, kPeopleLookM, kPeopleHorizonSec, kPeopleStepSec);
    const std::vector<Eigen::Vector2d> people_now = PeopleAround(task_, at, kPeopleLookM, 0.0, 0.0);
    const double comfortable = task_.config.footprint_radius + task_.config.comfort_distance;
    const double passable = task_.config.footprint_radius + kPassMarginM;
    // Where the base laser looks (its latest scan's sweep, in B; a margin inside its edges):
    // behind the robot, in its blind sector, nobody is seen (P1 seed 2000: a person waiting
    // right behind it was backed into).
    const Pose2 X_ML = belief_.X_MB * belief_.X_BL;
    const auto seen = [&](const Eigen::Vector2d& p) {
      if (!belief_.scan || (p - at).norm() <= task_.config.footprint_radius) return true;
      const Eigen::Vector2d p_L = X_ML.Inverse() * p;
      const double bearing = std::atan2(p_L.y(), p_L.x());
      return bearing >= belief_.scan->angle_min + kSweepMarginRad &&
             bearing <= belief_.scan->angle_max() - kSweepMarginRad;
    };
    // The straight lines of `way` and on to q keep clear of everyone now, within the laser's view.
    const auto clear_way = [&](const Eigen::Vector2d& q) {
      std::vector<Eigen::Vector2d> corners;
      for (const Pose2& p : way)
        corners.push_back(p.translation());
      corners.push_back(q);
      for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
        const double length = (corners[i + 1] - corners[i]).norm();
        const int steps = std::max(1, int(std::ceil(length / kPathSampleM)));
        for (int k = 1; k <= steps; ++k) {
          const Eigen::Vector2d p =
              corners[i] + (corners[i + 1] - corners[i]) * (double(k) / steps);
          if (RoomAt(people_now, p) < passable || !seen(p)) return false;
        }
      }
      return true;
    };
    const auto score = [&](const Eigen::Vector2d& q) {
      return std::min(RoomAt(people, q), comfortable) - kWayCostPerM * (q - at).norm();
    };
    const bool safe_ok = clear_way(safe.translation());
    if (safe_ok && RoomAt(people, safe.translation()) >= comfortable) return std::pair{safe, false};
    std::optional<std::pair<Pose2, bool>> best;
    double best_score = -std::numeric_limits<double>::infinity();
    if (safe_ok) {
      best = std::pair{safe, false};
      best_score = score(safe.translation());
    }
    const Pose2& from = way.back();
    for (const double radius : kSpotRadiiM) {
      for (int k = 0; k < kSpotHeadings; ++k) {
        const double a = 2 * M_PI * k / kSpotHeadings;
        const Eigen::Vector2d q = at + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
        const double s = score(q);
        if (s <= best_score || IsInAnyDoorZone(task_, q) || !clear_way(q)) continue;
        const Pose2 candidate{q.x(), q.y(), belief_.X_MB.yaw};
        if (!task_.planner->IsPathValid({from, candidate})) continue;
        best = std::pair{candidate, true};
        best_score = s;
      }
    }
    return best;
  }

  bool pending_{false};
  bool failure_noted_{false};
  Time started_{};
};

// Waits until the door zone has been clear as long as IsPathClear asks (the same hysteresis,
// from the belief), so the retry after a standby finds the path clear.
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
    Note("waiting for the door zone to clear");
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    if (IsDoorZoneClearFor(task_, Door(), Input<double>("clear_for"))) return NodeStatus::kSuccess;
    if (ToSeconds(belief_.now - started_) > Input<double>("timeout")) {
      Note("gave up waiting");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Time started_{};
};

}  // namespace

void RegisterNavigationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<NavigateTo>(factory, "NavigateTo", services);
  Register<RetractToSafe>(factory, "RetractToSafe", services);
  Register<WaitForClear>(factory, "WaitForClear", services);
}

}  // namespace egress::behavior::detail
