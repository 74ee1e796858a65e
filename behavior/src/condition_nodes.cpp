#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace egress::behavior::detail {
namespace {

// ---- conditions

class IsPathClear final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
                "door", "door whose zone must be free of people now and over the forecast"),
            InputPort<double>("clear_for", 1.0,
                              "seconds the zone must have been clear (hysteresis) [s]")};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    // A standby retreat runs to its end before the robot resumes: stopping it half-way can
    // leave the robot in the doorway with the leaf about to close.
    if (ctx_.retreating) return last_ = NodeStatus::kFailure;
    if (IsDoorZoneOccupied(ctx_, door)) {
      if (last_ != NodeStatus::kFailure)
        Note("a person is in or entering the door zone", DecisionEvent::kPersonInDoorZone);
      ctx_.zone_occupied_at[door] = ctx_.now;
      return last_ = NodeStatus::kFailure;
    }
    const auto it = ctx_.zone_occupied_at.find(door);
    if (it != ctx_.zone_occupied_at.end() &&
        ToSeconds(ctx_.now - it->second) < Input<double>("clear_for")) {
      return last_ = NodeStatus::kFailure;
    }
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
                              "clearance beyond the robot's footprint the opening must leave [m]")};
  }
  NodeStatus Tick() override {
    return DoorPassable(ctx_, Door(), Input<double>("margin")) ? NodeStatus::kSuccess
                                                               : NodeStatus::kFailure;
  }
};

class IsPersonHoldingDoor final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
        "door", "door id: a person stands still at the leaf and it is open enough")};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    for (const auto& entry : ctx_.world.people) {
      if (IsHoldingDoorAside(ctx_, entry, door) && DoorPassable(ctx_, door, 0.0)) {
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
    return ctx_.holding_object ? NodeStatus::kSuccess : NodeStatus::kFailure;
  }
};

}  // namespace

void RegisterConditionNodes(bt::BehaviorTreeFactory& factory, TaskContext* context) {
  Register<IsPathClear>(factory, "IsPathClear", context);
  Register<IsDoorOpen>(factory, "IsDoorOpen", context);
  Register<IsPersonHoldingDoor>(factory, "IsPersonHoldingDoor", context);
  Register<IsHoldingPayload>(factory, "IsHoldingPayload", context);
}

}  // namespace egress::behavior::detail
