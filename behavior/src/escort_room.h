#pragma once
// Internal to behavior/src: where HoldForResidents (escort_nodes.cpp) steps to, out of the way of
// the residents it holds a door for.

#include <optional>
#include <string>

#include "egress/behavior/door_rules.h"
#include "egress/behavior/task_services.h"

namespace egress::behavior::detail {

/// Whether a step from `at` to `q` [M] goes into the residents' way in to `pass` (InTheLane),
/// nearer its doorway, or into a doorway (IntoADoorway).
bool InTheirWay(const TaskServices& task, const DoorPass& pass, const Eigen::Vector2d& at,
                const Eigen::Vector2d& q);

/// Where to step to make room when someone is within 0.35 m of the robot's edge (or,
/// during a step to `stepping_to`, of that step's end): of the poses a free straight step away
/// (the same heading), not in the residents' way in, the one farthest from everyone near, if
/// it gains 0.1 m over staying (over the step's end) and is predicted to leave everyone
/// room. nullopt: nobody that near, or no better place.
std::optional<Pose2> FindRoom(const TaskServices& task, const DoorPass& pass,
                              const std::optional<Eigen::Vector2d>& stepping_to);

/// Where the robot (task.belief), at an actuator beside `door`'s open doorway, steps sideways to,
/// out of the way between the open leaf's edge and itself: along the door line away from the
/// middle of the clear opening (ClearOpeningCentre), as far as the walls leave room, up to
/// 0.4 m, facing the way the residents come (LookYaw). nullopt: no free step of 0.1 m or more.
std::optional<Pose2> SqueezeAsidePose(const TaskServices& task, const DoorPass& pass,
                                      const std::string& door);

}  // namespace egress::behavior::detail
