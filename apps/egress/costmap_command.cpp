// `egress costmap MAP.yaml --out costmap.png`: loads a map_server map, builds the door-aware
// costmap egress plans on, and writes it as a PNG (black lethal, dark inscribed, gray decay,
// white free, blue unknown; doorway thresholds tinted green).

#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "commands.h"
#include "egress/perception/costmap.h"
#include "egress/perception/image_io.h"
#include "render.h"

namespace egress::apps {
namespace {

struct CostmapOptions {
  std::string map;
  std::string out{"costmap.png"};
  double robot_radius{0.215};
  double inflation_radius{0.55};
  std::vector<double> doorways;  // x1 y1 x2 y2, repeated
  bool overwrite{false};
};

void Run(const CostmapOptions& options) {
  using namespace perception;
  if (options.doorways.size() % 4 != 0) {
    throw CommandFailed("--doorway takes 4 numbers per doorway: hinge x y, latch x y [m]");
  }
  if (std::filesystem::exists(options.out) && !options.overwrite) {
    throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", options.out));
  }
  CostmapConfig config;
  config.robot_radius = options.robot_radius;
  config.inflation_radius = options.inflation_radius;
  Costmap2D costmap(OccupancyGrid::LoadMapServerYaml(options.map), config);
  for (std::size_t i = 0; i < options.doorways.size(); i += 4) {
    costmap.AddDoorway({fmt::format("doorway_{}", i / 4),
                        {options.doorways[i], options.doorways[i + 1]},
                        {options.doorways[i + 2], options.doorways[i + 3]}});
  }
  const cv::Mat image = RenderCostmap(costmap);
  if (!perception::WriteImageFile(options.out, image))
    throw CommandFailed(fmt::format("cannot write '{}'", options.out));
  std::size_t lethal = 0, free_cells = 0;
  for (const auto cost : costmap.costs()) {
    lethal += cost == kLethalCost;
    free_cells += cost == kFreeCost;
  }
  const GridGeometry& g = costmap.geometry();
  fmt::print("costmap {}x{} cells at {:.3f} m: {} lethal, {} free, {} doorways -> {}\n", g.width,
             g.height, g.resolution, lethal, free_cells, costmap.doorways().size(), options.out);
}

}  // namespace

void AddCostmapCommand(CLI::App& app) {
  auto options = std::make_shared<CostmapOptions>();
  auto* command =
      app.add_subcommand("costmap", "Render the door-aware costmap of a map_server map as a PNG");
  command->add_option("MAP", options->map, "map_server YAML (image, resolution, origin, ...)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out, "PNG to write")->capture_default_str();
  command->add_option("--robot-radius", options->robot_radius, "inscribed radius [m]")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  command->add_option("--inflation-radius", options->inflation_radius, "[m]")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  command->add_option("--doorway", options->doorways, "hinge x y latch x y [m] (repeatable)")
      ->expected(4)
      ->take_all();
  command->add_flag("--overwrite", options->overwrite, "replace an existing PNG");
  command->callback([options] { Run(*options); });
}

}  // namespace egress::apps
