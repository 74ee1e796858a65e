// Decorators: Inverter, ForceSuccess, ForceFailure, Repeat, RetryUntilSuccessful,
// KeepRunningUntilFailure, Delay, Timeout, RunOnce, Precondition, LoopInt, LoopBool,
// LoopDouble, LoopString, SkipUnlessUpdated, WaitValueUpdate; and the SubTree node.

#include "builtin_nodes.h"
#include "egress/bt/factory.h"

namespace egress::bt::internal {
namespace {

/// Inverter, ForceSuccess, ForceFailure: map a completed child's result; RUNNING and SKIPPED
/// pass through.
class MapResultNode : public DecoratorNode {
 public:
  enum class Mode { kInvert, kForceSuccess, kForceFailure, kPassThrough };
  MapResultNode(std::string name, NodeConfig config, Mode mode)
      : DecoratorNode(std::move(name), std::move(config)), mode_(mode) {}

 protected:
  NodeStatus Tick() override {
    SetStatus(NodeStatus::kRunning);
    const NodeStatus child_status = child_->ExecuteTick();
    if (!IsCompleted(child_status)) return child_status;
    child_->ResetStatus();
    switch (mode_) {
      case Mode::kInvert:
        return child_status == NodeStatus::kSuccess ? NodeStatus::kFailure : NodeStatus::kSuccess;
      case Mode::kForceSuccess:
        return NodeStatus::kSuccess;
      case Mode::kForceFailure:
        return NodeStatus::kFailure;
      case Mode::kPassThrough:
        return child_status;
    }
    return child_status;
  }

 private:
  Mode mode_;
};

/// Repeat (while the child succeeds) and RetryUntilSuccessful (while it fails), as BT.CPP 4.10's
/// RepeatNode and RetryNode: a child that completes after RUNNING is started again within the
/// same tick; after a cycle that completed within its first tick the node yields RUNNING with a
/// wake-up pass (the tree is ticked again at once, guards above re-checked). Deliberate
/// difference: an endless loop (-1) yields without the wake-up pass, so a tick always ends
/// (BT.CPP's tickOnce() never returns from an endless synchronous loop).
class LoopNode : public DecoratorNode {
 public:
  LoopNode(std::string name, NodeConfig config, bool repeat_on_success)
      : DecoratorNode(std::move(name), std::move(config)), repeat_on_success_(repeat_on_success) {}

 protected:
  NodeStatus Tick() override {
    const char* port = repeat_on_success_ ? "num_cycles" : "num_attempts";
    int limit = GetInput<int>(port).value();
    SetStatus(NodeStatus::kRunning);
    const NodeStatus continue_on = repeat_on_success_ ? NodeStatus::kSuccess : NodeStatus::kFailure;
    bool loop = limit == -1 || count_ < limit;
    while (loop) {
      const NodeStatus previous = child_->status();
      const NodeStatus child_status = child_->ExecuteTick();
      if (child_status == NodeStatus::kRunning) return child_status;
      if (child_status == NodeStatus::kSkipped) {
        child_->ResetStatus();
        return NodeStatus::kSkipped;  // keeps the counter
      }
      if (child_status != continue_on) {
        count_ = 0;
        HaltChild();
        return child_status;
      }
      ++count_;
      // RetryUntilSuccessful re-reads its limit after a failure (a child may have changed it).
      if (!repeat_on_success_) limit = GetInput<int>(port).value();
      loop = limit == -1 || count_ < limit;
      HaltChild();
      if (previous == NodeStatus::kIdle && loop) {
        if (limit != -1) EmitWakeUpSignal();
        return NodeStatus::kRunning;
      }
    }
    count_ = 0;
    return continue_on;
  }
  void Halt() override {
    count_ = 0;
    HaltChild();
  }

 private:
  bool repeat_on_success_;
  int count_{0};
};

class KeepRunningUntilFailureNode : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;

 protected:
  NodeStatus Tick() override {
    SetStatus(NodeStatus::kRunning);
    const NodeStatus child_status = child_->ExecuteTick();
    if (child_status == NodeStatus::kFailure) {
      child_->ResetStatus();
      return NodeStatus::kFailure;
    }
    if (child_status == NodeStatus::kSuccess) {
      child_->ResetStatus();
      return NodeStatus::kRunning;
    }
    return child_status;
  }
};

/// Delay: RUNNING for delay_msec of the tree's clock, then ticks the child.
class DelayNode : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;
  static PortsList ProvidedPorts() {
    return {InputPort<unsigned>("delay_msec", "milliseconds to wait before ticking the child")};
  }

 protected:
  NodeStatus Tick() override {
    if (!started_) {
      started_ = true;
      start_ = context().Now();
      delay_ = std::chrono::milliseconds(GetInput<unsigned>("delay_msec").value());
      SetStatus(NodeStatus::kRunning);
    }
    if (context().Now() - start_ < delay_) return NodeStatus::kRunning;
    const NodeStatus child_status = child_->ExecuteTick();
    if (IsCompleted(child_status)) {
      started_ = false;
      child_->ResetStatus();
    }
    return child_status;
  }
  void Halt() override {
    started_ = false;
    HaltChild();
  }

 private:
  bool started_{false};
  Duration start_{};
  Duration delay_{};
};

/// Timeout: halts a child still RUNNING msec after the first tick and returns FAILURE. The
/// deadline is checked in the ticking thread (never from a timer thread).
class TimeoutNode : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;
  static PortsList ProvidedPorts() {
    return {InputPort<unsigned>("msec", "milliseconds before the child is halted (0: never)")};
  }

 protected:
  NodeStatus Tick() override {
    if (!started_) {
      started_ = true;
      start_ = context().Now();
      timeout_ = std::chrono::milliseconds(GetInput<unsigned>("msec").value());
      SetStatus(NodeStatus::kRunning);
    }
    if (timeout_.count() > 0 && context().Now() - start_ >= timeout_ &&
        child_->status() == NodeStatus::kRunning) {
      started_ = false;
      HaltChild();
      return NodeStatus::kFailure;
    }
    const NodeStatus child_status = child_->ExecuteTick();
    if (IsCompleted(child_status)) {
      started_ = false;
      child_->ResetStatus();
    }
    return child_status;
  }
  void Halt() override {
    started_ = false;
    HaltChild();
  }

 private:
  bool started_{false};
  Duration start_{};
  Duration timeout_{};
};

class RunOnceNode : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;
  static PortsList ProvidedPorts() {
    return {
        InputPort<bool>("then_skip", true, "after the first run: SKIPPED (true) or its result")};
  }

 protected:
  NodeStatus Tick() override {
    if (done_) return GetInput<bool>("then_skip").value() ? NodeStatus::kSkipped : result_;
    SetStatus(NodeStatus::kRunning);
    const NodeStatus child_status = child_->ExecuteTick();
    if (IsCompleted(child_status)) {
      done_ = true;
      result_ = child_status;
      child_->ResetStatus();
    }
    return child_status;
  }

 private:
  bool done_{false};
  NodeStatus result_{NodeStatus::kIdle};
};

/// Precondition: ticks the child if the `if` script is true, else returns `else`. Once the
/// script was true it is not checked again until the child completes (BT.CPP 4.7+), and the
/// node has no RUNNING of its own. Deliberate difference: a halt clears that, so a halted
/// Precondition checks its script again (BT.CPP 4.10 keeps the flag through a halt and runs the
/// child unchecked next time).
class PreconditionNode : public DecoratorNode {
 public:
  PreconditionNode(std::string name, NodeConfig config)
      : DecoratorNode(std::move(name), std::move(config)) {
    if (auto text = PortText("if"); text && !BlackboardKeyOf(*text, "if"))
      script_ = Script::Parse(*text);
  }
  static PortsList ProvidedPorts() {
    PortsList ports = {InputPort<std::string>("if", "the condition script"),
                       InputPort<NodeStatus>("else", NodeStatus::kFailure,
                                             "returned when the condition is false")};
    ports.at("if").script = true;
    return ports;
  }

 protected:
  NodeStatus Tick() override {
    const NodeStatus otherwise = GetInput<NodeStatus>("else").value();
    if (!child_running_) {
      std::shared_ptr<const Script> script = script_;
      if (!script) script = Script::Parse(GetInput<std::string>("if").value());
      try {
        child_running_ = script->EvaluateCondition(script_environment());
      } catch (const RuntimeError& e) {
        throw RuntimeError(Cat("[", path(), "] if: ", e.what()));
      }
      if (!child_running_) return otherwise;
    }
    const NodeStatus child_status = child_->ExecuteTick();
    if (IsCompleted(child_status)) {
      HaltChild();
      child_running_ = false;
    }
    return child_status;
  }
  void Halt() override {
    child_running_ = false;
    HaltChild();
  }

 private:
  std::shared_ptr<const Script> script_;
  bool child_running_{false};
};

/// LoopInt, LoopBool, LoopDouble, LoopString (BT.CPP 4's LoopNode<T>): pops the front of
/// `queue` into `value` and ticks the child, once per element; RUNNING after each element (the
/// next is popped on the next tick), FAILURE as soon as the child fails, `if_empty` once the
/// queue is empty (or absent). A queue on the blackboard is popped in place; a literal
/// ("a;b;c") is copied afresh at each start.
template <typename T>
class QueueLoopNode : public DecoratorNode {
 public:
  using DecoratorNode::DecoratorNode;
  static PortsList ProvidedPorts() {
    return {BidirectionalPort<SharedQueue<T>>("queue", "elements to loop over, popped in order"),
            InputPort<NodeStatus>("if_empty", NodeStatus::kSuccess,
                                  "status to return if the queue is empty: SUCCESS, FAILURE, "
                                  "SKIPPED"),
            OutputPort<T>("value", "the element the child runs with")};
  }

 protected:
  NodeStatus Tick() override {
    bool popped = false;
    if (status() == NodeStatus::kIdle) {
      child_running_ = false;
      auto queue = GetInput<SharedQueue<T>>("queue");
      queue_ = queue ? queue.value() : nullptr;
    }
    if (!child_running_ && queue_ && !queue_->empty()) {
      T value = std::move(queue_->front());
      queue_->pop_front();
      popped = true;
      SetOutput("value", value);
    }
    if (!popped && !child_running_) return GetInput<NodeStatus>("if_empty").value();
    if (status() == NodeStatus::kIdle) SetStatus(NodeStatus::kRunning);
    const NodeStatus child_status = child_->ExecuteTick();
    child_running_ = child_status == NodeStatus::kRunning;
    if (IsCompleted(child_status)) child_->ResetStatus();
    return child_status == NodeStatus::kFailure ? NodeStatus::kFailure : NodeStatus::kRunning;
  }
  void Halt() override {
    child_running_ = false;
    HaltChild();
  }

 private:
  bool child_running_{false};
  SharedQueue<T> queue_;
};

/// SkipUnlessUpdated and WaitValueUpdate (BT.CPP 4.10's EntryUpdatedDecorator): ticks the child
/// only if the watched blackboard entry was written since the node last looked, else returns
/// SKIPPED (SkipUnlessUpdated) or RUNNING (WaitValueUpdate); a RUNNING child is ticked on
/// without looking. The child is not reset after it completes (as in BT.CPP).
class EntryUpdatedNode : public DecoratorNode {
 public:
  EntryUpdatedNode(std::string name, NodeConfig config, NodeStatus if_not_updated)
      : DecoratorNode(std::move(name), std::move(config)),
        key_(WatchedEntryKey(*this)),
        if_not_updated_(if_not_updated) {}
  static PortsList ProvidedPorts() { return {InputPort<Any>("entry", "the entry to watch")}; }

 protected:
  NodeStatus Tick() override {
    if (!child_running_) {
      const std::uint64_t previous = sequence_;
      sequence_ = config().blackboard->SequenceId(key_);
      if (sequence_ == 0 || sequence_ == previous) return if_not_updated_;
    }
    const NodeStatus child_status = child_->ExecuteTick();
    child_running_ = child_status == NodeStatus::kRunning;
    return child_status;
  }
  void Halt() override {
    child_running_ = false;
    HaltChild();
  }

 private:
  std::string key_;
  NodeStatus if_not_updated_;
  std::uint64_t sequence_{0};
  bool child_running_{false};
};

}  // namespace

std::string WatchedEntryKey(const TreeNode& node) {
  const std::optional<std::string> text = node.PortText("entry");
  if (!text || text->empty()) throw LogicError(Cat("[", node.path(), "] missing port 'entry'"));
  if (auto key = BlackboardKeyOf(*text, "entry")) return *key;
  return *text;
}

NodeStatus SubTreeNode::Tick() {
  if (status() == NodeStatus::kIdle) SetStatus(NodeStatus::kRunning);
  const NodeStatus child_status = child_->ExecuteTick();
  if (IsCompleted(child_status)) child_->ResetStatus();
  return child_status;
}

std::unique_ptr<TreeNode> MakeStandInDecorator(std::string name, NodeConfig config) {
  return std::make_unique<MapResultNode>(std::move(name), std::move(config),
                                         MapResultNode::Mode::kPassThrough);
}

void RegisterBuiltinDecorators(BehaviorTreeFactory& factory) {
  const auto reg = [&](const std::string& id, PortsList ports, NodeBuilder builder) {
    factory.RegisterBuilder({id, NodeKind::kDecorator, std::move(ports), "", true},
                            std::move(builder));
  };
  using Mode = MapResultNode::Mode;
  for (const auto& [id, mapping] :
       {std::pair{"Inverter", Mode::kInvert}, std::pair{"ForceSuccess", Mode::kForceSuccess},
        std::pair{"ForceFailure", Mode::kForceFailure}}) {
    // A copy: a lambda may capture a structured binding only from C++20 compilers that
    // implement it (clang 14 does not).
    const Mode mode = mapping;
    reg(id, {}, [mode](const std::string& n, NodeConfig c) {
      return std::make_unique<MapResultNode>(n, std::move(c), mode);
    });
  }
  reg("Repeat", {InputPort<int>("num_cycles", "repetitions; -1 repeats forever")},
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<LoopNode>(n, std::move(c), true);
      });
  reg("RetryUntilSuccessful", {InputPort<int>("num_attempts", "attempts; -1 retries forever")},
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<LoopNode>(n, std::move(c), false);
      });
  reg("KeepRunningUntilFailure", {}, [](const std::string& n, NodeConfig c) {
    return std::make_unique<KeepRunningUntilFailureNode>(n, std::move(c));
  });
  reg("Delay", DelayNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<DelayNode>(n, std::move(c));
  });
  reg("Timeout", TimeoutNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<TimeoutNode>(n, std::move(c));
  });
  reg("RunOnce", RunOnceNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<RunOnceNode>(n, std::move(c));
  });
  reg("Precondition", PreconditionNode::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<PreconditionNode>(n, std::move(c));
  });
  for (const auto& [id, if_not_updated] : {std::pair{"SkipUnlessUpdated", NodeStatus::kSkipped},
                                           std::pair{"WaitValueUpdate", NodeStatus::kRunning}}) {
    const NodeStatus result = if_not_updated;  // a copy: see above
    reg(id, EntryUpdatedNode::ProvidedPorts(), [result](const std::string& n, NodeConfig c) {
      return std::make_unique<EntryUpdatedNode>(n, std::move(c), result);
    });
  }
  reg("LoopInt", QueueLoopNode<int>::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<QueueLoopNode<int>>(n, std::move(c));
  });
  reg("LoopBool", QueueLoopNode<bool>::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<QueueLoopNode<bool>>(n, std::move(c));
  });
  reg("LoopDouble", QueueLoopNode<double>::ProvidedPorts(), [](const std::string& n, NodeConfig c) {
    return std::make_unique<QueueLoopNode<double>>(n, std::move(c));
  });
  reg("LoopString", QueueLoopNode<std::string>::ProvidedPorts(),
      [](const std::string& n, NodeConfig c) {
        return std::make_unique<QueueLoopNode<std::string>>(n, std::move(c));
      });
}

}  // namespace egress::bt::internal
