// Planning regression suite: a table of problems on our worlds with expected feasibility and a
// path-length bound against the grid-optimal reference, and the MovingAI benchmark maps
// (../shared/reference/movingai, through EGRESS_REFERENCE_DIR) against their published
// optimal lengths. A planner change that breaks feasibility or lengthens paths past the stated
// bounds fails here.

#include <unistd.h>
#include <algorithm>
#include <cstdlib>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/planning/base_planner.h"
#include "egress/planning/movingai.h"

namespace egress::planning {
namespace {

using perception::Box2;

// The office (worlds/office), plus a corridor 0.55 m wide (robot 0.43 m) between two cabinets
// in room 3.
perception::OccupancyGrid Office() {
  perception::OccupancyGrid grid = perception::OccupancyGrid::LoadMapServerYaml(EGRESS_OFFICE_MAP);
  grid.AddBox({{11.0, 4.1, 0.0}, {1.5, 1.4}});
  grid.AddBox({{11.0, 2.475, 0.0}, {1.5, 0.75}});
  return grid;
}

struct Problem {
  const char* name;
  Pose2 start, goal;
  std::vector<std::string> closed_doors;
  bool feasible;
  double max_length_ratio;  // vs the grid shortest path on the same costmap
};

TEST(PlanningRegressionTest, OurWorlds) {
  const std::vector<Problem> problems = {
      {"through two open doors", {1.5, 4.5, 0.0}, {12.5, 1.5, 0.0}, {}, true, 1.05},
      {"through one open door", {1.0, 1.0, 0.0}, {7.0, 5.0, 1.57}, {}, true, 1.05},
      {"within a room", {6.0, 1.0, 0.0}, {8.0, 5.0, 0.0}, {}, true, 1.05},
      {"door A closed", {1.5, 4.5, 0.0}, {7.0, 4.5, 0.0}, {"A"}, false, 0.0},
      {"door B closed", {6.0, 4.5, 0.0}, {12.5, 1.5, 0.0}, {"B"}, false, 0.0},
      {"narrow corridor", {9.8, 3.1, 0.0}, {12.5, 3.1, 0.0}, {}, true, 1.05},
      {"start near a wall", {0.4, 3.0, 0.0}, {4.5, 5.5, 0.0}, {}, true, 1.05},
  };
  for (const Problem& problem : problems) {
    perception::Costmap2D costmap(Office());
    costmap.AddDoorway({"A", {5.0, 2.5}, {5.0, 3.5}});
    costmap.AddDoorway({"B", {9.0, 1.0}, {9.0, 2.0}});
    for (const auto& door : problem.closed_doors)
      costmap.SetDoorLeafAngle(door, 0.0);
    BasePlanner planner(costmap, nullptr);
    planner.AddDoor({"A", {5.0, 2.5}, {5.0, 3.5}});
    planner.AddDoor({"B", {9.0, 1.0}, {9.0, 2.0}});
    const PlanResult result = planner.Plan(problem.start, problem.goal);
    if (!problem.feasible) {
      EXPECT_EQ(result.status, PlanStatus::kGoalUnreachable) << problem.name;
      continue;
    }
    ASSERT_TRUE(result.ok()) << problem.name << ": " << result.message;
    const auto grid =
        GridShortestPathLength(costmap, problem.start.translation(), problem.goal.translation());
    ASSERT_TRUE(grid.has_value()) << problem.name;
    EXPECT_LE(result.length, problem.max_length_ratio * *grid) << problem.name;
    EXPECT_TRUE(planner.IsPathValid(result.path)) << problem.name;
  }
}

// Bounds stated from measured figures (Release, 12 scenarios per map spread over the length
// buckets): every map 100 % solved, median length ratio <= 1.0 (any-angle paths are shorter
// than octile ones), worst ratio <= 1.0 with a 2 % margin.
struct MapBounds {
  const char* name;
  double min_success;
  double max_median_ratio;
  double max_worst_ratio;
};

TEST(PlanningRegressionTest, MovingAiMapsAgainstPublishedOptima) {
  const char* env = std::getenv("EGRESS_REFERENCE_DIR");
  const std::filesystem::path dir = std::filesystem::path(env != nullptr ? env : "") / "movingai";
  if (env == nullptr || !std::filesystem::is_directory(dir)) {
    GTEST_SKIP()
        << "MovingAI maps not found: set EGRESS_REFERENCE_DIR to the folder holding movingai/ "
           "(default ../shared/reference)";
  }
  for (const MapBounds bounds :
       {MapBounds{"arena2", 1.0, 1.0, 1.02}, MapBounds{"8room_000", 1.0, 1.0, 1.02},
        MapBounds{"maze512-1-0", 1.0, 1.0, 1.02}}) {
    const auto grid = LoadMovingAiMap(dir / (std::string(bounds.name) + ".map"));
    const auto scenarios = LoadMovingAiScenarios(dir / (std::string(bounds.name) + ".map.scen"));
    // A point robot on the grid: obstacles are exactly the blocked cells.
    perception::CostmapConfig costmap_config;
    costmap_config.robot_radius = 0.3;
    costmap_config.inflation_radius = 0.3;
    perception::Costmap2D costmap(grid, costmap_config);
    BasePlannerConfig config;
    config.footprint_radius = 0.3;
    BasePlanner planner(costmap, nullptr, config);
    const std::size_t step = std::max<std::size_t>(1, scenarios.size() / 12);
    int attempted = 0, solved = 0;
    std::vector<double> ratios;
    for (std::size_t i = step; i < scenarios.size(); i += step) {
      const MovingAiScenario& s = scenarios[i];
      if (s.optimal_length <= 0.0) continue;
      ++attempted;
      const int h = grid.geometry().height;
      const Eigen::Vector2d a = MovingAiCellCenter(s.start, h), b = MovingAiCellCenter(s.goal, h);
      const PlanResult result = planner.Plan({a.x(), a.y(), 0.0}, {b.x(), b.y(), 0.0});
      if (!result.ok()) continue;
      ++solved;
      ratios.push_back(result.length / s.optimal_length);
    }
    ASSERT_GT(attempted, 0);
    std::sort(ratios.begin(), ratios.end());
    const double success = double(solved) / attempted;
    const double median = ratios.empty() ? 0.0 : ratios[ratios.size() / 2];
    const double worst = ratios.empty() ? 0.0 : ratios.back();
    RecordProperty(std::string(bounds.name) + "_success", std::to_string(success));
    RecordProperty(std::string(bounds.name) + "_median_ratio", std::to_string(median));
    RecordProperty(std::string(bounds.name) + "_worst_ratio", std::to_string(worst));
    std::printf("%-12s solved %d/%d, length / optimal: median %.3f, worst %.3f\n", bounds.name,
                solved, attempted, median, worst);
    EXPECT_GE(success, bounds.min_success) << bounds.name;
    EXPECT_LE(median, bounds.max_median_ratio) << bounds.name;
    EXPECT_LE(worst, bounds.max_worst_ratio) << bounds.name;
  }
}

TEST(PlanningRegressionTest, MalformedBenchmarkFilesAreReported) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("egress_movingai_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.map") << "type octile\nheight 2\nwidth 3\nmap\n..@\n.X.\n";
  try {
    LoadMovingAiMap(dir / "bad.map");
    FAIL() << "expected LoadError";
  } catch (const LoadError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.map:6: unknown terrain 'X'"), std::string::npos)
        << e.what();
  }
  std::ofstream(dir / "bad.scen") << "version 1\n0\tm.map\t3\t2\t0\t0\n";
  EXPECT_THROW(LoadMovingAiScenarios(dir / "bad.scen"), LoadError);
  EXPECT_THROW(LoadMovingAiMap(dir / "absent.map"), LoadError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace egress::planning
