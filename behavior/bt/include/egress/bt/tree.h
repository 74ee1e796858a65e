#pragma once
/// @file
/// Tree: an instantiated behavior tree, created by BehaviorTreeFactory. It owns its nodes and
/// blackboards and is ticked by the application (the executive ticks it at its own rate, in
/// the twin in lock-step with simulated time).

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "egress/bt/tree_node.h"

namespace egress::bt {

struct NodeManifest;

class Tree {
 public:
  Tree(Tree&&) noexcept;
  Tree& operator=(Tree&&) noexcept;
  /// Halts the tree if it is still running.
  ~Tree();

  /// One tick: a pass from the root, repeated at once while a node asked for a wake-up pass
  /// (BehaviorTree.CPP's tickOnce()). Returns the root's status.
  NodeStatus TickOnce();
  /// Ticks until the root is not RUNNING, calling `between_ticks` after each RUNNING pass (to
  /// advance a simulation or sleep); stops after `max_ticks` passes if non-zero.
  NodeStatus TickWhileRunning(const std::function<void()>& between_ticks = {},
                              std::uint64_t max_ticks = 0);
  /// Halts every running node (synchronously, in this thread) and resets the tree to IDLE.
  void HaltTree();

  TreeNode& root() const { return *nodes_.front(); }
  /// All nodes, in depth-first creation order (node.uid() == index + 1).
  std::span<const std::unique_ptr<TreeNode>> nodes() const { return nodes_; }
  /// The node with this instance path, or nullptr.
  TreeNode* FindNode(std::string_view path) const;
  /// Nodes whose instance name is `name`.
  std::vector<TreeNode*> FindNodesByName(std::string_view name) const;
  const Blackboard::Ptr& root_blackboard() const { return blackboards_.front(); }
  const std::string& main_tree_id() const { return main_tree_id_; }
  std::uint64_t tick_count() const { return tick_count_; }

  /// Replaces the clock timers and observers read (default: a SteadyClock).
  void SetClock(std::shared_ptr<const Clock> clock);
  const Clock& clock() const { return *context_->clock; }
  /// Adds a status-change observer; returns an id for RemoveStatusObserver.
  int AddStatusObserver(StatusCallback callback);
  void RemoveStatusObserver(int id);
  /// Decides the results of stand-in leaves (see LoadOptions::stand_in_unknown_nodes).
  void SetStandInDriver(std::function<NodeStatus(const TreeNode&)> driver);

  /// Node types the loader did not know and replaced by stand-ins.
  const std::vector<std::string>& stand_in_node_ids() const { return stand_in_ids_; }
  /// What the loader inferred of the unknown node type `id` (its kind, the ports the XML set),
  /// or nullptr.
  const NodeManifest* FindStandInManifest(std::string_view id) const;
  /// SubTree IDs without a definition that were replaced by stand-ins.
  const std::vector<std::string>& stubbed_subtree_ids() const { return stubbed_subtrees_; }

 private:
  friend class BehaviorTreeFactory;
  Tree();

  std::unique_ptr<TreeContext> context_;
  std::vector<std::unique_ptr<TreeNode>> nodes_;
  std::vector<Blackboard::Ptr> blackboards_;
  std::vector<std::shared_ptr<const void>> keep_alive_;  // manifests, type registry, enums
  std::string main_tree_id_;
  std::vector<std::string> stand_in_ids_;
  std::vector<std::shared_ptr<const NodeManifest>> stand_in_manifests_;
  std::vector<std::string> stubbed_subtrees_;
  std::uint64_t tick_count_{0};
  int next_observer_id_{1};
};

}  // namespace egress::bt
