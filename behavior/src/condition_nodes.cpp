#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace egress::behavior::detail {
namespace {

// ---- conditions

// No side effects: the zone's last occupied time is the belief's (kept by the executive every
// control step), a retreat under way is RetractToSafe's `retreating` entry. The node remembers
// only its own last answer, to note the transitions.
class IsPathClear final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
                "door", "door whose zone must be free of people now and over the forecast"),
            InputPort<double>("clear_for", 1.0,
                              "seconds the zone must have been clear (hysteresis) [s]"),
            RetreatingPort(bt::PortDirection::kInput)};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    // A standby retreat runs to its end before the robot resumes: stopping it half-way can
    // leave the robot in the doorway with the leaf about to close.
    if (Shared<bool>("retreating").value_or(false)) return last_ = NodeStatus::kFailure;
    if (IsDoorZoneOccupied(task_, door)) {
      if (last_ != NodeStatus::kFailure)
        Note("a person is in or entering the door zone", DecisionEvent::kPersonInDoorZone);
      return last_ = NodeStatus::kFailure;
    }
    if (!IsDoorZoneClearFor(task_, door, Input<double>("clear_for")))
      return last_ = NodeStatus::kFailure;
    if (last_ == NodeStatus::kFailure) Note("door zone clear", DecisionEvent::kDoorZoneClear);
    return last_ = NodeStatus::kSuccess;
  }

 private:
  NodeStatus last_{NodeStatus::kIdle};
};

class IsDoorOpen final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door id"),
            InputPort<double>("margin", 0.1,
                              "clearance beyond the robot's footprint the opening must leave [m]"),
            VisitPort(bt::PortDirection::kInput)};
  }
  NodeStatus Tick() override {
    const DoorVisit visit = Visit();
    return DoorPassable(task_, visit.door, Input<double>("margin"), &visit) ? NodeStatus::kSuccess
                                                                            : NodeStatus::kFailure;
  }
};

class IsPersonHoldingDoor final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
                "door", "door id: a person stands still at the leaf and it is open enough"),
            VisitPort(bt::PortDirection::kInput)};
  }
  NodeStatus Tick() override {
    const DoorVisit visit = Visit();
    for (const auto& entry : belief_.world.people) {
      if (IsHoldingDoorAside(task_, entry, visit.door) &&
          DoorPassable(task_, visit.door, 0.0, &visit)) {
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
};

// A traversal the robot yielded in after crossing the door line ends past it: the retry must
// not take it back to the side it came from to press again (clinic family, seed 2007: a
// resident made the robot yield 0.9 m past door_b; the retry waved from the far side, drove
// back through and was struck by the closing leaf). Through means its footprint is past the
// line by the leaf clearance, in front of the opening, and out of the leaf's sweep. Like
// TraverseDoor's success it ends the visit (a later traversal may come the other way).
class IsThroughDoor final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
                "door", "door id: the robot is on the far side of the one it approached from"),
            VisitPort(bt::PortDirection::kInOut)};
  }
  NodeStatus Tick() override {
    DoorVisit visit = Visit();
    if (!visit.approach_side) return NodeStatus::kFailure;
    const DoorPass pass = CalcKnownPass(task_, visit.door, &visit);  // throws for an unknown door
    const perception::DoorModel& model = *task_.map->FindDoor(visit.door);
    const Eigen::Vector2d offset = belief_.X_MB.translation() - pass.centre;
    const double past = -offset.dot(pass.n_M);
    const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
    const double body = task_.config.footprint_radius + kLeafClearance;
    if (past < body || lateral > pass.width / 2 + past ||
        model.InSweep(belief_.X_MB.translation(), body))
      return NodeStatus::kFailure;
    Note(StrCat("already through the door (", past, " m past its line)"));
    visit.approach_side.reset();
    Remember(visit);
    return NodeStatus::kSuccess;
  }
};

class IsHoldingPayload final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {
        InputPort<std::string>("payload", "", "payload class (bottle, flashlight); empty: any")};
  }
  NodeStatus Tick() override {
    if (belief_.holding_object) return NodeStatus::kSuccess;
    Note("the payload is not in the gripper (the fingers closed on nothing)");
    return NodeStatus::kFailure;
  }
};

}  // namespace

void RegisterConditionNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<IsPathClear>(factory, "IsPathClear", services);
  Register<IsDoorOpen>(factory, "IsDoorOpen", services);
  Register<IsPersonHoldingDoor>(factory, "IsPersonHoldingDoor", services);
  Register<IsThroughDoor>(factory, "IsThroughDoor", services);
  Register<IsHoldingPayload>(factory, "IsHoldingPayload", services);
}

}  // namespace egress::behavior::detail
