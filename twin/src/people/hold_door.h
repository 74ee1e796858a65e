#pragma once
#include "person_behavior.h"

namespace egress::twin::people {

/// Walks to beside its door's hinge jamb (on its own side, out of the doorway), holds the leaf
/// open there at its hold angle for `hold_duration` seconds, then lets go and walks to its goal.
class HoldDoor final : public PersonBehaviorModel {
 public:
  bool HoldsDoor() const override { return true; }
  void PlanRoute(const PersonSpec& /*spec*/, const Door* door, Person* p) const override {
    const DoorModel& d = *door->fixed;
    const double side = (p->walker.position - d.centre).dot(d.normal) >= 0 ? 1.0 : -1.0;
    p->route.push_back(d.desc->p_WH.head<2>() - d.along * 0.45 + d.normal * side * 0.45);
  }
  void AtRouteEnd(double time, const Door* door, Person* p,
                  const EventSink& add_event) const override {
    if (p->hold_started < 0) {
      p->state.phase = PersonPhase::kHolding;
      p->hold_started = time;
      add_event("person_holding_door", p->state.name, door->fixed->desc->name);
      return;
    }
    PersonBehaviorModel::AtRouteEnd(time, door, p, add_event);
  }
  void WhileResting(double time, const PersonSpec* spec, const Door* door, Person* p,
                    const EventSink& add_event) const override {
    if (p->state.phase != PersonPhase::kHolding || time - p->hold_started < p->hold_duration)
      return;
    p->state.phase = PersonPhase::kWalking;
    add_event("person_released_door", p->state.name, door->fixed->desc->name);
    if (spec != nullptr && (spec->goal - p->walker.position).norm() > 0.3)
      p->route.push_back(spec->goal);
  }
};

}  // namespace egress::twin::people
