#include "egress/twin/scenario_judge.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "egress/twin/trace.h"

namespace egress::twin {

DoorwayFrame CalcDoorwayFrame(const DoorDescription& d) {
  const Eigen::Vector2d hinge = d.p_WH.head<2>();
  const Eigen::Vector2d edge = d.CalcFreeEdge(0.0).head<2>();
  DoorwayFrame w;
  w.along = (edge - hinge).normalized();
  w.normal = Eigen::Vector2d(-w.along.y(), w.along.x());
  w.half_width = (edge - hinge).norm() / 2;
  w.centre = hinge + w.along * w.half_width;
  return w;
}

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::string Fmt(double v, int digits = 2) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

// Whether the person `p` is in sight of the robot at p_WB: the first thing the ray from the robot
// to them hits at ScenarioJudge::kSightHeight is a person (them, or someone between: people do
// not shut anyone out of personal space), or nothing short of them.
bool InSight(const TwinWorld& world, const Eigen::Vector2d& p_WB, const PersonState& p) {
  const double h = ScenarioJudge::kSightHeight;
  const Eigen::Vector3d from(p_WB.x(), p_WB.y(), h), to(p.position.x(), p.position.y(), h);
  const RayHit hit = world.CastRay(from, to, GlassMode::kOpaque);
  return !hit.hit || world.entity_kind(hit.entity) == EntityKind::kPerson;
}

}  // namespace

void ScenarioJudge::Observe(const TwinWorld& world) {
  const Pose2 X_WB = world.robot_pose();
  const double t = world.time();
  if (!initialized_) {
    initialized_ = true;
    last_pose_ = X_WB;
    last_time_ = t;
    for (std::size_t i = 0; i < world.door_count(); ++i) {
      const DoorwayFrame w = CalcDoorwayFrame(world.door(i));
      last_side_.push_back((X_WB.translation() - w.centre).dot(w.normal));
    }
    return;
  }
  const double dt = t - last_time_;
  const double step = (X_WB.translation() - last_pose_.translation()).norm();
  metrics_.path_length += step;
  const double speed = dt > 0 ? step / dt : 0.0;
  const double robot_r = world.robot_radius();
  if (world.scenario().goal && !metrics_.time_to_goal &&
      (X_WB.translation() - world.scenario().goal->translation()).norm() <=
          world.scenario().goal_tolerance) {
    metrics_.time_to_goal = t;
  }
  double nearest = std::numeric_limits<double>::infinity();
  double nearest_in_sight = std::numeric_limits<double>::infinity();
  for (const auto& p : world.people()) {
    if (p.out) continue;  // left the scene
    const double gap = (p.position - X_WB.translation()).norm() - robot_r - p.radius;
    nearest = std::min(nearest, gap);
    // A ray only for whoever would be the nearest in sight so far.
    if (gap < std::min(nearest_in_sight, metrics_.min_person_distance_in_sight) &&
        InSight(world, X_WB.translation(), p))
      nearest_in_sight = gap;
  }
  const Twist2 V_B = world.robot_velocity();
  if (nearest < metrics_.min_person_distance) {
    metrics_.min_person_distance = nearest;
    metrics_.closest_robot_speed = std::hypot(V_B.vx, V_B.vy);
    metrics_.closest_time = t;
  }
  if (nearest_in_sight < metrics_.min_person_distance_in_sight) {
    metrics_.min_person_distance_in_sight = nearest_in_sight;
    metrics_.closest_in_sight_robot_speed = std::hypot(V_B.vx, V_B.vy);
  }
  if (nearest < kPersonalSpace) metrics_.time_in_personal_space += dt;
  for (std::size_t i = 0; i < world.door_count(); ++i) {
    const DoorDescription& d = world.door(i);
    const DoorwayFrame w = CalcDoorwayFrame(d);
    const Eigen::Vector2d rel = X_WB.translation() - w.centre;
    const double side = rel.dot(w.normal);
    const bool within_jambs = std::abs(rel.dot(w.along)) <= w.half_width + 0.1;
    if (within_jambs && ((last_side_[i] < 0) != (side < 0))) {
      metrics_.crossings.push_back({d.name, t, world.door_angle(i), side >= 0 ? 1 : -1});
    }
    last_side_[i] = side;
    const bool crossed = std::any_of(metrics_.crossings.begin(), metrics_.crossings.end(),
                                     [&](const DoorCrossing& c) { return c.door == d.name; });
    if (!crossed && rel.norm() <= kDoorZone && speed < kWaitSpeed)
      metrics_.door_wait_time[d.name] += dt;
  }
  last_pose_ = X_WB;
  last_time_ = t;
}

int RunMetrics::ObstacleContacts() const {
  int n = 0;
  for (const char* kind : {"static", "door"})
    if (const auto it = contacts.find(kind); it != contacts.end()) n += it->second;
  return n;
}

Verdict ScenarioJudge::Finish(const TwinWorld& world) const {
  Verdict v;
  v.metrics = metrics_;
  RunMetrics& m = v.metrics;
  m.end_time = world.time();
  int presses = 0;
  for (std::size_t i = 0; i < world.door_count(); ++i) {
    m.button_presses[world.door(i).name] = world.button_presses(i);
    presses += world.button_presses(i);
    m.door_wait_time.try_emplace(world.door(i).name, 0.0);
  }
  for (const auto& e : world.events()) {
    if (e.kind != "contact") continue;
    const std::string kind = e.detail.substr(0, e.detail.find(' '));
    ++m.contacts[kind];
    ++m.contacts_with[e.subject];
  }
  m.presses_per_traversal =
      m.crossings.empty() ? double(presses) : double(presses) / double(m.crossings.size());
  const double open_threshold = world.config().door_crossed_open_angle_deg * M_PI / 180.0;
  const auto& scenario = world.scenario();
  auto crossings_of = [&](const std::string& door) {
    std::vector<DoorCrossing> out;
    for (const auto& c : m.crossings) {
      if (c.door == door) out.push_back(c);
    }
    return out;
  };
  using K = PredicateSpec::Kind;
  bool time_ok = m.end_time <= scenario.time_limit + 1e-9;
  bool all = true;
  bool has_time_limit_predicate = false;
  for (const auto& p : scenario.success) {
    PredicateResult r;
    r.name = ToString(p);
    switch (p.kind) {
      case K::kReachGoal:
        r.passed = m.time_to_goal.has_value();
        r.detail = r.passed ? "at " + Fmt(*m.time_to_goal, 1) + " s"
                            : "never within " + Fmt(scenario.goal_tolerance) + " m";
        break;
      case K::kCrossDoor: {
        const auto c = crossings_of(p.door);
        r.passed = !c.empty();
        r.detail = std::to_string(c.size()) + " crossing(s)";
        break;
      }
      case K::kDoorOpenWhenCrossed: {
        const auto c = crossings_of(p.door);
        double min_angle = std::numeric_limits<double>::infinity();
        for (const auto& x : c)
          min_angle = std::min(min_angle, x.angle);
        r.passed = !c.empty() && min_angle >= open_threshold;
        r.detail = c.empty() ? "not crossed" : "leaf at " + Fmt(min_angle * kRadToDeg, 0) + " deg";
        break;
      }
      case K::kButtonPressed:
      case K::kButtonNotPressed: {
        const int n = m.button_presses.count(p.door) ? m.button_presses.at(p.door) : 0;
        r.passed = p.kind == K::kButtonPressed ? n > 0 : n == 0;
        r.detail = std::to_string(n) + " press(es)";
        break;
      }
      case K::kPayloadHeld: {
        const auto held = world.held_payload();
        r.passed = held && *held == p.payload;
        r.detail = held ? "holding " + *held : "gripper empty";
        break;
      }
      case K::kPayloadDelivered: {
        const Eigen::Vector3d p_W = world.payload_pose(p.payload).translation();
        const double dist = (p_W.head<2>() - p.target).norm();
        const bool released = !(world.held_payload() && *world.held_payload() == p.payload);
        const bool high_enough = p_W.z() >= p.min_z;
        r.passed = released && dist <= p.radius && high_enough;
        r.detail = Fmt(dist) + " m from target" + (released ? "" : ", still held") +
                   (high_enough ? "" : ", fell (centre at z = " + Fmt(p_W.z()) + " m)");
        break;
      }
      case K::kNoPersonContact: {
        const int n = m.contacts.count("person") ? m.contacts.at("person") : 0;
        r.passed = n == 0;
        r.detail = std::to_string(n) + " contact(s)";
        break;
      }
      case K::kNoDoorStrike: {
        const int n = m.contacts.count("door") ? m.contacts.at("door") : 0;
        r.passed = n == 0;
        r.detail = std::to_string(n) + " leaf contact(s)";
        break;
      }
      case K::kNoContactWith: {
        const int n = m.contacts_with.count(p.model) ? m.contacts_with.at(p.model) : 0;
        r.passed = n == 0;
        r.detail = std::to_string(n) + " contact(s)";
        break;
      }
      case K::kWithinTimeLimit:
        has_time_limit_predicate = true;
        r.passed = time_ok;
        r.detail = Fmt(m.end_time, 1) + " / " + Fmt(scenario.time_limit, 1) + " s";
        break;
    }
    all = all && r.passed;
    v.predicates.push_back(std::move(r));
  }
  if (!has_time_limit_predicate) {
    v.predicates.push_back({"within_time_limit", time_ok,
                            Fmt(m.end_time, 1) + " / " + Fmt(scenario.time_limit, 1) + " s"});
    all = all && time_ok;
  }
  v.success = all;
  return v;
}

std::string FormatVerdict(const Verdict& v) {
  std::ostringstream out;
  std::size_t width = 9;
  for (const auto& p : v.predicates)
    width = std::max(width, p.name.size());
  out << (v.success ? "SUCCESS" : "FAILURE") << "\n";
  for (const auto& p : v.predicates) {
    out << "  " << (p.passed ? "PASS  " : "FAIL  ") << p.name
        << std::string(width - p.name.size() + 2, ' ') << p.detail << "\n";
  }
  const auto& m = v.metrics;
  out << "  metrics: time " << Fmt(m.end_time, 1) << " s";
  if (m.time_to_goal) out << ", to goal " << Fmt(*m.time_to_goal, 1) << " s";
  out << ", path " << Fmt(m.path_length) << " m";
  out << ", min person gap "
      << (std::isfinite(m.min_person_distance)
              ? Fmt(m.min_person_distance) + " m (at " + Fmt(m.closest_time, 1) + " s, robot at " +
                    Fmt(m.closest_robot_speed) + " m/s)"
              : "-");
  if (std::isfinite(m.min_person_distance_in_sight) &&
      m.min_person_distance_in_sight != m.min_person_distance)
    out << " (in sight " << Fmt(m.min_person_distance_in_sight) << " m)";
  out << ", personal space " << Fmt(m.time_in_personal_space, 1) << " s";
  int contacts = 0;
  for (const auto& [k, n] : m.contacts)
    contacts += n;
  out << ", contacts " << contacts;
  for (const auto& [k, n] : m.contacts)
    out << " " << k << ":" << n;
  out << ", presses/traversal " << Fmt(m.presses_per_traversal) << "\n";
  for (const auto& [door, wait] : m.door_wait_time) {
    const int presses = m.button_presses.count(door) ? m.button_presses.at(door) : 0;
    out << "  door " << door << ": wait " << Fmt(wait, 1) << " s, presses " << presses << "\n";
  }
  return out.str();
}

std::string VerdictToJson(const Verdict& v) {
  std::string s = "{\"success\":";
  s += v.success ? "true" : "false";
  s += ",\"predicates\":[";
  for (std::size_t i = 0; i < v.predicates.size(); ++i) {
    const auto& p = v.predicates[i];
    if (i) s += ',';
    s += "{\"name\":\"";
    s += JsonEscape(p.name);
    s += "\",\"passed\":";
    s += p.passed ? "true" : "false";
    s += ",\"detail\":\"";
    s += JsonEscape(p.detail);
    s += "\"}";
  }
  const auto& m = v.metrics;
  s += "],\"metrics\":{\"end_time\":";
  s += Fmt(m.end_time, 3);
  s += ",\"time_to_goal\":";
  s += m.time_to_goal ? Fmt(*m.time_to_goal, 3) : std::string("null");
  s += ",\"path_length\":";
  s += Fmt(m.path_length, 3);
  s += ",\"min_person_distance\":";
  s += std::isfinite(m.min_person_distance) ? Fmt(m.min_person_distance, 3) : std::string("null");
  s += ",\"closest_robot_speed\":";
  s += Fmt(m.closest_robot_speed, 3);
  s += ",\"closest_time\":";
  s += Fmt(m.closest_time, 3);
  s += ",\"min_person_distance_in_sight\":";
  s += std::isfinite(m.min_person_distance_in_sight) ? Fmt(m.min_person_distance_in_sight, 3)
                                                     : std::string("null");
  s += ",\"closest_in_sight_robot_speed\":";
  s += Fmt(m.closest_in_sight_robot_speed, 3);
  s += ",\"time_in_personal_space\":";
  s += Fmt(m.time_in_personal_space, 3);
  s += ",\"presses_per_traversal\":";
  s += Fmt(m.presses_per_traversal, 3);
  s += ",\"contacts\":{";
  bool first = true;
  for (const auto& [k, n] : m.contacts) {
    if (!first) s += ',';
    first = false;
    s += "\"";
    s += JsonEscape(k);
    s += "\":";
    s += std::to_string(n);
  }
  s += "},\"doors\":{";
  first = true;
  for (const auto& [door, wait] : m.door_wait_time) {
    if (!first) s += ',';
    first = false;
    s += "\"";
    s += JsonEscape(door);
    s += "\":{\"wait_time\":";
    s += Fmt(wait, 3);
    s += ",\"presses\":";
    s += std::to_string(m.button_presses.count(door) ? m.button_presses.at(door) : 0);
    s += "}";
  }
  s += "},\"crossings\":[";
  for (std::size_t i = 0; i < m.crossings.size(); ++i) {
    const auto& c = m.crossings[i];
    if (i) s += ',';
    s += "{\"door\":\"";
    s += JsonEscape(c.door);
    s += "\",\"t\":";
    s += Fmt(c.t, 3);
    s += ",\"angle_deg\":";
    s += Fmt(c.angle * kRadToDeg, 1);
    s += ",\"direction\":";
    s += std::to_string(c.direction);
    s += "}";
  }
  s += "]}}";
  return s;
}

}  // namespace egress::twin
