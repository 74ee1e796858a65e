// A scenario and its building: what the scenario leaves out (start and goal poses, door
// actuators, operators of doors it does not list) comes from the building description.

#include <algorithm>

#include "egress/hsr_interface/error.h"
#include "egress/twin/scenario.h"

namespace egress::twin {
namespace {

ActuatorKind KindOf(OperatorKind kind) {
  return kind == OperatorKind::kPushButton ? ActuatorKind::kPushButton
                                           : ActuatorKind::kProximityPlate;
}

const BuildingPlace& Place(const BuildingDescription& building, const Scenario& s,
                           const std::string& name, const char* field) {
  const BuildingPlace* place = building.FindPlace(name);
  if (place == nullptr) {
    throw LoadError(StrCat(s.source.string(), ": field '", field, "': the building has no place '",
                           name, "' (places: ", building.PlaceNames(), ")"));
  }
  return *place;
}

}  // namespace

BuildingDescription DescribeScenarioBuilding(const Scenario& scenario,
                                             const WorldDescription& world) {
  std::filesystem::path yaml = scenario.building_file;
  if (yaml.empty()) {
    if (auto beside = FindBuildingYamlBeside(scenario.world_file)) yaml = *beside;
  }
  BuildingDescription building = DescribeBuilding(world, yaml);
  for (std::size_t i = 0; i < scenario.doors.size(); ++i) {
    const DoorOperatorSpec& spec = scenario.doors[i];
    if (spec.kind == OperatorKind::kManual) continue;
    for (const auto& model : spec.actuators) {
      const BuildingActuator* known = building.FindActuator(model);
      if (known != nullptr && known->door == spec.door && known->kind == KindOf(spec.kind))
        continue;
      try {
        AssignActuator(world, model, spec.door, KindOf(spec.kind), &building);
      } catch (const LoadError& e) {
        throw LoadError(
            StrCat(scenario.source.string(), ": field 'doors[", i, "].actuator': ", e.what()));
      }
    }
  }
  return building;
}

void ApplyBuildingDefaults(const BuildingDescription& building, Scenario* scenario) {
  Scenario& s = *scenario;
  if (!s.start_place.empty()) {
    const BuildingPlace& p = Place(building, s, s.start_place, "robot.start.place");
    s.robot_start = p.X_WP;
  }
  if (!s.goal_place.empty()) s.goal = Place(building, s, s.goal_place, "robot.goal.place").X_WP;
  for (std::size_t i = 0; i < s.doors.size(); ++i) {
    DoorOperatorSpec& spec = s.doors[i];
    const BuildingDoor* door = building.FindDoor(spec.door);
    if (door == nullptr) continue;  // ValidateAgainst names it
    if (!spec.glass_given) spec.glass = door->glass;
    if (spec.kind == OperatorKind::kManual || !spec.actuators.empty()) continue;
    for (const auto& model : door->actuators) {
      if (building.FindActuator(model)->kind == KindOf(spec.kind)) spec.actuators.push_back(model);
    }
    if (spec.actuators.empty()) {
      throw LoadError(StrCat(s.source.string(), ": field 'doors[", i, "].actuator': door '",
                             spec.door, "' has no ",
                             spec.kind == OperatorKind::kPushButton ? "push button" : "plate",
                             " in the building; name its actuator"));
    }
  }
  for (const BuildingDoor& door : building.doors) {
    const bool listed = std::any_of(s.doors.begin(), s.doors.end(), [&](const DoorOperatorSpec& d) {
      return d.door == door.model;
    });
    if (listed || door.actuators.empty()) continue;
    DoorOperatorSpec spec;
    spec.door = door.model;
    spec.glass = door.glass;
    spec.actuators = door.actuators;
    const ActuatorKind kind = building.FindActuator(door.actuators.front())->kind;
    for (const auto& model : door.actuators) {
      if (building.FindActuator(model)->kind != kind) {
        throw LoadError(StrCat(
            s.source.string(), ": door '", door.model,
            "' has both push buttons and plates; the twin's operator has one kind: list the door "
            "under 'doors' with the actuators of one kind"));
      }
    }
    spec.kind = kind == ActuatorKind::kPushButton ? OperatorKind::kPushButton
                                                  : OperatorKind::kProximityPlate;
    s.doors.push_back(spec);
  }
}

}  // namespace egress::twin
