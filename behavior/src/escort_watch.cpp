#include "escort_watch.h"

#include <cmath>

#include "task_node_support.h"

namespace egress::behavior::detail {

Surroundings LookAround(const Belief& belief, const DoorPass& pass, double watch_radius,
                        double near_door) {
  const auto this_side = [&](const Eigen::Vector2d& p, double radius) {
    const Eigen::Vector2d d = p - pass.centre;
    return d.dot(pass.n_M) > -kThroughM && d.norm() < radius;
  };
  Surroundings s;
  for (const auto& entry : belief.world.people) {
    if (!this_side(entry.person.p_MP, watch_radius)) continue;
    s.near = true;
    // Walking off, not a tracker's wobble: away from where they stood as well as fast.
    const auto& person = entry.person;
    if (s.moving || person.v_MP.norm() <= kMovingMps ||
        (person.p_MP - person.p_MRest).norm() <= kWalkedOffM)
      continue;
    s.moving = true;
    s.mover = StrCat("person ", person.id, " at ", PoseText({person.p_MP.x(), person.p_MP.y(), 0}),
                     ", ", std::round(person.v_MP.norm() * 10) / 10, " m/s");
  }
  for (const Eigen::Vector2d& p : belief.off_map_returns)
    s.near = s.near || this_side(p, near_door);
  for (const Eigen::Vector2d& p : belief.moving_returns) {
    if (s.moving || !this_side(p, near_door)) continue;
    s.moving = true;
    s.mover = StrCat("laser returns moving at ", PoseText({p.x(), p.y(), 0}));
  }
  return s;
}

}  // namespace egress::behavior::detail
