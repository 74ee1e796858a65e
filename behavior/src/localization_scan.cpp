#include "localization_scan.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/perception/door_estimation.h"

namespace egress::behavior::detail {

bool NearMappedWall(const perception::OccupancyGrid& grid, const Eigen::Vector2d& p_M) {
  const auto& g = grid.geometry();
  const int r = int(std::ceil(kWallMatchM / g.resolution));
  const auto c = g.CellOf(p_M);
  if (!c) return false;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (g.Contains(c->x() + dx, c->y() + dy) &&
          grid.at(c->x() + dx, c->y() + dy) == perception::kLethalCost)
        return true;
    }
  }
  return false;
}

LaserScan WithoutDoorLeaves(const LaserScan& scan, const MissionMap& map, const Pose2& X_ML) {
  LaserScan out = scan;
  const std::vector<Eigen::Vector2d>& u_L = perception::BeamDirections(out);
  const Eigen::Matrix2d R_ML = X_ML.rotation();
  const Eigen::Vector2d p_ML = X_ML.translation();
  // Every test below holds only within the leaf's width and a margin of the hinge (the door
  // line's band reaches sqrt(width² + band²) from it): the rest of the scan skips the door
  // (with a hair more, so rounding never skips a point a test would drop).
  std::vector<double> reach_squared;
  reach_squared.reserve(map.doors.size());
  for (const auto& door : map.doors) {
    const double reach = door.width() + std::max(kSweepMarginM, kClosedLeafBandM) + 1e-6;
    reach_squared.push_back(reach * reach);
  }
  for (std::size_t i = 0; i < out.ranges.size(); ++i) {
    if (!out.IsValidReturn(i)) continue;
    const Eigen::Vector2d p_M = R_ML * (out.ranges[i] * u_L[i]) + p_ML;
    for (std::size_t k = 0; k < map.doors.size(); ++k) {
      const auto& door = map.doors[k];
      const Eigen::Vector2d offset = p_M - door.p_MHinge;
      if (offset.squaredNorm() > reach_squared[k]) continue;  // none of the tests below holds
      const bool in_sweep =
          offset.norm() <= door.width() + kSweepMarginM && offset.dot(door.SwingSide()) > 0.0;
      // The leaf itself, at whatever angle, is dropped near a wall too: by the hinge its returns
      // lie within kWallMatchM of the jamb's wall, and matched to it they pulled the estimate
      // back and round (passing the clinic's open exit: 0.19 m and 4.5 deg in 1.5 s). The closed
      // leaf reaches to within a few centimetres of the jambs: near a wall or not.
      if (door.InLeafReach(p_M, kSweepMarginM) || (in_sweep && !NearMappedWall(map.grid, p_M)) ||
          door.OnDoorLine(p_M, kClosedLeafBandM)) {
        out.ranges[i] = std::numeric_limits<float>::infinity();
        break;
      }
    }
  }
  return out;
}

bool NearEstimatedLeaf(const perception::TrackedDoor& door, const Eigen::Vector2d& p_M,
                       double margin) {
  if (!door.state.observed) return false;
  const Eigen::Vector2d hinge = door.model.p_MHinge;
  const Eigen::Vector2d leaf = door.model.LeafTip(door.state.angle) - hinge;
  const double s = std::clamp((p_M - hinge).dot(leaf) / leaf.squaredNorm(), 0.0, 1.0);
  return (hinge + s * leaf - p_M).norm() <= margin;
}

}  // namespace egress::behavior::detail
