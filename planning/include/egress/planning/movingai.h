#pragma once
/// @file
/// Readers for the MovingAI grid benchmarks (Sturtevant 2012): `.map` files (octile grids) and
/// `.scen` scenario files with published optimal path lengths, for the planning regression
/// suite. A map becomes an OccupancyGrid with one metre per cell: cell (x, y) of the file (y
/// down from the top row) is the cell centred at (x + 0.5, height − y − 0.5) in M.

#include <filesystem>
#include <string>
#include <vector>

#include "egress/perception/occupancy_grid.h"

namespace egress::planning {

/// @throws LoadError naming the file and line for a malformed map.
perception::OccupancyGrid LoadMovingAiMap(const std::filesystem::path& path);

struct MovingAiScenario {
  int bucket{0};
  Eigen::Vector2i start{Eigen::Vector2i::Zero()};  ///< (x, y) in file cells, y down.
  Eigen::Vector2i goal{Eigen::Vector2i::Zero()};
  double optimal_length{0.0};  ///< Octile, no corner cutting [cells].
};

/// @throws LoadError naming the file and line for a malformed scenario file.
std::vector<MovingAiScenario> LoadMovingAiScenarios(const std::filesystem::path& path);

/// The M position of the centre of file cell (x, y) on a map of `height` rows.
Eigen::Vector2d MovingAiCellCenter(const Eigen::Vector2i& cell, int height);

}  // namespace egress::planning
