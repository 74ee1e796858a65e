#include "people/person_behavior.h"
#include "twin_world_impl.h"

#include <algorithm>
#include <optional>

namespace egress::twin {
namespace {

// A walker at the end of its route steps to a wall within this reach [m], to this far from its
// face [m], and at least this far from a doorway's centre [m].
constexpr double kStepAsideReachM = 3.0;
constexpr double kAsideFromWallM = 0.4;
constexpr double kClearOfDoorwayM = 1.3;
// Stuck this near its final waypoint, a walker has arrived [m].
constexpr double kNearEnoughM = 0.6;
// A route's waypoint keeps at least the walker's radius plus this from any wall [m].
constexpr double kWaypointWallMarginM = 0.05;

// Whether segments ab and cd cross (touching counts).
bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return d1 * d2 <= 0.0 && d3 * d4 <= 0.0;
}

}  // namespace

std::string_view ToString(PersonPhase phase) {
  switch (phase) {
    case PersonPhase::kWaiting:
      return "waiting";
    case PersonPhase::kWalking:
      return "walking";
    case PersonPhase::kWaitingForDoor:
      return "waiting_for_door";
    case PersonPhase::kHolding:
      return "holding";
    case PersonPhase::kStanding:
      return "standing";
    case PersonPhase::kDone:
      return "done";
  }
  return "unknown";
}

void TwinWorld::Impl::BuildPeople() {
  std::mt19937_64 rng(DeriveSeed(seed, 4));
  // Its own stream: a scenario without the range draws exactly what it drew before.
  std::mt19937_64 hold_rng(DeriveSeed(seed, 5));
  const auto& r = scenario.randomize;
  for (const auto& spec : scenario.people) {
    const auto& model = fixed.behavior_models.at(spec.behavior);
    const int count = model->GroupSize(spec);
    const int columns = int(std::ceil(std::sqrt(double(count))));
    for (int k = 0; k < count; ++k) {
      Person p;
      p.state.name = count == 1 ? spec.name : spec.name + "_" + std::to_string(k);
      p.state.behavior = spec.behavior;
      p.state.radius = spec.radius;
      p.state.phase = PersonPhase::kWaiting;
      p.behavior = model.get();
      // A group stands in a grid around its start, 2.2 radii apart.
      Eigen::Vector2d offset = Eigen::Vector2d::Zero();
      if (count > 1) {
        offset = Eigen::Vector2d((k % columns) - (columns - 1) / 2.0,
                                 (k / columns) - (columns - 1) / 2.0) *
                 2.2 * spec.radius;
      }
      p.walker.position = spec.start + offset;
      p.walker.radius = spec.radius;
      p.walker.desired_speed = 0.0;
      p.walker.target = p.walker.position;
      p.speed = spec.speed.Sample(rng) * r.person_speed_scale.Sample(rng);
      p.trigger = spec.trigger;
      p.trigger_delay = r.person_delay_s.Sample(rng) + (count > 1 ? 0.3 * k : 0.0);
      p.door = spec.door.empty() ? -1 : FindDoor(spec.door);
      p.hold_angle = spec.hold_angle_deg * kDegToRad;
      if (model->HoldsDoor() && r.hold_angle_deg.max > 0.0)
        p.hold_angle = r.hold_angle_deg.Sample(hold_rng) * kDegToRad;
      p.hold_duration = spec.hold_duration;
      p.state.position = p.walker.position;
      model->PlanRoute(spec, p.door >= 0 ? &doors[std::size_t(p.door)] : nullptr, &p);
      // A waypoint a behaviour placed against a wall (a hold spot beside a hinge in a corner)
      // cannot be reached: it moves out to where the walker fits.
      for (auto& waypoint : p.route)
        waypoint = ClearOfWalls(waypoint, spec.radius + kWaypointWallMarginM);
      const int e = AddEntity(EntityKind::kPerson, p.state.name, int(people.size()));
      const Pose3 X_W(
          Eigen::Vector3d(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
      p.body =
          AddBody(std::make_unique<btCapsuleShapeZ>(spec.radius, kPersonHeight - 2 * spec.radius),
                  X_W, 0.0, kGPerson, kMaskPerson, e);
      MakeKinematic(p.body);
      people.push_back(std::move(p));
      states_cache.push_back(people.back().state);
    }
  }
}

int TwinWorld::Impl::FindDoor(const std::string& name) const {
  for (std::size_t i = 0; i < world.doors.size(); ++i) {
    if (world.doors[i].name == name) return int(i);
  }
  return -1;
}

void TwinWorld::Impl::UpdatePeople() {
  const Pose2 X_WB = RobotPose();
  for (auto& p : people) {
    if (!p.state.started) {
      bool go = false;
      switch (p.trigger.kind) {
        case TriggerSpec::Kind::kImmediately:
          go = time >= p.trigger_delay;
          break;
        case TriggerSpec::Kind::kAtTime:
          go = time >= p.trigger.value + p.trigger_delay;
          break;
        case TriggerSpec::Kind::kRobotWithin:
          go = (X_WB.translation() - p.walker.position).norm() <= p.trigger.value;
          break;
        case TriggerSpec::Kind::kEvent:
          go = HasEvent(p.trigger.event);
          break;
      }
      if (go) {
        p.state.started = true;
        p.state.phase = PersonPhase::kWalking;
        AddEvent("person_started", p.state.name);
      }
      continue;
    }
    const Door* door = p.door >= 0 ? &doors[std::size_t(p.door)] : nullptr;
    const people::EventSink add_event = [this](const std::string& kind, const std::string& subject,
                                               const std::string& detail) {
      AddEvent(kind, subject, detail);
    };
    if (p.state.phase == PersonPhase::kHolding || p.state.phase == PersonPhase::kStanding) {
      p.behavior->WhileResting(time, FindSpec(p.state.name), door, &p, add_event);
      continue;
    }
    if (p.route.empty()) {
      const PersonSpec* spec = FindSpec(p.state.name);
      if (!p.stepped_aside && spec != nullptr && spec->behavior == PersonBehavior::kWalkPast) {
        // Arrived: people do not stand in the middle of a corridor or on a door's axis; they
        // step to the nearest wall, off any doorway, and wait there.
        p.stepped_aside = true;
        if (const auto aside = SpotBesideWall(p.walker.position)) {
          p.route.push_back(*aside);
          p.aside_spot = aside;
          continue;
        }
      }
      // Standing aside: the walls' push would carry a standing walker back to the corridor's
      // middle; they keep to their spot.
      if (p.aside_spot) {
        p.walker.target = *p.aside_spot;
        p.walker.final_target = true;
        p.walker.desired_speed = (p.walker.position - *p.aside_spot).norm() > 0.1 ? p.speed : 0.0;
        p.behavior->AtRouteEnd(time, door, &p, add_event);
        continue;
      }
      p.walker.desired_speed = 0.0;
      p.behavior->AtRouteEnd(time, door, &p, add_event);
      continue;
    }
    // Wait in front of a door that is not open enough.
    p.walker.target = p.route.front();
    p.walker.final_target = p.route.size() == 1;
    p.walker.desired_speed = p.speed;
    if (p.door >= 0 && p.wait_before_waypoint >= 0 && PendingDoorWaypoint(p) &&
        (doors[p.door].angle < config.door_crossed_open_angle_deg * kDegToRad || DoorwayTaken(p))) {
      p.state.phase = PersonPhase::kWaitingForDoor;
      p.walker.desired_speed = 0.0;
    } else if (p.state.phase == PersonPhase::kWaitingForDoor) {
      p.state.phase = PersonPhase::kWalking;
    }
    // Pushed against a jamb (a social-force local minimum, e.g. after making way for the
    // robot), a walker heading for the doorway steps back onto the door's axis and goes again.
    const bool heading_for_doorway = p.door >= 0 && p.reached == p.wait_before_waypoint &&
                                     p.state.phase == PersonPhase::kWalking;
    p.stuck_for = heading_for_doorway && p.walker.velocity.norm() < 0.05 ? p.stuck_for + dt : 0.0;
    if (p.stuck_for > kStuckSec && !p.realigned) {
      const Door& d = doors[std::size_t(p.door)];
      const double side =
          (p.walker.position - d.fixed->centre).dot(d.fixed->normal) >= 0 ? 1.0 : -1.0;
      p.route.insert(p.route.begin(), d.fixed->centre + d.fixed->normal * side * 0.8);
      --p.reached;  // the doorway centre stays the next waypoint after this one
      p.realigned = true;
      p.stuck_for = 0.0;
      p.walker.target = p.route.front();
      p.walker.final_target = false;
    }
    // Walking into an open leaf that stands across the way to the next waypoint (the leaf is a
    // wall to the social forces, and a wall between walker and goal is a local minimum), a
    // walker steps round the leaf's free edge, as people do.
    p.blocked_for = p.state.phase == PersonPhase::kWalking && p.walker.velocity.norm() < 0.05
                        ? p.blocked_for + dt
                        : 0.0;
    // Held off its last waypoint by the walls round it (a hold spot in a corner: the social
    // forces balance short of it), a walker who is near enough has arrived.
    if (p.route.size() == 1 && p.blocked_for > kStuckSec &&
        (p.walker.position - p.route.front()).norm() < kNearEnoughM) {
      p.route.front() = p.walker.position;
    }
    if (p.blocked_for > kStuckSec) {
      for (const auto& d : doors) {
        const Eigen::Vector2d hinge = d.fixed->desc->p_WH.head<2>();
        const Eigen::Vector2d edge = d.fixed->desc->CalcFreeEdge(d.angle).head<2>();
        if (!SegmentsCross(p.walker.position, p.route.front(), hinge, edge)) continue;
        p.route.insert(p.route.begin(), edge + (edge - hinge).normalized() * kStepRoundLeaf);
        --p.reached;  // a detour, not a waypoint of the route
        p.walker.target = p.route.front();
        p.walker.final_target = false;
        AddEvent("person_steps_round_leaf", p.state.name, d.fixed->desc->name);
        break;
      }
      p.blocked_for = 0.0;
    }
    const double reached_radius = p.route.size() == 1 ? 0.25 : 0.4;
    if ((p.walker.position - p.route.front()).norm() < reached_radius &&
        p.state.phase != PersonPhase::kWaitingForDoor) {
      p.route.erase(p.route.begin());
      ++p.reached;
    }
  }
  // Social forces: the robot is a disc to avoid; door leaves are walls.
  std::vector<Walker> walkers;
  walkers.reserve(people.size());
  for (const auto& p : people)
    walkers.push_back(p.walker);
  std::vector<WallSegment> all_walls = fixed.walls;
  for (const auto& d : doors) {
    all_walls.push_back(
        {d.fixed->desc->p_WH.head<2>(), d.fixed->desc->CalcFreeEdge(d.angle).head<2>()});
  }
  const Twist2 V_B = RobotVelocity();
  const Eigen::Vector2d v_W = X_WB.rotation() * Eigen::Vector2d(V_B.vx, V_B.vy);
  const std::vector<DiscObstacle> discs = {{X_WB.translation(), v_W, robot_radius}};
  // Standing people do not integrate (they would drift under wall forces).
  sfm.Step(&walkers, discs, all_walls, dt);
  for (std::size_t i = 0; i < people.size(); ++i) {
    Person& p = people[i];
    if (!p.state.started) continue;
    p.walker = walkers[i];
    p.state.position = p.walker.position;
    p.state.velocity = p.walker.velocity;
    const btTransform T(btQuaternion::getIdentity(),
                        btVector3(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
    p.body->getMotionState()->setWorldTransform(T);
    p.body->setWorldTransform(T);
  }
}

bool TwinWorld::Impl::DoorwayTaken(const Person& me) const {
  const Door& d = doors[me.door];
  for (const auto& other : people) {
    if (&other == &me || !other.state.started) continue;
    if ((other.walker.position - d.fixed->centre).norm() < 0.9) return true;
  }
  return false;
}

Eigen::Vector2d TwinWorld::Impl::ClearOfWalls(Eigen::Vector2d p, double clearance) const {
  for (int pass = 0; pass < 3; ++pass) {  // a corner needs two pushes
    for (const auto& w : fixed.walls) {
      const Eigen::Vector2d offset = p - ClosestPointOnSegment(p, w);
      const double d = offset.norm();
      if (d > 1e-6 && d < clearance) p += offset / d * (clearance - d);
    }
  }
  return p;
}

std::optional<Eigen::Vector2d> TwinWorld::Impl::SpotBesideWall(const Eigen::Vector2d& p) const {
  // The nearest wall within reach, the spot kAsideFromWallM off its face on this side, moved
  // along the wall out of any doorway's way.
  const WallSegment* nearest = nullptr;
  Eigen::Vector2d foot = p;
  double best = kStepAsideReachM;
  for (const auto& w : fixed.walls) {
    const Eigen::Vector2d q = ClosestPointOnSegment(p, w);
    if ((p - q).norm() < best) {
      best = (p - q).norm();
      nearest = &w;
      foot = q;
    }
  }
  if (nearest == nullptr || best < 1e-6) return std::nullopt;
  Eigen::Vector2d spot = foot + (p - foot).normalized() * kAsideFromWallM;
  const Eigen::Vector2d along = (nearest->b - nearest->a).normalized();
  for (const auto& d : doors) {
    const Eigen::Vector2d offset = spot - d.fixed->centre;
    if (offset.norm() < kClearOfDoorwayM) {
      const double s = offset.dot(along) >= 0 ? 1.0 : -1.0;
      spot = d.fixed->centre + along * s * kClearOfDoorwayM + (spot - foot);
    }
  }
  return spot;
}

const PersonSpec* TwinWorld::Impl::FindSpec(const std::string& person_name) const {
  for (const auto& s : scenario.people) {
    if (person_name == s.name || person_name.rfind(s.name + "_", 0) == 0) return &s;
  }
  return nullptr;
}

}  // namespace egress::twin
