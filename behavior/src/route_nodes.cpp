// The route-level nodes: PlanRoute (the doors between the robot and a goal, in order),
// DoorApproachPose (where to wait before one of them), IsBeforeDoor (already there) and
// MarkDoorBlocked (a door the route must avoid from now on). A mission loops DoorTraversal over
// PlanRoute's doors (LoopString).

#include <deque>
#include <memory>
#include <set>

#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

using RoutePtr = std::shared_ptr<const planning::Route>;

// A door list "a;b" (BehaviorTree.CPP's vector convention, the engine's own splitter).
std::set<std::string> SplitList(const std::string& text) {
  std::set<std::string> out;
  for (std::string_view part : bt::SplitSemicolons(text))
    if (!part.empty()) out.emplace(part);
  return out;
}

class PlanRoute final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {
        InputPort<std::string>("goal", "a place of the building, or a pose x;y;yaw"),
        InputPort<std::string>("avoid", "", "doors not to route through (locked, blocked): a;b"),
        OutputPort<bt::SharedQueue<std::string>>("doors", "the doors on the route, in order"),
        OutputPort<RoutePtr>("route", "the route (for DoorApproachPose)"),
        OutputPort<std::string>("destination", "the goal as a pose x;y;yaw")};
  }
  NodeStatus Tick() override {
    Pose2 goal;
    try {
      goal = ResolveGoal(*task_.map, Input<std::string>("goal"), belief_.X_MB);
    } catch (const InvalidArgument& e) {
      Note(e.what());
      return NodeStatus::kFailure;
    }
    if (!planner_) {
      planner_.emplace(task_.map->grid, task_.map->doorways, task_.config.route);
    }
    const std::optional<std::string> avoid_text = Shared<std::string>("avoid");
    const std::set<std::string> avoid = SplitList(avoid_text.value_or(""));
    const planning::RouteResult result = planner_->Plan(belief_.X_MB, goal, avoid);
    if (!result.ok()) {
      Note("no route: " + result.message);
      return NodeStatus::kFailure;
    }
    auto doors = std::make_shared<std::deque<std::string>>();
    std::string list;
    for (const auto& leg : result.route->legs) {
      doors->push_back(leg.door);
      list += (list.empty() ? "" : ", ") + leg.door;
    }
    Note(StrCat("route of ", std::round(result.route->length * 10) / 10, " m to ", PoseText(goal),
                doors->empty() ? ", no door" : " through " + list));
    this->SetOutput("doors", doors);
    this->SetOutput("route", RoutePtr(std::make_shared<planning::Route>(*result.route)));
    this->SetOutput("destination", PosePortText(goal));
    return NodeStatus::kSuccess;
  }

 private:
  std::optional<planning::RoutePlanner> planner_;  // the map is fixed: built once
};

class DoorApproachPose final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "a door on the route"),
            InputPort<RoutePtr>("route", "PlanRoute's route"),
            OutputPort<std::string>("pose", "where to wait before the door, facing it: x;y;yaw")};
  }
  NodeStatus Tick() override {
    const RoutePtr route = Input<RoutePtr>("route");
    const std::string door = Door();
    if (!route) {
      Note("no route: PlanRoute must run first");
      return NodeStatus::kFailure;
    }
    for (const auto& leg : route->legs) {
      if (leg.door != door) continue;
      this->SetOutput("pose", PosePortText(leg.X_MB_approach));
      return NodeStatus::kSuccess;
    }
    Note(StrCat("door '", door, "' is not on the route"));
    return NodeStatus::kFailure;
  }
};

// The robot is already before a door on the route: on the side the route comes from, within
// near_door_distance of its centre, in front of the opening (not round a corner) and out of the
// leaf's sweep. Then the door traversal can start from here (driving to the approach pose first
// would spend seconds of a door held open for it).
class IsBeforeDoor final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "a door on the route"),
            InputPort<RoutePtr>("route", "PlanRoute's route")};
  }
  NodeStatus Tick() override {
    const RoutePtr route = Input<RoutePtr>("route");
    const std::string door = Door();
    const perception::DoorModel* model = task_.map->FindDoor(door);
    if (!route || model == nullptr) return NodeStatus::kFailure;
    for (const auto& leg : route->legs) {
      if (leg.door != door) continue;
      const Eigen::Vector2d centre = (model->p_MHinge + model->p_MLatch) / 2;
      const Eigen::Vector2d along = (model->p_MLatch - model->p_MHinge).normalized();
      Eigen::Vector2d n(-along.y(), along.x());
      if ((leg.X_MB_approach.translation() - centre).dot(n) < 0) n = -n;
      const Eigen::Vector2d offset = belief_.X_MB.translation() - centre;
      const double depth = offset.dot(n), lateral = std::abs(offset.dot(along));
      const bool in_front =
          depth > task_.config.footprint_radius && lateral < depth + model->width() / 2;
      const bool near = offset.norm() <= task_.config.route.near_door_distance;
      const bool clear_of_sweep =
          !leg.opens_towards_robot || (belief_.X_MB.translation() - model->p_MHinge).norm() >
                                          model->width() + task_.config.footprint_radius;
      return in_front && near && clear_of_sweep ? NodeStatus::kSuccess : NodeStatus::kFailure;
    }
    return NodeStatus::kFailure;
  }
};

class MarkDoorBlocked final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "the door that could not be passed"),
            bt::BidirectionalPort<std::string>("blocked", "doors to avoid: a;b (appended to)")};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    std::set<std::string> blocked = SplitList(Shared<std::string>("blocked").value_or(""));
    blocked.insert(door);
    std::string list;
    for (const auto& d : blocked)
      list += (list.empty() ? "" : ";") + d;
    this->SetOutput("blocked", list);
    Note(StrCat("door '", door, "' could not be passed: routing round it"));
    return NodeStatus::kSuccess;
  }
};

}  // namespace

void RegisterRouteNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<PlanRoute>(factory, "PlanRoute", services);
  Register<DoorApproachPose>(factory, "DoorApproachPose", services);
  Register<MarkDoorBlocked>(factory, "MarkDoorBlocked", services);
  Register<IsBeforeDoor>(factory, "IsBeforeDoor", services);
}

}  // namespace egress::behavior::detail
