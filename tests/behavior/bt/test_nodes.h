#pragma once
// Test node types for the BT engine suites: a stateful action that records its lifecycle and
// takes its results from a script the test controls, and a condition read from the blackboard.

#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "egress/bt/factory.h"

namespace egress::bt::testing {

/// Shared between the test and its nodes: the event log ("start:A", "running:A", "halt:A",
/// "tick:N" markers) and queued results per action name.
struct Recorder {
  std::vector<std::string> events;
  std::map<std::string, std::deque<NodeStatus>> results;  // popped per OnStart/OnRunning
  NodeStatus Next(const std::string& name) {
    auto& queue = results[name];
    if (queue.empty()) return NodeStatus::kRunning;  // runs until told otherwise
    const NodeStatus s = queue.front();
    queue.pop_front();
    return s;
  }
  /// Index of the first event equal to `event`, or -1.
  int IndexOf(const std::string& event) const {
    for (std::size_t i = 0; i < events.size(); ++i) {
      if (events[i] == event) return int(i);
    }
    return -1;
  }
};

/// `<Async name="X"/>`: OnStart/OnRunning log and return the next queued result (RUNNING when
/// none is queued); OnHalted logs.
class AsyncAction final : public StatefulActionNode {
 public:
  AsyncAction(const std::string& name, NodeConfig config, Recorder* recorder)
      : StatefulActionNode(name, std::move(config)), recorder_(recorder) {}

 protected:
  NodeStatus OnStart() override {
    recorder_->events.push_back("start:" + name());
    return recorder_->Next(name());
  }
  NodeStatus OnRunning() override {
    recorder_->events.push_back("running:" + name());
    return recorder_->Next(name());
  }
  void OnHalted() override { recorder_->events.push_back("halt:" + name()); }

 private:
  Recorder* recorder_;
};

/// Registers Async (above), Flag (condition: SUCCESS if blackboard bool `key` is true) and
/// Counter (sync action incrementing the blackboard int `key`).
inline void RegisterTestNodes(BehaviorTreeFactory& factory, Recorder* recorder) {
  factory.RegisterBuilder({"Async", NodeKind::kAction, {}, "test action", false},
                          [recorder](const std::string& name, NodeConfig config) {
                            return std::make_unique<AsyncAction>(name, std::move(config), recorder);
                          });
  factory.RegisterSimpleCondition(
      "Flag",
      [](TreeNode& node) {
        return node.GetInput<bool>("key").value() ? NodeStatus::kSuccess : NodeStatus::kFailure;
      },
      {InputPort<bool>("key", "the flag")});
  factory.RegisterSimpleAction("Counter",
                               [](TreeNode& node) {
                                 const int value = node.GetInput<int>("key").value();
                                 node.SetOutput("key", value + 1);
                                 return NodeStatus::kSuccess;
                               },
                               {BidirectionalPort<int>("key", "the counter")});
}

/// The reference data folder (EGRESS_REFERENCE_DIR), or empty when it is absent.
std::string ReferenceDir();

}  // namespace egress::bt::testing
