#pragma once
// Synthetic sensor data for the perception tests and benchmarks: scans ray-cast in a grid, a
// two-room map with a doorway.

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/sensor_types.h"
#include "egress/perception/occupancy_grid.h"

namespace egress::perception::testing {

/// An HSR-like laser: `beams` over 270 degrees.
inline LaserScan MakeScan(int beams, double range_max = 20.0) {
  LaserScan scan;
  scan.angle_min = -0.75 * std::numbers::pi;
  scan.angle_increment = 1.5 * std::numbers::pi / (beams - 1);
  scan.range_min = 0.05;
  scan.range_max = range_max;
  scan.ranges.assign(std::size_t(beams), std::numeric_limits<float>::infinity());
  return scan;
}

/// Fills `scan` by ray casting `grid` from the laser pose X_ML.
inline void CastScan(const OccupancyGrid& grid, const Pose2& X_ML, LaserScan* scan) {
  for (std::size_t i = 0; i < scan->ranges.size(); ++i) {
    const auto hit =
        RayCast(grid, X_ML.translation(), X_ML.yaw + scan->AngleAt(i), scan->range_max);
    scan->ranges[i] = hit ? float(*hit) : std::numeric_limits<float>::infinity();
  }
}

/// A disc at laser height (a leg, a body section) for CastScanAtDiscs.
struct Disc {
  Eigen::Vector2d centre;
  double radius;
};

/// Fills `scan` with the nearest hit of each beam on `discs` (and on `grid` if given) from the
/// laser pose X_ML; beams that hit nothing keep +inf.
inline void CastScanAtDiscs(const std::vector<Disc>& discs, const Pose2& X_ML, LaserScan* scan,
                            const OccupancyGrid* grid = nullptr) {
  const Eigen::Vector2d origin = X_ML.translation();
  for (std::size_t i = 0; i < scan->ranges.size(); ++i) {
    const double angle = X_ML.yaw + scan->AngleAt(i);
    const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
    double best = std::numeric_limits<double>::infinity();
    if (grid != nullptr) {
      if (const auto hit = RayCast(*grid, origin, angle, scan->range_max)) best = *hit;
    }
    for (const Disc& disc : discs) {
      // |origin + t d - c|^2 = r^2, nearest t > 0.
      const Eigen::Vector2d f = origin - disc.centre;
      const double b = f.dot(d);
      const double c = f.squaredNorm() - disc.radius * disc.radius;
      const double discriminant = b * b - c;
      if (discriminant < 0.0) continue;
      const double t = -b - std::sqrt(discriminant);
      if (t > 0.0 && t < best) best = t;
    }
    scan->ranges[i] =
        best <= scan->range_max ? float(best) : std::numeric_limits<float>::infinity();
  }
}

/// 12 m x 8 m: two rooms split at x = 6 by a wall with a 1 m doorway at y in [3.5, 4.5], and
/// furniture that breaks the symmetry.
inline OccupancyGrid TwoRoomMap() {
  std::vector<Box2> walls = {
      {{6.0, 0.05, 0.0}, {12.0, 0.1}}, {{6.0, 7.95, 0.0}, {12.0, 0.1}},  // south, north
      {{0.05, 4.0, 0.0}, {0.1, 8.0}},  {{11.95, 4.0, 0.0}, {0.1, 8.0}},  // west, east
      {{6.0, 1.75, 0.0}, {0.1, 3.5}},  {{6.0, 6.25, 0.0}, {0.1, 3.5}},   // divider around the door
      {{2.0, 6.5, 0.0}, {1.2, 0.6}},   {{9.5, 1.5, 0.5}, {1.0, 0.8}},    // a table, a cabinet
      {{3.5, 2.0, 0.0}, {0.4, 0.4}},   {{10.5, 6.0, 0.0}, {0.6, 1.4}},
  };
  return OccupancyGrid::FromBoxes(walls, {0.0, 0.0}, {12.0, 8.0}, 0.05);
}

}  // namespace egress::perception::testing
