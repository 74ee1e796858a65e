#include "doorway_way.h"

#include <cmath>

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

}  // namespace egress::twin::world_detail
