#pragma once
// One class per people behaviour (the scenario's `behavior:` of a person): the route a person of
// it walks, and what they do when the route ends and while they rest there. The crowd
// (twin_crowd.cpp) walks everyone with the social force model and asks the behaviour only at
// those points, so adding a behaviour is one new file here plus its name in the scenario parser
// (scenario.h's PersonBehavior, scenario.cpp's name table and MakePersonBehavior).

#include <functional>
#include <memory>
#include <string>

#include "../twin_world_impl.h"

namespace egress::twin::people {

using Person = world_detail::Person;
using Door = world_detail::Door;
using DoorModel = world_detail::DoorModel;
/// Raises a run event (kind, subject, detail).
using EventSink = std::function<void(const std::string&, const std::string&, const std::string&)>;

class PersonBehaviorModel {
 public:
  virtual ~PersonBehaviorModel() = default;
  /// How many people one scenario entry stands for (a group stands in a grid around its start).
  virtual int GroupSize(const PersonSpec& /*spec*/) const { return 1; }
  /// Whether the person holds a door open (draws the scenario's hold-angle range).
  virtual bool HoldsDoor() const { return false; }
  /// The waypoints from where `p` stands (its door, if the spec names one, is `door`); a route
  /// through a doorway sets p->wait_before_waypoint to the doorway centre's index.
  virtual void PlanRoute(const PersonSpec& spec, const Door* door, Person* p) const = 0;
  /// The route is walked (called each step while it is empty and the person is not resting).
  virtual void AtRouteEnd(double time, const Door* door, Person* p,
                          const EventSink& add_event) const;
  /// Each step while resting (holding a door, or standing): whether and where they move on.
  virtual void WhileResting(double /*time*/, const PersonSpec* /*spec*/, const Door* /*door*/,
                            Person* /*p*/, const EventSink& /*add_event*/) const {}
  /// Appends the waypoints through `door` (index `door_index` in the run) from the route's end
  /// (or where `p` stands), its centre recorded in p->doorway_waypoints: a multi-door route.
  static void AppendDoorway(const Door& door, int door_index, Person* p);

 protected:
  /// Waypoints through `door`'s doorway from `start`: kKeepRight to the right of its axis 1 m
  /// before, its centre, 1 m beyond.
  static void RouteThroughDoor(const Door& door, const Eigen::Vector2d& start, Person* p);
};

/// The behaviour named by `kind` (defined next to the scenario parser's name table).
std::unique_ptr<PersonBehaviorModel> MakePersonBehavior(PersonBehavior kind);

}  // namespace egress::twin::people
