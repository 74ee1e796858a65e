#include "group_layout.h"
#include "people/person_behavior.h"
#include "twin_world_impl.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "egress/twin/mobility.h"

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
// An evacuee this near a doorway's centre, on its far side, is past it [m].
constexpr double kPastDoorwayReachM = 2.5;
// Slower than this, a person is held up (Person::slow_for; see GateDoor) [m/s].
constexpr double kHeldUpMps = 0.2;
// Where an evacuee lines up before an open door, on its axis [m].
constexpr double kLineUpBeforeDoorM = 0.6;
// The pace whose drive every evacuee has (Boyce et al.'s mean without disability) [m/s].
constexpr double kReferencePaceMps = 1.24;
// The body whose room from walls the social force model keeps (a walker's, mobility.h) [m].
constexpr double kReferenceBodyRadiusM = 0.23;
// Within this of an open door's centre an evacuee skips the queueing spot before it [m].
constexpr double kSkipQueueSpotM = 2.5;
// A walker this near a waypoint before the last one has reached it [m].
constexpr double kWaypointReachedM = 0.4;
// Where the body of a person who has left the scene is put (below the floor: no ray, no contact).
constexpr double kOutOfSceneZ = -50.0;
// A doorway's line, as a barrier to a group's layout, runs this far on into each jamb [m].
constexpr double kDoorwayLineOverrunM = 0.1;

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
  std::mt19937_64 mobility_rng(DeriveSeed(seed, 6));
  const auto& r = scenario.randomize;
  for (std::size_t i = 0; i < scenario.people.size(); ++i) {
    const PersonSpec& spec = scenario.people[i];
    const auto& model = fixed.behavior_models.at(spec.behavior);
    const int count = model->GroupSize(spec);
    // A group stands in a grid around its start, 2.2 radii apart (a group of mixed sizes, 2.2
    // of its largest radii), where the building leaves room (GroupLayout).
    std::optional<world_detail::GroupLayout> layout;
    if (count > 1) {
      std::vector<Eigen::Vector2d> grid(std::size_t(count), spec.start);
      for (int k = 0; k < count; ++k) {
        const Eigen::Vector2d offset =
            world_detail::GroupLayout::GridUnit(k, count) * 2.2 * spec.radius;
        grid[std::size_t(k)] = spec.mobility.empty() ? Eigen::Vector2d(spec.start + offset)
                                                     : spec.start + offset / spec.radius * 0.45;
      }
      layout.emplace(spec.start, grid, 2.2 * (spec.mobility.empty() ? spec.radius : 0.45),
                     fixed.walls, StartKeepOff());
    }
    for (int k = 0; k < count; ++k) {
      Person p;
      p.state.name = count == 1 ? spec.name : spec.name + "_" + std::to_string(k);
      p.state.behavior = spec.behavior;
      p.state.radius = spec.radius;
      p.state.phase = PersonPhase::kWaiting;
      p.behavior = model.get();
      p.walker.position = spec.start;
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
      // Evacuees operate a door they wait at; everyone else waits for it (the door scenarios'
      // people wait for the robot).
      p.can_operate = spec.behavior == PersonBehavior::kEvacuate;
      if (!spec.mobility.empty()) {
        // The member's class, drawn by the shares; it sets their size, pace and whether (and
        // how fast) they operate an actuator.
        double total = 0.0;
        for (const auto& [name, share] : spec.mobility)
          total += share;
        double pick = std::uniform_real_distribution<double>(0.0, total)(mobility_rng);
        const MobilityClass* cls = FindMobilityClass(spec.mobility.back().first);
        for (const auto& [name, share] : spec.mobility) {
          if (pick < share) {
            cls = FindMobilityClass(name);
            break;
          }
          pick -= share;
        }
        p.state.mobility = cls->name;
        p.state.radius = p.walker.radius = cls->radius;
        p.speed = cls->speed.Sample(mobility_rng) * r.person_speed_scale.Sample(mobility_rng);
        p.can_operate =
            std::uniform_real_distribution<double>(0.0, 1.0)(mobility_rng) < cls->operate_share;
        p.operate_time = cls->operate_time.Sample(mobility_rng);
        // The drive of a walker at the reference pace, whatever their own (social_force.h).
        p.walker.relaxation_time =
            sfm.params().relaxation_time * std::min(1.0, p.speed / kReferencePaceMps);
        p.walker.wall_scale = std::min(1.0, std::pow(kReferenceBodyRadiusM / cls->radius, 4));
      }
      if (layout) {
        const auto place = layout->Place(k, p.walker.radius);
        if (!place) {
          throw LoadError(StrCat(
              scenario.source.string(), ": field 'people[", i, "].count' ('", spec.name,
              "'): a group of ", count, " does not fit around its start (", spec.start.x(), ", ",
              spec.start.y(), "): no room for member ", k, " (", p.state.name, ", radius ",
              p.walker.radius, " m) on the start's side of the walls and doorways within ",
              world_detail::kGroupLayoutExtraRings, " places of the group"));
        }
        p.walker.position = *place;
      }
      p.state.position = p.walker.position;
      p.state.can_operate = p.can_operate;
      if (!spec.route_doors.empty()) {
        // A multi-door route (an exit route): its via points, each door's doorway in order, the
        // goal beyond the last.
        for (const auto& v : spec.via)
          p.route.push_back(v);
        for (const auto& name : spec.route_doors) {
          const int d = FindDoor(name);
          people::PersonBehaviorModel::AppendDoorway(doors[std::size_t(d)], d, &p);
        }
        p.route.push_back(spec.goal);
        p.door = -1;  // the route's doorways decide where to wait
      } else {
        model->PlanRoute(spec, p.door >= 0 ? &doors[std::size_t(p.door)] : nullptr, &p);
      }
      // A waypoint a behaviour placed against a wall (a hold spot beside a hinge in a corner)
      // cannot be reached: it moves out to where the walker fits.
      for (auto& waypoint : p.route)
        waypoint = ClearOfWalls(waypoint, spec.radius + kWaypointWallMarginM);
      if (!p.doorway_waypoints.empty()) p.planned_route = p.route;
      const int e = AddEntity(EntityKind::kPerson, p.state.name, int(people.size()));
      const Pose3 X_W(
          Eigen::Vector3d(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
      const double body_radius = p.walker.radius;
      p.body =
          AddBody(std::make_unique<btCapsuleShapeZ>(body_radius, kPersonHeight - 2 * body_radius),
                  X_W, 0.0, kGPerson, kMaskPerson, e);
      MakeKinematic(p.body);
      // Posed by PlacePersonBody alone: without a motion state Bullet reads the transform set
      // on the body, the same one, instead of a copy through a virtual call per person and
      // physics step (~1 % of a 100-resident run).
      p.body->setMotionState(nullptr);
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
      // The moment the trigger's condition first held; the person starts trigger_delay after
      // it, whatever the kind of trigger (a scenario's person_delay_s applies to each).
      std::optional<double> since;
      switch (p.trigger.kind) {
        case TriggerSpec::Kind::kImmediately:
          since = 0.0;
          break;
        case TriggerSpec::Kind::kAtTime:
          since = p.trigger.value;
          break;
        case TriggerSpec::Kind::kRobotWithin:
          if (p.robot_came_within_at < 0.0 &&
              (X_WB.translation() - p.walker.position).norm() <= p.trigger.value)
            p.robot_came_within_at = time;
          if (p.robot_came_within_at >= 0.0) since = p.robot_came_within_at;
          break;
        case TriggerSpec::Kind::kEvent:
          since = FirstEventTime(p.trigger.event);
          break;
      }
      const bool go = since && time >= *since + p.trigger_delay;
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
      if (p.state.arrived_at < 0.0) {
        p.state.arrived_at = time;
        // An evacuee at the assembly point beyond the exit has left the building: out of the
        // scene (the crowd behind would otherwise push them back towards the exit).
        if (p.state.behavior == PersonBehavior::kEvacuate) {
          p.state.out = true;
          p.state.phase = PersonPhase::kDone;
          p.state.waiting_for.clear();
          const btTransform T(btQuaternion::getIdentity(), btVector3(0, 0, kOutOfSceneZ));
          p.body->setWorldTransform(T);
        }
      }
      if (p.state.out) continue;
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
    // Carried through a doorway by the crowd before reaching the waypoints before it, an evacuee
    // goes on from beyond it: their route resumes after the doorway they are past.
    if (p.state.behavior == PersonBehavior::kEvacuate) AdvancePastDoorways(p);
    // A wide evacuee (a wheelchair, a frame) whose next door already stands open lines up on
    // its axis, not at the spot to its right where they would queue (which may lie under the
    // open leaf, or behind them after they operated the door from its actuator): square to the
    // opening, a wide body clears both jambs. Walkers keep to the queue (their flow through a
    // door is the hydraulic one, evacuees_test).
    if (p.state.behavior == PersonBehavior::kEvacuate && p.route.size() > 1 &&
        p.walker.radius > kReferenceBodyRadiusM + 0.01) {
      const auto next = p.doorway_waypoints.find(p.reached + 1);
      if (next != p.doorway_waypoints.end()) {
        const DoorModel& d = *doors[std::size_t(next->second)].fixed;
        if (doors[std::size_t(next->second)].angle >=
                config.door_crossed_open_angle_deg * kDegToRad &&
            (p.walker.position - d.centre).norm() < kSkipQueueSpotM) {
          // Level with where they stand if that is nearer the door: pressed into a corner beside
          // a jamb, a wide evacuee walked back to the spot, against those behind, who held them
          // there (clinic two wards seed 48: 22 residents at the open exit to the time limit).
          const double out = (p.walker.position - d.centre).dot(d.normal);
          p.route.front() =
              d.centre + d.normal * std::copysign(std::min(kLineUpBeforeDoorM, std::abs(out)), out);
        }
      }
    }
    // Wait in front of a door that is not open enough (operating its actuator if they can).
    p.walker.target = p.route.front();
    p.walker.final_target = p.route.size() == 1;
    p.walker.desired_speed = p.speed;
    const int gate = GateDoor(p);
    // Someone waiting goes on only once the leaf is a few degrees past the threshold: a leaf
    // held right at it (by someone behind it) would otherwise set them walking into it and
    // stopping again, step after step.
    const double open_enough =
        (config.door_crossed_open_angle_deg +
         (p.state.phase == PersonPhase::kWaitingForDoor ? kResumeMarginDeg : 0.0)) *
        kDegToRad;
    if (gate >= 0 && (doors[gate].angle < open_enough || DoorwayTaken(p, gate))) {
      p.state.phase = PersonPhase::kWaitingForDoor;
      p.state.waiting_for = doors[std::size_t(gate)].fixed->desc->name;
      p.walker.desired_speed = 0.0;
      if (OperateDoor(p, gate)) continue;
      const Door& d = doors[std::size_t(gate)];
      // Someone who cannot operate the door keeps the front of its actuator clear for whoever
      // can (a resident, the robot): pushed there by the queue, a wheelchair user waited for the
      // door at its button, where nobody else could stand to press it (two-wards seed 17).
      if (const auto clear = ClearOfActuator(p, gate)) {
        p.walker.target = *clear;
        p.walker.final_target = true;
        p.walker.desired_speed = p.speed;
      }
      // Waiting in the sweep of a leaf that opens towards them, people step back out of it as
      // it comes (standing there they would hold shut the door they wait for).
      const Eigen::Vector2d hinge = d.fixed->desc->p_WH.head<2>();
      const Eigen::Vector2d from_hinge = p.walker.position - hinge;
      const double clear = d.fixed->reach + p.walker.radius + kSweepMarginM;
      if (d.op && d.op->phase() != DoorPhase::kClosed && d.fixed->swing_side != 0.0 &&
          from_hinge.dot(d.fixed->normal) * d.fixed->swing_side > 0.0 &&
          from_hinge.norm() < clear && from_hinge.norm() > 1e-6) {
        // Behind the leaf (it stands between them and the doorway, in the pocket it makes with
        // the wall), out past its free edge: stepping straight back keeps them in the pocket,
        // leaning on the leaf that cannot open for them.
        const Eigen::Vector2d edge = FreeEdge(d);
        const bool behind = SegmentsCross(p.walker.position, d.fixed->centre, hinge, edge);
        p.walker.target = hinge + (behind ? Eigen::Vector2d((edge - hinge).normalized())
                                          : from_hinge.normalized()) *
                                      clear;
        p.walker.final_target = true;
        p.walker.desired_speed = p.speed;
      }
    } else if (p.state.phase == PersonPhase::kWaitingForDoor) {
      p.state.phase = PersonPhase::kWalking;
      p.state.waiting_for.clear();
      p.operating = -1;
    }
    // Pushed against a jamb (a social-force local minimum, e.g. after making way for the
    // robot), a walker heading for the doorway steps back onto the door's axis and goes again.
    const bool heading_for_doorway = gate >= 0 && p.state.phase == PersonPhase::kWalking;
    p.stuck_for =
        heading_for_doorway && p.walker.velocity.norm() < 0.05 ? p.stuck_for + crowd_dt : 0.0;
    if (p.stuck_for > kStuckSec && !p.realigned) {
      const Door& d = doors[std::size_t(gate)];
      const double side =
          (p.walker.position - d.fixed->centre).dot(d.fixed->normal) >= 0 ? 1.0 : -1.0;
      p.route.insert(p.route.begin(), d.fixed->centre + d.fixed->normal * side * kOutOfDoorwayM);
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
                        ? p.blocked_for + crowd_dt
                        : 0.0;
    p.slow_for = p.walker.velocity.norm() < kHeldUpMps ? p.slow_for + crowd_dt : 0.0;
    if (p.blocked_for > kStuckSec) {
      RewindIfPushedBack(p);
      GiveWayIfJammed(p);
      FindWayBackThroughDoorway(p);
    }
    // Held off its last waypoint by the walls round it (a hold spot in a corner: the social
    // forces balance short of it), a walker who is near enough has arrived.
    if (p.route.size() == 1 && p.blocked_for > kStuckSec &&
        (p.walker.position - p.route.front()).norm() < kNearEnoughM) {
      p.route.front() = p.walker.position;
    }
    // People see an open leaf across their way and walk round it at once (pressed against its
    // back they would be in a local minimum of the social forces, the pocket between leaf and
    // wall); a closed leaf is the gate's business.
    if (p.state.phase == PersonPhase::kWalking) {
      for (std::size_t k = 0; k < doors.size(); ++k) {
        const Door& d = doors[k];
        if (d.angle <= AdaDoorOperator::kClosedAngle) {
          // The leaf they were going round has shut: the way round it (now likely through the
          // wall beside the doorway) is no way at all.
          if (p.round_leaf == int(k)) {
            SkipRouteTo(p, p.reached + 1);
            p.walker.target = p.route.front();
          }
          continue;
        }
        const Eigen::Vector2d hinge = d.fixed->desc->p_WH.head<2>();
        const Eigen::Vector2d edge = FreeEdge(d);
        // Past the free edge and a shoulder to the side of the leaf the waypoint is on: from
        // there the way on does not cross the leaf again.
        const Eigen::Vector2d along = (edge - hinge).normalized();
        const Eigen::Vector2d across(-along.y(), along.x());
        const Eigen::Vector2d& next =
            p.round_leaf == int(k) && p.route.size() > 1 ? p.route[1] : p.route.front();
        const double to_next = across.dot(next - hinge) >= 0.0 ? 1.0 : -1.0;
        // In the doorway of a door not on their route (pushed there by the crowd), with its leaf
        // swung to the far side from the waypoint, the way on is back out of the doorway on the
        // waypoint's side: round the leaf's free edge lies the room beyond, a wall between it and
        // the route (clinic two wards seed 23: a north-ward resident walking the corridor, pressed
        // into door_d's doorway as it stood open for the south ward, went round its leaf into the
        // south ward and walked into the ward's wall to the time limit).
        // The route's doors are looked up only for a leaf on the far side (every walker meets
        // every door each step).
        const double next_side = (next - d.fixed->centre).dot(d.fixed->normal);
        const auto on_route = [&] {
          return p.door == int(k) ||
                 std::any_of(p.doorway_waypoints.begin(), p.doorway_waypoints.end(),
                             [&](const auto& w) { return w.second == int(k); });
        };
        const bool back_out =
            next_side * (edge - d.fixed->centre).dot(d.fixed->normal) < 0.0 && !on_route();
        const Eigen::Vector2d round =
            back_out ? Eigen::Vector2d(d.fixed->centre + d.fixed->normal *
                                                             (next_side >= 0.0 ? 1.0 : -1.0) *
                                                             kOutOfDoorwayM)
                     : Eigen::Vector2d(edge + along * kStepRoundLeaf +
                                       across * to_next * p.walker.radius);
        if (p.round_leaf == int(k)) {
          // Carried on past the way round by the crowd behind, towards the doorway: once the
          // straight way on clears the leaf (by a body's width past its free edge), the detour
          // is done. Walking back to it would be against the crowd, in the doorway where they
          // stand (clinic two wards seed 22: 6 residents kept at door_e to the time limit).
          // Through a wall it is no way on: pressed into the doorway beside the hinge, the line
          // on passed the hinge through the wall, and they walked into the room beyond (clinic
          // two wards seed 7, doors propped open: door_b's leaf open into the corridor).
          if (p.route.size() > 1 &&
              !SegmentsCross(p.walker.position, p.route[1], hinge,
                             edge + along * p.walker.radius) &&
              !WallBetween(p.walker.position, p.route[1])) {
            SkipRouteTo(p, p.reached + 1);
            p.walker.target = p.route.front();
            p.walker.final_target = p.route.size() == 1;
            continue;
          }
          p.route.front() = round;  // the leaf moves: so does the way round it
        } else {
          if (!SegmentsCross(p.walker.position, p.route.front(), hinge, edge)) continue;
          if (SegmentsCross(p.walker.position, round, hinge, edge)) continue;
          // A leaf seen through a wall is not in their way: standing in the doorway of a room
          // beside the corridor, the straight way on ran along the wall's face past door_c's
          // leaf, open into the next room, and the way round it led through that room's wall
          // (clinic two wards seed 7, doors propped open: a resident walked into it to the time
          // limit).
          if (WallBetween(p.walker.position, round)) continue;
          if (p.round_leaf >= 0) continue;  // one leaf at a time
          // At the edge already: a detour there would be reached at once, and inserted again
          // the next step.
          if ((round - p.walker.position).norm() < kWaypointReachedM) continue;
          p.route.insert(p.route.begin(), round);
          --p.reached;  // a detour, not a waypoint of the route
          p.round_leaf = int(k);
          AddEvent("person_steps_round_leaf", p.state.name, d.fixed->desc->name);
        }
        p.walker.target = p.route.front();
        p.walker.final_target = false;
        break;
      }
    }
    if (p.blocked_for > kStuckSec) p.blocked_for = 0.0;
    // An evacuee is at the assembly point anywhere near its goal (the others there would keep
    // them off its exact spot).
    const double reached_radius =
        p.route.size() == 1 ? (p.state.behavior == PersonBehavior::kEvacuate ? kNearEnoughM : 0.25)
                            : kWaypointReachedM;
    // A doorway's centre is not reached through its shut leaf: the gate makes them wait for it
    // at the next step. (Going round a closing leaf when it shut, the detour was dropped and the
    // route came back to the doorway within reach of its centre after the gate had looked;
    // counted reached, a wheelchair user walked at the shut door for good, never waiting for
    // it, and the robot never knew to open it: clinic seed 13, with the robot.)
    const auto doorway = p.doorway_waypoints.find(p.reached);
    const bool shut_doorway =
        doorway != p.doorway_waypoints.end() &&
        doors[std::size_t(doorway->second)].angle < config.door_crossed_open_angle_deg * kDegToRad;
    if (((p.walker.position - p.route.front()).norm() < reached_radius || PassedWaypoint(p)) &&
        p.state.phase != PersonPhase::kWaitingForDoor && !shut_doorway) {
      SkipRouteTo(p, p.reached + 1);
    }
  }
  // Social forces: the robot is a disc to avoid; door leaves are walls.
  std::vector<Walker> walkers;
  std::vector<std::size_t> walker_of;  // people's index of each walker (those out are not)
  walkers.reserve(people.size());
  for (std::size_t i = 0; i < people.size(); ++i) {
    if (people[i].state.out) continue;
    walkers.push_back(people[i].walker);
    walkers.back().held = !people[i].state.started;  // standing people do not integrate
    auto& way_back = people[i].way_back;
    if (people[i].state.phase != PersonPhase::kWalking) way_back.clear();
    if (!way_back.empty() &&
        (way_back.front() - walkers.back().position).norm() < kWaypointReachedM)
      way_back.erase(way_back.begin());
    if (!way_back.empty()) {
      walkers.back().target = way_back.front();
      walkers.back().final_target = false;
    }
    if (time < people[i].give_way_until && people[i].state.phase == PersonPhase::kWalking) {
      walkers.back().target = people[i].give_way_spot;
      walkers.back().final_target = true;
    }
    walker_of.push_back(i);
  }
  std::vector<WallSegment> leaves;
  for (const auto& d : doors) {
    leaves.push_back({d.fixed->desc->p_WH.head<2>(), FreeEdge(d)});
  }
  const Twist2 V_B = RobotVelocity();
  const Eigen::Vector2d v_W = X_WB.rotation() * Eigen::Vector2d(V_B.vx, V_B.vy);
  const std::vector<DiscObstacle> discs = {{X_WB.translation(), v_W, robot_radius}};
  // The social terms every few steps, held between (sums of every walker's neighbours and walls
  // within a few metres are most of a crowd's cost); the drive and body contact, which are
  // stiff, every crowd step, as is the integration, so bodies move smoothly.
  const auto social_every = std::max<std::uint64_t>(
      1, std::uint64_t(std::lround(config.crowd_rate_hz / config.crowd_social_rate_hz)));
  std::vector<Eigen::Vector2d> accelerations;
  if (social_every == 1) {
    // Every term every step: one sum.
    accelerations = sfm.CalcAccelerations(walkers, discs, fixed.wall_cells, leaves);
  } else {
    std::vector<Eigen::Vector2d> social;
    if (step / crowd_every % social_every == 0) {
      social = sfm.CalcSocialAccelerations(walkers, discs, fixed.wall_cells, leaves);
      for (std::size_t k = 0; k < walkers.size(); ++k)
        people[walker_of[k]].social_acceleration = social[k];
    } else {
      for (std::size_t k = 0; k < walkers.size(); ++k)
        social.push_back(people[walker_of[k]].social_acceleration);
    }
    accelerations =
        sfm.CalcAccelerationsWithSocial(social, walkers, discs, fixed.wall_cells, leaves);
  }
  // Velocities over the crowd step, positions over this physics step: CarryPeople moves them
  // on over the rest (v += a crowd_dt, x += v dt).
  for (auto& a : accelerations)
    a *= double(crowd_every);
  sfm.Integrate(&walkers, accelerations, dt, discs);
  // Standing people do not integrate (they would drift under wall forces).
  for (std::size_t k = 0; k < walkers.size(); ++k) {
    Person& p = people[walker_of[k]];
    if (!p.state.started) continue;
    p.walker = walkers[k];
    p.state.position = p.walker.position;
    p.state.velocity = p.walker.velocity;
    PlacePersonBody(p);
  }
}

bool TwinWorld::Impl::PassedWaypoint(const Person& p) const {
  // Doorway centres and the spots before them are where people line up and wait: passing those
  // is the doors' business (AdvancePastDoorways, the gate); a way round a leaf moves with it.
  const auto at_door = [&](int waypoint) {
    return p.doorway_waypoints.count(waypoint) > 0 || waypoint == p.wait_before_waypoint;
  };
  if (p.route.size() < 2 || p.round_leaf >= 0 || at_door(p.reached) || at_door(p.reached + 1))
    return false;
  const Eigen::Vector2d& at = p.walker.position;
  const Eigen::Vector2d& waypoint = p.route[0];
  const Eigen::Vector2d& next = p.route[1];
  if ((at - waypoint).dot(next - waypoint) <= 0.0) return false;
  return !WallBetween(at, next);
}

bool TwinWorld::Impl::WallBetween(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  return std::any_of(fixed.walls.begin(), fixed.walls.end(),
                     [&](const WallSegment& w) { return SegmentsCross(a, b, w.a, w.b); });
}

void TwinWorld::Impl::RewindIfPushedBack(Person& p) {
  if (p.planned_route.empty() || p.route.empty()) return;
  const Eigen::Vector2d& at = p.walker.position;
  if (!WallBetween(at, p.route.front())) return;
  // The latest doorway already passed that they stand before again: on its waiting side, in
  // sight of the waypoint before it (the drive towards the next waypoint may have slid them
  // along the walls far from the doorway).
  for (auto it = p.doorway_waypoints.rbegin(); it != p.doorway_waypoints.rend(); ++it) {
    const int centre = it->first;
    if (centre >= p.reached || centre < 1) continue;
    const DoorModel& d = *doors[std::size_t(it->second)].fixed;
    const Eigen::Vector2d& before = p.planned_route[std::size_t(centre - 1)];
    if ((at - d.centre).dot(d.normal) * (before - d.centre).dot(d.normal) <= 0.0) continue;
    if (WallBetween(at, before)) continue;
    p.route.assign(p.planned_route.begin() + (centre - 1), p.planned_route.end());
    p.reached = centre - 1;
    p.round_leaf = -1;
    p.walker.target = p.route.front();
    AddEvent("person_rewinds_route", p.state.name, d.desc->name);
    return;
  }
}

void TwinWorld::Impl::SkipRouteTo(Person& p, int waypoint) {
  p.route.erase(p.route.begin(), p.route.begin() + long(waypoint - p.reached));
  p.reached = waypoint;
  // A way round a leaf is always the route's first waypoint, now dropped: left set, it would
  // turn the next waypoint into that way round (clinic escort seed 54: past door_e, back
  // through it against the crowd, 11 residents held there for 300 s).
  p.round_leaf = -1;
}

void TwinWorld::Impl::AdvancePastDoorways(Person& p) const {
  for (auto it = p.doorway_waypoints.rbegin(); it != p.doorway_waypoints.rend(); ++it) {
    const int centre = it->first;
    const std::size_t beyond = std::size_t(centre + 1 - p.reached);  // in the remaining route
    if (centre < p.reached || beyond >= p.route.size()) continue;
    const DoorModel& d = *doors[std::size_t(it->second)].fixed;
    const Eigen::Vector2d rel = p.walker.position - d.centre;
    // Pushed into the doorway by the crowd before reaching the waypoints before it (the spot
    // before the door they head for first), an evacuee goes on through: back to those would be
    // against the crowd, and standing in the doorway they keep everyone behind waiting for it
    // (door_d propped open, no robot, seed 15: 7 residents held in the ward for 250 s).
    if (centre > p.reached && std::abs(rel.dot(d.normal)) < p.walker.radius &&
        std::abs(rel.dot(d.along)) < d.reach / 2) {
      SkipRouteTo(p, centre);
      return;
    }
    const bool past = rel.dot(d.normal) * (p.route[beyond] - d.centre).dot(d.normal) > 0.0 &&
                      std::abs(rel.dot(d.normal)) > p.walker.radius &&
                      rel.norm() < kPastDoorwayReachM;
    if (!past) continue;
    SkipRouteTo(p, centre + 1);
    return;
  }
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

std::vector<WallSegment> TwinWorld::Impl::StartKeepOff() const {
  // Each doorway's line (run on into its jambs, past the gaps the leaf leaves there) and a square
  // round the robot.
  std::vector<WallSegment> keep_off;
  for (const auto& d : doors) {
    const Eigen::Vector2d hinge = d.fixed->desc->p_WH.head<2>();
    const Eigen::Vector2d& along = d.fixed->along;
    keep_off.push_back({hinge - along * kDoorwayLineOverrunM,
                        hinge + along * (d.fixed->reach + kDoorwayLineOverrunM), -1});
  }
  const Eigen::Vector2d p_WB = RobotPose().translation();
  const Eigen::Vector2d corners[4] = {p_WB + Eigen::Vector2d(robot_radius, robot_radius),
                                      p_WB + Eigen::Vector2d(-robot_radius, robot_radius),
                                      p_WB + Eigen::Vector2d(-robot_radius, -robot_radius),
                                      p_WB + Eigen::Vector2d(robot_radius, -robot_radius)};
  for (int c = 0; c < 4; ++c)
    keep_off.push_back({corners[c], corners[(c + 1) % 4], -1});
  return keep_off;
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
