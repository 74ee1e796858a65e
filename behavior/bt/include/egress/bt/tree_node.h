#pragma once
/// @file
/// TreeNode and the base classes application nodes derive from.
///
/// A node is ticked through ExecuteTick(), which applies the v4 pre-conditions (`_failureIf`,
/// `_successIf`, `_skipIf`, `_while`), calls Tick(), records the status and runs the
/// post-conditions (`_onSuccess`, `_onFailure`, `_post`). HaltNode() stops a RUNNING node:
/// Halt() (recursively for parents, in child order), then `_onHalted`, then back to IDLE. All of
/// it happens synchronously in the ticking thread.
///
/// Application nodes derive from SyncActionNode (completes within one tick), StatefulActionNode
/// (OnStart/OnRunning/OnHalted), ConditionNode, ControlNode or DecoratorNode, declare
/// `static PortsList ProvidedPorts()`, and are registered with BehaviorTreeFactory.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "egress/bt/blackboard.h"
#include "egress/bt/clock.h"
#include "egress/bt/ports.h"
#include "egress/bt/script.h"
#include "egress/bt/status.h"

namespace egress::bt {

class TreeNode;

/// The category of a node type, as in the TreeNodesModel.
enum class NodeKind { kAction, kCondition, kControl, kDecorator, kSubTree };
std::string_view ToString(NodeKind kind);

/// Called on every status change: (time, node, previous, new).
using StatusCallback = std::function<void(Duration, const TreeNode&, NodeStatus, NodeStatus)>;

/// State shared by all nodes of one tree (owned by the Tree, address-stable).
struct TreeContext {
  std::shared_ptr<const Clock> clock;
  std::vector<std::pair<int, StatusCallback>> observers;
  const TypeRegistry* types{nullptr};
  const ScriptEnums* enums{nullptr};
  /// Drives stand-in leaves (nodes the loader did not know); returns their result.
  std::function<NodeStatus(const TreeNode&)> stand_in_driver;
  /// Preemption guards pushed by reactive parents while they tick an earlier child and a later
  /// child is RUNNING; run (innermost first) just before any action starts. See NotifyStarting.
  std::vector<std::function<void()>> start_guards;
  /// Set by a node that returned RUNNING only to let the tree re-check what is above it (a
  /// loop between synchronous cycles): Tree::TickOnce ticks the root again at once, as
  /// BehaviorTree.CPP's tickOnce() does after emitWakeUpSignal().
  bool wake_up{false};

  Duration Now() const { return clock->Now(); }
  /// Called by a node about to start an asynchronous action: halts the branches that reactive
  /// ancestors are about to preempt, so two actions never run at once.
  void NotifyStarting();
};

/// Pre-condition scripts, in evaluation order.
enum PreCondition { kFailureIf = 0, kSuccessIf, kSkipIf, kWhileTrue, kNumPreConditions };
/// Post-condition scripts.
enum PostCondition { kOnSuccess = 0, kOnFailure, kOnPost, kOnHalted, kNumPostConditions };

/// Attribute names of the pre- and post-conditions, indexed as above.
const std::array<std::string_view, kNumPreConditions>& PreConditionNames();
const std::array<std::string_view, kNumPostConditions>& PostConditionNames();

/// Everything the loader gives a node instance.
struct NodeConfig {
  Blackboard::Ptr blackboard;
  /// Port name → XML text (a literal or a blackboard reference), for ports set in the XML.
  std::map<std::string, std::string, std::less<>> ports;
  /// The node type's port declarations (null for nodes without ports).
  const PortsList* manifest_ports{nullptr};
  std::string registration_id;
  /// For a SubTree node (registration ID "SubTree"), the ID of the tree it includes.
  std::string subtree_id;
  std::string path;      ///< Unique instance path, e.g. "Main/FirstSubtree/SleepSequence".
  std::uint16_t uid{0};  ///< 1, 2, 3… in depth-first creation order.
  /// The file and line of the node's element (named in runtime errors).
  std::shared_ptr<const std::string> file;
  int line{0};
  std::array<std::shared_ptr<const Script>, kNumPreConditions> pre;
  std::array<std::shared_ptr<const Script>, kNumPostConditions> post;
  TreeContext* context{nullptr};
};

/// A value or the reason there is none (port reads).
template <typename T>
class Expected {
 public:
  Expected(T value) : value_(std::move(value)) {}  // NOLINT
  static Expected Error(std::string message) {
    Expected e;
    e.error_ = std::move(message);
    return e;
  }
  explicit operator bool() const { return value_.has_value(); }
  bool has_value() const { return value_.has_value(); }
  /// @throws RuntimeError with the error message when there is no value.
  const T& value() const {
    if (!value_) throw RuntimeError(error_);
    return *value_;
  }
  const T& operator*() const { return value(); }
  const std::string& error() const { return error_; }

 private:
  Expected() = default;
  std::optional<T> value_;
  std::string error_;
};

class TreeNode {
 public:
  TreeNode(std::string name, NodeConfig config);
  virtual ~TreeNode() = default;
  TreeNode(const TreeNode&) = delete;
  TreeNode& operator=(const TreeNode&) = delete;

  /// Ticks the node with the v4 pre/post-condition semantics (see file comment).
  NodeStatus ExecuteTick();
  /// Stops the node if it is RUNNING (Halt(), then `_onHalted`) and resets it to IDLE.
  void HaltNode();
  /// Resets a completed node to IDLE without halting it.
  void ResetStatus();

  NodeStatus status() const { return status_; }
  const std::string& name() const { return name_; }
  const std::string& registration_id() const { return config_.registration_id; }
  const std::string& path() const { return config_.path; }
  std::uint16_t uid() const { return config_.uid; }
  const NodeConfig& config() const { return config_; }
  virtual NodeKind kind() const = 0;
  /// The node's children (empty for leaves).
  virtual std::span<TreeNode* const> children() const { return {}; }

  /// Reads input port `port`: the XML literal converted to T, or the blackboard entry it
  /// references, or the declared default. The error names the node path and the port.
  template <typename T>
  Expected<T> GetInput(std::string_view port) const;
  /// Writes output port `port` (which must reference a blackboard key).
  /// @throws RuntimeError naming the node and port otherwise.
  template <typename T>
  void SetOutput(std::string_view port, T value);
  /// The raw XML text of a port (or its default); nullopt if neither exists.
  std::optional<std::string> PortText(std::string_view port) const;
  /// The script environment of this node (its blackboard and the tree's enums).
  ScriptEnvironment script_environment() const {
    return {config_.blackboard.get(), config_.context->enums};
  }

 protected:
  /// The node's own behaviour. Must not be called directly; use ExecuteTick().
  virtual NodeStatus Tick() = 0;
  /// Stops whatever the node is doing; called only while it is RUNNING.
  virtual void Halt() {}
  void SetStatus(NodeStatus status);
  TreeContext& context() const { return *config_.context; }
  /// Asks for another pass from the root within the current TickOnce (see TreeContext).
  void EmitWakeUpSignal() { config_.context->wake_up = true; }

 private:
  std::optional<NodeStatus> CheckPreConditions();
  void RunPostConditions(NodeStatus status);
  [[noreturn]] void ThrowScriptError(std::string_view attribute, const std::exception& e) const;

  std::string name_;
  NodeConfig config_;
  NodeStatus status_{NodeStatus::kIdle};

 protected:
  /// Set by DecoratorNode: ExecuteTick resets a completed child after the node's own status.
  bool resets_completed_child_{false};
};

/// A leaf that completes within one tick; returning RUNNING is an error.
class SyncActionNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  NodeKind kind() const override { return NodeKind::kAction; }
};

/// A leaf that checks something; must not return RUNNING.
class ConditionNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  NodeKind kind() const override { return NodeKind::kCondition; }
};

/// An asynchronous action: OnStart() on the first tick, OnRunning() on the following ones while
/// it returns RUNNING, OnHalted() when it is halted while running.
class StatefulActionNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  NodeKind kind() const override { return NodeKind::kAction; }

 protected:
  virtual NodeStatus OnStart() = 0;
  virtual NodeStatus OnRunning() = 0;
  virtual void OnHalted() = 0;

 private:
  NodeStatus Tick() final;
  void Halt() final { OnHalted(); }
};

/// A node with one or more children.
class ControlNode : public TreeNode {
 public:
  using TreeNode::TreeNode;
  NodeKind kind() const override { return NodeKind::kControl; }
  std::span<TreeNode* const> children() const override { return children_; }
  void AddChild(TreeNode* child) { children_.push_back(child); }

 protected:
  /// Halts (or resets) every child from `first` on.
  void HaltChildren(std::size_t first = 0);
  void Halt() override { HaltChildren(); }
  std::vector<TreeNode*> children_;
};

/// A node with exactly one child.
class DecoratorNode : public TreeNode {
 public:
  DecoratorNode(std::string name, NodeConfig config)
      : TreeNode(std::move(name), std::move(config)) {
    resets_completed_child_ = true;
  }
  NodeKind kind() const override { return NodeKind::kDecorator; }
  std::span<TreeNode* const> children() const override { return {&child_, child_ ? 1u : 0u}; }
  void SetChild(TreeNode* child) { child_ = child; }
  TreeNode* child() const { return child_; }

 protected:
  void HaltChild() { child_->HaltNode(); }
  void Halt() override { HaltChild(); }
  TreeNode* child_{nullptr};
};

/// A leaf from a function (RegisterSimpleAction / RegisterSimpleCondition).
class SimpleLeafNode : public TreeNode {
 public:
  using Function = std::function<NodeStatus(TreeNode&)>;
  SimpleLeafNode(std::string name, NodeConfig config, NodeKind kind, Function function)
      : TreeNode(std::move(name), std::move(config)), kind_(kind), function_(std::move(function)) {}
  NodeKind kind() const override { return kind_; }

 protected:
  NodeStatus Tick() override;

 private:
  NodeKind kind_;
  Function function_;
};

// ---- template implementations

template <typename T>
Expected<T> TreeNode::GetInput(std::string_view port) const {
  const auto fail = [&](const std::string& what) {
    return Expected<T>::Error(Cat("[", path(), "] input port '", port, "': ", what));
  };
  const std::optional<std::string> text = PortText(port);
  if (!text) return fail("not set in the XML and it has no default");
  try {
    if (auto key = BlackboardKeyOf(*text, port)) {
      const std::optional<Any> value = config_.blackboard->GetAny(*key);
      if (!value || value->empty()) return fail(Cat("blackboard entry '", *key, "' is not set"));
      return value->template Cast<T>(config_.context->types);
    }
    if constexpr (std::is_same_v<T, std::string>) {
      return *text;
    } else if constexpr (std::is_same_v<T, Any>) {
      return Any(*text);
    } else if constexpr ((std::is_integral_v<T> || std::is_enum_v<T>)&&!std::is_same_v<T, bool>) {
      // Integer ports accept the names of scripting enums.
      if (config_.context->enums != nullptr) {
        if (auto it = config_.context->enums->find(*text); it != config_.context->enums->end()) {
          return static_cast<T>(it->second);
        }
      }
      return Any(*text).template Cast<T>(config_.context->types);
    } else {
      return ConvertFromString<T>(*text, config_.context->types);
    }
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

template <typename T>
void TreeNode::SetOutput(std::string_view port, T value) {
  const std::optional<std::string> text = PortText(port);
  if (!text) throw RuntimeError(Cat("[", path(), "] output port '", port, "' is not set"));
  const auto key = BlackboardKeyOf(*text, port);
  if (!key) {
    throw RuntimeError(Cat("[", path(), "] output port '", port, "' holds the literal '", *text,
                           "'; an output must be a blackboard reference like {key}"));
  }
  try {
    config_.blackboard->Set(*key, Any(std::move(value)));
  } catch (const RuntimeError& e) {
    throw RuntimeError(Cat("[", path(), "] output port '", port, "': ", e.what()));
  }
}

}  // namespace egress::bt
