#pragma once
#include "walk_past.h"

namespace egress::twin::people {

/// Walks to its goal as WalkPast, then stands there (a responder waiting for what the robot
/// brings, someone talking in a doorway) for `hold_duration` seconds (0: for good), then walks
/// to `leave` if the spec gives it, else stays.
class ApproachAndWait final : public WalkPast {
 public:
  void AtRouteEnd(double time, const Door* /*door*/, Person* p,
                  const EventSink& /*add_event*/) const override {
    if (p->state.phase == PersonPhase::kDone) return;
    p->state.phase = PersonPhase::kStanding;
    if (p->wait_started < 0) p->wait_started = time;
  }
  void WhileResting(double time, const PersonSpec* spec, const Door* /*door*/, Person* p,
                    const EventSink& /*add_event*/) const override {
    if (p->state.phase == PersonPhase::kStanding && p->wait_started >= 0 &&
        time - p->wait_started >= p->hold_duration && p->hold_duration > 0) {
      if (spec != nullptr && spec->leave) {
        p->state.phase = PersonPhase::kWalking;
        p->route.push_back(*spec->leave);
        p->hold_duration = 0.0;  // where they went, they stay

      } else {
        p->state.phase = PersonPhase::kDone;
      }
    }
  }
};

}  // namespace egress::twin::people
