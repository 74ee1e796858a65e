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
#include "egress/planning/route_planner.h"

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
  // The building-scale route (PlanRoute): building the planner (its distance transform, once
  // per map) and one route, on the office and on a 60 m x 30 m floor of 10 rooms off a corridor.
  {
    std::vector<perception::Box2> walls{{{30.0, -0.05, 0.0}, {60.2, 0.1}},
                                        {{30.0, 30.05, 0.0}, {60.2, 0.1}},
                                        {{-0.05, 15.0, 0.0}, {0.1, 30.2}},
                                        {{60.05, 15.0, 0.0}, {0.1, 30.2}}};
    std::vector<perception::Doorway> doorways;
    for (int side = 0; side < 2; ++side) {
      const double y = side == 0 ? 13.95 : 16.05;  // the corridor: y 14-16
      for (int k = 0; k < 5; ++k) {
        const double x0 = 12.0 * k, door = x0 + 6.0;
        walls.push_back({{(x0 + door - 0.5) / 2, y, 0.0}, {door - 0.5 - x0, 0.1}});
        walls.push_back({{(door + 0.5 + x0 + 12.0) / 2, y, 0.0}, {x0 + 12.0 - door - 0.5, 0.1}});
        walls.push_back({{x0 + 12.0, side == 0 ? 7.0 : 23.0, 0.0}, {0.1, 14.0}});
        perception::Doorway d{
            "d" + std::to_string(side) + std::to_string(k), {door - 0.475, y}, {door + 0.475, y}};
        doorways.push_back(d);
      }
    }
    const auto floor =
        perception::OccupancyGrid::FromBoxes(walls, {-0.2, -0.2}, {60.2, 30.2}, 0.05);
    struct RouteCase {
      const char* name;
      const perception::OccupancyGrid* grid;
      std::vector<perception::Doorway> doors;
      Pose2 start, goal;
    };
    const perception::OccupancyGrid office = Office();
    const std::vector<RouteCase> cases{
        {"office: room 1 -> room 3",
         &office,
         {{"door_a", {5.0, 2.525}, {5.0, 3.475}}, {"door_b", {9.0, 1.975}, {9.0, 1.025}}},
         {1.5, 4.5, 0.0},
         {12.5, 1.5, 0.0}},
        {"60x30 m floor: room -> far room", &floor, doorways, {3.0, 5.0, 0.0}, {57.0, 25.0, 0.0}}};
    std::printf("\n%-34s %10s %12s %12s %6s\n", "route", "cells", "build [ms]", "plan [ms]",
                "doors");
    for (const auto& c : cases) {
      std::vector<double> build, plan;
      std::size_t doors = 0;
      for (int r = 0; r < std::max(3, runs / 4); ++r) {
        auto t0 = std::chrono::steady_clock::now();
        const planning::RoutePlanner routes(*c.grid, c.doors);
        auto t1 = std::chrono::steady_clock::now();
        const planning::RouteResult result = routes.Plan(c.start, c.goal);
        auto t2 = std::chrono::steady_clock::now();
        build.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        plan.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        doors = result.ok() ? result.route->legs.size() : 0;
      }
      std::printf("%-34s %10zu %12.2f %12.2f %6zu\n", c.name, c.grid->geometry().size(),
                  Median(build), Median(plan), doors);
      json.push_back({{"route", c.name},
                      {"cells", c.grid->geometry().size()},
                      {"build_median_ms", Median(build)},
                      {"plan_median_ms", Median(plan)},
                      {"doors", doors}});
    }
  }
  std::ofstream("planning_bench.json") << json.dump(2) << "\n";
  return 0;
}
