// Base planning on the office world (three rooms joined by two doors): median time to a
// solution and the simplified path length against the shortest 8-connected grid path on the
// same inflated costmap. Prints a table and writes planning_bench.json.
// Run: build/bench/planning_bench [runs] [planner]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "egress/planning/base_planner.h"

namespace {

using namespace egress;
using perception::Box2;

perception::OccupancyGrid Office() {
  return perception::OccupancyGrid::LoadMapServerYaml(EGRESS_OFFICE_MAP);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 50;
  planning::BasePlannerConfig config;
  if (argc > 2) config.planner = argv[2];
  perception::Costmap2D costmap(Office());
  costmap.AddDoorway({"A", {5.0, 2.5}, {5.0, 3.5}});
  costmap.AddDoorway({"B", {9.0, 1.0}, {9.0, 2.0}});
  const planning::BasePlanner planner = [&] {
    planning::BasePlanner p(costmap, nullptr, config);
    p.AddDoor({"A", {5.0, 2.5}, {5.0, 3.5}});
    p.AddDoor({"B", {9.0, 1.0}, {9.0, 2.0}});
    return p;
  }();
  struct Query {
    const char* name;
    Pose2 start, goal;
  };
  const std::vector<Query> queries = {
      {"room 1 -> room 3 (two doors)", {1.5, 4.5, 0.0}, {12.5, 1.5, 0.0}},
      {"room 1 -> room 2 (one door)", {1.0, 1.0, 0.0}, {7.0, 5.0, 1.57}},
      {"within room 2", {6.0, 1.0, 0.0}, {8.0, 5.0, 0.0}}};
  nlohmann::json json = nlohmann::json::array();
  std::printf("%-32s %9s %12s %12s %10s %8s\n", "query", "success", "median [ms]", "max [ms]",
              "len/grid", "doors");
  for (const Query& query : queries) {
    const double grid = *planning::GridShortestPathLength(costmap, query.start.translation(),
                                                          query.goal.translation());
    std::vector<double> times, ratios;
    int successes = 0;
    std::size_t doors = 0;
    for (int r = 0; r < runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const planning::PlanResult result = planner.Plan(query.start, query.goal);
      times.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (!result.ok()) continue;
      ++successes;
      ratios.push_back(result.length / grid);
      doors = result.doors_crossed.size();
    }
    std::printf("%-32s %8d%% %12.2f %12.2f %10.3f %8zu\n", query.name, 100 * successes / runs,
                Median(times), *std::max_element(times.begin(), times.end()),
                ratios.empty() ? 0.0 : Median(ratios), doors);
    json.push_back({{"query", query.name},
                    {"planner", config.planner},
                    {"success_percent", 100.0 * successes / runs},
                    {"median_ms", Median(times)},
                    {"median_length_over_grid", ratios.empty() ? 0.0 : Median(ratios)},
                    {"worst_length_over_grid",
                     ratios.empty() ? 0.0 : *std::max_element(ratios.begin(), ratios.end())}});
  }
  std::printf(
      "(len/grid: simplified path length over the shortest 8-connected grid path on the same "
      "costmap)\n");
  std::ofstream("planning_bench.json") << json.dump(2) << "\n";
  return 0;
}
