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
    // Walking off, not a tracker's wobble: away from where they stood as well as fast, and seen
    // so now (a standing person's track that lost them at the edge of the laser's view, or behind
    // someone, coasts on a step's worth of wobble and walks off on its own).
    const auto& person = entry.person;
    if (s.moving || person.v_MP.norm() <= kMovingMps ||
        (person.p_MP - person.p_MRest).norm() <= kWalkedOffM ||
        ToSeconds(belief.now - person.last_seen) > kSeenMovingWithinSec)
      continue;
    s.moving = true;
    s.mover = StrCat("person ", person.id, " at ", PoseText({person.p_MP.x(), person.p_MP.y(), 0}),
                     ", ", std::round(person.v_MP.norm() * 10) / 10, " m/s");
  }
  // A leaf on the move is drawn in the costmap where the door estimate last put it, which lags
  // the leaf: its returns land off the map, and move (two wards seed 7: door_e's leaf, opening
  // towards the robot at its button, read as someone at the door after each press, and the hold
  // never ran out with everyone through). Returns where a moving leaf sweeps are its own.
  const auto on_moving_leaf = [&](const Eigen::Vector2d& p) {
    for (const auto& d : belief.world.doors)
      if (d.state.observed &&
          (d.state.motion == perception::DoorMotion::kOpening ||
           d.state.motion == perception::DoorMotion::kClosing) &&
          d.model.InSweep(p, kOffMapM))
        return true;
    return false;
  };
  for (const Eigen::Vector2d& p : belief.off_map_returns)
    s.near = s.near || (this_side(p, near_door) && !on_moving_leaf(p));
  for (const Eigen::Vector2d& p : belief.moving_returns) {
    if (s.moving || !this_side(p, near_door) || on_moving_leaf(p)) continue;
    s.moving = true;
    s.mover = StrCat("laser returns moving at ", PoseText({p.x(), p.y(), 0}));
  }
  return s;
}

}  // namespace egress::behavior::detail
