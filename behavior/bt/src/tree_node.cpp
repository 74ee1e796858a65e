#include "egress/bt/tree_node.h"

namespace egress::bt {

std::string_view ToString(NodeKind kind) {
  switch (kind) {
    case NodeKind::kAction:
      return "Action";
    case NodeKind::kCondition:
      return "Condition";
    case NodeKind::kControl:
      return "Control";
    case NodeKind::kDecorator:
      return "Decorator";
    case NodeKind::kSubTree:
      return "SubTree";
  }
  return "Unknown";
}

const std::array<std::string_view, kNumPreConditions>& PreConditionNames() {
  static constexpr std::array<std::string_view, kNumPreConditions> kNames = {
      "_failureIf", "_successIf", "_skipIf", "_while"};
  return kNames;
}

const std::array<std::string_view, kNumPostConditions>& PostConditionNames() {
  static constexpr std::array<std::string_view, kNumPostConditions> kNames = {
      "_onSuccess", "_onFailure", "_post", "_onHalted"};
  return kNames;
}

void TreeContext::NotifyStarting() {
  // Innermost guard first: the closest reactive parent preempts its own running branch, then
  // the outer ones. Each guard runs once.
  while (!start_guards.empty()) {
    auto guard = std::move(start_guards.back());
    start_guards.pop_back();
    if (guard) guard();
  }
}

TreeNode::TreeNode(std::string name, NodeConfig config)
    : name_(std::move(name)), config_(std::move(config)) {}

std::optional<std::string> TreeNode::PortText(std::string_view port) const {
  if (auto it = config_.ports.find(port); it != config_.ports.end()) return it->second;
  if (config_.manifest_ports != nullptr) {
    if (auto it = config_.manifest_ports->find(port); it != config_.manifest_ports->end()) {
      return it->second.default_value;
    }
  }
  return std::nullopt;
}

void TreeNode::SetStatus(NodeStatus status) {
  const NodeStatus previous = status_;
  status_ = status;
  if (previous != status && !config_.context->observers.empty()) {
    const Duration now = config_.context->Now();
    for (const auto& [id, callback] : config_.context->observers)
      callback(now, *this, previous, status);
  }
}

void TreeNode::ResetStatus() {
  SetStatus(NodeStatus::kIdle);
}

void TreeNode::ThrowScriptError(std::string_view attribute, const std::exception& e) const {
  const std::string location = config_.file ? Cat(*config_.file, ":", config_.line, ": ") : "";
  throw RuntimeError(Cat(location, "[", path(), "] ", attribute, ": ", e.what()));
}

std::optional<NodeStatus> TreeNode::CheckPreConditions() {
  const ScriptEnvironment env = script_environment();
  for (int i = 0; i < kNumPreConditions; ++i) {
    const auto& script = config_.pre[i];
    if (!script) continue;
    bool value;
    try {
      if (status_ == NodeStatus::kIdle) {
        value = script->EvaluateCondition(env);
      } else if (status_ == NodeStatus::kRunning && i == kWhileTrue) {
        value = script->EvaluateCondition(env);
      } else {
        continue;
      }
    } catch (const std::exception& e) {
      ThrowScriptError(PreConditionNames()[i], e);
    }
    if (status_ == NodeStatus::kIdle) {
      if (value && i == kFailureIf) return NodeStatus::kFailure;
      if (value && i == kSuccessIf) return NodeStatus::kSuccess;
      if (value && i == kSkipIf) return NodeStatus::kSkipped;
      if (!value && i == kWhileTrue) return NodeStatus::kSkipped;
    } else if (!value) {  // _while turned false while RUNNING: preempt within this tick.
      HaltNode();
      return NodeStatus::kSkipped;
    }
  }
  return std::nullopt;
}

void TreeNode::RunPostConditions(NodeStatus status) {
  const ScriptEnvironment env = script_environment();
  const auto run = [&](int index) {
    if (!config_.post[index]) return;
    try {
      config_.post[index]->Evaluate(env);
    } catch (const std::exception& e) {
      ThrowScriptError(PostConditionNames()[index], e);
    }
  };
  if (status == NodeStatus::kSuccess) run(kOnSuccess);
  if (status == NodeStatus::kFailure) run(kOnFailure);
  if (IsCompleted(status)) run(kOnPost);
}

NodeStatus TreeNode::ExecuteTick() {
  NodeStatus result;
  if (auto pre = CheckPreConditions()) {
    result = *pre;
  } else {
    result = Tick();
    if (result == NodeStatus::kIdle) {
      throw LogicError(Cat("[", path(), "] Tick() returned IDLE; a node must return RUNNING, ",
                           "SUCCESS, FAILURE or SKIPPED"));
    }
    if (result == NodeStatus::kRunning &&
        (kind() == NodeKind::kCondition || dynamic_cast<SyncActionNode*>(this) != nullptr)) {
      throw LogicError(Cat("[", path(), "] a ",
                           kind() == NodeKind::kCondition ? "condition" : "synchronous action",
                           " returned RUNNING"));
    }
  }
  // Post-conditions run before the status is published, and a skipped node keeps the status
  // it had (the parent sees SKIPPED), both as in BehaviorTree.CPP 4.10.
  RunPostConditions(result);
  if (result != NodeStatus::kSkipped) SetStatus(result);
  // A decorator's completed child goes back to IDLE once the decorator's own status is set
  // (BT.CPP's DecoratorNode::executeTick; most decorators reset it themselves, earlier).
  if (resets_completed_child_) {
    if (const auto children = this->children();
        !children.empty() && IsCompleted(children.front()->status())) {
      children.front()->ResetStatus();
    }
  }
  return result;
}

void TreeNode::HaltNode() {
  if (status_ == NodeStatus::kRunning) {
    Halt();
    if (const auto& script = config_.post[kOnHalted]) {
      try {
        script->Evaluate(script_environment());
      } catch (const std::exception& e) {
        ThrowScriptError(PostConditionNames()[kOnHalted], e);
      }
    }
  }
  ResetStatus();
}

NodeStatus StatefulActionNode::Tick() {
  if (status() == NodeStatus::kRunning) return OnRunning();
  context().NotifyStarting();
  return OnStart();
}

void ControlNode::HaltChildren(std::size_t first) {
  for (std::size_t i = first; i < children_.size(); ++i)
    children_[i]->HaltNode();
}

NodeStatus SimpleLeafNode::Tick() {
  return function_(*this);
}

}  // namespace egress::bt
