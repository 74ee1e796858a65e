#include "doorway_way.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/geometry.h"

namespace egress::twin::world_detail {

bool KeepsEvacueeWaiting(const DoorwayFrame& d, const Eigen::Vector2d& p_WE,
                         const Eigen::Vector2d& p_WO, const Eigen::Vector2d& v_WO) {
  const double my_side = (p_WE - d.p_WD).dot(d.normal) >= 0.0 ? 1.0 : -1.0;
  // Through the doorway, away from the evacuee's side.
  const Eigen::Vector2d my_heading = -d.normal * my_side;
  const Eigen::Vector2d rel = p_WO - d.p_WD;
  const double side = rel.dot(d.normal);
  const double onward = v_WO.dot(my_heading);
  // On the evacuee's side (ahead of them in the queue), or going on the way they go.
  if (side * my_side > 0.0 || onward > kComingBackMps) return false;
  const bool coming_back = onward < -kComingBackMps;
  const bool in_opening =
      std::abs(side) <= kInOpeningM && std::abs(rel.dot(d.along)) <= d.half_width;
  return coming_back || in_opening;
}

std::optional<Eigen::Vector2d> WaitClearOfActuator(const DoorwayFrame& d, double side,
                                                   const Eigen::Vector2d& p_WS,
                                                   const Eigen::Vector2d& p_WP, double keep,
                                                   double lane_half, const LeafSweep& leaf) {
  const Eigen::Vector2d away = p_WP - p_WS;
  // The way to it, square to the door from the room: waiting in the middle of a 2 m corridor,
  // 1.4 m before the exit door (out of its leaf's sweep), a wheelchair user left 0.5 m by the
  // wall to its button, and nobody could get by to press it (clinic room A seeds 11, 22). They
  // wait across the lane, on the doorway's side of it. So too someone within `keep` of the spot
  // on the wall's side of it: stepping straight away from the spot walked them into the wall,
  // which held them where they were (atrium west seed 36: a wheelchair user shut out waited
  // 0.07 m from the plate's spot, between it and the wall, for 330 s, and the robot never found
  // the plate's standoff free).
  const Eigen::Vector2d along(-d.normal.y(), d.normal.x());
  const double u_spot = (p_WS - d.p_WD).dot(along);
  const double u = (p_WP - d.p_WD).dot(along);
  const double out_spot = (p_WS - d.p_WD).dot(d.normal) * side;
  const double out = (p_WP - d.p_WD).dot(d.normal) * side;
  if ((out > out_spot || away.norm() < keep) && std::abs(u - u_spot) < lane_half &&
      std::abs(u_spot) > 1e-3) {
    const double u_clear = u_spot - std::copysign(lane_half, u_spot);
    // Across the lane may be beside the hinge: out of the sweep of a leaf that opens towards
    // them, further back if need be (beside the clinic's exit hinge, waiting there, two held its
    // leaf shut and 15 were left behind: two wards seed 21).
    double out_clear = out;
    if (leaf.swing_side * side > 0.0) {
      const double du = u_clear - (leaf.p_WH - d.p_WD).dot(along);
      if (std::abs(du) < leaf.clear_radius)
        out_clear = std::max(out, std::sqrt(leaf.clear_radius * leaf.clear_radius - du * du));
    }
    return p_WP + along * (u_clear - u) + d.normal * side * (out_clear - out);
  }
  if (away.norm() >= keep || away.norm() <= 1e-6) return std::nullopt;
  return p_WS + away.normalized() * keep;
}

std::optional<Eigen::Vector2d> AsideOfRobotsWay(
    const Eigen::Vector2d& p_WP, const Eigen::Vector2d& p_WB, const Eigen::Vector2d& p_WS,
    double keep, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& clear_of_walls,
    const std::function<bool(const Eigen::Vector2d&, const Eigen::Vector2d&)>& wall_between) {
  const Eigen::Vector2d foot = egress::ClosestPointOnSegment(p_WP, p_WB, p_WS);
  const Eigen::Vector2d off = p_WP - foot;
  if (off.norm() >= keep || (foot - p_WB).norm() < 1e-6) return std::nullopt;
  const Eigen::Vector2d way = (p_WS - p_WB).normalized();
  Eigen::Vector2d across(-way.y(), way.x());
  if (across.dot(off) < 0.0) across = -across;
  for (const double s : {1.0, -1.0}) {
    const Eigen::Vector2d target = clear_of_walls(foot + across * s * keep);
    // Atrium west seed 36: the way ran along the wall; a wheelchair user who could not operate
    // the door made for a point beyond it, and stood pressed against it on the plate's spot for
    // 330 s. Crossing the way instead, they kept the next resident who could operate the door
    // from it (office seed 71: 110 s to 189 s).
    if (wall_between(p_WP, target)) return std::nullopt;
    if ((target - egress::ClosestPointOnSegment(target, p_WB, p_WS)).norm() > keep - 0.02)
      return target;
  }
  return std::nullopt;
}

}  // namespace egress::twin::world_detail
