#pragma once
/// @file
/// MissionMap: what the robot brain knows of a building before it moves — the floor plan (an
/// occupancy grid of walls and fixed furniture), its doors (hinge, latch, opening side) and the
/// door actuators (push buttons, proximity plates) with their mounting walls. A building map,
/// not ground truth: people, payloads, door angles and obstacles the map does not show are
/// perceived at run time.

#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/perception/costmap.h"
#include "egress/perception/door_estimation.h"
#include "egress/perception/occupancy_grid.h"
#include "egress/planning/ik_solver.h"

namespace egress::behavior {

/// The button or plate that opens one door.
struct MapActuator {
  std::string id;    ///< Its name in the building map.
  std::string door;  ///< The door it operates.
  planning::ButtonType type{planning::ButtonType::kPushButton};
  Eigen::Vector3d p_M{Eigen::Vector3d::Zero()};   ///< Face centre of the actuator [m].
  Eigen::Vector3d n_M{Eigen::Vector3d::UnitX()};  ///< Outward normal of its wall (unit).
  double protrusion{0.0};                         ///< How far its face stands out of the wall [m].
};

/// A named place of the building (a room, an exit, a table, a responder's post).
struct MapPlace {
  std::string name;
  std::string kind;     ///< room | exit | table | post | place
  Pose2 X_MP;           ///< Where to stand.
  bool has_yaw{false};  ///< Whether X_MP's yaw matters (else any heading will do).
};

struct MissionMap {
  perception::OccupancyGrid grid;
  std::vector<perception::Doorway> doorways;  ///< The doors as the costmap and planner see them.
  std::vector<perception::DoorModel> doors;   ///< The same doors for door-angle estimation.
  std::vector<MapActuator> actuators;
  std::vector<MapPlace> places;
  std::set<std::string> glass_doors;  ///< Doors with a glass leaf (the laser hardly sees it).

  const perception::DoorModel* FindDoor(const std::string& id) const;
  /// The actuator of `door` on the side of the door line where `p_M` is (the nearest if there
  /// are several; mounted on the door's wall or on any other wall), or nullptr if there is none
  /// on that side (a door opened by hand, or one with its button only on the other side).
  const MapActuator* FindActuatorOf(const std::string& door, const Eigen::Vector2d& p_M) const;
  /// The actuator named `id`, or nullptr.
  const MapActuator* FindActuator(const std::string& id) const;
  /// The place named `name`, or nullptr.
  const MapPlace* FindPlace(const std::string& name) const;
  /// Which side of the door line of `door` `p_M` is on: +1 on the side its leaf opens into, −1
  /// on the other, 0 on the line (within 1 mm) or for an unknown door.
  int SideOfDoor(const std::string& door, const Eigen::Vector2d& p_M) const;
  /// @throws InvalidArgument for a door without a doorway, an actuator of an unknown door or a
  /// non-finite pose.
  void Validate() const;
};

}  // namespace egress::behavior
