#pragma once
// Where a scenario may put the robot: its start and goal on the building's floor (not inside a
// model, not far outside the walls), and where a robot off the scene stands (OffScenePose,
// declared in scenario.h).

#include <string>

#include "egress/hsr_interface/geometry.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// @throws LoadError "<where>: field '<field>' (place '<place>'): (x, y) is inside model 'M'" or
/// "... is D m outside the building's walls".
void CheckRobotPose(const WorldDescription& world, const std::string& where,
                    const std::string& field, const std::string& place, const Pose2& X_WB);

}  // namespace egress::twin
