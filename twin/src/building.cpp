#include "egress/twin/building.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
#include "yaml_field_reader.h"

namespace egress::twin {
namespace {

namespace fs = std::filesystem;

template <typename... Args>
void LoadCheck(bool condition, const Args&... message) {
  if (!condition) throw LoadError(StrCat(message...));
}

// How far behind an actuator's face a wall must be to count as the one it is mounted on [m].
constexpr double kMountProbeDepth = 0.02;
// Largest extent of a box that can be an actuator [m] (a plate is about 0.15 m).
constexpr double kMaxActuatorSize = 0.6;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool Contains(const std::string& text, std::string_view part) {
  return text.find(part) != std::string::npos;
}

// The actuator kind a model's name says, if it says one.
std::optional<ActuatorKind> KindFromName(const std::string& model) {
  const std::string name = Lower(model);
  if (Contains(name, "plate") || Contains(name, "proximity") || Contains(name, "wave"))
    return ActuatorKind::kProximityPlate;
  if (Contains(name, "button") || Contains(name, "push")) return ActuatorKind::kPushButton;
  return std::nullopt;
}

bool Inside(const ShapeDescription& shape, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p_S = shape.X_WS.Inverse() * p_W;
  switch (shape.kind) {
    case ShapeKind::kBox:
      return (p_S.cwiseAbs() - shape.box_size / 2).maxCoeff() <= 0.0;
    case ShapeKind::kCylinder:
      return p_S.head<2>().norm() <= shape.radius && std::abs(p_S.z()) <= shape.length / 2;
    case ShapeKind::kSphere:
      return p_S.norm() <= shape.radius;
    case ShapeKind::kPlane:
      return false;
    case ShapeKind::kMesh: {
      Eigen::Vector3d lo, hi;
      shape.CalcWorldBounds(&lo, &hi);
      return (p_W.array() >= lo.array()).all() && (p_W.array() <= hi.array()).all();
    }
  }
  return false;
}

bool InsideAnyOther(const WorldDescription& world, const std::string& model,
                    const Eigen::Vector3d& p_W) {
  for (const auto& shape : world.shapes) {
    if (shape.model != model && Inside(shape, p_W)) return true;
  }
  return false;
}

// What the building YAML says of one actuator.
struct ActuatorOverride {
  std::optional<std::string> door;
  std::optional<ActuatorKind> kind;
};

struct BuildingYaml {
  std::string source;
  std::vector<BuildingPlace> places;
  std::map<std::string, bool> glass;  // door -> glass
  std::map<std::string, ActuatorOverride> actuators;
  std::string name;
};

BuildingYaml ParseYaml(const WorldDescription& world, const std::string& text,
                       const std::string& source) {
  const FieldReader reader{source};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw LoadError(StrCat(source, ":", e.mark.line + 1, ": not valid YAML: ", e.msg));
  }
  BuildingYaml out;
  out.source = source;
  if (!root || root.IsNull()) return out;
  reader.CheckKeys(root, "", {"name", "places", "doors", "actuators"});
  if (root["name"]) out.name = reader.String(root["name"], "name");
  if (const YAML::Node places = root["places"]) {
    if (!places.IsMap()) reader.Fail(places, "places", "expected a mapping of place names");
    for (const auto& kv : places) {
      const std::string name = reader.Key(kv.first, "places");
      const std::string field = "places." + name;
      reader.CheckKeys(kv.second, field, {"x", "y", "yaw", "yaw_deg", "kind"});
      BuildingPlace place;
      place.name = name;
      place.X_WP.x = reader.Number(reader.Required(kv.second, field, "x"), field + ".x");
      place.X_WP.y = reader.Number(reader.Required(kv.second, field, "y"), field + ".y");
      if (kv.second["yaw"] && kv.second["yaw_deg"])
        reader.Fail(kv.second, field, "give yaw or yaw_deg, not both");
      if (kv.second["yaw"]) {
        place.X_WP.yaw = reader.Number(kv.second["yaw"], field + ".yaw");
        place.has_yaw = true;
      } else if (kv.second["yaw_deg"]) {
        place.X_WP.yaw = reader.Number(kv.second["yaw_deg"], field + ".yaw_deg") * M_PI / 180;
        place.has_yaw = true;
      }
      if (kv.second["kind"]) {
        place.kind = reader.String(kv.second["kind"], field + ".kind");
        if (place.kind != "room" && place.kind != "exit" && place.kind != "table" &&
            place.kind != "post" && place.kind != "place") {
          reader.Fail(kv.second["kind"], field + ".kind",
                      "'" + place.kind + "' is not one of room, exit, table, post, place");
        }
      }
      out.places.push_back(place);
    }
  }
  if (const YAML::Node doors = root["doors"]) {
    if (!doors.IsMap()) reader.Fail(doors, "doors", "expected a mapping of door models");
    for (const auto& kv : doors) {
      const std::string name = reader.Key(kv.first, "doors");
      const std::string field = "doors." + name;
      if (world.FindDoor(name) == nullptr)
        reader.Fail(
            kv.first, field,
            StrCat("the world ", world.source.string(), " has no hinged door model '", name, "'"));
      reader.CheckKeys(kv.second, field, {"glass"});
      if (kv.second["glass"]) out.glass[name] = reader.Bool(kv.second["glass"], field + ".glass");
    }
  }
  if (const YAML::Node actuators = root["actuators"]) {
    if (!actuators.IsMap())
      reader.Fail(actuators, "actuators", "expected a mapping of actuator models");
    for (const auto& kv : actuators) {
      const std::string name = reader.Key(kv.first, "actuators");
      const std::string field = "actuators." + name;
      if (world.ShapesOfModel(name).empty())
        reader.Fail(
            kv.first, field,
            StrCat("the world ", world.source.string(), " has no static model '", name, "'"));
      reader.CheckKeys(kv.second, field, {"door", "type"});
      ActuatorOverride o;
      if (kv.second["door"]) {
        o.door = reader.String(kv.second["door"], field + ".door");
        if (world.FindDoor(*o.door) == nullptr)
          reader.Fail(kv.second["door"], field + ".door",
                      StrCat("the world has no hinged door model '", *o.door, "'"));
      }
      if (kv.second["type"]) {
        const std::string type = reader.String(kv.second["type"], field + ".type");
        if (type == "push") {
          o.kind = ActuatorKind::kPushButton;
        } else if (type == "proximity") {
          o.kind = ActuatorKind::kProximityPlate;
        } else {
          reader.Fail(kv.second["type"], field + ".type",
                      "'" + type + "' is not push or proximity");
        }
      }
      out.actuators[name] = o;
    }
  }
  return out;
}

std::string KindFromPlaceName(const std::string& name) {
  const std::string prefix = Lower(name.substr(0, name.find('_')));
  for (const char* kind : {"room", "exit", "table", "post"}) {
    if (prefix == kind) return kind;
  }
  return "place";
}

// The actuator `model` (its one box) as a face and a facing; `door` for the fallback facing.
BuildingActuator DescribeActuator(const WorldDescription& world, const std::string& model,
                                  ActuatorKind kind, const BuildingDoor& door) {
  const auto shapes = world.ShapesOfModel(model);
  const std::string where = StrCat(world.source.string(), ": actuator model '", model, "'");
  LoadCheck(shapes.size() == 1 && shapes.front()->kind == ShapeKind::kBox, where,
            ": an actuator is one box (its thinnest axis the press direction)");
  const ShapeDescription& box = *shapes.front();
  int k = 0;
  box.box_size.minCoeff(&k);
  Eigen::Vector3d n = box.X_WS.rotation().col(k);
  n.z() = 0.0;
  LoadCheck(n.norm() > 0.7, where,
            ": its thinnest axis is not horizontal; a button or plate is mounted on a wall");
  n.normalize();
  const double half = box.box_size[k] / 2;
  const Eigen::Vector3d centre = box.X_WS.translation();
  const bool wall_ahead = InsideAnyOther(world, model, centre + n * (half + kMountProbeDepth));
  const bool wall_behind = InsideAnyOther(world, model, centre - n * (half + kMountProbeDepth));
  if (wall_ahead && !wall_behind) {
    n = -n;
  } else if (wall_ahead == wall_behind) {
    // Free-standing (or boxed in): face the doorway.
    const Eigen::Vector2d to_door = door.centre() - centre.head<2>();
    if (to_door.dot(n.head<2>()) < 0) n = -n;
  }
  BuildingActuator a;
  a.model = model;
  a.door = door.model;
  a.kind = kind;
  a.n_W = n;
  a.p_W = centre + n * half;
  a.protrusion = 2 * half;
  return a;
}

BuildingDescription Describe(const WorldDescription& world, const BuildingYaml& yaml) {
  BuildingDescription b;
  b.name = yaml.name.empty() ? world.name : yaml.name;
  b.world_source = world.source;
  for (const auto& d : world.doors) {
    BuildingDoor door = DescribeDoor(d);
    if (auto it = yaml.glass.find(d.name); it != yaml.glass.end()) door.glass = it->second;
    b.doors.push_back(door);
  }
  // Actuators: named as such, or listed in the YAML.
  std::vector<std::string> models;
  for (const auto& shape : world.shapes) {
    if (std::find(models.begin(), models.end(), shape.model) != models.end() ||
        world.FindDoor(shape.model) != nullptr) {
      continue;  // a door's frame is not its button
    }
    if (KindFromName(shape.model) || yaml.actuators.count(shape.model) > 0)
      models.push_back(shape.model);
  }
  for (const auto& model : models) {
    const ActuatorOverride o =
        yaml.actuators.count(model) > 0 ? yaml.actuators.at(model) : ActuatorOverride{};
    const auto shapes = world.ShapesOfModel(model);
    Eigen::Vector3d lo, hi;
    shapes.front()->CalcWorldBounds(&lo, &hi);
    if (!o.door && !o.kind && (shapes.size() != 1 || (hi - lo).maxCoeff() > kMaxActuatorSize)) {
      b.notes.push_back(StrCat("model '", model,
                               "' has an actuator's name but not its size (one small box): "
                               "not an actuator"));
      continue;
    }
    const ActuatorKind kind = o.kind ? *o.kind : *KindFromName(model);
    const Eigen::Vector2d p = shapes.front()->X_WS.translation().head<2>();
    BuildingDoor* door = nullptr;
    if (o.door) {
      for (auto& d : b.doors)
        if (d.model == *o.door) door = &d;
    } else {
      double best = kMaxActuatorDistance;
      for (auto& d : b.doors) {
        const double distance = (p - ClosestPointOnSegment(p, d.p_WHinge, d.p_WLatch)).norm();
        if (distance <= best) {
          best = distance;
          door = &d;
        }
      }
    }
    if (door == nullptr) {
      b.notes.push_back(StrCat("actuator model '", model, "': no door within ",
                               kMaxActuatorDistance, " m; it operates nothing"));
      continue;
    }
    b.actuators.push_back(DescribeActuator(world, model, kind, *door));
    door->actuators.push_back(model);
  }
  for (const auto& [name, X_WF] : world.frames) {
    BuildingPlace place;
    place.name = name;
    place.kind = KindFromPlaceName(name);
    place.X_WP = X_WF.ToPose2();
    place.has_yaw = true;
    b.places.push_back(place);
  }
  for (BuildingPlace place : yaml.places) {
    if (place.kind.empty()) place.kind = KindFromPlaceName(place.name);
    auto same = std::find_if(b.places.begin(), b.places.end(),
                             [&](const BuildingPlace& p) { return p.name == place.name; });
    if (same != b.places.end()) {
      *same = place;  // the YAML says more than a frame can
    } else {
      b.places.push_back(place);
    }
  }
  return b;
}

}  // namespace

std::string_view ToString(ActuatorKind kind) {
  return kind == ActuatorKind::kPushButton ? "push" : "proximity";
}

Eigen::Vector2d BuildingDoor::OpeningSideNormal() const {
  const Eigen::Vector2d along = (p_WLatch - p_WHinge).normalized();
  // A leaf turning counter-clockwise about the hinge moves its latch edge to the left of the
  // hinge-to-latch direction.
  return swing_sign * Eigen::Vector2d(-along.y(), along.x());
}

const BuildingDoor* BuildingDescription::FindDoor(const std::string& model) const {
  for (const auto& d : doors)
    if (d.model == model) return &d;
  return nullptr;
}

const BuildingActuator* BuildingDescription::FindActuator(const std::string& model) const {
  for (const auto& a : actuators)
    if (a.model == model) return &a;
  return nullptr;
}

const BuildingPlace* BuildingDescription::FindPlace(const std::string& name) const {
  for (const auto& p : places)
    if (p.name == name) return &p;
  return nullptr;
}

std::string BuildingDescription::PlaceNames() const {
  std::string out;
  for (const auto& p : places)
    out += (out.empty() ? "" : ", ") + p.name;
  return out.empty() ? "(none)" : out;
}

BuildingDoor DescribeDoor(const DoorDescription& d) {
  BuildingDoor door;
  door.model = d.name;
  door.p_WHinge = d.p_WH.head<2>();
  door.p_WLatch = d.CalcFreeEdge(0.0).head<2>();
  door.swing_sign = d.open_sign * (d.axis_W.z() > 0 ? 1.0 : -1.0);  // counter-clockwise = +1
  door.leaf_reach = d.LeafReach();
  door.max_open_angle = d.max_open_angle;
  return door;
}

BuildingDescription DescribeBuildingFromString(const WorldDescription& world,
                                               const std::string& building_yaml,
                                               const std::string& source_name) {
  BuildingDescription b = Describe(world, FieldReader{source_name}.Guard([&] {
    return ParseYaml(world, building_yaml, source_name);
  }));
  b.yaml_source = source_name;
  return b;
}

BuildingDescription DescribeBuilding(const WorldDescription& world,
                                     const std::filesystem::path& building_yaml) {
  if (building_yaml.empty()) return Describe(world, BuildingYaml{});
  return DescribeBuildingFromString(world, ReadTextFile(building_yaml, "building file"),
                                    building_yaml.string());
}

void AssignActuator(const WorldDescription& world, const std::string& model,
                    const std::string& door, ActuatorKind kind, BuildingDescription* building) {
  auto& actuators = building->actuators;
  actuators.erase(std::remove_if(actuators.begin(), actuators.end(),
                                 [&](const BuildingActuator& a) { return a.model == model; }),
                  actuators.end());
  BuildingDoor* target = nullptr;
  for (auto& d : building->doors) {
    auto& list = d.actuators;
    list.erase(std::remove(list.begin(), list.end(), model), list.end());
    if (d.model == door) target = &d;
  }
  LoadCheck(target != nullptr, world.source.string(), ": actuator model '", model,
            "': no hinged door '", door, "'");
  actuators.push_back(DescribeActuator(world, model, kind, *target));
  target->actuators.push_back(model);
}

std::optional<std::filesystem::path> FindBuildingYamlBeside(const std::filesystem::path& world) {
  fs::path candidate = world;
  candidate.replace_extension(".building.yaml");
  std::error_code ec;
  if (fs::is_regular_file(candidate, ec)) return candidate;
  return std::nullopt;
}

}  // namespace egress::twin
