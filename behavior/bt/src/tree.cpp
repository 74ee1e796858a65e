#include "egress/bt/tree.h"

#include "egress/bt/factory.h"

#include <algorithm>

namespace egress::bt {

Tree::Tree() : context_(std::make_unique<TreeContext>()) {
  context_->clock = std::make_shared<SteadyClock>();
}
Tree::Tree(Tree&&) noexcept = default;
Tree& Tree::operator=(Tree&&) noexcept = default;

Tree::~Tree() {
  if (context_ && !nodes_.empty()) {
    try {
      HaltTree();
    } catch (...) {  // a destructor must not throw; a failing _onHalted script is dropped here
    }
  }
}

NodeStatus Tree::TickOnce() {
  ++tick_count_;
  context_->start_guards.clear();
  NodeStatus status;
  // The wake-up pass: a node that yielded between synchronous cycles asked for the tree to be
  // ticked again, so that reactive guards above it are re-checked before the next cycle.
  do {
    context_->wake_up = false;
    status = root().ExecuteTick();
  } while (status == NodeStatus::kRunning && context_->wake_up);
  context_->wake_up = false;
  // A tree whose root completed is ready to start over: reset it, as BT.CPP's tick loop does.
  if (IsCompleted(status)) root().ResetStatus();
  return status;
}

NodeStatus Tree::TickWhileRunning(const std::function<void()>& between_ticks,
                                  std::uint64_t max_ticks) {
  NodeStatus status = NodeStatus::kRunning;
  for (std::uint64_t n = 0; status == NodeStatus::kRunning && (max_ticks == 0 || n < max_ticks);
       ++n) {
    status = TickOnce();
    if (status == NodeStatus::kRunning && between_ticks) between_ticks();
  }
  return status;
}

void Tree::HaltTree() {
  context_->start_guards.clear();
  root().HaltNode();
}

TreeNode* Tree::FindNode(std::string_view path) const {
  for (const auto& node : nodes_) {
    if (node->path() == path) return node.get();
  }
  return nullptr;
}

std::vector<TreeNode*> Tree::FindNodesByName(std::string_view name) const {
  std::vector<TreeNode*> found;
  for (const auto& node : nodes_) {
    if (node->name() == name) found.push_back(node.get());
  }
  return found;
}

const NodeManifest* Tree::FindStandInManifest(std::string_view id) const {
  for (const auto& manifest : stand_in_manifests_) {
    if (manifest->id == id) return manifest.get();
  }
  return nullptr;
}

void Tree::SetClock(std::shared_ptr<const Clock> clock) {
  if (!clock) throw LogicError("Tree::SetClock: the clock must not be null");
  context_->clock = std::move(clock);
}

int Tree::AddStatusObserver(StatusCallback callback) {
  const int id = next_observer_id_++;
  context_->observers.emplace_back(id, std::move(callback));
  return id;
}

void Tree::RemoveStatusObserver(int id) {
  std::erase_if(context_->observers, [id](const auto& entry) { return entry.first == id; });
}

void Tree::SetStandInDriver(std::function<NodeStatus(const TreeNode&)> driver) {
  context_->stand_in_driver = std::move(driver);
}

}  // namespace egress::bt
