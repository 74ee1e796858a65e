#pragma once
/// @file
/// A building and a goal as a scenario (`egress sim run WORLD.sdf --goal PLACE`, `egress robot
/// --ros2 --map WORLD.sdf --goal PLACE`): the world's doors with their operators (from the world
/// and its building YAML), the robot at the start, the mission a tree that goes to the goal.

#include <string>

#include "egress/twin/scenario.h"

namespace egress::apps {

/// Whether `path` names an SDF world (.sdf, .world) rather than a scenario YAML.
bool IsWorldFile(const std::string& path);

struct GoalMission {
  std::string world;         ///< SDF world file
  std::string start;         ///< A place or "x;y;yaw"; empty: the building's first place.
  std::string goal;          ///< A place or "x;y;yaw".
  double time_limit{300.0};  ///< [s]
  std::string tree;          ///< The mission tree (go_to.xml by default in the commands).
};

/// @throws InvalidArgument naming the option (--start, --goal) or the file.
twin::Scenario GoalScenario(const GoalMission& mission);

}  // namespace egress::apps
