// The escort's sweep (behavior/trees/evacuation_escort.xml): before the robot leaves by the last
// door of the exit route (an exit door may have no actuator outside: it could not come back), it
// opens, farthest first, the doors of the rooms whose way out joins that route, and watches each
// doorway until whoever waited behind it is through. A resident who cannot operate a door (a
// wheelchair user who reached it after it shut behind the others) waits there for good otherwise
// (clinic two wards seed 62: north_12 behind door_a from 122 s to the time limit, door_a off the
// robot's route). PlanSweep finds the doors, FeederApproachPose where to wait before one,
// WatchDoorway the watch.

#include <algorithm>
#include <deque>
#include <memory>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

using RoutePtr = std::shared_ptr<const planning::Route>;

// [m] How far either side of a door's line its rooms are probed from (beyond the leaf's
// threshold, inside a room of any size a door leads to).
constexpr double kRoomProbeM = 1.0;

// If `door` leads from a room whose way out to `goal` is through it first and leaves by the
// route's last door (its residents join the route; through other rooms on the way, perhaps), a
// point in that room, kRoomProbeM beyond the door.
std::optional<Eigen::Vector2d> RoomJoiningRoute(const planning::RoutePlanner& planner,
                                                const perception::Doorway& door, const Pose2& goal,
                                                const planning::Route& route) {
  if (route.legs.empty()) return std::nullopt;
  const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge).normalized();
  const Eigen::Vector2d n(-along.y(), along.x());
  const Eigen::Vector2d centre = (door.p_MHinge + door.p_MLatch) / 2;
  for (const double side : {1.0, -1.0}) {
    const Eigen::Vector2d p = centre + side * kRoomProbeM * n;
    const planning::RouteResult out = planner.Plan({p.x(), p.y(), 0.0}, goal);
    if (!out.ok()) continue;
    const std::vector<planning::RouteLeg>& legs = out.route->legs;
    // Through the door first, out by the route's last: a room with an exit of its own is not
    // swept.
    if (legs.size() >= 2 && legs.front().door == door.id &&
        legs.back().door == route.legs.back().door)
      return p;
  }
  return std::nullopt;
}

// What both route-level sweep nodes need: the goal from their `goal` port, and a route planner of
// their own, built on first use (the map is fixed).
class SweepRouteNode : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;

 protected:
  // The `goal` port as a pose; nullopt (noted) if it names no place and is no pose.
  std::optional<Pose2> Goal() {
    try {
      return ResolveGoal(*task_.map, Input<std::string>("goal"), belief_.X_MB);
    } catch (const InvalidArgument& e) {
      Note(e.what());
      return std::nullopt;
    }
  }
  const planning::RoutePlanner& Planner() {
    if (!planner_) planner_.emplace(task_.map->grid, task_.map->doorways, task_.config.route);
    return *planner_;
  }

 private:
  std::optional<planning::RoutePlanner> planner_;
};

// PlanSweep: at the route's last door, the doors to sweep (see the file comment: the rooms whose
// way out leaves by that door, through the swept door first) in the order to
// visit them: farthest first by route from the robot, so that the residents let out walk ahead
// of it towards the exit and the robot sweeps back the way they go. Fails, saying nothing, at any
// other door or with `sweep` false; fails with a note when no room joins the route. Each door
// once, and none on a route it was given before: a later round of the escort (after the sweep,
// from elsewhere) finds only rooms neither swept nor escorted from yet.
class PlanSweep final : public SweepRouteNode {
 public:
  using SweepRouteNode::SweepRouteNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "the route's door the robot is at"),
            InputPort<RoutePtr>("route", "PlanRoute's route"),
            InputPort<std::string>("goal", "the route's goal: a place, or a pose x;y;yaw"),
            InputPort<bool>("sweep", true,
                            "whether to sweep the rooms joining the route before its last door"),
            OutputPort<bt::SharedQueue<std::string>>(
                "doors", "the doors of the rooms to sweep, in the order to visit them")};
  }
  NodeStatus Tick() override {
    const RoutePtr route = Input<RoutePtr>("route");
    const std::string door = Door();
    if (!Input<bool>("sweep") || !route || route->legs.empty() || route->legs.back().door != door)
      return NodeStatus::kFailure;
    const std::optional<Pose2> goal = Goal();
    if (!goal) return NodeStatus::kFailure;
    const planning::RoutePlanner& planner = Planner();
    // Doors given last time and left in the queue (a round ended at a room someone came out
    // of) are still to sweep.
    if (last_given_) {
      for (const std::string& id : *last_given_)
        swept_.erase(id);
      last_given_.reset();
    }
    // Not the rooms of any route's doors: the escort came through them.
    for (const auto& leg : route->legs)
      escorted_.insert(leg.door);
    std::set<std::string> on_route = escorted_;
    on_route.insert(swept_.begin(), swept_.end());      // each room once
    std::vector<std::pair<double, std::string>> found;  // route length to the room, door
    for (const perception::Doorway& d : task_.map->doorways) {
      if (on_route.count(d.id) != 0) continue;
      const std::optional<Eigen::Vector2d> room = RoomJoiningRoute(planner, d, *goal, *route);
      if (!room) continue;
      const Eigen::Vector2d centre = (d.p_MHinge + d.p_MLatch) / 2;
      // An actuator on the route's side, where the robot will stand.
      if (task_.map->FindActuatorOf(d.id, 2 * centre - *room) == nullptr) {
        Note(StrCat("no actuator on this side of ", d.id, ": its room is not swept"));
        continue;
      }
      const planning::RouteResult to_room = planner.Plan(belief_.X_MB, {room->x(), room->y(), 0});
      if (to_room.ok()) found.emplace_back(to_room.route->length, d.id);
    }
    if (found.empty()) {
      Note(StrCat("no room's way out joins the route before ", door, ": nothing to sweep"));
      return NodeStatus::kFailure;
    }
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    auto doors = std::make_shared<std::deque<std::string>>();
    std::string list;
    for (const auto& [length, id] : found) {
      doors->push_back(id);
      list += (list.empty() ? "" : ", ") + id;
    }
    Note(StrCat("before leaving by ", door,
                ", sweeping the rooms whose way out joins the route: ", list));
    swept_.insert(doors->begin(), doors->end());
    last_given_ = doors;
    this->SetOutput("doors", doors);
    return NodeStatus::kSuccess;
  }

 private:
  std::set<std::string> swept_;     // doors given to sweep so far
  std::set<std::string> escorted_;  // doors of every route it was given
  // The queue given last: the loop pops each door as it visits it.
  std::shared_ptr<const std::deque<std::string>> last_given_;
};

// FeederApproachPose: where to wait before a swept door on the route's side (PlanRoute's
// approach pose for it, on a route from the robot into its room).
class FeederApproachPose final : public SweepRouteNode {
 public:
  using SweepRouteNode::SweepRouteNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "a door PlanSweep gave"),
            InputPort<RoutePtr>("route", "the route the door's room joins"),
            InputPort<std::string>("goal", "the route's goal: a place, or a pose x;y;yaw"),
            OutputPort<std::string>("pose", "where to wait before the door, facing it: x;y;yaw")};
  }
  NodeStatus Tick() override {
    const RoutePtr route = Input<RoutePtr>("route");
    const std::string door = Door();
    const auto doorway = std::find_if(task_.map->doorways.begin(), task_.map->doorways.end(),
                                      [&](const perception::Doorway& d) { return d.id == door; });
    if (!route || doorway == task_.map->doorways.end()) {
      Note(StrCat("no route, or no door '", door, "' on the map"));
      return NodeStatus::kFailure;
    }
    const std::optional<Pose2> goal = Goal();
    if (!goal) return NodeStatus::kFailure;
    const planning::RoutePlanner& planner = Planner();
    const std::optional<Eigen::Vector2d> room = RoomJoiningRoute(planner, *doorway, *goal, *route);
    if (!room) {
      Note(StrCat("the room beyond ", door, " does not join the route"));
      return NodeStatus::kFailure;
    }
    const planning::RouteResult to_room = planner.Plan(belief_.X_MB, {room->x(), room->y(), 0});
    if (!to_room.ok() || to_room.route->legs.empty() || to_room.route->legs.back().door != door) {
      Note(StrCat("no way to ", door, "'s near side: ", to_room.message));
      return NodeStatus::kFailure;
    }
    this->SetOutput("pose", PosePortText(to_room.route->legs.back().X_MB_approach));
    return NodeStatus::kSuccess;
  }
};

// WatchDoorway: after the robot opened a door for whoever may wait behind it, it stands and
// watches (the head looking through the doorway into the room) until those who came are through:
// SUCCESS once nobody has been within `watch_radius` of the doorway's centre, either side, for
// `clear_for` seconds after someone was; or if nobody came within `wait_for`; or after
// `max_watch` whatever happens.
class WatchDoorway final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "the door the robot opened"),
            InputPort<double>("wait_for", 10.0,
                              "nobody by the doorway this long after the watch began: done [s]"),
            InputPort<double>("clear_for", 5.0,
                              "nobody by the doorway this long after the last one: done [s]"),
            InputPort<double>("max_watch", 60.0, "the longest watch [s]"),
            InputPort<double>("watch_radius", 2.5,
                              "someone this near the doorway's centre is by it [m]"),
            OutputPort<bool>("came", "whether anyone came by the doorway during the watch")};
  }
  NodeStatus OnStart() override {
    const std::string door = Door();
    const perception::DoorModel* model = task_.map->FindDoor(door);
    const double wait_for = Input<double>("wait_for"), clear_for = Input<double>("clear_for"),
                 max_watch = Input<double>("max_watch"), radius = Input<double>("watch_radius");
    if (model == nullptr || !(wait_for >= 0) || !(clear_for >= 0) || !(max_watch >= 0) ||
        !(radius > 0)) {
      Note(StrCat("unknown door '", door,
                  "', or a negative or non-finite wait_for, clear_for, max_watch or watch_radius"));
      return NodeStatus::kFailure;
    }
    centre_ = (model->p_MHinge + model->p_MLatch) / 2;
    started_ = belief_.now;
    last_seen_.reset();
    // Off the actuator: whoever comes through passes beside it.
    if (!ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model)))
      task_.motion->MoveArm({{task_.config.arm_tuck_time, TuckedArm(*task_.model)}}, belief_.now);
    Note(StrCat("watching ", door, "'s doorway for residents coming through"));
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const DoorPass pass = CalcDoorPass(*task_.map, Door(), belief_.X_MB);
    if (task_.gaze != nullptr) {
      // Through the doorway into the room, level: residents walk from there.
      const Eigen::Vector2d p = pass.centre - pass.n_M * 1.5;
      task_.gaze->RequestLook({p.x(), p.y(), belief_.X_MC.translation().z()},
                              belief_.now + SecondsToDuration(0.5));
    }
    const double radius = Input<double>("watch_radius");
    bool someone = false;
    for (const auto& entry : belief_.world.people)
      someone = someone || (entry.person.p_MP - centre_).norm() <= radius;
    for (const Eigen::Vector2d& p : belief_.moving_returns)
      someone = someone || (p - centre_).norm() <= radius;
    if (someone) {
      if (!last_seen_) Note("someone by the doorway: watching until they are through");
      last_seen_ = belief_.now;
    }
    this->SetOutput("came", last_seen_.has_value());
    const double watched = ToSeconds(belief_.now - started_);
    if (watched >= Input<double>("max_watch")) {
      Note("watched for max_watch: going on");
      return NodeStatus::kSuccess;
    }
    if (!last_seen_ && watched >= Input<double>("wait_for")) {
      Note("nobody came: going on");
      return NodeStatus::kSuccess;
    }
    if (last_seen_ && ToSeconds(belief_.now - *last_seen_) >= Input<double>("clear_for")) {
      Note("they are through: going on");
      return NodeStatus::kSuccess;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Eigen::Vector2d centre_{Eigen::Vector2d::Zero()};
  Time started_{};
  std::optional<Time> last_seen_;
};

}  // namespace

void RegisterSweepNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<PlanSweep>(factory, "PlanSweep", services);
  Register<FeederApproachPose>(factory, "FeederApproachPose", services);
  Register<WatchDoorway>(factory, "WatchDoorway", services);
}

}  // namespace egress::behavior::detail
