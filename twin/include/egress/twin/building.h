#pragma once
/// @file
/// BuildingDescription: what a building's SDF world says about getting around in it — its doors
/// (hinge, latch, the side each opens into), their actuators (push buttons and proximity plates,
/// found from the world's models: any wall, any yaw, either side of the door) and its named
/// places (rooms, exits, tables, a responder's post). Engine-free: the twin (default door
/// operators), the robot brain's building map and egress-navd all read the same description.
///
/// Sources, in order:
/// - the SDF world: hinged models are doors; a static model whose name contains "button" (or
///   "push") is a push button, one whose name contains "plate" (or "proximity", "wave") is a
///   proximity plate; each actuator operates the nearest door within kMaxActuatorDistance of it.
///   Its face and facing come from its own box: the box's thinnest axis is the press direction,
///   and of its two faces the one not against a wall (or other static shape) faces out.
///   World-level `<frame name="...">` elements are named places.
/// - an optional building YAML (`building:` in a scenario, or `<world stem>.building.yaml`
///   beside the world) for what SDF cannot say: places and their kind, which door is glass,
///   an actuator's door or type when its name does not tell. Every key is checked.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// Farthest an actuator may be from its door's opening to be matched to it by proximity [m].
inline constexpr double kMaxActuatorDistance = 2.5;

enum class ActuatorKind { kPushButton, kProximityPlate };
std::string_view ToString(ActuatorKind kind);

/// One push button or proximity plate.
struct BuildingActuator {
  std::string model;  ///< SDF model name.
  std::string door;   ///< The door it operates.
  ActuatorKind kind{ActuatorKind::kPushButton};
  Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};   ///< Centre of its outward face [m].
  Eigen::Vector3d n_W{Eigen::Vector3d::UnitX()};  ///< Outward normal of its face (unit).
  double protrusion{0.0};                         ///< Its thickness along n_W [m].
};

/// One hinged door as seen on the floor plan.
struct BuildingDoor {
  std::string model;                                  ///< SDF model name.
  Eigen::Vector2d p_WHinge{Eigen::Vector2d::Zero()};  ///< Hinge-side jamb [m].
  Eigen::Vector2d p_WLatch{Eigen::Vector2d::Zero()};  ///< Latch (free) edge, closed [m].
  /// +1 if the leaf turns counter-clockwise (seen from above) as it opens, −1 clockwise.
  double swing_sign{1.0};
  double leaf_reach{0.0};              ///< Hinge to free edge [m].
  double max_open_angle{0.0};          ///< [rad]
  bool glass{false};                   ///< From the building YAML (SDF does not say).
  std::vector<std::string> actuators;  ///< Models of its actuators.

  double width() const { return (p_WLatch - p_WHinge).norm(); }
  Eigen::Vector2d centre() const { return (p_WHinge + p_WLatch) / 2; }
  /// Unit normal of the door line pointing to the side the leaf opens into.
  Eigen::Vector2d OpeningSideNormal() const;
};

/// A named place: where to go, or where something is.
struct BuildingPlace {
  std::string name;
  std::string kind;     ///< room | exit | table | post | place (from the YAML or the name's prefix)
  Pose2 X_WP;           ///< Where the robot stands (position; yaw the way to face there).
  bool has_yaw{false};  ///< Whether the yaw was given (else any heading will do).
};

struct BuildingDescription {
  std::string name;
  std::filesystem::path world_source;
  std::filesystem::path yaml_source;  ///< Empty without a building YAML.
  std::vector<BuildingDoor> doors;
  std::vector<BuildingActuator> actuators;
  std::vector<BuildingPlace> places;
  std::vector<std::string> notes;  ///< Models that look like actuators but were not matched.

  const BuildingDoor* FindDoor(const std::string& model) const;
  const BuildingActuator* FindActuator(const std::string& model) const;
  const BuildingPlace* FindPlace(const std::string& name) const;
  /// "a, b, c": the places, for error messages.
  std::string PlaceNames() const;
};

/// The door of `door` as a floor-plan doorway (hinge, latch, swing): one definition for every
/// reader of a world.
BuildingDoor DescribeDoor(const DoorDescription& door);

/// Describes `world`; `building_yaml` (optional) adds places, glass leaves and actuator
/// assignments. @throws LoadError naming the file, line and field (YAML) or the model (an
/// actuator whose shape is not one box, one with no door in reach, a YAML name the world lacks).
BuildingDescription DescribeBuilding(const WorldDescription& world,
                                     const std::filesystem::path& building_yaml = {});
/// The same from YAML text (`source_name` for messages).
BuildingDescription DescribeBuildingFromString(const WorldDescription& world,
                                               const std::string& building_yaml,
                                               const std::string& source_name);
/// Makes `model` (one box in `world`) an actuator of `door` of that kind, replacing what the
/// description said of it. @throws LoadError naming the model if it is not one box or the
/// door is unknown.
void AssignActuator(const WorldDescription& world, const std::string& model,
                    const std::string& door, ActuatorKind kind, BuildingDescription* building);
/// `<world stem>.building.yaml` beside the world file, if that file exists.
std::optional<std::filesystem::path> FindBuildingYamlBeside(const std::filesystem::path& world);

}  // namespace egress::twin
