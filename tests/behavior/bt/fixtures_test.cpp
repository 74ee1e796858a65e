// Conformance: the eight public trees in ../shared/reference/bt_trees/ (Nav2, MoveIt Pro and
// BehaviorTree.CPP's own) load unchanged; log_test.xml runs end to end.

#include <algorithm>
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/bt/factory.h"
#include "egress/bt/loggers.h"
#include "test_nodes.h"

namespace egress::bt {
namespace {

namespace fs = std::filesystem;

fs::path FixtureDir() {
  const std::string reference = testing::ReferenceDir();
  return reference.empty() ? fs::path() : fs::path(reference) / "bt_trees";
}

#define REQUIRE_FIXTURES()                                                                     \
  if (FixtureDir().empty() || !fs::is_directory(FixtureDir())) {                               \
    GTEST_SKIP() << "reference BT fixtures not found: set EGRESS_REFERENCE_DIR to the folder " \
                    "holding bt_trees/ (default ../shared/reference)";                         \
  }

TEST(FixturesTest, LogTestRunsEndToEnd) {
  REQUIRE_FIXTURES();
  BehaviorTreeFactory factory;
  Tree tree = factory.CreateTreeFromFile(FixtureDir() / "BehaviorTree.CPP__log_test.xml", "Main");
  auto clock = std::make_shared<ManualClock>();
  tree.SetClock(clock);
  TreeObserver observer(tree);
  int ticks = 0;
  const NodeStatus result = tree.TickWhileRunning([&] {
    ++ticks;
    clock->Advance(std::chrono::milliseconds(100));
  });
  EXPECT_EQ(result, NodeStatus::kSuccess);
  EXPECT_EQ(ticks, 6);  // two Sleep(300 ms) in sequence at 100 ms per tick
  EXPECT_EQ(observer.at("FirstSubtree/SleepSequence").successes, 1u);
  EXPECT_EQ(observer.at("SecondSubtree/SleepSequence").successes, 1u);
}

TEST(FixturesTest, Nav2TreesLoadWithStandInsFromTheirModel) {
  REQUIRE_FIXTURES();
  for (const char* file :
       {"navigation2__navigate_to_pose_w_replanning_and_recovery.xml",
        "navigation2__navigate_to_pose_w_replanning_goal_patience_and_recovery.xml"}) {
    BehaviorTreeFactory factory;
    const auto registered =
        factory.RegisterStandInsFromModelFile(FixtureDir() / "navigation2__nav2_tree_nodes.xml");
    EXPECT_GT(registered.size(), 60u);
    Tree tree = factory.CreateTreeFromFile(FixtureDir() / file);
    EXPECT_EQ(tree.main_tree_id(), "MainTree") << file;
    EXPECT_TRUE(tree.stand_in_node_ids().empty()) << file;  // every node is in the model
    EXPECT_EQ(tree.root().registration_id(), "RecoveryNode");
    tree.SetStandInDriver([](const TreeNode& node) {
      return node.registration_id() == "FollowPath" ? NodeStatus::kRunning : NodeStatus::kSuccess;
    });
    EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning) << file;
  }
}

TEST(FixturesTest, MoveItProTreesLoadWithStandInsAndStubSubTrees) {
  REQUIRE_FIXTURES();
  for (const char* file : {"moveit_pro_example_ws__errorcheckvectorsize.xml",
                           "moveit_pro_example_ws__ml_move_boxes_to_loading_zone.xml",
                           "moveit_pro_example_ws__mpc_pose_tracking.xml",
                           "moveit_pro_example_ws__request_teleoperation.xml"}) {
    BehaviorTreeFactory factory;
    Tree tree = factory.CreateTreeFromFile(FixtureDir() / file, "", nullptr, {true, true});
    EXPECT_FALSE(tree.nodes().empty()) << file;
  }
}

TEST(FixturesTest, MoveItProSubTreeInterfaceSemantics) {
  REQUIRE_FIXTURES();
  // errorcheckvectorsize: a SubTree model with defaults 1 and {vector}; Precondition else=SUCCESS.
  BehaviorTreeFactory factory;
  factory.RegisterSimpleAction(
      "GetSizeOfVector",
      [](TreeNode& node) {
        node.SetOutput("vector_size",
                       int(node.GetInput<std::vector<int>>("vector_in").value().size()));
        return NodeStatus::kSuccess;
      },
      {InputPort<std::vector<int>>("vector_in"), OutputPort<int>("vector_size")});
  factory.RegisterSimpleAction(
      "LogMessage", [](TreeNode&) { return NodeStatus::kSuccess; },
      {InputPort<std::string>("log_level", "info", ""), InputPort<std::string>("message")});
  factory.RegisterTreesFromFile(FixtureDir() / "moveit_pro_example_ws__errorcheckvectorsize.xml");
  factory.RegisterTreesFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='Outer'><SubTree ID='ErrorCheckVectorSize' "
      "vector='{vector}'/></BehaviorTree></root>");
  auto board = Blackboard::Create();
  board->Set("vector", std::string("4"));  // one element
  EXPECT_EQ(factory.CreateTree("Outer", board).TickOnce(), NodeStatus::kSuccess);
  board->Set("vector", std::string("4;5"));  // two elements: expected 1 -> error branch fails
  EXPECT_EQ(factory.CreateTree("Outer", board).TickOnce(), NodeStatus::kFailure);
}

TEST(FixturesTest, EveryFixtureIsValidXmlForTheLoader) {
  REQUIRE_FIXTURES();
  int count = 0;
  for (const auto& entry : fs::directory_iterator(FixtureDir())) {
    if (entry.path().extension() != ".xml") continue;
    ++count;
    BehaviorTreeFactory factory;
    EXPECT_NO_THROW(factory.RegisterTreesFromFile(entry.path())) << entry.path();
  }
  EXPECT_EQ(count, 8);
}

// Every BehaviorTree of every public file, loaded with stand-ins (Nav2's from its model, the
// others inferred) and stub subtrees, runs to completion when every leaf succeeds: no tree of
// theirs makes the engine loop, stall or throw.
TEST(FixturesTest, EveryPublicTreeRunsToCompletionWithStandIns) {
  REQUIRE_FIXTURES();
  std::vector<fs::path> models, files;
  for (const auto& entry : fs::directory_iterator(FixtureDir())) {
    if (entry.path().extension() != ".xml") continue;
    BehaviorTreeFactory probe;
    probe.RegisterTreesFromFile(entry.path());
    (probe.RegisteredTreeIds().empty() ? models : files).push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  int trees = 0;
  for (const fs::path& file : files) {
    BehaviorTreeFactory factory;
    for (const fs::path& model : models)
      factory.RegisterStandInsFromModelFile(model);
    factory.RegisterTreesFromFile(file);
    const std::vector<std::string> ids = factory.RegisteredTreeIds();
    for (const std::string& id : ids) {
      SCOPED_TRACE(file.filename().string() + " / " + id);
      // Run as its users include it, so its SubTree model's port defaults apply.
      factory.RegisterTreesFromText("<root BTCPP_format='4'><BehaviorTree ID='RunFixture_" + id +
                                    "'><SubTree ID='" + id + "'/></BehaviorTree></root>");
      Tree tree = factory.CreateTree("RunFixture_" + id, nullptr, {true, true});
      auto clock = std::make_shared<ManualClock>();
      tree.SetClock(clock);
      // A stand-in stands for a real node that would write its outputs: every blackboard entry
      // its ports reference and nobody set yet gets a 0, so the scripts reading them run.
      tree.SetStandInDriver([](const TreeNode& node) {
        for (const auto& [port, text] : node.config().ports) {
          const auto key = BlackboardKeyOf(text, port);
          if (key && !node.config().blackboard->GetAny(*key))
            node.config().blackboard->Set(*key, Any(std::int64_t{0}));
        }
        return NodeStatus::kSuccess;
      });
      TreeObserver observer(tree);
      const NodeStatus result =
          tree.TickWhileRunning([&] { clock->Advance(std::chrono::milliseconds(100)); }, 10'000);
      EXPECT_NE(result, NodeStatus::kRunning);
      EXPECT_NE(result, NodeStatus::kIdle);
      // Something ran: the root and at least one leaf completed.
      EXPECT_GE(observer.transitions().size(), 2u);
      ++trees;
    }
  }
  EXPECT_GE(trees, 7);  // log_test's two trees, Nav2's two, MoveIt Pro's (at least) three
}

}  // namespace
}  // namespace egress::bt
