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
  Register<IsHoldingPayload>(factory, "IsHoldingPayload", services);
}

}  // namespace egress::behavior::detail
