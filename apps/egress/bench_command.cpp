// `egress bench plan`: runs the base planners over the planning suite (the office problems, and
// the MovingAI maps when the reference data is present) with OMPL's benchmark tool, writing one
// OMPL benchmark log per problem (Planner Arena reads them) and a CSV summary.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>

#include <fmt/format.h>

#include "commands.h"
#include "egress/planning/base_planner.h"
#include "egress/planning/movingai.h"

namespace egress::apps {
namespace {

struct BenchOptions {
  std::string out{"bench_plan"};
  std::vector<std::string> planners{"RRTConnect", "RRTstar", "PRMstar", "BITstar",
                                    "InformedRRTstar"};
  int runs{5};
  double time{1.0};
  std::string reference;
  int movingai_problems{2};
};

perception::OccupancyGrid Office() {
  return perception::OccupancyGrid::LoadMapServerYaml(EGRESS_OFFICE_MAP);
}

struct Problem {
  std::string name;
  std::shared_ptr<perception::Costmap2D> costmap;
  double robot_radius;
  Pose2 start, goal;
  double reference_length;  // grid or published optimum [m]
};

void Progress(std::size_t done, std::size_t total, const std::string& label) {
  const int width = 30;
  const int filled = int(width * done / std::max<std::size_t>(1, total));
  fmt::print(stderr, "\r[{}{}] {}/{} {:<40}", std::string(std::size_t(filled), '#'),
             std::string(std::size_t(width - filled), '.'), done, total, label);
  if (done == total) fmt::print(stderr, "\n");
}

void Run(const BenchOptions& options) {
  std::vector<Problem> problems;
  auto office = std::make_shared<perception::Costmap2D>(Office());
  for (auto [name, start, goal] :
       {std::tuple{"office_two_doors", Pose2{1.5, 4.5, 0}, Pose2{12.5, 1.5, 0}},
        std::tuple{"office_one_door", Pose2{1.0, 1.0, 0}, Pose2{7.0, 5.0, 0}}}) {
    problems.push_back(
        {name, office, 0.215, start, goal,
         *planning::GridShortestPathLength(*office, start.translation(), goal.translation())});
  }
  std::string reference = options.reference;
  if (reference.empty()) {
    const char* env = std::getenv("EGRESS_REFERENCE_DIR");
    reference = env != nullptr ? env : "../shared/reference";
  }
  const std::filesystem::path movingai = std::filesystem::path(reference) / "movingai";
  if (std::filesystem::is_directory(movingai)) {
    for (const char* map : {"arena2", "8room_000", "maze512-1-0"}) {
      const auto grid = planning::LoadMovingAiMap(movingai / (std::string(map) + ".map"));
      const auto scenarios =
          planning::LoadMovingAiScenarios(movingai / (std::string(map) + ".map.scen"));
      perception::CostmapConfig config;
      config.robot_radius = config.inflation_radius = 0.3;
      auto costmap = std::make_shared<perception::Costmap2D>(grid, config);
      for (int k = 1; k <= options.movingai_problems; ++k) {
        const auto& s = scenarios[scenarios.size() * std::size_t(k) /
                                  std::size_t(options.movingai_problems + 1)];
        const int h = grid.geometry().height;
        const Eigen::Vector2d a = planning::MovingAiCellCenter(s.start, h),
                              b = planning::MovingAiCellCenter(s.goal, h);
        problems.push_back({fmt::format("{}_bucket{}", map, s.bucket),
                            costmap,
                            0.3,
                            {a.x(), a.y(), 0},
                            {b.x(), b.y(), 0},
                            s.optimal_length});
      }
    }
  } else {
    fmt::print(stderr, "note: {} not found; benchmarking the office problems only\n",
               movingai.string());
  }
  std::filesystem::create_directories(options.out);
  std::ofstream csv(std::filesystem::path(options.out) / "summary.csv");
  csv << "problem,planner,runs,solved,median_time_s,median_length_m,reference_length_m,length_"
         "ratio\n";
  fmt::print("{:<24} {:<16} {:>7} {:>12} {:>12}\n", "problem", "planner", "solved", "median [ms]",
             "len/ref");
  std::size_t done = 0;
  for (const Problem& problem : problems) {
    Progress(done, problems.size(), problem.name);
    planning::BasePlannerConfig config;
    config.footprint_radius = problem.robot_radius;
    const planning::BasePlanner planner(*problem.costmap, nullptr, config);
    const auto log = std::filesystem::path(options.out) / (problem.name + ".log");
    const auto rows = planner.RunOmplBenchmark(problem.start, problem.goal, options.planners,
                                               options.runs, options.time, problem.name, log);
    Progress(++done, problems.size(), problem.name);
    for (const auto& row : rows) {
      const double ratio =
          row.median_length > 0 ? row.median_length / problem.reference_length : 0.0;
      fmt::print("{:<24} {:<16} {:>3}/{:<3} {:>12.2f} {:>12.3f}\n", problem.name, row.planner,
                 row.solved, row.runs, row.median_time * 1000, ratio);
      csv << fmt::format("{},{},{},{},{:.6f},{:.4f},{:.4f},{:.4f}\n", problem.name, row.planner,
                         row.runs, row.solved, row.median_time, row.median_length,
                         problem.reference_length, ratio);
    }
  }
  fmt::print("OMPL benchmark logs (Planner Arena) and summary.csv in {}\n", options.out);
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  auto options = std::make_shared<BenchOptions>();
  auto* bench = app.add_subcommand("bench", "Benchmark egress components");
  bench->require_subcommand(1);
  auto* plan = bench->add_subcommand(
      "plan", "Run the base planners over the planning suite (OMPL benchmark logs + CSV)");
  plan->add_option("--out", options->out, "output folder")->capture_default_str();
  plan->add_option("--planner", options->planners, "planners to run (default: all)");
  plan->add_option("--runs", options->runs, "runs per planner and problem")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxTrials));
  plan->add_option("--time", options->time, "time limit per run [s]")
      ->capture_default_str()
      ->check(FiniteIn(1e-3, 3600.0));
  plan->add_option("--reference", options->reference,
                   "folder holding movingai/ (default: EGRESS_REFERENCE_DIR)");
  plan->add_option("--movingai-problems", options->movingai_problems, "scenarios per MovingAI map")
      ->capture_default_str()
      ->check(CLI::Range(0, kMaxTrials));
  plan->callback([options] {
    if (options->runs < 1 || options->time <= 0)
      throw CommandFailed("--runs must be >= 1 and --time > 0");
    Run(*options);
  });
}

}  // namespace egress::apps
