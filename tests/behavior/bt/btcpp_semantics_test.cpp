// BehaviorTree.CPP 4.10's tick semantics that the status-stream conformance cases
// (tests/apps/bt_conformance_test.cpp) do not show on their own: the wake-up pass, the
// deliberate differences, SubTree identity, the stand-ins' model, TryCatch and the
// entry-update nodes driven by a real blackboard.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/bt/factory.h"
#include "egress/bt/loggers.h"
#include "test_nodes.h"

namespace egress::bt {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr auto S = NodeStatus::kSuccess;
constexpr auto F = NodeStatus::kFailure;
constexpr auto R = NodeStatus::kRunning;
constexpr auto K = NodeStatus::kSkipped;

class BtCppSemanticsTest : public ::testing::Test {
 protected:
  BtCppSemanticsTest() { testing::RegisterTestNodes(factory, &recorder); }
  Tree Load(const std::string& body, const std::string& extra = "") {
    return factory.CreateTreeFromText(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"T\">"
        "<BehaviorTree ID=\"T\">" +
            body + "</BehaviorTree>" + extra + "</root>",
        "T", board);
  }
  BehaviorTreeFactory factory;
  testing::Recorder recorder;
  Blackboard::Ptr board = Blackboard::Create();
};

TEST_F(BtCppSemanticsTest, AFiniteLoopOfSynchronousCyclesEndsWithinOneTick) {
  board->Set("n", 0);
  Tree tree = Load("<Repeat num_cycles='3'><Counter key='{n}'/></Repeat>");
  EXPECT_EQ(tree.TickOnce(), S);  // three wake-up passes inside one TickOnce
  EXPECT_EQ(board->Get<int>("n"), 3);
  EXPECT_EQ(tree.tick_count(), 1u);
}

TEST_F(BtCppSemanticsTest, TheWakeUpPassReChecksTheGuardsAboveBetweenCycles) {
  // The guard turns false during the second cycle: BT.CPP re-ticks the whole tree between
  // synchronous cycles, so the ReactiveSequence fails before a third cycle runs.
  board->Set("n", 0);
  board->Set("go", true);
  Tree tree = Load(
      "<ReactiveSequence><ScriptCondition code='go'/><Repeat num_cycles='3'><Sequence>"
      "<Counter key='{n}'/><Script code='go := n &lt; 2'/></Sequence></Repeat></ReactiveSequence>");
  EXPECT_EQ(tree.TickOnce(), F);
  EXPECT_EQ(board->Get<int>("n"), 2);
}

TEST_F(BtCppSemanticsTest, AnEndlessLoopYieldsAfterEachCycle) {
  // Deliberate difference: BT.CPP's tickOnce() would never return here.
  board->Set("n", 0);
  Tree tree = Load("<Repeat num_cycles='-1'><Counter key='{n}'/></Repeat>");
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(board->Get<int>("n"), 1);
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(board->Get<int>("n"), 2);
}

TEST_F(BtCppSemanticsTest, ARetryGoesOnInTheTickItsRunningChildFailed) {
  Tree tree =
      Load("<RetryUntilSuccessful num_attempts='3'><Async name='A'/></RetryUntilSuccessful>");
  recorder.results["A"] = {R, F, R};
  EXPECT_EQ(tree.TickOnce(), R);
  EXPECT_EQ(tree.TickOnce(), R);  // A failed after RUNNING: started again in this tick
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "running:A", "start:A"));
}

TEST_F(BtCppSemanticsTest, APreconditionChecksAgainAfterAHalt) {
  // Deliberate difference: BT.CPP 4.10 keeps "child running" through a halt and runs the child
  // unchecked the next time.
  board->Set("allowed", true);
  board->Set("stop", false);
  Tree tree = Load(
      "<ReactiveFallback><ScriptCondition code='stop'/>"
      "<Precondition if='allowed' else='FAILURE'><Async name='A'/></Precondition>"
      "</ReactiveFallback>");
  EXPECT_EQ(tree.TickOnce(), R);
  board->Set("stop", true);
  EXPECT_EQ(tree.TickOnce(), S);  // the Precondition and A halted
  board->Set("stop", false);
  board->Set("allowed", false);
  EXPECT_EQ(tree.TickOnce(), F);  // checked again: not allowed
  EXPECT_THAT(recorder.events, ElementsAre("start:A", "halt:A"));
}

TEST_F(BtCppSemanticsTest, ASubTreeNodeIsOfTypeSubTreeAndNamedAsInBtCpp) {
  Tree tree = Load("<Sequence><SubTree ID='Inner'/><SubTree ID='Inner' name='second'/></Sequence>",
                   "<BehaviorTree ID='Inner'><AlwaysSuccess name='leaf'/></BehaviorTree>");
  std::vector<std::string> subtrees;
  for (const auto& node : tree.nodes()) {
    if (node->kind() != NodeKind::kSubTree) continue;
    EXPECT_EQ(node->registration_id(), "SubTree");
    EXPECT_EQ(node->config().subtree_id, "Inner");
    subtrees.push_back(node->path());
  }
  EXPECT_THAT(subtrees, ElementsAre("Inner::2", "second"));
  EXPECT_NE(tree.FindNode("Inner::2/leaf"), nullptr);
  EXPECT_NE(tree.FindNode("second/leaf"), nullptr);
  // The tree's XML (Groot2, .btlog) names the included tree, not the node type.
  EXPECT_THAT(WriteTreeToXml(tree, factory), HasSubstr("<SubTree ID=\"Inner\""));
}

TEST_F(BtCppSemanticsTest, InferredStandInsAreInTheTreesModel) {
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='T'><Sequence><OpenHatch side='left'/>"
      "<Condition ID='IsHatchOpen'/></Sequence></BehaviorTree></root>",
      "T", nullptr, {true, true});
  const std::string xml = WriteTreeToXml(tree, factory);
  EXPECT_THAT(xml, HasSubstr("<Action ID=\"OpenHatch\">"));
  EXPECT_THAT(xml, HasSubstr("<input_port name=\"side\""));
  EXPECT_THAT(xml, HasSubstr("<Condition ID=\"IsHatchOpen\""));
}

TEST_F(BtCppSemanticsTest, TryCatchRunsItsCatchBlockOnFailureAndOnHalt) {
  board->Set("stop", false);
  Tree tree = Load(
      "<ReactiveFallback><ScriptCondition code='stop'/>"
      "<TryCatch catch_on_halt='true'><Async name='Try'/><Async name='Catch'/></TryCatch>"
      "</ReactiveFallback>");
  recorder.results["Try"] = {F};
  recorder.results["Catch"] = {R, S};
  EXPECT_EQ(tree.TickOnce(), R);  // Try failed: the catch block runs
  EXPECT_EQ(tree.TickOnce(), F);  // catch done: the TryCatch fails
  recorder.results["Catch"] = {S};
  EXPECT_EQ(tree.TickOnce(), R);  // Try runs
  board->Set("stop", true);
  EXPECT_EQ(tree.TickOnce(), S);  // halted during the try block: the catch block ran once
  EXPECT_THAT(recorder.events, ElementsAre("start:Try", "start:Catch", "running:Catch", "start:Try",
                                           "halt:Try", "start:Catch"));

  factory.ClearRegisteredTrees();
  Tree lonely = Load("<TryCatch><AlwaysSuccess/></TryCatch>");
  try {
    lonely.TickOnce();
    FAIL() << "a TryCatch with one child ran";
  } catch (const LogicError& e) {
    EXPECT_THAT(e.what(), HasSubstr("TryCatch::1"));
  }
}

TEST_F(BtCppSemanticsTest, EntryUpdateNodesFollowTheBlackboardsWrites) {
  Tree tree = Load("<Sequence><WasEntryUpdated entry='{goal}'/><Counter key='{n}'/></Sequence>");
  board->Set("n", 0);
  EXPECT_EQ(tree.TickOnce(), F);  // never written
  board->Set("goal", std::string("door_a"));
  EXPECT_EQ(tree.TickOnce(), S);
  EXPECT_EQ(tree.TickOnce(), F);              // not written since
  board->Set("goal", std::string("door_a"));  // the same value, but a write
  EXPECT_EQ(tree.TickOnce(), S);

  factory.ClearRegisteredTrees();
  Tree skip = Load("<SkipUnlessUpdated entry='goal'><Counter key='{n}'/></SkipUnlessUpdated>");
  EXPECT_EQ(skip.TickOnce(), S);  // the goal was written before this node first looked
  EXPECT_EQ(skip.TickOnce(), K);
  factory.ClearRegisteredTrees();
  Tree wait = Load("<WaitValueUpdate entry='{other}'><Counter key='{n}'/></WaitValueUpdate>");
  EXPECT_EQ(wait.TickOnce(), R);
  board->Set("other", 1);
  EXPECT_EQ(wait.TickOnce(), S);
  EXPECT_EQ(board->Get<int>("n"), 4);
}

}  // namespace
}  // namespace egress::bt
