// Leaves: AlwaysSuccess, AlwaysFailure, Script, ScriptCondition, SetBlackboard,
// UnsetBlackboard, Sleep, WasEntryUpdated; and the stand-in leaf for unknown node types.

#include "builtin_nodes.h"
#include "egress/bt/factory.h"

namespace egress::bt::internal {
namespace {

class ConstantNode final : public SyncActionNode {
 public:
  ConstantNode(std::string name, NodeConfig config, NodeStatus result)
      : SyncActionNode(std::move(name), std::move(config)), result_(result) {}

 protected:
  NodeStatus Tick() override { return result_; }

 private:
  NodeStatus result_;
};

/// WasEntryUpdated (BT.CPP 4.10's EntryUpdatedAction): SUCCESS if the watched blackboard entry
/// was written since the node last looked, else FAILURE.
class WasEntryUpdatedNode final : public SyncActionNode {
 public:
  WasEntryUpdatedNode(std::string name, NodeConfig config)
      : SyncActionNode(std::move(name), std::move(config)), key_(WatchedEntryKey(*this)) {}
  static PortsList ProvidedPorts() { return {InputPort<Any>("entry", "the entry to watch")}; }

 protected:
  NodeStatus Tick() override {
    const std::uint64_t previous = sequence_;
    sequence_ = config().blackboard->SequenceId(key_);
    return sequence_ != 0 && sequence_ != previous ? NodeStatus::kSuccess : NodeStatus::kFailure;
  }

 private:
  std::string key_;
  std::uint64_t sequence_{0};
};

/// Script (always SUCCESS once the code ran) and ScriptCondition (SUCCESS if the result is
/// true). The code is parsed when the node is created, i.e. at load time.
class ScriptNode final : public TreeNode {
 public:
  ScriptNode(std::string name, NodeConfig config, bool is_condition)
      : TreeNode(std::move(name), std::move(config)), is_condition_(is_condition) {
    if (auto text = PortText("code"); text && !BlackboardKeyOf(*text, "code"))
      script_ = Script::Parse(*text);
  }
  NodeKind kind() const override {
    return is_condition_ ? NodeKind::kCondition : NodeKind::kAction;
  }

 protected:
  NodeStatus Tick() override {
    std::shared_ptr<const Script> script = script_;
    if (!script) script = Script::Parse(GetInput<std::string>("code").value());
    try {
      if (is_condition_) {
        return script->EvaluateCondition(script_environment()) ? NodeStatus::kSuccess
                                                               : NodeStatus::kFailure;
      }
      script->Evaluate(script_environment());
      return NodeStatus::kSuccess;
    } catch (const RuntimeError& e) {
      throw RuntimeError(Cat("[", path(), "] ", e.what()));
    }
  }

 private:
  bool is_condition_;
  std::shared_ptr<const Script> script_;
};

/// SetBlackboard: output_key is a literal key name; value is a literal or {other} (copied with
/// its type).
class SetBlackboardNode final : public SyncActionNode {
 public:
  using SyncActionNode::SyncActionNode;
  static PortsList ProvidedPorts() {
    return {InputPort<Any>("value", "a literal or {key} to copy"),
            InputPort<std::string>("output_key", "name of the blackboard key to write")};
  }

 protected:
  NodeStatus Tick() override {
    const std::string key = GetInput<std::string>("output_key").value();
    const std::string text = PortText("value").value_or("");
    Any value = Any(text);
    if (auto source = BlackboardKeyOf(text, "value")) {
      auto copied = config().blackboard->GetAny(*source);
      if (!copied)
        throw RuntimeError(
            Cat("[", path(), "] value: blackboard entry '", *source, "' is not set"));
      value = *copied;
    }
    try {
      config().blackboard->Set(key, std::move(value));
    } catch (const RuntimeError& e) {
      throw RuntimeError(Cat("[", path(), "] ", e.what()));
    }
    return NodeStatus::kSuccess;
  }
};

class UnsetBlackboardNode final : public SyncActionNode {
 public:
  using SyncActionNode::SyncActionNode;
  static PortsList ProvidedPorts() { return {InputPort<std::string>("key", "the key to remove")}; }

 protected:
  NodeStatus Tick() override {
    config().blackboard->Unset(GetInput<std::string>("key").value());
    return NodeStatus::kSuccess;
  }
};

/// Sleep: RUNNING until msec of the tree's clock have passed, then SUCCESS.
class SleepNode final : public StatefulActionNode {
 public:
  using StatefulActionNode::StatefulActionNode;
  static PortsList ProvidedPorts() {
    return {InputPort<unsigned>("msec", "milliseconds to sleep")};
  }

 protected:
  NodeStatus OnStart() override {
    duration_ = std::chrono::milliseconds(GetInput<unsigned>("msec").value());
    if (duration_.count() == 0) return NodeStatus::kSuccess;
    start_ = context().Now();
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    return context().Now() - start_ >= duration_ ? NodeStatus::kSuccess : NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Duration start_{};
  Duration duration_{};
};

class StandInLeaf final : public TreeNode {
 public:
  StandInLeaf(std::string name, NodeConfig config, NodeKind kind)
      : TreeNode(std::move(name), std::move(config)), kind_(kind) {}
  NodeKind kind() const override { return kind_; }

 protected:
  NodeStatus Tick() override {
    const auto& driver = context().stand_in_driver;
    const NodeStatus result = driver ? driver(*this) : NodeStatus::kSuccess;
    if (result == NodeStatus::kIdle) {
      throw RuntimeError(Cat("[", path(), "] the stand-in driver returned IDLE"));
    }
    if (result == NodeStatus::kRunning && status() != NodeStatus::kRunning) {
      if (kind_ == NodeKind::kCondition) {
        throw RuntimeError(Cat("[", path(), "] a stand-in condition cannot return RUNNING"));
      }
      context().NotifyStarting();  // it starts an asynchronous action: preempt first
    }
    return result;
  }

 private:
  NodeKind kind_;
};

}  // namespace

std::unique_ptr<TreeNode> MakeStandInControl(std::string name, NodeConfig config);
std::unique_ptr<TreeNode> MakeStandInDecorator(std::string name, NodeConfig config);
void RegisterBuiltinControls(BehaviorTreeFactory& factory);
void RegisterBuiltinDecorators(BehaviorTreeFactory& factory);

std::unique_ptr<TreeNode> MakeStandIn(NodeKind kind, std::string name, NodeConfig config) {
  switch (kind) {
    case NodeKind::kControl:
      return MakeStandInControl(std::move(name), std::move(config));
    case NodeKind::kDecorator:
    case NodeKind::kSubTree:
      return MakeStandInDecorator(std::move(name), std::move(config));
    default:
      return std::make_unique<StandInLeaf>(std::move(name), std::move(config), kind);
  }
}

void RegisterBuiltinNodes(BehaviorTreeFactory& factory) {
  RegisterBuiltinControls(factory);
  RegisterBuiltinDecorators(factory);
  const auto reg = [&](const std::string& id, NodeKind kind, PortsList ports, NodeBuilder builder) {
    factory.RegisterBuilder({id, kind, std::move(ports), "", true}, std::move(builder));
  };
  reg("WasEntryUpdated", NodeKind::kAction, WasEntryUpdatedNode::ProvidedPorts(),
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<WasEntryUpdatedNode>(n, std::move(c));
      });
  reg("AlwaysSuccess", NodeKind::kAction, {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ConstantNode>(n, std::move(c), NodeStatus::kSuccess);
  });
  reg("AlwaysFailure", NodeKind::kAction, {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ConstantNode>(n, std::move(c), NodeStatus::kFailure);
  });
  PortsList code = {InputPort<std::string>("code", "the script to run")};
  code.begin()->second.script = true;
  reg("Script", NodeKind::kAction, code, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ScriptNode>(n, std::move(c), false);
  });
  reg("ScriptCondition", NodeKind::kCondition, code, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ScriptNode>(n, std::move(c), true);
  });
  reg("SetBlackboard", NodeKind::kAction, SetBlackboardNode::ProvidedPorts(),
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<SetBlackboardNode>(n, std::move(c));
      });
  reg("UnsetBlackboard", NodeKind::kAction, UnsetBlackboardNode::ProvidedPorts(),
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<UnsetBlackboardNode>(n, std::move(c));
      });
  reg("Sleep", NodeKind::kAction, SleepNode::ProvidedPorts(),
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<SleepNode>(n, std::move(c));
      });
}

}  // namespace egress::bt::internal
