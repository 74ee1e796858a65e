#include "scenario_poses.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "egress/twin/scenario.h"

namespace egress::twin {
namespace {

// A robot's or person's place may lie outside the walls' bounds by at most this [m] (a goal
// outside the exit door is fine; one 50 m off is a typo, and the run would only find out at its
// time limit).
constexpr double kPoseOutsideWallsMaxM = 5.0;

// The static box or upright cylinder whose floor outline holds p, or null. Meshes are skipped:
// their outline is only their bounds, which may cover free floor.
const ShapeDescription* ShapeHolding(const WorldDescription& world, const Eigen::Vector2d& p) {
  for (const auto& shape : world.shapes) {
    if (shape.kind != ShapeKind::kBox && shape.kind != ShapeKind::kCylinder) continue;
    const auto f = CalcFloorFootprint(shape);
    if (!f) continue;
    if (shape.kind == ShapeKind::kCylinder) {
      if ((p - Eigen::Vector2d(f->X_WF.x, f->X_WF.y)).norm() < shape.radius) return &shape;
      continue;
    }
    const Eigen::Vector2d q = f->X_WF.Inverse() * p;
    if (std::abs(q.x()) < 0.5 * f->size.x() && std::abs(q.y()) < 0.5 * f->size.y()) return &shape;
  }
  return nullptr;
}

}  // namespace

// A start, goal or waypoint: on the floor, not inside a wall, not far outside the building.
void CheckOnTheFloor(const WorldDescription& world, const std::string& where,
                     const std::string& field, const std::string& place, const Pose2& X_WB) {
  const std::string what =
      StrCat(where, ": field '", field, "'", place.empty() ? "" : " (place '" + place + "')", ": (",
             X_WB.x, ", ", X_WB.y, ")");
  if (const ShapeDescription* shape = ShapeHolding(world, {X_WB.x, X_WB.y}))
    throw LoadError(StrCat(what, " is inside model '", shape->model, "'"));
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const FloorFootprint& f : CalcFloorFootprints(world)) {
    for (const double sx : {-0.5, 0.5}) {
      for (const double sy : {-0.5, 0.5}) {
        const Eigen::Vector2d corner = f.X_WF * Eigen::Vector2d(sx * f.size.x(), sy * f.size.y());
        lo = lo.cwiseMin(corner);
        hi = hi.cwiseMax(corner);
      }
    }
  }
  if (!(lo.x() <= hi.x())) return;  // no walls: nothing to be outside of
  const Eigen::Vector2d p(X_WB.x, X_WB.y);
  const double outside = (p - p.cwiseMax(lo).cwiseMin(hi)).norm();
  if (outside > kPoseOutsideWallsMaxM)
    throw LoadError(StrCat(what, " is ", outside, " m outside the building's walls (x ", lo.x(),
                           "..", hi.x(), ", y ", lo.y(), "..", hi.y(), " m; at most ",
                           kPoseOutsideWallsMaxM, " m allowed)"));
}

Pose2 OffScenePose(const WorldDescription& world) {
  double max_x = 0.0;
  for (const auto& f : CalcFloorFootprints(world))
    max_x = std::max(max_x, f.X_WF.x + f.size.norm());
  return {max_x + kOffSceneDistanceM, 0.0, 0.0};
}

}  // namespace egress::twin
