// Control nodes: Sequence, AsyncSequence, SequenceWithMemory (SequenceStar), ReactiveSequence,
// Fallback, AsyncFallback, ReactiveFallback, Parallel, ParallelAll, IfThenElse, WhileDoElse,
// Switch2..Switch6, TryCatch.

#include <algorithm>
#include <cmath>
#include <set>

#include "builtin_nodes.h"
#include "egress/bt/factory.h"

namespace egress::bt::internal {
namespace {

/// Sequence, SequenceWithMemory, Fallback, AsyncSequence and AsyncFallback (BT.CPP 4.10's
/// SequenceNode, SequenceWithMemory and FallbackNode): tick children in order and resume at a
/// RUNNING child without re-ticking completed ones. A Sequence stops at the first FAILURE (and
/// starts over next time; with memory it retries the failed child), a Fallback at the first
/// SUCCESS. SequenceWithMemory and the Async variants yield (RUNNING with a wake-up pass) after
/// a child that completed within its first tick, so reactive guards above them are re-checked
/// between children.
class OrderedNode : public ControlNode {
 public:
  enum class Flavor { kPlain, kAsync, kMemory };
  OrderedNode(std::string name, NodeConfig config, bool is_sequence, Flavor flavor)
      : ControlNode(std::move(name), std::move(config)),
        is_sequence_(is_sequence),
        flavor_(flavor) {}

 protected:
  NodeStatus Tick() override {
    const std::size_t n = children_.size();
    if (!IsActive(status())) skipped_ = 0;
    SetStatus(NodeStatus::kRunning);
    const NodeStatus stop_on = is_sequence_ ? NodeStatus::kFailure : NodeStatus::kSuccess;
    while (index_ < n) {
      const NodeStatus previous = children_[index_]->status();
      const NodeStatus child_status = children_[index_]->ExecuteTick();
      if (child_status == NodeStatus::kRunning) return NodeStatus::kRunning;
      if (child_status == NodeStatus::kSkipped) {
        ++index_;
        ++skipped_;
        continue;
      }
      if (child_status == stop_on) {
        if (flavor_ == Flavor::kMemory) {
          HaltChildren(index_);  // keep the index: the next tick retries this child
        } else {
          HaltChildren();
          index_ = 0;
        }
        return stop_on;
      }
      ++index_;
      if (flavor_ != Flavor::kPlain && previous == NodeStatus::kIdle && index_ < n) {
        EmitWakeUpSignal();
        return NodeStatus::kRunning;
      }
    }
    const bool all_skipped = skipped_ == n;
    if (index_ == n) {
      HaltChildren();
      index_ = 0;
      skipped_ = 0;
    }
    if (all_skipped) return NodeStatus::kSkipped;
    return is_sequence_ ? NodeStatus::kSuccess : NodeStatus::kFailure;
  }

  void Halt() override {
    // As in BT.CPP, a halted SequenceWithMemory keeps its index and resumes there.
    if (flavor_ != Flavor::kMemory) {
      index_ = 0;
      skipped_ = 0;
    }
    HaltChildren();
  }

 private:
  static bool IsActive(NodeStatus s) { return s != NodeStatus::kIdle && s != NodeStatus::kSkipped; }
  bool is_sequence_;
  Flavor flavor_;
  std::size_t index_{0};
  std::size_t skipped_{0};
};

/// ReactiveSequence and ReactiveFallback: every tick re-ticks from child 0.
///
/// Difference from BehaviorTree.CPP (its open issue #1031): when an earlier child starts an
/// asynchronous action while a later child is RUNNING, BT.CPP halts the later child only after
/// the earlier one has started, so two actions briefly run at once. Here the reactive node
/// registers a preemption guard while it ticks the earlier child, and the guard halts the
/// running child just before the new action's OnStart — in the same tick, and before it.
class ReactiveNode : public ControlNode {
 public:
  ReactiveNode(std::string name, NodeConfig config, bool is_sequence)
      : ControlNode(std::move(name), std::move(config)), is_sequence_(is_sequence) {}

 protected:
  NodeStatus Tick() override {
    SetStatus(NodeStatus::kRunning);
    bool all_skipped = true;
    const NodeStatus stop_on = is_sequence_ ? NodeStatus::kFailure : NodeStatus::kSuccess;
    for (std::size_t index = 0; index < children_.size(); ++index) {
      const std::size_t running = RunningChildAfter(index);
      std::size_t guard_depth = 0;
      if (running != kNone) {
        context().start_guards.push_back([this, running] { children_[running]->HaltNode(); });
        guard_depth = context().start_guards.size();
      }
      const NodeStatus child_status = children_[index]->ExecuteTick();
      if (guard_depth != 0 && context().start_guards.size() >= guard_depth) {
        context().start_guards.resize(guard_depth - 1);  // not fired: drop ours (and inner ones)
      }
      all_skipped = all_skipped && child_status == NodeStatus::kSkipped;
      if (child_status == NodeStatus::kRunning) {
        for (std::size_t i = 0; i < children_.size(); ++i) {
          if (i != index) children_[i]->HaltNode();
        }
        return NodeStatus::kRunning;
      }
      if (child_status == stop_on) {
        HaltChildren();
        return stop_on;
      }
      if (child_status == NodeStatus::kSkipped) children_[index]->HaltNode();
    }
    HaltChildren();
    if (all_skipped) return NodeStatus::kSkipped;
    return is_sequence_ ? NodeStatus::kSuccess : NodeStatus::kFailure;
  }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t RunningChildAfter(std::size_t index) const {
    for (std::size_t i = index + 1; i < children_.size(); ++i) {
      if (children_[i]->status() == NodeStatus::kRunning) return i;
    }
    return kNone;
  }
  bool is_sequence_;
};

/// Resolves a negative threshold t to N + t + 1 (so -1 means "all").
std::size_t Threshold(int value, std::size_t children) {
  if (value >= 0) return std::size_t(value);
  const long resolved = long(children) + value + 1;
  return resolved < 0 ? 0 : std::size_t(resolved);
}

class ParallelNode : public ControlNode {
 public:
  using ControlNode::ControlNode;
  static PortsList ProvidedPorts() {
    return {InputPort<int>("success_count", -1, "children that must succeed (-1: all)"),
            InputPort<int>("failure_count", 1, "children that must fail (-1: all)")};
  }

 protected:
  NodeStatus Tick() override {
    const int success_threshold = GetInput<int>("success_count").value();
    const int failure_threshold = GetInput<int>("failure_count").value();
    const std::size_t n = children_.size();
    const std::size_t required_success = Threshold(success_threshold, n);
    const std::size_t required_failure = Threshold(failure_threshold, n);
    if (required_success > n || required_failure > n) {
      throw RuntimeError(Cat("[", path(), "] Parallel: success_count (", success_threshold,
                             ") or failure_count (", failure_threshold, ") exceeds its ", n,
                             " children"));
    }
    SetStatus(NodeStatus::kRunning);
    std::size_t skipped = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!completed_.contains(i)) {
        const NodeStatus child_status = children_[i]->ExecuteTick();
        if (child_status == NodeStatus::kSkipped) ++skipped;
        if (child_status == NodeStatus::kSuccess) {
          completed_.insert(i);
          ++successes_;
        }
        if (child_status == NodeStatus::kFailure) {
          completed_.insert(i);
          ++failures_;
        }
      }
      if (successes_ >= required_success ||
          (success_threshold < 0 && successes_ + skipped >= required_success)) {
        Clear();
        return NodeStatus::kSuccess;
      }
      if (n - failures_ < required_success || failures_ >= required_failure) {
        Clear();
        return NodeStatus::kFailure;
      }
    }
    return skipped == n ? NodeStatus::kSkipped : NodeStatus::kRunning;
  }
  void Halt() override { Clear(); }

 private:
  void Clear() {
    completed_.clear();
    successes_ = failures_ = 0;
    HaltChildren();
  }
  std::set<std::size_t> completed_;
  std::size_t successes_{0};
  std::size_t failures_{0};
};

class ParallelAllNode : public ControlNode {
 public:
  using ControlNode::ControlNode;
  static PortsList ProvidedPorts() {
    return {InputPort<int>("max_failures", 1, "failures that make the node fail (-1: all)")};
  }

 protected:
  NodeStatus Tick() override {
    const int max_failures = GetInput<int>("max_failures").value();
    const std::size_t n = children_.size();
    const std::size_t threshold = Threshold(max_failures, n);
    if (threshold > n) {
      throw RuntimeError(Cat("[", path(), "] ParallelAll: max_failures (", max_failures,
                             ") exceeds its ", n, " children"));
    }
    SetStatus(NodeStatus::kRunning);
    std::size_t skipped = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (completed_.contains(i)) continue;
      const NodeStatus child_status = children_[i]->ExecuteTick();
      if (child_status == NodeStatus::kSkipped) ++skipped;
      if (IsCompleted(child_status)) completed_.insert(i);
      if (child_status == NodeStatus::kFailure) ++failures_;
    }
    if (skipped == n) return NodeStatus::kSkipped;
    if (skipped + completed_.size() >= n) {
      const NodeStatus result =
          failures_ >= threshold ? NodeStatus::kFailure : NodeStatus::kSuccess;
      Halt();
      return result;
    }
    return NodeStatus::kRunning;
  }
  void Halt() override {
    completed_.clear();
    failures_ = 0;
    HaltChildren();
  }

 private:
  std::set<std::size_t> completed_;
  std::size_t failures_{0};
};

/// IfThenElse: the condition is evaluated once, then the chosen branch runs to completion.
class IfThenElseNode : public ControlNode {
 public:
  using ControlNode::ControlNode;

 protected:
  NodeStatus Tick() override {
    SetStatus(NodeStatus::kRunning);
    if (branch_ == 0) {
      const NodeStatus condition = children_[0]->ExecuteTick();
      if (condition == NodeStatus::kRunning) return NodeStatus::kRunning;
      if (condition == NodeStatus::kSkipped) {
        HaltChildren();
        return NodeStatus::kSkipped;
      }
      if (condition == NodeStatus::kSuccess) {
        branch_ = 1;
      } else if (children_.size() == 3) {
        branch_ = 2;
      } else {
        HaltChildren();
        return NodeStatus::kFailure;
      }
    }
    const NodeStatus result = children_[branch_]->ExecuteTick();
    if (result == NodeStatus::kRunning) return result;
    HaltChildren();
    branch_ = 0;
    return result;
  }
  void Halt() override {
    branch_ = 0;
    HaltChildren();
  }

 private:
  std::size_t branch_{0};
};

/// WhileDoElse: the condition is ticked every tick; the losing branch is halted before the
/// selected one is ticked.
class WhileDoElseNode : public ControlNode {
 public:
  using ControlNode::ControlNode;

 protected:
  NodeStatus Tick() override {
    SetStatus(NodeStatus::kRunning);
    const NodeStatus condition = children_[0]->ExecuteTick();
    if (condition == NodeStatus::kRunning) return condition;
    if (condition == NodeStatus::kSkipped) {
      HaltChildren();
      return NodeStatus::kSkipped;
    }
    NodeStatus result;
    if (condition == NodeStatus::kSuccess) {
      if (children_.size() == 3) children_[2]->HaltNode();
      result = children_[1]->ExecuteTick();
    } else if (children_.size() == 3) {
      children_[1]->HaltNode();
      result = children_[2]->ExecuteTick();
    } else {
      result = NodeStatus::kFailure;
    }
    if (result == NodeStatus::kRunning) return result;
    HaltChildren();
    return result;
  }
};

/// SwitchN: runs the child whose case_i equals `variable` (the last child is the default);
/// reactive, and halts the previously running branch before ticking a newly matched one.
class SwitchNode : public ControlNode {
 public:
  SwitchNode(std::string name, NodeConfig config, int cases)
      : ControlNode(std::move(name), std::move(config)), cases_(cases) {}
  static PortsList Ports(int cases) {
    PortsList ports = {InputPort<std::string>("variable", "the value to match")};
    for (int i = 1; i <= cases; ++i) {
      ports.insert(InputPort<std::string>(Cat("case_", i), "", "a value to match"));
    }
    return ports;
  }

 protected:
  NodeStatus Tick() override {
    int match = cases_;
    if (auto variable = GetInput<std::string>("variable")) {
      for (int i = 0; i < cases_; ++i) {
        auto value = GetInput<std::string>(Cat("case_", i + 1));
        if (value && Matches(*variable, *value)) {
          match = i;
          break;
        }
      }
    }
    if (running_ >= 0 && running_ != match) children_[std::size_t(running_)]->HaltNode();
    // No RUNNING of its own before the child runs: BT.CPP's Switch goes from IDLE straight to
    // the child's result.
    const NodeStatus result = children_[match]->ExecuteTick();
    if (result == NodeStatus::kSkipped) {
      running_ = -1;
    } else if (result == NodeStatus::kRunning) {
      running_ = match;
    } else {
      HaltChildren();
      running_ = -1;
    }
    return result;
  }
  void Halt() override {
    running_ = -1;
    HaltChildren();
  }

 private:
  // Exact string, then integers (enum names resolved), then doubles within epsilon.
  bool Matches(const std::string& a, const std::string& b) const {
    if (a == b) return true;
    const auto integer = [&](const std::string& s) -> std::optional<std::int64_t> {
      if (const auto* enums = context().enums) {
        if (auto it = enums->find(s); it != enums->end()) return it->second;
      }
      try {
        return ParseInteger(s);
      } catch (const RuntimeError&) {
        return std::nullopt;
      }
    };
    const auto ia = integer(a), ib = integer(b);
    if (ia && ib) return *ia == *ib;
    try {
      const double da = ParseReal(a), db = ParseReal(b);
      return std::abs(da - db) <= std::numeric_limits<float>::epsilon();
    } catch (const RuntimeError&) {
      return false;
    }
  }
  int cases_;
  int running_{-1};
};

/// TryCatch (BT.CPP 4.10): children 0..N-2 run as a Sequence (the try block); when one fails,
/// the try block is reset and the last child (the catch block) runs to completion, after which
/// the node fails. With `catch_on_halt`, halting it during the try block runs the catch block
/// once, synchronously (a catch block still RUNNING then is halted too).
class TryCatchNode : public ControlNode {
 public:
  using ControlNode::ControlNode;
  static PortsList ProvidedPorts() {
    return {InputPort<bool>("catch_on_halt", false,
                            "run the catch child when halted during the try block")};
  }

 protected:
  NodeStatus Tick() override {
    const std::size_t n = children_.size();
    if (n < 2) throw LogicError(Cat("[", path(), "] TryCatch requires at least 2 children"));
    if (status() == NodeStatus::kIdle || status() == NodeStatus::kSkipped) {
      skipped_ = 0;
      in_catch_ = false;
    }
    SetStatus(NodeStatus::kRunning);
    const std::size_t try_count = n - 1;
    while (!in_catch_ && index_ < try_count) {
      const NodeStatus child_status = children_[index_]->ExecuteTick();
      if (child_status == NodeStatus::kRunning) return NodeStatus::kRunning;
      if (child_status == NodeStatus::kFailure) {
        HaltChildren();
        index_ = 0;
        in_catch_ = true;
        break;
      }
      if (child_status == NodeStatus::kSkipped) ++skipped_;
      ++index_;
    }
    if (in_catch_) {
      if (children_.back()->ExecuteTick() == NodeStatus::kRunning) return NodeStatus::kRunning;
      HaltChildren();
      index_ = 0;
      in_catch_ = false;
      return NodeStatus::kFailure;
    }
    const bool all_skipped = skipped_ == try_count;
    HaltChildren();
    index_ = 0;
    skipped_ = 0;
    return all_skipped ? NodeStatus::kSkipped : NodeStatus::kSuccess;
  }

  void Halt() override {
    const bool catch_on_halt = GetInput<bool>("catch_on_halt").value();
    if (catch_on_halt && !in_catch_ && status() == NodeStatus::kRunning) {
      for (std::size_t i = 0; i + 1 < children_.size(); ++i)
        children_[i]->HaltNode();
      if (children_.back()->ExecuteTick() == NodeStatus::kRunning) children_.back()->HaltNode();
    }
    index_ = 0;
    skipped_ = 0;
    in_catch_ = false;
    HaltChildren();
  }

 private:
  std::size_t index_{0};
  std::size_t skipped_{0};
  bool in_catch_{false};
};

/// Stand-in for an unknown control node: a Sequence.
class StandInControl final : public OrderedNode {
 public:
  StandInControl(std::string name, NodeConfig config)
      : OrderedNode(std::move(name), std::move(config), true, Flavor::kPlain) {}
};

}  // namespace

std::unique_ptr<TreeNode> MakeStandInControl(std::string name, NodeConfig config) {
  return std::make_unique<StandInControl>(std::move(name), std::move(config));
}

void RegisterBuiltinControls(BehaviorTreeFactory& factory) {
  const auto reg = [&](const std::string& id, PortsList ports, auto make) {
    factory.RegisterBuilder({id, NodeKind::kControl, std::move(ports), "", true},
                            [make](const std::string& name, NodeConfig config) {
                              return make(name, std::move(config));
                            });
  };
  using Flavor = OrderedNode::Flavor;
  const auto ordered = [&](const std::string& id, bool is_sequence, Flavor flavor,
                           std::string registration_id) {
    reg(id, {}, [=](const std::string& n, NodeConfig c) {
      c.registration_id = registration_id;  // SequenceStar reports SequenceWithMemory
      return std::make_unique<OrderedNode>(n, std::move(c), is_sequence, flavor);
    });
  };
  ordered("Sequence", true, Flavor::kPlain, "Sequence");
  ordered("AsyncSequence", true, Flavor::kAsync, "AsyncSequence");
  ordered("SequenceWithMemory", true, Flavor::kMemory, "SequenceWithMemory");
  ordered("SequenceStar", true, Flavor::kMemory, "SequenceWithMemory");  // v3 name
  ordered("Fallback", false, Flavor::kPlain, "Fallback");
  ordered("AsyncFallback", false, Flavor::kAsync, "AsyncFallback");
  reg("ReactiveSequence", {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ReactiveNode>(n, std::move(c), true);
  });
  reg("ReactiveFallback", {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<ReactiveNode>(n, std::move(c), false);
  });
  reg("Parallel", ParallelNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<ParallelNode>(n, std::move(c));
  });
  reg("ParallelAll", ParallelAllNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<ParallelAllNode>(n, std::move(c));
  });
  reg("IfThenElse", {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<IfThenElseNode>(n, std::move(c));
  });
  reg("WhileDoElse", {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<WhileDoElseNode>(n, std::move(c));
  });
  reg("TryCatch", TryCatchNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<TryCatchNode>(n, std::move(c));
  });
  for (int cases = 2; cases <= 6; ++cases) {
    reg(Cat("Switch", cases), SwitchNode::Ports(cases),
        [cases](const std::string& n, NodeConfig c) {
          return std::make_unique<SwitchNode>(n, std::move(c), cases);
        });
  }
}

}  // namespace egress::bt::internal
