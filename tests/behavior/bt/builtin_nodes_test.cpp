// Semantics of every built-in node, halting order and SKIPPED handling.

#include <deque>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/bt/factory.h"
#include "egress/bt/loggers.h"
#include "test_nodes.h"

namespace egress::bt {
namespace {

using ::testing::ElementsAre;
using testing::Recorder;

class NodesTest : public ::testing::Test {
 protected:
  NodesTest() { testing::RegisterTestNodes(factory, &recorder); }

  Tree Load(const std::string& body) {
    return factory.CreateTreeFromText(
        "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\">" + body + "</BehaviorTree></root>", "T",
        board);
  }
  void Queue(const std::string& name, std::initializer_list<NodeStatus> results) {
    for (NodeStatus s : results)
      recorder.results[name].push_back(s);
  }

  BehaviorTreeFactory factory;
  Recorder recorder;
  Blackboard::Ptr board = Blackboard::Create();
};

constexpr auto S = NodeStatus::kSuccess;
constexpr auto F = NodeStatus::kFailure;
constexpr auto R = NodeStatus::kRunning;
constexpr auto K = NodeStatus::kSkipped;

TEST_F(NodesTest, SequenceResumesAtTheRunningChild) {
  board->Set("n", 0);
  Tree tree = Load("<Sequence><Counter key='{n}'/><Async name='A'/><Async name='B'/></Sequence>");
  Queue("A", {R, S});
  Queue("B", {S});
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), S);       // A succeeds, B succeeds synchronously
  EXPECT_EQ(board->Get<int>("n"), 1);  // Counter is not re-ticked while A runs
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "running:A", "start:B"));
}

TEST_F(NodesTest, SequenceRestartsAfterFailureWithMemoryRetries) {
  board->Set("n", 0);
  Tree plain = Load("<Sequence><Counter key='{n}'/><Async name='A'/></Sequence>");
  Queue("A", {F, S});
  EXPECT_EQ(plain.TickOnce(), F);
  EXPECT_EQ(plain.TickOnce(), S);
  EXPECT_EQ(board->Get<int>("n"), 2);  // restarted from child 0

  board->Set("n", 0);
  factory.ClearRegisteredTrees();
  Tree memory =
      Load("<SequenceWithMemory><Counter key='{n}'/><Async name='B'/></SequenceWithMemory>");
  Queue("B", {F, S});
  EXPECT_EQ(memory.TickOnce(), F);
  EXPECT_EQ(memory.TickOnce(), S);
  EXPECT_EQ(board->Get<int>("n"), 1);  // retried the failed child only
}

TEST_F(NodesTest, FallbackTriesChildrenInOrder) {
  Tree tree = Load("<Fallback><Async name='A'/><Async name='B'/></Fallback>");
  Queue("A", {F});
  Queue("B", {R, S});
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "start:B", "running:B"));
}

TEST_F(NodesTest, ReactiveSequenceHaltsTheActionWhenTheGuardFails) {
  board->Set("clear", true);
  Tree tree =
      Load("<ReactiveSequence><Flag key='{clear}'/><Async name='Press'/></ReactiveSequence>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("clear", false);
  recorder.events.push_back("tick");
  EXPECT_EQ(tree.TickOnce(), F);  // same tick: the guard fails and Press is halted
  EXPECT_THAT(recorder.events, ElementsAre("start:Press", "tick", "halt:Press"));
  EXPECT_EQ(tree.FindNodesByName("Press").front()->status(), NodeStatus::kIdle);
}

TEST_F(NodesTest, ReactiveFallbackHaltsRecoveryWhenTheGoalIsReached) {
  board->Set("reached", false);
  Tree tree =
      Load("<ReactiveFallback><Flag key='{reached}'/><Async name='Move'/></ReactiveFallback>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("reached", true);
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_THAT(recorder.events, ElementsAre("start:Move", "halt:Move"));
}

// The paper's preemption: a person enters the door zone while the robot traverses; the yield
// branch (earlier child) starts. The running traversal must be halted *before* Yield starts,
// within the same tick (BehaviorTree.CPP halts it after, issue #1031).
TEST_F(NodesTest, ReactivePreemptionHaltsBeforeTheNewActionStarts) {
  board->Set("clear", true);
  Tree tree = Load(
      "<ReactiveSequence>"
      "  <Fallback><Flag key='{clear}'/><Async name='Yield'/></Fallback>"
      "  <Async name='Traverse'/>"
      "</ReactiveSequence>");
  TreeObserver observer(tree);
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("clear", false);
  recorder.events.push_back("tick 2");
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_THAT(recorder.events,
              ElementsAre("start:Traverse", "tick 2", "halt:Traverse", "start:Yield"));
  EXPECT_EQ(tree.tick_count(), 2u);
  // The status transitions agree: Traverse RUNNING->IDLE precedes Yield IDLE->RUNNING.
  const auto traverse = tree.FindNodesByName("Traverse").front()->uid();
  const auto yield = tree.FindNodesByName("Yield").front()->uid();
  int halt_at = -1, start_at = -1;
  for (std::size_t i = 0; i < observer.transitions().size(); ++i) {
    const auto& t = observer.transitions()[i];
    if (t.uid == traverse && t.previous == R && t.status == NodeStatus::kIdle) halt_at = int(i);
    if (t.uid == yield && t.status == R) start_at = int(i);
  }
  ASSERT_GE(halt_at, 0);
  ASSERT_GE(start_at, 0);
  EXPECT_LT(halt_at, start_at);
}

TEST_F(NodesTest, ReactiveGuardDoesNotHaltWhenEarlierChildCompletesSynchronously) {
  board->Set("n", 0);
  Tree tree =
      Load("<ReactiveSequence><Counter key='{n}'/><Async name='Traverse'/></ReactiveSequence>");
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(board->Get<int>("n"), 2);  // re-ticked every tick
  EXPECT_THAT(recorder.events, ElementsAre("start:Traverse", "running:Traverse"));
}

TEST_F(NodesTest, ParallelThresholds) {
  Tree tree = Load(
      "<Parallel success_count='2' failure_count='2'>"
      "<Async name='A'/><Async name='B'/><Async name='C'/></Parallel>");
  Queue("A", {R, S});
  Queue("B", {R, R});
  Queue("C", {R, S});
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), S);  // A and C succeeded: B is halted
  EXPECT_GE(recorder.IndexOf("halt:B"), 0);

  factory.ClearRegisteredTrees();
  recorder = {};
  Tree failing = Load("<Parallel success_count='-1'><Async name='A'/><Async name='B'/></Parallel>");
  Queue("A", {F});
  EXPECT_EQ(failing.TickOnce(), F);            // success needs all: one failure makes it impossible
  EXPECT_EQ(recorder.IndexOf("start:B"), -1);  // decided before B was ticked
}

TEST_F(NodesTest, ParallelAllRunsEveryChildToCompletion) {
  Tree tree =
      Load("<ParallelAll max_failures='2'><Async name='A'/><Async name='B'/></ParallelAll>");
  Queue("A", {F});
  Queue("B", {R, S});
  EXPECT_EQ(tree.TickOnce(), R);  // one failure is below max_failures: B keeps running
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(recorder.IndexOf("halt:B"), -1);
}

TEST_F(NodesTest, IfThenElseIsNotReactive) {
  board->Set("c", true);
  Tree tree =
      Load("<IfThenElse><Flag key='{c}'/><Async name='Then'/><Async name='Else'/></IfThenElse>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("c", false);
  EXPECT_EQ(tree.TickOnce(), R);  // the condition is not re-evaluated
  EXPECT_THAT(recorder.events, ElementsAre("start:Then", "running:Then"));
}

TEST_F(NodesTest, WhileDoElseHaltsTheOtherBranchFirst) {
  board->Set("c", true);
  Tree tree =
      Load("<WhileDoElse><Flag key='{c}'/><Async name='Do'/><Async name='Else'/></WhileDoElse>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("c", false);
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_THAT(recorder.events, ElementsAre("start:Do", "halt:Do", "start:Else"));
}

TEST_F(NodesTest, SwitchMatchesStringsNumbersAndEnums) {
  factory.RegisterScriptingEnum("PROXIMITY", 2);
  board->Set("type", std::string("push"));
  Tree tree = Load(
      "<Switch3 variable='{type}' case_1='push' case_2='PROXIMITY' case_3='3.0'>"
      "<Async name='Press'/><Async name='Wave'/><Async name='Three'/><Async "
      "name='Default'/></Switch3>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("type", 2);  // matches the enum name
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("type", std::string("3"));  // numeric match
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("type", std::string("other"));
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_THAT(recorder.events, ElementsAre("start:Press", "halt:Press", "start:Wave", "halt:Wave",
                                           "start:Three", "halt:Three", "start:Default"));
}

TEST_F(NodesTest, SimpleDecorators) {
  Tree tree = Load(
      "<Sequence><Inverter><AlwaysFailure/></Inverter><ForceSuccess><AlwaysFailure/></ForceSuccess>"
      "<ForceFailure><Inverter><AlwaysSuccess/></Inverter></ForceFailure></Sequence>");
  EXPECT_EQ(tree.TickOnce(), F);
  factory.ClearRegisteredTrees();
  Tree running = Load("<Inverter><Async name='A'/></Inverter>");
  EXPECT_EQ(running.TickOnce(), R);  // RUNNING passes through
}

TEST_F(NodesTest, RepeatAndRetry) {
  board->Set("n", 0);
  Tree repeat = Load("<Repeat num_cycles='3'><Counter key='{n}'/></Repeat>");
  EXPECT_EQ(repeat.TickOnce(), S);  // a synchronous child loops within one tick
  EXPECT_EQ(board->Get<int>("n"), 3);

  factory.ClearRegisteredTrees();
  Tree retry =
      Load("<RetryUntilSuccessful num_attempts='3'><Async name='A'/></RetryUntilSuccessful>");
  Queue("A", {F, F, S});
  EXPECT_EQ(retry.TickOnce(), S);
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "start:A", "start:A"));

  factory.ClearRegisteredTrees();
  recorder = {};
  Tree exhausted =
      Load("<RetryUntilSuccessful num_attempts='2'><Async name='B'/></RetryUntilSuccessful>");
  Queue("B", {F, F});
  EXPECT_EQ(exhausted.TickOnce(), F);

  factory.ClearRegisteredTrees();
  board->Set("n", 0);
  Tree forever = Load("<Repeat num_cycles='-1'><Counter key='{n}'/></Repeat>");
  EXPECT_EQ(forever.TickOnce(), R);  // an endless loop yields every cycle: the tick ends
  EXPECT_EQ(forever.TickOnce(), R);
  EXPECT_EQ(board->Get<int>("n"), 2);
}

TEST_F(NodesTest, KeepRunningUntilFailure) {
  Tree tree = Load("<KeepRunningUntilFailure><Async name='A'/></KeepRunningUntilFailure>");
  Queue("A", {S, S, F});
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), F);
}

TEST_F(NodesTest, RunOnceThenSkips) {
  board->Set("n", 0);
  Tree tree = Load("<Sequence><RunOnce><Counter key='{n}'/></RunOnce><AlwaysSuccess/></Sequence>");
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(board->Get<int>("n"), 1);
  factory.ClearRegisteredTrees();
  Tree repeat_result = Load("<RunOnce then_skip='false'><AlwaysFailure/></RunOnce>");
  EXPECT_EQ(repeat_result.TickOnce(), F);
  EXPECT_EQ(repeat_result.TickOnce(), F);
}

TEST_F(NodesTest, LoopStringPopsTheBlackboardQueueOncePerElement) {
  // BT.CPP 4's LoopNode: one element per child run, RUNNING after each, if_empty at the end.
  auto queue = std::make_shared<std::deque<std::string>>(std::deque<std::string>{"a", "b"});
  board->Set("doors", queue);
  Tree tree = Load(
      "<LoopString queue='{doors}' value='{door}'><Sequence><Counter key='{n}'/>"
      "<Async name='A'/></Sequence></LoopString>");
  board->Set("n", 0);
  Queue("A", {R, S, S});
  EXPECT_EQ(tree.TickOnce(), R);  // "a": A running
  EXPECT_EQ(board->Get<std::string>("door"), "a");
  EXPECT_EQ(queue->size(), 1u);   // popped in place
  EXPECT_EQ(tree.TickOnce(), R);  // "a" done: RUNNING, not the next element in this tick
  EXPECT_EQ(board->Get<int>("n"), 1);
  EXPECT_EQ(tree.TickOnce(), R);  // "b"
  EXPECT_EQ(board->Get<std::string>("door"), "b");
  EXPECT_EQ(tree.TickOnce(), S);  // empty: if_empty
  EXPECT_EQ(board->Get<int>("n"), 2);
  EXPECT_TRUE(queue->empty());
}

TEST_F(NodesTest, LoopFailsWithItsChildAndLiteralQueuesRestart) {
  board->Set("sum", 0.0);
  Tree tree = Load(
      "<LoopDouble queue='1.5;2.5' value='{x}'><ScriptCondition code='x &lt; 2'/></LoopDouble>");
  EXPECT_EQ(tree.TickOnce(), R);  // 1.5 passes
  EXPECT_EQ(tree.TickOnce(), F);  // 2.5 fails: the loop fails
  EXPECT_EQ(tree.TickOnce(), R);  // a literal queue starts over
  EXPECT_DOUBLE_EQ(*board->Get<double>("x"), 1.5);
  factory.ClearRegisteredTrees();
  Tree empty = Load("<LoopInt queue='{missing}' if_empty='SKIPPED'><AlwaysSuccess/></LoopInt>");
  EXPECT_EQ(empty.TickOnce(), K);
}

TEST_F(NodesTest, PreconditionIsCheckedOnlyBeforeTheChildRuns) {
  board->Set("ok", true);
  Tree tree = Load("<Precondition if='ok' else='SKIPPED'><Async name='A'/></Precondition>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("ok", false);
  EXPECT_EQ(tree.TickOnce(), R);  // BT.CPP 4.7+: not re-checked while RUNNING
  Queue("A", {S});
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(tree.TickOnce(), K);  // now false: returns `else`
}

TEST_F(NodesTest, LeavesScriptsAndBlackboardNodes) {
  Tree tree = Load(
      "<Sequence><Script code=\"x := 2; label := 'door'\"/><ScriptCondition code='x == 2'/>"
      "<SetBlackboard value='{label}' output_key='copy'/><SetBlackboard value='7' "
      "output_key='seven'/>"
      "<UnsetBlackboard key='x'/></Sequence>");
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(board->Get<std::string>("copy"), "door");
  EXPECT_EQ(board->Get<int>("seven"), 7);
  EXPECT_FALSE(board->Has("x"));
  factory.ClearRegisteredTrees();
  Tree failing = Load("<ScriptCondition code='1 > 2'/>");
  EXPECT_EQ(failing.TickOnce(), F);
}

TEST_F(NodesTest, SkippedChildrenAndPreConditions) {
  board->Set("n", 0);
  Tree tree = Load(
      "<Sequence><Counter key='{n}' _skipIf='n == 0'/><AlwaysSuccess _skipIf='true'/></Sequence>");
  EXPECT_EQ(tree.TickOnce(), K);  // all children skipped
  EXPECT_EQ(board->Get<int>("n"), 0);
  // A skipped result is not a status: the Sequence keeps the RUNNING it set before its children
  // skipped, as in BT.CPP 4.10 (its parent, if any, resets it).
  EXPECT_EQ(tree.root().status(), NodeStatus::kRunning);
  EXPECT_EQ(tree.TickOnce(), K);  // and it skips again

  factory.ClearRegisteredTrees();
  Tree guarded = Load("<Sequence><AlwaysSuccess _failureIf='n == 0'/></Sequence>");
  EXPECT_EQ(guarded.TickOnce(), F);
  factory.ClearRegisteredTrees();
  Tree success_if =
      Load("<AlwaysFailure _successIf='true' _onSuccess='done := 1' _post='post := 1'/>");
  EXPECT_EQ(success_if.TickOnce(), S);
  EXPECT_EQ(board->Get<int>("done"), 1);
  EXPECT_EQ(board->Get<int>("post"), 1);
}

TEST_F(NodesTest, WhilePreemptsWithinTheTickAndReportsSkipped) {
  board->Set("mode", 5);
  board->Set("n", 0);
  Tree tree = Load(
      "<Sequence><Async name='Jog' _while='mode == 5' _onHalted=\"halted := 'yes'\"/>"
      "<Counter key='{n}'/></Sequence>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("mode", 4);
  EXPECT_EQ(tree.TickOnce(), S);  // Jog halted and SKIPPED; the Sequence moves on
  EXPECT_THAT(recorder.events, ElementsAre("start:Jog", "halt:Jog"));
  EXPECT_EQ(board->Get<std::string>("halted"), "yes");
  EXPECT_EQ(board->Get<int>("n"), 1);
}

TEST_F(NodesTest, HaltTreeIsRecursiveAndOrdered) {
  Tree tree = Load(
      "<Parallel success_count='-1'><Sequence><Async name='A'/></Sequence><Async "
      "name='B'/></Parallel>");
  EXPECT_EQ(tree.TickOnce(), R);
  tree.HaltTree();
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "start:B", "halt:A", "halt:B"));
  for (const auto& node : tree.nodes())
    EXPECT_EQ(node->status(), NodeStatus::kIdle) << node->path();
}

TEST_F(NodesTest, TimersFollowTheInjectedClock) {
  auto clock = std::make_shared<ManualClock>();
  Tree tree = Load(
      "<Sequence><Delay delay_msec='100'><AlwaysSuccess/></Delay><Sleep msec='50'/></Sequence>");
  tree.SetClock(clock);
  EXPECT_EQ(tree.TickOnce(), R);
  clock->Advance(std::chrono::milliseconds(99));
  EXPECT_EQ(tree.TickOnce(), R);
  clock->Advance(std::chrono::milliseconds(1));
  EXPECT_EQ(tree.TickOnce(), R);  // delay done; Sleep started
  clock->Advance(std::chrono::milliseconds(50));
  EXPECT_EQ(tree.TickOnce(), S);
}

TEST_F(NodesTest, TimeoutHaltsTheChildInTheTickThread) {
  auto clock = std::make_shared<ManualClock>();
  Tree tree = Load("<Timeout msec='200'><Async name='Press'/></Timeout>");
  tree.SetClock(clock);
  EXPECT_EQ(tree.TickOnce(), R);
  clock->Advance(std::chrono::milliseconds(199));
  EXPECT_EQ(tree.TickOnce(), R);
  clock->Advance(std::chrono::milliseconds(1));
  EXPECT_EQ(tree.TickOnce(), F);
  EXPECT_THAT(recorder.events, ElementsAre("start:Press", "running:Press", "halt:Press"));
}

TEST_F(NodesTest, SyncNodesMustNotReturnRunning) {
  factory.RegisterSimpleCondition("Bad", [](TreeNode&) { return NodeStatus::kRunning; });
  Tree tree = Load("<Bad/>");
  EXPECT_THROW(tree.TickOnce(), LogicError);
}

}  // namespace
}  // namespace egress::bt
