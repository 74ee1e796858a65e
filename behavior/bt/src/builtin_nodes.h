#pragma once
// Built-in node types of BehaviorTree.CPP v4, registered by BehaviorTreeFactory's constructor
// through the same public path applications use.

#include "egress/bt/tree_node.h"

namespace egress::bt {

class BehaviorTreeFactory;

namespace internal {

/// Registers every built-in node type.
void RegisterBuiltinNodes(BehaviorTreeFactory& factory);

/// A node the loader did not know, standing in for the real one: leaves ask the tree's
/// stand-in driver for their result (SUCCESS when there is none), a control behaves like a
/// Sequence, a decorator passes its child's status through.
std::unique_ptr<TreeNode> MakeStandIn(NodeKind kind, std::string name, NodeConfig config);

/// The blackboard key a WasEntryUpdated / SkipUnlessUpdated / WaitValueUpdate node watches: its
/// `entry` port, "{key}" or a bare key name.
/// @throws LogicError naming the node when the port is missing or empty.
std::string WatchedEntryKey(const TreeNode& node);

/// The node a SubTree element becomes: ticks the subtree's root.
class SubTreeNode final : public DecoratorNode {
 public:
  SubTreeNode(std::string name, NodeConfig config, std::string subtree_id)
      : DecoratorNode(std::move(name), std::move(config)), subtree_id_(std::move(subtree_id)) {}
  NodeKind kind() const override { return NodeKind::kSubTree; }
  const std::string& subtree_id() const { return subtree_id_; }

 protected:
  NodeStatus Tick() override;

 private:
  std::string subtree_id_;
};

}  // namespace internal
}  // namespace egress::bt
