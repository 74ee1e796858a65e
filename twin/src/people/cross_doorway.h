#pragma once
#include "person_behavior.h"

namespace egress::twin::people {

/// Walks its `via` points, through its door's doorway (waiting before it while the leaf is not
/// open enough or someone else is in it), on to its goal.
class CrossDoorway : public PersonBehaviorModel {
 public:
  void PlanRoute(const PersonSpec& spec, const Door* door, Person* p) const override {
    for (const auto& v : spec.via)
      p->route.push_back(v);
    RouteThroughDoor(*door, p->walker.position, p);
    p->route.push_back(spec.goal);
  }
};

}  // namespace egress::twin::people
