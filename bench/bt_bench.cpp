// Behavior-tree engine costs: ticking a 50-node tree of trivial leaves (target <= 2 us per
// tick) and loading the Nav2 navigator fixture (target <= 5 ms).

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "egress/bt/factory.h"

namespace {

namespace bt = egress::bt;

// A ReactiveSequence of 7 Sequences, each with 4 AlwaysSuccess and an Inverter over an
// AlwaysFailure: 1 + 7 * (1 + 6) = 50 nodes, every one ticked on every tick.
std::string FiftyNodeTree() {
  std::string xml = "<root BTCPP_format='4'><BehaviorTree ID='T'><ReactiveSequence>";
  for (int i = 0; i < 7; ++i) {
    xml += "<Sequence>";
    xml +=
        "<AlwaysSuccess/><AlwaysSuccess/><Inverter><AlwaysFailure/></Inverter><AlwaysSuccess/"
        "><AlwaysSuccess/>";
    xml += "</Sequence>";
  }
  return xml + "</ReactiveSequence></BehaviorTree></root>";
}

void BM_Tick50NodeTree(benchmark::State& state) {
  bt::BehaviorTreeFactory factory;
  bt::Tree tree = factory.CreateTreeFromText(FiftyNodeTree());
  state.counters["nodes"] = double(tree.nodes().size());
  for (auto _ : state)
    benchmark::DoNotOptimize(tree.TickOnce());
}
BENCHMARK(BM_Tick50NodeTree);

std::filesystem::path ReferenceDir() {
  const char* env = std::getenv("EGRESS_REFERENCE_DIR");
  return env != nullptr ? env : EGRESS_REFERENCE_DIR;
}

void BM_LoadNav2Navigator(benchmark::State& state) {
  const auto dir = ReferenceDir() / "bt_trees";
  const auto tree_file =
      dir / "navigation2__navigate_to_pose_w_replanning_goal_patience_and_recovery.xml";
  if (!std::filesystem::exists(tree_file)) {
    state.SkipWithError("reference BT fixtures not found (set EGRESS_REFERENCE_DIR)");
    return;
  }
  bt::BehaviorTreeFactory factory;
  factory.RegisterStandInsFromModelFile(dir / "navigation2__nav2_tree_nodes.xml");
  for (auto _ : state) {
    factory.ClearRegisteredTrees();
    benchmark::DoNotOptimize(factory.CreateTreeFromFile(tree_file));
  }
}
BENCHMARK(BM_LoadNav2Navigator)->Unit(benchmark::kMicrosecond);

void BM_LoadNav2ModelAndNavigator(benchmark::State& state) {
  const auto dir = ReferenceDir() / "bt_trees";
  if (!std::filesystem::exists(dir)) {
    state.SkipWithError("reference BT fixtures not found (set EGRESS_REFERENCE_DIR)");
    return;
  }
  for (auto _ : state) {
    bt::BehaviorTreeFactory factory;
    factory.RegisterStandInsFromModelFile(dir / "navigation2__nav2_tree_nodes.xml");
    benchmark::DoNotOptimize(factory.CreateTreeFromFile(
        dir / "navigation2__navigate_to_pose_w_replanning_and_recovery.xml"));
  }
}
BENCHMARK(BM_LoadNav2ModelAndNavigator)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
