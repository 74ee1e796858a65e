#pragma once
/// @file
/// RoutePlanner: the building-scale route from where the robot is to a goal, over the floor
/// plan with every door passable, and the doors on it in order, each with the poses the robot
/// needs there: where to wait before it (outside the leaf's sweep when the leaf opens towards
/// the robot, with the door in view) and where it comes out beyond it. The route is a plan of
/// legs, not a path to follow: the base planner drives each leg on the live costmap. A pure
/// function of the map and the request (grid A*, no sampling).

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/perception/costmap.h"
#include "egress/perception/occupancy_grid.h"

namespace egress::planning {

struct RoutePlannerConfig {
  /// Cells closer than this to a wall are not on any route [m]: the footprint radius plus a
  /// little (a corridor narrowed to just above the robot's width must still pass).
  double clearance{0.24};
  /// Extra cost per metre of route for running close to walls: keeps the route in the middle
  /// of corridors and doorways. Weighted by (comfort − distance) for cells nearer than comfort.
  double wall_cost{4.0};
  double comfort_distance{0.6};  ///< [m]
  /// How far before a door the robot waits for it [m] (door in view, actuator in reach of a
  /// short drive) — farther when the leaf opens towards it: the leaf's reach plus sweep_margin.
  double approach_distance{1.2};
  double sweep_margin{0.35};  ///< [m] beyond the leaf's reach
  double exit_distance{0.9};  ///< [m] beyond the door line on the far side
  /// A robot already this near a door on the route's side, in front of the opening and out of
  /// the leaf's sweep, need not drive to the approach pose first [m] (from the door's centre).
  double near_door_distance{3.0};
  /// How far a start or goal that lies within `clearance` of a wall may be moved to free space
  /// [m]; beyond that the request fails.
  double snap_distance{0.3};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// One door on a route.
struct RouteLeg {
  std::string door;
  Pose2 X_MB_approach;  ///< Where to wait before the door, facing it.
  Pose2 X_MB_exit;      ///< Beyond it on the route's side, facing on.
  /// The leaf opens towards the side the robot comes from (it must wait outside its sweep).
  bool opens_towards_robot{false};
  double distance_along{0.0};  ///< Route length from the start to the door line [m].
};

struct Route {
  std::vector<Eigen::Vector2d> path;  ///< Cell centres, start to goal, string-pulled [m].
  double length{0.0};                 ///< [m]
  std::vector<RouteLeg> legs;         ///< The doors crossed, in order.
  Pose2 X_MB_goal;                    ///< The goal (moved to free space if it had to be).
};

struct RouteResult {
  std::optional<Route> route;
  std::string message;  ///< Why there is no route (names the start, the goal or the doors).
  bool ok() const { return route.has_value(); }
};

class RoutePlanner {
 public:
  /// @throws InvalidArgument for an empty grid, a bad config or a door with coincident jambs.
  RoutePlanner(const perception::OccupancyGrid& grid, std::vector<perception::Doorway> doors,
               RoutePlannerConfig config = {});

  /// The route from `X_MB_start` to `X_MB_goal` through any door but those in `avoid`
  /// (locked, blocked). A start or goal off the map, inside a wall, or not connected gives no
  /// route and a message saying which.
  RouteResult Plan(const Pose2& X_MB_start, const Pose2& X_MB_goal,
                   const std::set<std::string>& avoid = {}) const;

  /// Distance from `p_M` to the nearest occupied cell [m] (0 inside one, large off the map).
  double ClearanceAt(const Eigen::Vector2d& p_M) const;

 private:
  perception::OccupancyGrid grid_;
  std::vector<perception::Doorway> doors_;
  RoutePlannerConfig config_;
  std::vector<float> distance_;  // per cell: distance to the nearest occupied cell [m]
};

}  // namespace egress::planning
