// IsNobodyComing (behavior/trees/evacuation_escort.xml), the escort's guard of an operation: it
// breaks the robot's approach and press off when residents come to the door it holds.

#include "escort_watch.h"
#include "task_node_support.h"

#include <string>

namespace egress::behavior::detail {
namespace {

// IsNobodyComing: the guard of an operation during a hold (a ReactiveSequence above
// ApproachButton and PressButton / WaveAtPlate): FAILURE as soon as someone moves near the door
// on the robot's side (LookAround, as HoldForResidents sees them), so the robot breaks off
// instead of standing at the actuator, beside the doorway, as the residents arrive.
class IsNobodyComing final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door held open for the residents"),
            InputPort<double>("near_door", 5.0,
                              "laser returns off the map this close to the doorway, on the "
                              "robot's side, are watched for motion [m]"),
            InputPort<double>("watch_radius", 6.0,
                              "tracked people this close to the doorway, on the robot's side, "
                              "are watched [m]")};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    const DoorPass pass = CalcDoorPass(*task_.map, door, belief_.X_MB);
    const Surroundings around =
        LookAround(belief_, pass, Input<double>("watch_radius"), Input<double>("near_door"));
    if (!around.moving) return NodeStatus::kSuccess;
    Note(StrCat("someone coming to ", door, " (", around.mover, "): breaking off"));
    return NodeStatus::kFailure;
  }
};

}  // namespace

void RegisterEscortGuard(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<IsNobodyComing>(factory, "IsNobodyComing", services);
}

}  // namespace egress::behavior::detail
