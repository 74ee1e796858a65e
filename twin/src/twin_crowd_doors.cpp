// People at doors: which door an evacuee waits for, who operates a shut door's actuator and
// how, whether a doorway is taken, where someone who cannot operate it waits, and who gives way
// in a jam before one.
#include "twin_world_impl.h"

#include "doorway_way.h"
#include "egress/hsr_interface/geometry.h"

#include <cmath>
#include <limits>
#include <optional>

namespace egress::twin {
namespace {

// Operating an actuator: where a person stands (this far in front of its face) [m], how near the
// doorway they must be to go and operate it [m], near enough to the spot to operate [m], and
// within arm's reach when the queue keeps them off the spot [m].
constexpr double kActuatorStandOffM = 0.45;
constexpr double kPersonAtActuatorRadiusM = 0.3;
constexpr double kOperateReachM = 3.0;
constexpr double kAtActuatorM = 0.25;
constexpr double kArmReachM = 0.7;
// Between whoever stands at an actuator and someone waiting who cannot operate it [m].
constexpr double kActuatorClearMarginM = 0.15;
// Half the width of the way to an actuator (from the room, square to its door) that someone
// waiting who cannot operate it keeps clear: room for a wheelchair or the robot (0.43 m) to come
// by to it [m].
constexpr double kActuatorLaneHalfM = 0.6;
// Someone waiting who cannot operate the door steps out of the robot's straight way to the
// actuator on their side once the robot is this near the actuator's spot [m], to this much more
// than the two bodies' radii [m]: people make way for whoever comes to open the door for them.
constexpr double kMakeWayForRobotM = 3.0;
constexpr double kRobotWayMarginM = 0.3;
// A jammed walker gives way to someone nearer the bottleneck for this long [s]: long enough for
// them to step clear (half a metre at a wheelchair's pace), short enough not to be overtaken by
// the rest behind.
constexpr double kGiveWaySec = 1.5;
// Bodies this near (surface to surface) press on each other in a jam [m].
constexpr double kPressingGapM = 0.05;
// How far a walker who gives way steps back [m]: room for a wide body beside it to pass.
constexpr double kGiveWayStepM = 0.3;
// Room left between the one who gives way and the body coming across in front of them [m].
constexpr double kGiveWayMarginM = 0.05;
// Kept from the actuator this long, a person gives up operating it (and for as long again) [s].
constexpr double kOperateGiveUpSec = 12.0;
// Held up (Person::slow_for) this long within this of the spot before a shut door, an evacuee
// queues for it (GateDoor) [s], [m].
constexpr double kHeldUpSec = 1.0;
constexpr double kQueueNearSpotM = 1.5;
// A stuck walker looks for a way back through doorways this near [m].
constexpr double kWayBackReachM = 3.0;

}  // namespace

int TwinWorld::Impl::GateDoor(const Person& p) const {
  if (p.door >= 0 && p.wait_before_waypoint >= 0 && PendingDoorWaypoint(p)) return p.door;
  const auto it = p.doorway_waypoints.find(p.reached);
  if (it != p.doorway_waypoints.end()) return it->second;
  // Held up near the spot before a shut door: queueing for it, as those at the spot are (clinic
  // seed 21, no robot: the group stood round the spot before the exit door, which someone who
  // could not open it held; none of them waited for the door, so nobody pressed its button).
  const auto next = p.doorway_waypoints.find(p.reached + 1);
  if (next == p.doorway_waypoints.end() || p.state.behavior != PersonBehavior::kEvacuate ||
      p.route.empty())
    return -1;
  const Door& d = doors[std::size_t(next->second)];
  const bool shut = d.angle < config.door_crossed_open_angle_deg * kDegToRad;
  return shut && p.slow_for >= kHeldUpSec &&
                 (p.walker.position - p.route.front()).norm() < kQueueNearSpotM
             ? next->second
             : -1;
}

std::optional<Eigen::Vector2d> TwinWorld::Impl::ActuatorSpot(int door, double side,
                                                             const Eigen::Vector2d& p_W) const {
  // The building's actuators of this door, each faced from its own box (building.h): the
  // person stands in front of the face, on their side of the door.
  const DoorModel& d = *doors[std::size_t(door)].fixed;
  std::optional<Eigen::Vector2d> best;
  const auto& actuators = twin_model->building().actuators;
  actuator_spots.resize(actuators.size());
  for (std::size_t k = 0; k < actuators.size(); ++k) {
    const BuildingActuator& a = actuators[k];
    if (a.door != d.desc->name) continue;
    const Eigen::Vector2d n = a.n_W.head<2>();
    if (n.norm() < 1e-6) continue;
    const Eigen::Vector2d front = a.p_W.head<2>() + n.normalized() * kActuatorStandOffM;
    if ((front - d.centre).dot(d.normal) * side <= 0.0) continue;
    // Cleared of the walls once: the walls do not move, and people wait here every step.
    if (!actuator_spots[k]) actuator_spots[k] = ClearOfWalls(front, kPersonAtActuatorRadiusM);
    const Eigen::Vector2d spot = *actuator_spots[k];
    if (!best || (spot - p_W).norm() < (*best - p_W).norm()) best = spot;
  }
  return best;
}

bool TwinWorld::Impl::OperateDoor(Person& p, int gate) {
  Door& d = doors[std::size_t(gate)];
  if (!d.op) return false;
  const bool shut = d.op->phase() == DoorPhase::kClosed || d.op->phase() == DoorPhase::kClosing;
  if (p.operating >= 0 && (p.operating != gate || !shut)) {
    p.operating = -1;  // someone else opened it meanwhile
    return false;
  }
  if (p.operating < 0) {
    if (!p.can_operate || !shut || time < p.operate_retry_at) return false;
    // One operator per door: of the waiting people who can, within reach of the doorway, the
    // one nearest the actuator.
    if ((p.walker.position - d.fixed->centre).norm() > kOperateReachM) return false;
    const double side = (p.walker.position - d.fixed->centre).dot(d.fixed->normal) >= 0 ? 1 : -1;
    const auto spot = ActuatorSpot(gate, side, p.walker.position);
    if (!spot) return false;
    const double mine = (p.walker.position - *spot).norm();
    for (const auto& other : people) {
      if (other.operating == gate) return false;
      // Someone nearer who would go: on this side, within reach (deferring to anyone nearer,
      // whether or not they could go, left a crowd waiting at a shut door for ever).
      if (&other != &p && other.can_operate && !other.state.out && GateDoor(other) == gate &&
          other.state.phase == PersonPhase::kWaitingForDoor && time >= other.operate_retry_at &&
          (other.walker.position - d.fixed->centre).norm() <= kOperateReachM &&
          (other.walker.position - d.fixed->centre).dot(d.fixed->normal) * side >= 0.0 &&
          (other.walker.position - *spot).norm() < mine)
        return false;
    }
    p.operating = gate;
    p.operate_spot = *spot;
    p.operate_elapsed = 0.0;
    p.operate_progress_at = time;
  }
  const double away = (p.walker.position - p.operate_spot).norm();
  // At the actuator (or as near as the queue lets them: within reach and not getting closer).
  const bool there = away < kAtActuatorM || (away < kArmReachM && p.walker.velocity.norm() < 0.05);
  // Kept off the actuator by the queue for too long, or pushed off it part-way through: they
  // give up for a while and someone else (nearer now) may go. (Counting only a wait that never
  // reached it, someone pushed off after a second at it stayed the door's operator for ever,
  // and everyone else waited for them.)
  if (!there && time - p.operate_progress_at > kOperateGiveUpSec) {
    p.operating = -1;
    p.operate_elapsed = 0.0;
    p.operate_retry_at = time + kOperateGiveUpSec;
    return false;
  }
  p.walker.target = p.operate_spot;
  p.walker.final_target = true;
  p.walker.desired_speed = there ? 0.0 : p.speed;
  if (there) {
    p.operate_elapsed += crowd_dt;
    p.operate_progress_at = time;
  }
  if (p.operate_elapsed >= p.operate_time) {
    d.op->Trigger(time);
    ++p.state.doors_operated;
    AddEvent("door_operated", d.fixed->desc->name, p.state.name);
    p.operating = -1;
    p.operate_elapsed = 0.0;
  }
  return true;
}

bool TwinWorld::Impl::DoorwayTaken(const Person& me, int door) const {
  const Door& d = doors[std::size_t(door)];
  const bool evacuee = me.state.behavior == PersonBehavior::kEvacuate;
  const DoorwayFrame frame{d.fixed->centre, d.fixed->normal, d.fixed->along, 0.5 * d.fixed->reach};
  for (const auto& other : people) {
    if (&other == &me || !other.state.started || other.state.out) continue;
    if ((other.walker.position - d.fixed->centre).norm() >= 0.9) continue;
    if (evacuee && !KeepsEvacueeWaiting(frame, me.walker.position, other.walker.position,
                                        other.walker.velocity))
      continue;
    return true;
  }
  return false;
}

std::optional<Eigen::Vector2d> TwinWorld::Impl::ClearOfActuator(const Person& p, int gate) const {
  if (p.can_operate) return std::nullopt;
  const DoorModel& d = *doors[std::size_t(gate)].fixed;
  const double side = (p.walker.position - d.centre).dot(d.normal) >= 0 ? 1 : -1;
  const auto spot = ActuatorSpot(gate, side, p.walker.position);
  if (!spot) return std::nullopt;
  if (const auto aside = OutOfRobotsWayTo(p, gate, *spot, side)) return aside;
  // Out of the way to it as well, square to the door from the room (WaitClearOfActuator).
  const DoorwayFrame frame{d.centre, d.normal, d.along, 0.5 * d.reach};
  const auto to = WaitClearOfActuator(
      frame, side, *spot, p.walker.position,
      kPersonAtActuatorRadiusM + kActuatorClearMarginM + p.walker.radius,
      kActuatorLaneHalfM + p.walker.radius,
      {d.desc->p_WH.head<2>(), d.swing_side, d.reach + p.walker.radius + kSweepMarginM});
  if (!to) return std::nullopt;
  return ClearOfWalls(*to, p.walker.radius);
}

std::optional<Eigen::Vector2d> TwinWorld::Impl::OutOfRobotsWayTo(const Person& p, int gate,
                                                                 const Eigen::Vector2d& spot,
                                                                 double side) const {
  // Two who could not press door_e's button waited across the 2 m corridor before it, the
  // button's lane (square to the door) kept clear, but not the robot's way along the corridor to
  // it: the robot stood 1.3 m from the button for 390 s (clinic two wards seed 54).
  const Eigen::Vector2d p_WB = RobotPose().translation();
  const DoorModel& d = *doors[std::size_t(gate)].fixed;
  if ((p_WB - spot).norm() > kMakeWayForRobotM || (p_WB - d.centre).dot(d.normal) * side <= 0.0)
    return std::nullopt;
  // Aside, square to the robot's way, on their side (AsideOfRobotsWay).
  return AsideOfRobotsWay(
      p.walker.position, p_WB, spot, robot_radius + p.walker.radius + kRobotWayMarginM,
      [&](const Eigen::Vector2d& q) { return ClearOfWalls(q, p.walker.radius); },
      [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return WallBetween(a, b); });
}

void TwinWorld::Impl::GiveWayIfJammed(Person& p) {
  // The jam's front is whoever is nearest the bottleneck: the next doorway of the route (by
  // distance from the door's line), else the waypoint. They keep their drive; whoever presses on
  // them steps back a moment, and so does the column pressing on that one from behind. One
  // bottleneck for all who share it, so two never give way to each other.
  // Before a doorway, an arch of wide bodies (a pushed wheelchair on the axis, two more in the
  // corners beside the jambs heading for the spot it stands on) held everyone still for good:
  // two wards seed 48 (22 residents at the open exit). Ranked by distance from the doorway's
  // centre, the one on the axis went first, but the corner ones stood nearer the door line and
  // kept it there; they stepped away from the centre into the side walls, the five behind held
  // the axis one in place, and the arch stood for 210 s (two wards seed 36, people at 120 Hz).
  // Now a corner one goes first, and the axis one and its column step back square to the door's
  // wall, far enough for a wide body to come across in front of them.
  if (p.state.phase != PersonPhase::kWalking || time < p.give_way_until) return;
  Eigen::Vector2d bottleneck = p.walker.target;
  const DoorModel* door = nullptr;
  const auto doorway = p.doorway_waypoints.lower_bound(p.reached);
  if (doorway != p.doorway_waypoints.end()) {
    door = doors[std::size_t(doorway->second)].fixed;
    bottleneck = door->centre;
  }
  const auto depth = [&](const Person& q) {
    const Eigen::Vector2d r = q.walker.position - bottleneck;
    return door != nullptr ? std::abs(r.dot(door->normal)) : r.norm();
  };
  const auto pressing = [](const Person& a, const Person& b) {
    return (a.walker.position - b.walker.position).norm() - a.walker.radius - b.walker.radius <=
           kPressingGapM;
  };
  const Eigen::Vector2d from_bottleneck = p.walker.position - bottleneck;
  const double mine = depth(p);
  if (from_bottleneck.norm() < 1e-6) return;
  const Eigen::Vector2d back =
      door != nullptr && mine > 1e-6
          ? Eigen::Vector2d(door->normal * std::copysign(1.0, from_bottleneck.dot(door->normal)))
          : Eigen::Vector2d(from_bottleneck.normalized());
  for (const Person& o : people) {
    if (&o == &p || o.state.out || !o.state.started || !pressing(o, p) || depth(o) >= mine)
      continue;
    // Far enough for o to come across in front of them, at least a step.
    const double step = std::max(
        kGiveWayStepM, door != nullptr
                           ? p.walker.radius + o.walker.radius - (mine - depth(o)) + kGiveWayMarginM
                           : 0.0);
    const auto give_way = [&](Person& q, const Person& to) {
      q.give_way_spot = q.walker.position + back * step;
      q.give_way_until = time + kGiveWaySec;
      AddEvent("person_gives_way", q.state.name, to.state.name);
    };
    give_way(p, o);
    std::vector<Person*> column = {&p};
    while (!column.empty()) {
      const Person& q = *column.back();
      column.pop_back();
      for (Person& r : people) {
        if (&r == &q || r.state.out || !r.state.started || r.state.phase != PersonPhase::kWalking ||
            time < r.give_way_until || !pressing(r, q) || depth(r) <= depth(q))
          continue;
        give_way(r, q);
        column.push_back(&r);
      }
    }
    return;
  }
}

void TwinWorld::Impl::FindWayBackThroughDoorway(Person& p) {
  if (p.state.phase != PersonPhase::kWalking || !p.way_back.empty() || time < p.give_way_until)
    return;
  const Eigen::Vector2d& at = p.walker.position;
  const Eigen::Vector2d& to = p.walker.target;
  if (!WallBetween(at, to)) return;
  // Each doorway open enough to pass, its centre within reach: out of it on this side, then on
  // the waypoint's, each leg clear of walls; the shortest such way.
  double best = std::numeric_limits<double>::infinity();
  int best_door = -1;
  for (std::size_t k = 0; k < doors.size(); ++k) {
    if (doors[k].angle < config.door_crossed_open_angle_deg * kDegToRad) continue;
    const DoorModel& d = *doors[k].fixed;
    if ((at - d.centre).norm() > kWayBackReachM) continue;
    const double mine = (at - d.centre).dot(d.normal), theirs = (to - d.centre).dot(d.normal);
    if (mine * theirs >= 0.0) continue;  // the doorway does not lead to the waypoint's side
    const Eigen::Vector2d near = d.centre + d.normal * std::copysign(kOutOfDoorwayM, mine);
    const Eigen::Vector2d far = d.centre + d.normal * std::copysign(kOutOfDoorwayM, theirs);
    const double length = (near - at).norm() + (to - far).norm();
    if (length >= best || WallBetween(at, near) || WallBetween(near, far) || WallBetween(far, to))
      continue;
    best = length;
    best_door = int(k);
    p.way_back = {near, far};
  }
  if (best_door >= 0)
    AddEvent("person_finds_way_back", p.state.name,
             doors[std::size_t(best_door)].fixed->desc->name);
}

}  // namespace egress::twin
