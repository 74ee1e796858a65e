#include "person_behavior.h"

namespace egress::twin::people {

void PersonBehaviorModel::AtRouteEnd(double time, const Door* /*door*/, Person* p,
                                     const EventSink& /*add_event*/) const {
  if (p->state.phase != PersonPhase::kDone) {
    p->state.phase = PersonPhase::kDone;
    if (p->wait_started < 0) p->wait_started = time;
  }
}

void PersonBehaviorModel::AppendDoorway(const Door& door, int door_index, Person* p) {
  const Eigen::Vector2d from = p->route.empty() ? p->walker.position : p->route.back();
  const int saved = p->wait_before_waypoint;
  RouteThroughDoor(door, from, p);
  p->doorway_waypoints[p->wait_before_waypoint] = door_index;
  p->wait_before_waypoint = saved;
}

void PersonBehaviorModel::RouteThroughDoor(const Door& door, const Eigen::Vector2d& start,
                                           Person* p) {
  const DoorModel& d = *door.fixed;
  const double side = (start - d.centre).dot(d.normal) >= 0 ? 1.0 : -1.0;
  // People keep right: wait and leave kKeepRight to the right of the doorway's axis, so two
  // walkers crossing in opposite directions do not meet head-on at its ends. On the side the
  // leaf opens into they wait clear of its sweep (standing in it, they would hold shut the door
  // they wait to see open); evacuees, who meet nobody coming the other way, also keep to its
  // latch side there (the open leaf stands along the hinge side of the way; keeping right
  // towards it, the crowd is pushed round its free edge into the pocket between leaf and wall).
  const Eigen::Vector2d heading = -d.normal * side;
  const Eigen::Vector2d right(heading.y(), -heading.x());
  const bool evacuee = p->state.behavior == PersonBehavior::kEvacuate;
  const auto waypoint = [&](double waypoint_side) {
    const Eigen::Vector2d out = d.normal * waypoint_side;
    if (waypoint_side != d.swing_side)
      return Eigen::Vector2d(d.centre + out * 1.0 + right * kKeepRight);
    const Eigen::Vector2d keep = evacuee ? Eigen::Vector2d(d.along) : right;
    return Eigen::Vector2d(d.centre + out * std::max(1.0, d.reach + kClearOfSweepM) +
                           keep * kKeepRight);
  };
  p->route.push_back(waypoint(side));
  p->wait_before_waypoint = int(p->route.size());
  p->route.push_back(d.centre);
  p->route.push_back(waypoint(-side));
}

}  // namespace egress::twin::people
