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

/// Rasterizes `world` at `resolution` [m] over the bounds of its footprints (snapped to the
/// grid). @throws InvalidArgument for a bad resolution, a world without walls, or more than
/// `max_cells` cells.
SdfMap RasterizeSdfWorld(const twin::WorldDescription& world, double resolution,
                         std::int64_t max_cells);

}  // namespace egress::apps

#include "egress/behavior/mission_map.h"
#include "egress/twin/scenario.h"

namespace egress::apps {

/// The building map the robot brain gets for a twin scenario: the world's floor plan and doors
/// (RasterizeSdfWorld) and the scenario's door actuators (their SDF boxes, face on the side of
/// the door line they stand on). The scenario's extra obstacles, people and payloads are not in
/// it: the robot perceives them. @throws InvalidArgument for an actuator without a shape.
behavior::MissionMap BuildMissionMap(const twin::WorldDescription& world,
                                     const twin::Scenario& scenario, double resolution = 0.05);

}  // namespace egress::apps

#include <memory>

#include "egress/behavior/executive.h"
#include "egress/twin/twin_world.h"

namespace egress::apps {

/// The robot brain for a twin run of `scenario`: its mission tree and blackboard, the building
/// map, and as the initial pose the twin's start (what an operator's initial pose estimate
/// gives a real robot; after that the brain localizes on odometry alone).
/// @throws InvalidArgument / LogicError naming the file for a scenario without a mission, a bad
/// tree or an unknown node.
std::unique_ptr<behavior::Executive> MakeScenarioExecutive(const twin::Scenario& scenario,
                                                           const twin::WorldDescription& world,
                                                           const twin::TwinWorld& twin_world,
                                                           std::shared_ptr<const RobotModel> model,
                                                           const behavior::ExecutiveConfig& config);

}  // namespace egress::apps
