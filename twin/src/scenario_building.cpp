// A scenario and its building: what the scenario leaves out (start and goal poses, door
// actuators, operators of doors it does not list) comes from the building description.

#include <algorithm>

#include "egress/hsr_interface/error.h"
#include "egress/twin/scenario.h"
#include "seeds.h"

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

// The random stream of a family's variant (the run's own streams are 1-5 and 101-104).
constexpr std::uint64_t kVariantStream = 7;

std::string Pick(const std::vector<std::string>& names, std::mt19937_64& rng,
                 const std::string& other = "") {
  std::vector<std::string> options;
  for (const auto& n : names)
    if (n != other) options.push_back(n);
  if (options.empty()) options = names;
  return options[std::uniform_int_distribution<std::size_t>(0, options.size() - 1)(rng)];
}

}  // namespace

bool RandomizeSpec::DrawsVariants() const {
  return !start_places.empty() || !goal_places.empty() || !person_places.empty() ||
         open_doors > 0.0 || obstacle_xy > 0.0;
}

Scenario DrawScenarioVariant(const Scenario& scenario, const BuildingDescription& building,
                             std::uint64_t seed) {
  const RandomizeSpec& z = scenario.randomize;
  if (!z.DrawsVariants()) return scenario;
  Scenario v = scenario;
  std::mt19937_64 rng(DeriveSeed(seed, kVariantStream));
  const auto check = [&](const std::vector<std::string>& names, const char* field) {
    for (const auto& name : names)
      Place(building, scenario, name, field);
  };
  check(z.start_places, "randomize.start_places");
  check(z.goal_places, "randomize.goal_places");
  check(z.person_places, "randomize.person_places");
  if (!z.start_places.empty()) v.start_place = Pick(z.start_places, rng);
  if (!z.goal_places.empty()) v.goal_place = Pick(z.goal_places, rng, v.start_place);
  if (!v.start_place.empty()) v.robot_start = building.FindPlace(v.start_place)->X_WP;
  if (!v.goal_place.empty()) v.goal = building.FindPlace(v.goal_place)->X_WP;
  for (auto& person : v.people) {
    if (z.person_places.size() < 2) break;
    const std::string from = Pick(z.person_places, rng);
    const std::string to = Pick(z.person_places, rng, from);
    person.start = building.FindPlace(from)->X_WP.translation();
    person.goal = building.FindPlace(to)->X_WP.translation();
    person.via.clear();
  }
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (auto& door : v.doors) {
    if (door.kind != OperatorKind::kManual && unit(rng) < z.open_doors)
      door.open_at.insert(door.open_at.begin(), 0.0);
  }
  for (auto& obstacle : v.obstacles) {
    const double dx = (2 * unit(rng) - 1) * z.obstacle_xy, dy = (2 * unit(rng) - 1) * z.obstacle_xy;
    const Eigen::Vector3d p = obstacle.X_WS.translation() + Eigen::Vector3d(dx, dy, 0.0);
    obstacle.X_WS = Pose3(obstacle.X_WS.rotation(), p);
  }
  // The variant is concrete: it draws nothing more itself.
  v.randomize.start_places.clear();
  v.randomize.goal_places.clear();
  v.randomize.person_places.clear();
  v.randomize.open_doors = 0.0;
  v.randomize.obstacle_xy = 0.0;
  return v;
}

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
