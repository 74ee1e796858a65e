#pragma once
/// @file
/// An SDF world as the planners see it: its static shapes at body height rasterized into an
/// occupancy grid, and its hinged doors as doorways. Used by egress-navd's LoadWorld and by
/// `egress plan --map world.sdf`, so both read a world the same way.

#include <cstdint>
#include <vector>

#include "egress/perception/costmap.h"
#include "egress/perception/occupancy_grid.h"
#include "egress/twin/world_description.h"

namespace egress::apps {

struct SdfMap {
  perception::OccupancyGrid grid;
  std::vector<perception::Doorway> doors;  ///< id = the SDF model name; hinge and latch jambs
};

/// Rasterizes `world` at `resolution` [m] over the bounds of its footprints, grown to hold
/// every point of `cover` outside them with `cover_margin` [m] of free space round it (places
/// beyond the exit, where a route leads out of the building), snapped to the grid.
/// @throws InvalidArgument for a bad resolution or margin, a non-finite point, a world without
/// walls, or more than `max_cells` cells.
SdfMap RasterizeSdfWorld(const twin::WorldDescription& world, double resolution,
                         std::int64_t max_cells, const std::vector<Eigen::Vector2d>& cover = {},
                         double cover_margin = 0.0);

}  // namespace egress::apps
