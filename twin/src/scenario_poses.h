#pragma once
// Where a scenario may put the robot and the people: their starts, goals and waypoints on the
// building's floor (not inside a model, not far outside the walls), and where a robot off the
// scene stands (OffScenePose, declared in scenario.h).

#include <string>

#include "egress/hsr_interface/geometry.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// A place X_WB (the robot's, or a person's: the yaw is not used) on the building's floor.
/// @throws LoadError "<where>: field '<field>' (place '<place>'): (x, y) is inside model 'M'" or
/// "... is D m outside the building's walls".
void CheckOnTheFloor(const WorldDescription& world, const std::string& where,
                     const std::string& field, const std::string& place, const Pose2& X_WB);

}  // namespace egress::twin
