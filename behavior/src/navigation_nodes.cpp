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
    return {InputPort<std::string>("goal", "goal pose x;y;yaw"),
            InputPort<double>("detour_speed", 0.2,
                              "speed of the Bug2 detour when the costmap has no path [m/s]"),
            InputPort<double>("patience", 15.0, "how long to keep re-planning a blocked goal [s]")};
  }
  NodeStatus OnStart() override {
    blocked_since_.reset();
    detour_tried_ = false;
    return Start();
  }
  NodeStatus OnRunning() override {
    if (blocked_since_) {
      if (ToSeconds(ctx_.now - last_try_) < kReplanPeriod) return NodeStatus::kRunning;
      return Start();
    }
    if (!ctx_.motion->bug_active() && IsPathAheadBlocked(ctx_)) {
      ctx_.motion->StopBase();
      Note("the path ahead is blocked: planning again");
      return Start();
    }
    const NodeStatus s = BaseMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kFailure ? Blocked() : s;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }

 private:
  static constexpr double kReplanPeriod = 0.5;  // [s]

  NodeStatus Start() {
    last_try_ = ctx_.now;
    const Pose2 goal = ParsePose2(Input<std::string>("goal"));
    // Quiet while re-planning: the first failure is noted, not every retry.
    const NodeStatus s = StartPath(ctx_, goal, "goal", [this](const std::string& t) {
      if (!blocked_since_) Note(t);
    });
    if (s != NodeStatus::kFailure) {
      if (blocked_since_) Note("the way is free again");
      blocked_since_.reset();
      return s;
    }
    // No path on the costmap, though the goal itself is free: round the obstacle by the laser.
    if (!detour_tried_ && ctx_.planner->IsValid(goal)) {
      detour_tried_ = true;
      planning::BugConfig bug;
      bug.speed = Input<double>("detour_speed");
      bug.robot_radius = ctx_.config.footprint_radius;
      ctx_.motion->FollowBug(ctx_.X_MB, goal.translation(), bug, ctx_.now);
      Note("no path on the costmap: detouring round the obstacle (Bug2)");
      return NodeStatus::kRunning;
    }
    return Blocked();
  }
  NodeStatus Blocked() {
    if (!blocked_since_) {
      blocked_since_ = ctx_.now;
      last_try_ = ctx_.now;
      Note(StrCat("waiting up to ", Input<double>("patience"), " s for a way"));
    }
    if (ToSeconds(ctx_.now - *blocked_since_) > Input<double>("patience")) {
      Note("gave up: the goal stayed blocked");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  std::optional<Time> blocked_since_;
  Time last_try_{};
  bool detour_tried_{false};
};

class RetractToSafe final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<bool>("back_off", true, "also drive back to the last safe waypoint")};
  }
  NodeStatus OnStart() override {
    ctx_.motion->StopBase();
    if (!ArmAt(ctx_.motion->arm_target(), TuckedArm(*ctx_.model)) ||
        ctx_.motion->arm_moving(ctx_.now)) {
      ctx_.motion->MoveArm({{ctx_.config.arm_tuck_time, TuckedArm(*ctx_.model)}}, ctx_.now);
      Note("tucking the arm");
    }
    if (Input<bool>("back_off") && ctx_.last_safe &&
        (ctx_.last_safe->translation() - ctx_.X_MB.translation()).norm() > 0.05) {
      // Out of a doorway straight back along the door's normal first (a diagonal line to the
      // safe waypoint would cut the jamb or the leaf), then to the waypoint.
      std::vector<Pose2> path{ctx_.X_MB};
      for (const auto& door : ctx_.map->doors) {
        const DoorPass pass = CalcKnownPass(ctx_, door.id);
        const Eigen::Vector2d offset = ctx_.X_MB.translation() - pass.centre;
        const double along = offset.dot(pass.n_M);
        const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
        const double entry = EntryDistance(ctx_, door.id, pass);
        if (along < entry - 0.05 && along > -ExitDistance(ctx_, door.id) &&
            lateral < pass.width / 2 + 0.3) {
          const Eigen::Vector2d out = ctx_.X_MB.translation() + pass.n_M * (entry - along);
          path.push_back({out.x(), out.y(), ctx_.X_MB.yaw});
          break;
        }
      }
      if ((path.back().translation() - ctx_.last_safe->translation()).norm() > 0.05)
        path.push_back(*ctx_.last_safe);
      ctx_.motion->FollowPath(path, std::vector<bool>(path.size() - 1, false),
                              TuckedArm(*ctx_.model), ctx_.now);
      ctx_.retreating = true;
      Note(StrCat("backing off to the last safe waypoint (", PoseText(*ctx_.last_safe), ")"),
           DecisionEvent::kRetreating);
    }
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (ctx_.motion->base_failed()) ctx_.motion->StopBase();  // blocked: stay, arm tucked
    const bool busy = ctx_.motion->arm_moving(ctx_.now) || ctx_.motion->base_moving();
    if (!busy) ctx_.retreating = false;
    return busy ? NodeStatus::kRunning : NodeStatus::kSuccess;
  }
  void OnHalted() override {
    ctx_.motion->StopBase();
    ctx_.retreating = false;
  }
};

class WaitForClear final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose zone to watch"),
            InputPort<double>("timeout", 30.0, "give up after [s]")};
  }
  NodeStatus OnStart() override {
    started_ = ctx_.now;
    Note("waiting for the door zone to clear");
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    if (!IsDoorZoneOccupied(ctx_, Door())) return NodeStatus::kSuccess;
    if (ToSeconds(ctx_.now - started_) > Input<double>("timeout")) {
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

void RegisterNavigationNodes(bt::BehaviorTreeFactory& factory, TaskContext* context) {
  Register<NavigateTo>(factory, "NavigateTo", context);
  Register<RetractToSafe>(factory, "RetractToSafe", context);
  Register<WaitForClear>(factory, "WaitForClear", context);
}

}  // namespace egress::behavior::detail
