#pragma once
#include "person_behavior.h"

namespace egress::twin::people {

/// Walks its `via` points to its goal (no door), then is done.
class WalkPast : public PersonBehaviorModel {
 public:
  void PlanRoute(const PersonSpec& spec, const Door* /*door*/, Person* p) const override {
    for (const auto& v : spec.via)
      p->route.push_back(v);
    p->route.push_back(spec.goal);
  }
};

}  // namespace egress::twin::people
