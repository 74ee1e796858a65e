#include "manipulation_support.h"

#include <array>
#include <cmath>

namespace egress::behavior::detail {
namespace {

// Waits (up to `timeout`) for the perception pipeline to confirm a payload of the class, and
// writes its position.
class DetectPayload final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("kind", "bottle or flashlight"),
            InputPort<double>("timeout", 4.0, "how long to look before failing [s]"),
            OutputPort<std::string>("pose", "payload position x;y;z in the map")};
  }
  NodeStatus OnStart() override {
    started_ = belief_.now;
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const std::string kind = Input<std::string>("kind");
    const perception::TrackedObject* best = nullptr;
    for (const auto& object : belief_.world.payloads) {
      if (object.label != kind) continue;
      if (best == nullptr || (object.p_MO.head<2>() - belief_.X_MB.translation()).norm() <
                                 (best->p_MO.head<2>() - belief_.X_MB.translation()).norm()) {
        best = &object;
      }
    }
    if (best != nullptr) {
      this->SetOutput("pose", StrCat(best->p_MO.x(), ";", best->p_MO.y(), ";", best->p_MO.z()));
      Note(StrCat("found a ", kind, " at (", std::round(best->p_MO.x() * 100) / 100, ", ",
                  std::round(best->p_MO.y() * 100) / 100, ", ",
                  std::round(best->p_MO.z() * 100) / 100, ")"));
      return NodeStatus::kSuccess;
    }
    const double timeout = Input<double>("timeout");
    const double looking = ToSeconds(belief_.now - started_);
    if (looking > timeout) {
      Note(StrCat("no ", kind, " in sight"));
      return NodeStatus::kFailure;
    }
    // Not in the level view ahead: look lower, ahead and to either side (a payload on a low
    // table or the floor near the robot is below a level camera's view).
    if (const double searching = looking - timeout * kLevelShare; searching >= 0.0) {
      const int k = std::min(2, int(searching / (timeout * (1.0 - kLevelShare) / 3.0)));
      const double bearing = belief_.X_MB.yaw + std::array{0.0, kSearchPanRad, -kSearchPanRad}[k];
      const Eigen::Vector2d p =
          belief_.X_MB.translation() +
          kSearchRange * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
      LookAt({p.x(), p.y(), kSearchHeight});
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  static constexpr double kLevelShare = 0.25;   // of the timeout, looking level ahead first
  static constexpr double kSearchRange = 1.2;   // [m] from the base, the points looked at
  static constexpr double kSearchHeight = 0.4;  // [m] above the floor
  static constexpr double kSearchPanRad = 0.6;  // to either side
  Time started_{};
};

// Opens or closes the gripper and waits until the fingers, having moved, come to rest, as the
// gripper measures them (closing: on the payload, or on nothing; LiftPayload and WithdrawArm
// tell which from the grip).
template <GripperCommand::Mode kMode>
class MoveGripper final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    PortsList ports{
        InputPort<double>("timeout", 3.0, "how long the fingers may take to come to rest [s]")};
    if constexpr (kMode == GripperCommand::Mode::kGrasp)
      ports.insert(InputPort<double>("effort", 10.0, "grip force [N]"));
    return ports;
  }
  NodeStatus OnStart() override {
    GripperCommand command;
    command.mode = kMode;
    if constexpr (kMode == GripperCommand::Mode::kGrasp) {
      command.effort = Input<double>("effort");
      ThrowUnless(std::isfinite(command.effort) && command.effort > 0.0,
                  "CloseGripper: effort must be a positive force [N], got ", command.effort);
    }
    task_.motion->SetGripper(command);
    started_ = belief_.now;
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (belief_.gripper_at_rest) return NodeStatus::kSuccess;
    if (ToSeconds(belief_.now - started_) > Input<double>("timeout")) {
      Note("the fingers did not come to rest in time");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Time started_{};
};

}  // namespace

void RegisterManipulationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<DetectPayload>(factory, "DetectPayload", services);
  Register<MoveGripper<GripperCommand::Mode::kGrasp>>(factory, "CloseGripper", services);
  Register<MoveGripper<GripperCommand::Mode::kOpen>>(factory, "OpenGripper", services);
}

}  // namespace egress::behavior::detail
