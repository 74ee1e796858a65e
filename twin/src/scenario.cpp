#include "egress/twin/scenario.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
#include "egress/twin/mobility.h"
#include "people/approach_and_wait.h"
#include "people/evacuate.h"
#include "people/hold_door.h"
#include "people/walk_past.h"
#include "scenario_faults.h"
#include "scenario_poses.h"
#include "scenario_sensors.h"
#include "yaml_field_reader.h"

namespace egress::twin {
namespace {
// A simulated run is bounded: a day of simulated time is far past any scenario's need.
constexpr double kMaxTimeLimitSec = 86400.0;
}  // namespace

namespace {

constexpr double kDegToRad = M_PI / 180.0;

OperatorKind ParseOperator(const FieldReader& r, const YAML::Node& node, const std::string& field) {
  const std::string s = r.String(node, field);
  if (s == "push") return OperatorKind::kPushButton;
  if (s == "proximity") return OperatorKind::kProximityPlate;
  if (s == "manual") return OperatorKind::kManual;
  r.Fail(node, field, "'" + s + "' is not an operator (push, proximity, manual)");
}

PersonBehavior ParseBehavior(const FieldReader& r, const YAML::Node& node,
                             const std::string& field) {
  const std::string s = r.String(node, field);
  for (auto b :
       {PersonBehavior::kCrossDoorway, PersonBehavior::kHoldDoor, PersonBehavior::kWalkPast,
        PersonBehavior::kApproachAndWait, PersonBehavior::kEvacuate}) {
    if (s == ToString(b)) return b;
  }
  r.Fail(node, field,
         "'" + s +
             "' is not a behavior (cross_doorway, hold_door, walk_past, approach_and_wait, "
             "evacuate)");
}

TriggerSpec ParseTrigger(const FieldReader& r, const YAML::Node& node, const std::string& field) {
  r.CheckKeys(node, field, {"at", "robot_within", "event"});
  if (node.size() != 1) r.Fail(node, field, "give exactly one of at, robot_within, event");
  TriggerSpec t;
  if (node["at"]) {
    t.kind = TriggerSpec::Kind::kAtTime;
    t.value = r.NonNegative(node["at"], field + ".at");
  } else if (node["robot_within"]) {
    t.kind = TriggerSpec::Kind::kRobotWithin;
    t.value = r.Positive(node["robot_within"], field + ".robot_within");
  } else {
    t.kind = TriggerSpec::Kind::kEvent;
    t.event = r.String(node["event"], field + ".event");
    const auto colon = t.event.find(':');
    const std::string kind = t.event.substr(0, colon);
    if (colon == std::string::npos || (kind != "button_pressed" && kind != "door_opened" &&
                                       kind != "door_closed" && kind != "person_started")) {
      r.Fail(node["event"], field + ".event",
             "expected button_pressed:<door>, door_opened:<door>, door_closed:<door> or "
             "person_started:<name>");
    }
  }
  return t;
}

ShapeDescription ParseObstacle(const FieldReader& r, const YAML::Node& node,
                               const std::string& field, int index) {
  r.CheckKeys(node, field, {"name", "box", "cylinder", "x", "y", "z", "yaw"});
  ShapeDescription s;
  s.model =
      node["name"] ? r.String(node["name"], field + ".name") : "obstacle_" + std::to_string(index);
  s.link = "link";
  s.collision = "collision";
  const double yaw = node["yaw"] ? r.Number(node["yaw"], field + ".yaw") : 0.0;
  Eigen::Vector3d p(r.Number(r.Required(node, field, "x"), field + ".x"),
                    r.Number(r.Required(node, field, "y"), field + ".y"), 0.0);
  if (node["box"]) {
    const YAML::Node b = node["box"];
    if (!b.IsSequence() || b.size() != 3)
      r.Fail(b, field + ".box", "expected [size_x, size_y, size_z]");
    s.kind = ShapeKind::kBox;
    for (int i = 0; i < 3; ++i)
      s.box_size[i] = r.Positive(b[i], field + ".box[" + std::to_string(i) + "]");
    p.z() = s.box_size.z() / 2;
  } else if (node["cylinder"]) {
    const YAML::Node c = node["cylinder"];
    if (!c.IsSequence() || c.size() != 2)
      r.Fail(c, field + ".cylinder", "expected [radius, height]");
    s.kind = ShapeKind::kCylinder;
    s.radius = r.Positive(c[0], field + ".cylinder[0]");
    s.length = r.Positive(c[1], field + ".cylinder[1]");
    p.z() = s.length / 2;
  } else {
    r.Fail(node, field, "give box: [sx, sy, sz] or cylinder: [radius, height]");
  }
  if (node["z"]) p.z() = r.Number(node["z"], field + ".z");
  s.X_WS = Pose3::FromPose2({p.x(), p.y(), yaw});
  s.X_WS = Pose3(s.X_WS.rotation(), p);
  return s;
}

PredicateSpec ParsePredicate(const FieldReader& r, const YAML::Node& node,
                             const std::string& field) {
  PredicateSpec p;
  using K = PredicateSpec::Kind;
  if (node.IsScalar()) {
    const std::string s = node.Scalar();
    if (s == "reach_goal")
      p.kind = K::kReachGoal;
    else if (s == "no_person_contact")
      p.kind = K::kNoPersonContact;
    else if (s == "no_door_strike")
      p.kind = K::kNoDoorStrike;
    else if (s == "within_time_limit")
      p.kind = K::kWithinTimeLimit;
    else
      r.Fail(node, field,
             "'" + s +
                 "' is not a predicate without arguments (reach_goal, "
                 "no_person_contact, no_door_strike, within_time_limit)");
    return p;
  }
  if (!node.IsMap() || node.size() != 1) r.Fail(node, field, "expected one predicate");
  const std::string key = r.Key(node.begin()->first, field);
  const YAML::Node value = node.begin()->second;
  const std::string sub = field + "." + key;
  if (key == "cross_door" || key == "door_open_when_crossed" || key == "button_pressed" ||
      key == "button_not_pressed") {
    p.kind = key == "cross_door"               ? K::kCrossDoor
             : key == "door_open_when_crossed" ? K::kDoorOpenWhenCrossed
             : key == "button_pressed"         ? K::kButtonPressed
                                               : K::kButtonNotPressed;
    p.door = r.String(value, sub);
  } else if (key == "no_contact_with") {
    p.kind = K::kNoContactWith;
    p.model = r.String(value, sub);
  } else if (key == "payload_held") {
    p.kind = K::kPayloadHeld;
    p.payload = r.String(value, sub);
  } else if (key == "payload_delivered") {
    p.kind = K::kPayloadDelivered;
    r.CheckKeys(value, sub, {"payload", "x", "y", "radius", "min_z"});
    p.payload = r.String(r.Required(value, sub, "payload"), sub + ".payload");
    p.target = {r.Number(r.Required(value, sub, "x"), sub + ".x"),
                r.Number(r.Required(value, sub, "y"), sub + ".y")};
    if (value["radius"]) p.radius = r.Positive(value["radius"], sub + ".radius");
    if (value["min_z"]) p.min_z = r.Number(value["min_z"], sub + ".min_z");
  } else {
    r.Fail(node, field,
           "'" + key +
               "' is not a predicate (reach_goal, cross_door, "
               "door_open_when_crossed, button_pressed, button_not_pressed, "
               "payload_held, payload_delivered, no_person_contact, no_door_strike, "
               "no_contact_with, within_time_limit)");
  }
  return p;
}

Scenario Parse(const YAML::Node& root, const FieldReader& r,
               const std::filesystem::path& base_dir) {
  r.CheckKeys(root, "",
              {"name", "world", "building", "seed", "time_limit", "robot", "doors", "people",
               "payloads", "obstacles", "randomize", "success", "sensors", "faults", "mission"});
  Scenario s;
  s.name = root["name"] ? r.String(root["name"], "name") : std::string();
  const std::string world = r.String(r.Required(root, "", "world"), "world");
  s.world_file =
      std::filesystem::path(world).is_absolute() ? std::filesystem::path(world) : base_dir / world;
  if (!PathExists(s.world_file)) {
    r.Fail(root["world"], "world", "no such file: " + s.world_file.string());
  }
  if (root["building"]) {
    const std::string building = r.String(root["building"], "building");
    s.building_file = std::filesystem::path(building).is_absolute()
                          ? std::filesystem::path(building)
                          : base_dir / building;
    if (!PathExists(s.building_file))
      r.Fail(root["building"], "building", "no such file: " + s.building_file.string());
  }
  if (root["seed"]) {
    const double seed = r.NonNegative(root["seed"], "seed");
    if (seed != std::floor(seed)) r.Fail(root["seed"], "seed", "must be a whole number");
    // Seeds are read as doubles: above 2^53 they are no longer exact (and past 2^64 the
    // conversion was undefined).
    if (seed > double(kMaxScenarioSeed)) r.Fail(root["seed"], "seed", "must be at most 2^53");
    s.seed = std::uint64_t(seed);
  }
  if (root["time_limit"]) {
    s.time_limit = r.Positive(root["time_limit"], "time_limit");
    if (s.time_limit > kMaxTimeLimitSec)
      r.Fail(root["time_limit"], "time_limit", StrCat("must be at most ", kMaxTimeLimitSec, " s"));
  }

  const YAML::Node robot = r.Required(root, "", "robot");
  r.CheckKeys(robot, "robot", {"start", "goal", "off_scene"});
  if (robot["off_scene"]) s.robot_off_scene = r.Bool(robot["off_scene"], "robot.off_scene");
  if (s.robot_off_scene) {
    if (robot["start"] || robot["goal"])
      r.Fail(robot, "robot", "a robot off the scene has no start or goal");
  } else if (const YAML::Node start = r.Required(robot, "robot", "start"); start["place"]) {
    r.CheckKeys(start, "robot.start", {"place"});
    s.start_place = r.String(start["place"], "robot.start.place");
  } else {
    s.robot_start = r.ReadPose2(start, "robot.start");
  }
  if (const YAML::Node goal = robot["goal"]; goal && goal["place"]) {
    r.CheckKeys(goal, "robot.goal", {"place", "tolerance"});
    s.goal_place = r.String(goal["place"], "robot.goal.place");
    if (goal["tolerance"]) s.goal_tolerance = r.Positive(goal["tolerance"], "robot.goal.tolerance");
  } else if (goal) {
    r.CheckKeys(goal, "robot.goal", {"x", "y", "yaw", "yaw_deg", "tolerance"});
    Pose2 g;
    g.x = r.Number(r.Required(goal, "robot.goal", "x"), "robot.goal.x");
    g.y = r.Number(r.Required(goal, "robot.goal", "y"), "robot.goal.y");
    if (goal["yaw"]) g.yaw = r.Number(goal["yaw"], "robot.goal.yaw");
    if (goal["yaw_deg"]) g.yaw = r.Number(goal["yaw_deg"], "robot.goal.yaw_deg") * kDegToRad;
    s.goal = g;
    if (goal["tolerance"]) s.goal_tolerance = r.Positive(goal["tolerance"], "robot.goal.tolerance");
  }

  if (const YAML::Node doors = root["doors"]) {
    if (!doors.IsSequence()) r.Fail(doors, "doors", "expected a list");
    for (std::size_t i = 0; i < doors.size(); ++i) {
      const std::string f = "doors[" + std::to_string(i) + "]";
      const YAML::Node d = doors[i];
      r.CheckKeys(d, f,
                  {"door", "operator", "actuator", "glass", "open_angle_deg", "open_time_s",
                   "hold_open_s", "close_time_s", "latch_time_s", "stall_force", "button_stroke",
                   "button_max_force", "proximity_range", "open_at"});
      DoorOperatorSpec op;
      op.door = r.String(r.Required(d, f, "door"), f + ".door");
      op.kind = ParseOperator(r, r.Required(d, f, "operator"), f + ".operator");
      if (const YAML::Node a = d["actuator"]; a && op.kind == OperatorKind::kManual) {
        r.Fail(a, f + ".actuator", "a manual door has no actuator");
      } else if (a) {  // else the building's actuators of the door
        if (a.IsSequence()) {
          if (a.size() == 0) r.Fail(a, f + ".actuator", "expected at least one actuator");
          for (std::size_t k = 0; k < a.size(); ++k)
            op.actuators.push_back(r.String(a[k], StrCat(f, ".actuator[", k, "]")));
        } else {
          op.actuators.push_back(r.String(a, f + ".actuator"));
        }
      }
      if (d["glass"]) {
        op.glass = r.Bool(d["glass"], f + ".glass");
        op.glass_given = true;
      }
      auto& t = op.timing;
      if (d["open_angle_deg"])
        t.open_angle_deg = r.Positive(d["open_angle_deg"], f + ".open_angle_deg");
      if (d["open_time_s"]) t.open_time_s = r.Positive(d["open_time_s"], f + ".open_time_s");
      if (d["hold_open_s"]) t.hold_open_s = r.NonNegative(d["hold_open_s"], f + ".hold_open_s");
      if (d["close_time_s"]) t.close_time_s = r.Positive(d["close_time_s"], f + ".close_time_s");
      if (d["latch_time_s"]) t.latch_time_s = r.Positive(d["latch_time_s"], f + ".latch_time_s");
      if (d["stall_force"]) t.stall_force = r.Positive(d["stall_force"], f + ".stall_force");
      if (d["button_stroke"])
        op.button_stroke = r.Positive(d["button_stroke"], f + ".button_stroke");
      if (d["button_max_force"])
        op.button_max_force = r.Positive(d["button_max_force"], f + ".button_max_force");
      if (d["proximity_range"])
        op.proximity_range = r.Positive(d["proximity_range"], f + ".proximity_range");
      if (const YAML::Node at = d["open_at"]) {
        if (!at.IsSequence()) r.Fail(at, f + ".open_at", "expected a list of times [s]");
        for (std::size_t k = 0; k < at.size(); ++k) {
          op.open_at.push_back(r.NonNegative(at[k], f + ".open_at[" + std::to_string(k) + "]"));
        }
      }
      if (t.open_angle_deg > 180.0)
        r.Fail(d["open_angle_deg"], f + ".open_angle_deg", "must be at most 180");
      for (const auto& other : s.doors) {
        if (other.door == op.door)
          r.Fail(d["door"], f + ".door", "door '" + op.door + "' is listed twice");
      }
      s.doors.push_back(std::move(op));
    }
  }

  if (const YAML::Node people = root["people"]) {
    if (!people.IsSequence()) r.Fail(people, "people", "expected a list");
    for (std::size_t i = 0; i < people.size(); ++i) {
      const std::string f = "people[" + std::to_string(i) + "]";
      const YAML::Node n = people[i];
      r.CheckKeys(
          n, f,
          {"name", "behavior", "start", "goal", "via", "door", "speed", "trigger", "hold_angle_deg",
           "hold_duration", "wait_s", "count", "radius", "mobility", "route", "leave"});
      PersonSpec p;
      p.name = n["name"] ? r.String(n["name"], f + ".name") : "person_" + std::to_string(i);
      p.behavior = ParseBehavior(r, r.Required(n, f, "behavior"), f + ".behavior");
      p.start = r.Point(r.Required(n, f, "start"), f + ".start");
      p.goal = n["goal"] ? r.Point(n["goal"], f + ".goal") : p.start;
      if (const YAML::Node via = n["via"]) {
        if (!via.IsSequence()) r.Fail(via, f + ".via", "expected a list of points");
        for (std::size_t k = 0; k < via.size(); ++k) {
          p.via.push_back(r.Point(via[k], f + ".via[" + std::to_string(k) + "]"));
        }
      }
      if (n["door"]) p.door = r.String(n["door"], f + ".door");
      if (n["leave"]) {
        if (p.behavior != PersonBehavior::kApproachAndWait)
          r.Fail(n["leave"], f + ".leave",
                 "is for approach_and_wait only (where to go after the wait)");
        p.leave = r.Point(n["leave"], f + ".leave");
      }
      if (const YAML::Node route = n["route"]) {
        if (!route.IsSequence() || route.size() == 0)
          r.Fail(route, f + ".route", "expected a list of door names (the exit route, in order)");
        for (std::size_t k = 0; k < route.size(); ++k)
          p.route_doors.push_back(r.String(route[k], f + ".route[" + std::to_string(k) + "]"));
        if (p.door.empty()) p.door = p.route_doors.front();
      }
      if (const YAML::Node mobility = n["mobility"]) {
        if (!mobility.IsMap() || mobility.size() == 0)
          r.Fail(mobility, f + ".mobility", "expected a map of mobility class -> share");
        double total = 0.0;
        for (const auto& entry : mobility) {
          const std::string name = r.String(entry.first, f + ".mobility");
          if (FindMobilityClass(name) == nullptr)
            r.Fail(entry.first, f + ".mobility." + name,
                   "is not a mobility class (" + MobilityClassNames() + ")");
          const double share = r.NonNegative(entry.second, f + ".mobility." + name);
          total += share;
          p.mobility.emplace_back(name, share);
        }
        if (!(total > 0.0)) r.Fail(mobility, f + ".mobility", "the shares must not all be 0");
      }
      if ((!p.route_doors.empty() || !p.mobility.empty()) &&
          p.behavior != PersonBehavior::kEvacuate)
        r.Fail(n, f, "route and mobility are for behavior evacuate");
      const bool needs_door = p.behavior == PersonBehavior::kCrossDoorway ||
                              p.behavior == PersonBehavior::kHoldDoor ||
                              p.behavior == PersonBehavior::kEvacuate;
      if (needs_door && p.door.empty())
        r.Fail(n, f + ".door", "is required for " + std::string(ToString(p.behavior)));
      if (!n["goal"] && p.behavior != PersonBehavior::kApproachAndWait &&
          p.behavior != PersonBehavior::kHoldDoor) {
        r.Fail(n, f + ".goal", "is required for " + std::string(ToString(p.behavior)));
      }
      if (n["speed"]) {
        p.speed = r.ReadRange(n["speed"], f + ".speed");
        if (!(p.speed.min > 0.0) || p.speed.max > 3.0)
          r.Fail(n["speed"], f + ".speed", "must be within (0, 3] m/s");
      }
      if (n["trigger"]) p.trigger = ParseTrigger(r, n["trigger"], f + ".trigger");
      if (n["hold_angle_deg"])
        p.hold_angle_deg = r.Positive(n["hold_angle_deg"], f + ".hold_angle_deg");
      if (n["hold_duration"])
        p.hold_duration = r.NonNegative(n["hold_duration"], f + ".hold_duration");
      if (n["wait_s"]) p.hold_duration = r.NonNegative(n["wait_s"], f + ".wait_s");
      if (n["count"]) {
        const double count = r.Positive(n["count"], f + ".count");
        if (count != std::floor(count) || count > 200)
          r.Fail(n["count"], f + ".count", "must be a whole number up to 200");
        p.count = int(count);
      }
      if (n["radius"]) p.radius = r.Positive(n["radius"], f + ".radius");
      s.people.push_back(std::move(p));
    }
  }

  if (const YAML::Node payloads = root["payloads"]) {
    if (!payloads.IsSequence()) r.Fail(payloads, "payloads", "expected a list");
    for (std::size_t i = 0; i < payloads.size(); ++i) {
      const std::string f = "payloads[" + std::to_string(i) + "]";
      const YAML::Node n = payloads[i];
      r.CheckKeys(n, f, {"name", "kind", "x", "y", "z", "yaw"});
      PayloadSpec p;
      p.name = r.String(r.Required(n, f, "name"), f + ".name");
      const std::string kind = r.String(r.Required(n, f, "kind"), f + ".kind");
      if (kind == "water_bottle")
        p.kind = PayloadKind::kWaterBottle;
      else if (kind == "flashlight")
        p.kind = PayloadKind::kFlashlight;
      else
        r.Fail(n["kind"], f + ".kind",
               "'" + kind + "' is not a payload (water_bottle, flashlight)");
      const Eigen::Vector3d xyz(r.Number(r.Required(n, f, "x"), f + ".x"),
                                r.Number(r.Required(n, f, "y"), f + ".y"),
                                r.Number(r.Required(n, f, "z"), f + ".z"));
      const double yaw = n["yaw"] ? r.Number(n["yaw"], f + ".yaw") : 0.0;
      p.X_WP = Pose3(Pose3::FromPose2({0, 0, yaw}).rotation(), xyz);
      for (const auto& other : s.payloads) {
        if (other.name == p.name)
          r.Fail(n["name"], f + ".name", "payload '" + p.name + "' is listed twice");
      }
      s.payloads.push_back(std::move(p));
    }
  }

  if (const YAML::Node obstacles = root["obstacles"]) {
    if (!obstacles.IsSequence()) r.Fail(obstacles, "obstacles", "expected a list");
    for (std::size_t i = 0; i < obstacles.size(); ++i) {
      s.obstacles.push_back(
          ParseObstacle(r, obstacles[i], "obstacles[" + std::to_string(i) + "]", int(i)));
    }
  }

  if (const YAML::Node rnd = root["randomize"]) {
    const std::string f = "randomize";
    r.CheckKeys(rnd, f,
                {"robot_dx", "robot_dy", "robot_dyaw", "payload_xy", "hold_open_s",
                 "hold_angle_deg", "person_delay_s", "person_speed_scale", "start_places",
                 "goal_places", "person_places", "open_doors", "obstacle_xy"});
    auto& z = s.randomize;
    if (rnd["robot_dx"]) z.robot_dx = r.ReadRange(rnd["robot_dx"], f + ".robot_dx");
    if (rnd["robot_dy"]) z.robot_dy = r.ReadRange(rnd["robot_dy"], f + ".robot_dy");
    if (rnd["robot_dyaw"]) z.robot_dyaw = r.ReadRange(rnd["robot_dyaw"], f + ".robot_dyaw");
    if (rnd["payload_xy"]) z.payload_xy = r.NonNegative(rnd["payload_xy"], f + ".payload_xy");
    const auto names = [&](const char* key, std::size_t at_least) {
      std::vector<std::string> out;
      const YAML::Node list = rnd[key];
      if (!list) return out;
      const std::string field = f + "." + key;
      if (!list.IsSequence() || list.size() < at_least)
        r.Fail(list, field, StrCat("expected a list of at least ", at_least, " place names"));
      for (std::size_t k = 0; k < list.size(); ++k)
        out.push_back(r.String(list[k], StrCat(field, "[", k, "]")));
      return out;
    };
    z.start_places = names("start_places", 1);
    z.goal_places = names("goal_places", 1);
    z.person_places = names("person_places", 2);
    if (z.start_places.size() == 1 && z.goal_places.size() == 1 &&
        z.start_places[0] == z.goal_places[0]) {
      r.Fail(rnd["goal_places"], f + ".goal_places", "the only goal is the only start");
    }
    if (rnd["open_doors"]) z.open_doors = r.Fraction(rnd["open_doors"], f + ".open_doors");
    if (rnd["obstacle_xy"]) z.obstacle_xy = r.NonNegative(rnd["obstacle_xy"], f + ".obstacle_xy");
    if (rnd["hold_open_s"]) z.hold_open_s = r.ReadRange(rnd["hold_open_s"], f + ".hold_open_s");
    if (rnd["hold_angle_deg"]) {
      z.hold_angle_deg = r.ReadRange(rnd["hold_angle_deg"], f + ".hold_angle_deg");
      if (!(z.hold_angle_deg.min > 0 && z.hold_angle_deg.max <= 90))
        r.Fail(rnd["hold_angle_deg"], f + ".hold_angle_deg", "must lie in (0, 90] degrees");
    }
    if (rnd["person_delay_s"])
      z.person_delay_s = r.ReadRange(rnd["person_delay_s"], f + ".person_delay_s");
    if (rnd["person_speed_scale"]) {
      z.person_speed_scale = r.ReadRange(rnd["person_speed_scale"], f + ".person_speed_scale");
      if (!(z.person_speed_scale.min > 0))
        r.Fail(rnd["person_speed_scale"], f + ".person_speed_scale", "must be positive");
    }
    if (z.hold_open_s.min < 0)
      r.Fail(rnd["hold_open_s"], f + ".hold_open_s", "must not be negative");
    if (z.person_delay_s.min < 0)
      r.Fail(rnd["person_delay_s"], f + ".person_delay_s", "must not be negative");
  }

  if (const YAML::Node success = root["success"]) {
    if (!success.IsSequence()) r.Fail(success, "success", "expected a list of predicates");
    for (std::size_t i = 0; i < success.size(); ++i) {
      s.success.push_back(ParsePredicate(r, success[i], "success[" + std::to_string(i) + "]"));
      if (s.success.back().kind == PredicateSpec::Kind::kReachGoal && !s.goal &&
          s.goal_place.empty()) {
        r.Fail(success[i], "success[" + std::to_string(i) + "]", "reach_goal needs robot.goal");
      }
    }
  }
  if (const YAML::Node sensors = root["sensors"]) ParseSensors(r, sensors, &s.sensors);
  if (const YAML::Node faults = root["faults"]) s.faults = ParseFaults(r, faults);
  if (const YAML::Node mission = root["mission"]) {
    r.CheckKeys(mission, "mission", {"tree", "main", "blackboard"});
    MissionSpec m;
    const YAML::Node tree = r.Required(mission, "mission", "tree");
    const std::filesystem::path file = r.String(tree, "mission.tree");
    m.tree_file = file.is_absolute() ? file : base_dir / file;
    m.tree_line = tree.Mark().line + 1;
    if (!PathExists(m.tree_file))
      r.Fail(tree, "mission.tree", "no such file: " + m.tree_file.string());
    if (mission["main"]) m.tree_id = r.String(mission["main"], "mission.main");
    if (const YAML::Node bb = mission["blackboard"]) {
      if (!bb.IsMap()) r.Fail(bb, "mission.blackboard", "expected a mapping of key: value");
      for (const auto& kv : bb) {
        const std::string key = r.Key(kv.first, "mission.blackboard");
        if (!kv.second.IsScalar())
          r.Fail(kv.second, "mission.blackboard." + key, "expected a scalar value");
        m.blackboard[key] = kv.second.Scalar();
      }
    }
    s.mission = std::move(m);
  }
  return s;
}

}  // namespace

double Range::Sample(std::mt19937_64& rng) const {
  if (max <= min) return min;
  return std::uniform_real_distribution<double>(min, max)(rng);
}

namespace people {

std::unique_ptr<PersonBehaviorModel> MakePersonBehavior(PersonBehavior kind) {
  switch (kind) {
    case PersonBehavior::kCrossDoorway:
      return std::make_unique<CrossDoorway>();
    case PersonBehavior::kHoldDoor:
      return std::make_unique<HoldDoor>();
    case PersonBehavior::kWalkPast:
      return std::make_unique<WalkPast>();
    case PersonBehavior::kApproachAndWait:
      return std::make_unique<ApproachAndWait>();
    case PersonBehavior::kEvacuate:
      return std::make_unique<Evacuate>();
  }
  throw InvalidArgument(StrCat("unknown people behaviour ", int(kind)));
}

}  // namespace people

std::string_view ToString(PersonBehavior behavior) {
  switch (behavior) {
    case PersonBehavior::kCrossDoorway:
      return "cross_doorway";
    case PersonBehavior::kHoldDoor:
      return "hold_door";
    case PersonBehavior::kWalkPast:
      return "walk_past";
    case PersonBehavior::kApproachAndWait:
      return "approach_and_wait";
    case PersonBehavior::kEvacuate:
      return "evacuate";
  }
  return "unknown";
}

std::string_view ToString(PayloadKind kind) {
  return kind == PayloadKind::kWaterBottle ? "water_bottle" : "flashlight";
}

std::string ToString(const PredicateSpec& p) {
  using K = PredicateSpec::Kind;
  switch (p.kind) {
    case K::kReachGoal:
      return "reach_goal";
    case K::kCrossDoor:
      return "cross_door:" + p.door;
    case K::kDoorOpenWhenCrossed:
      return "door_open_when_crossed:" + p.door;
    case K::kButtonPressed:
      return "button_pressed:" + p.door;
    case K::kButtonNotPressed:
      return "button_not_pressed:" + p.door;
    case K::kPayloadHeld:
      return "payload_held:" + p.payload;
    case K::kPayloadDelivered:
      return "payload_delivered:" + p.payload;
    case K::kNoPersonContact:
      return "no_person_contact";
    case K::kNoDoorStrike:
      return "no_door_strike";
    case K::kNoContactWith:
      return "no_contact_with:" + p.model;
    case K::kWithinTimeLimit:
      return "within_time_limit";
  }
  return "unknown";
}

void Scenario::ValidateAgainst(const WorldDescription& world) const {
  const std::string where = source.string();
  if (!robot_off_scene) CheckOnTheFloor(world, where, "robot.start", start_place, robot_start);
  if (goal) CheckOnTheFloor(world, where, "robot.goal", goal_place, *goal);
  for (std::size_t i = 0; i < doors.size(); ++i) {
    const auto& op = doors[i];
    const std::string f = StrCat(where, ": field 'doors[", i, "]");
    if (world.FindDoor(op.door) == nullptr) {
      throw LoadError(
          StrCat(f, ".door': world ", world_file.string(), " has no hinged door '", op.door, "'"));
    }
    if (op.kind != OperatorKind::kManual && op.actuators.empty()) {
      throw LoadError(StrCat(f, ".actuator': door '", op.door,
                             "' has an operator but no actuator (name one, or give the building "
                             "one the building description finds)"));
    }
    for (const auto& actuator : op.actuators) {
      const auto shapes = world.ShapesOfModel(actuator);
      if (shapes.size() != 1 || shapes.front()->kind != ShapeKind::kBox) {
        throw LoadError(StrCat(f, ".actuator': world ", world_file.string(), " has no model '",
                               actuator, "' with exactly one box collision"));
      }
    }
  }
  auto known_door = [&](const std::string& name) {
    for (const auto& d : world.doors) {
      if (d.name == name) return true;
    }
    return false;
  };
  for (const FaultSpec& fault : faults) {
    if (!fault.door.empty() && !known_door(fault.door)) {
      throw LoadError(StrCat(where, ":", fault.line, ": field 'faults': world ",
                             world_file.string(), " has no hinged door '", fault.door, "'"));
    }
  }
  for (std::size_t i = 0; i < people.size(); ++i) {
    // Where they start and walk: a person placed inside a wall or 100 m off stands there, or is
    // "left behind", until the time limit, and nothing says why.
    const PersonSpec& person = people[i];
    const auto on_floor = [&](const std::string& field, const Eigen::Vector2d& p_W) {
      CheckOnTheFloor(world, where, StrCat("people[", i, "].", field), "", {p_W.x(), p_W.y(), 0.0});
    };
    on_floor("start", person.start);
    on_floor("goal", person.goal);
    for (std::size_t k = 0; k < person.via.size(); ++k)
      on_floor(StrCat("via[", k, "]"), person.via[k]);
    if (person.leave) on_floor("leave", *person.leave);
    if (!people[i].door.empty() && !known_door(people[i].door)) {
      throw LoadError(StrCat(where, ": field 'people[", i, "].door': world has no door '",
                             people[i].door, "'"));
    }
    for (std::size_t k = 0; k < people[i].route_doors.size(); ++k) {
      if (!known_door(people[i].route_doors[k]))
        throw LoadError(StrCat(where, ": field 'people[", i, "].route[", k,
                               "]': world has no door '", people[i].route_doors[k], "'"));
    }
  }
  for (std::size_t i = 0; i < success.size(); ++i) {
    const auto& p = success[i];
    if (!p.door.empty() && !known_door(p.door)) {
      throw LoadError(
          StrCat(where, ": field 'success[", i, "]': world has no door '", p.door, "'"));
    }
    if (!p.payload.empty()) {
      bool found = false;
      for (const auto& pl : payloads)
        found = found || pl.name == p.payload;
      if (!found)
        throw LoadError(StrCat(where, ": field 'success[", i, "]': no payload '", p.payload, "'"));
    }
    if (!p.model.empty()) {
      bool found = !world.ShapesOfModel(p.model).empty();
      for (const auto& o : obstacles)
        found = found || o.model == p.model;
      if (!found) {
        throw LoadError(StrCat(where, ": field 'success[", i, "].no_contact_with': neither world ",
                               world_file.string(), " nor the scenario's obstacles have a model '",
                               p.model, "'"));
      }
    }
  }
}

Scenario LoadScenario(const std::filesystem::path& path) {
  Scenario s = LoadScenarioFromString(ReadTextFile(path, "scenario file"), path.string(),
                                      path.parent_path());
  s.source = path;
  return s;
}

Scenario LoadScenarioFromString(const std::string& yaml, std::string_view source_name,
                                const std::filesystem::path& base_dir) {
  const FieldReader reader{std::string(source_name)};
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw LoadError(StrCat(source_name, ":", e.mark.line + 1, ": not valid YAML: ", e.msg));
  }
  if (!root.IsMap()) throw LoadError(StrCat(source_name, ": a scenario is a YAML mapping"));
  Scenario s = reader.Guard([&] { return Parse(root, reader, base_dir); });
  s.source = std::string(source_name);
  return s;
}

}  // namespace egress::twin
