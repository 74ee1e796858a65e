#pragma once
/// @file
/// The laser returns localization may match against the building map. A door's leaf is not on
/// the floor plan (a doorway is a gap in it), so returns off a leaf in its sweep would pull the
/// estimate towards the jambs: passing an open exit with little else in view they turned it
/// 0.4 rad.

#include "egress/behavior/mission_map.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress::behavior::detail {

/// How far past a leaf's reach a return still counts as in its sweep [m].
constexpr double kSweepMarginM = 0.1;
/// A return this near a mapped wall is the wall (kept for localization, in a sweep or not) [m].
constexpr double kWallMatchM = 0.1;

/// Whether p_M lies within kWallMatchM of an occupied cell of the building map.
bool NearMappedWall(const perception::OccupancyGrid& grid, const Eigen::Vector2d& p_M);

/// The scan without the returns that end inside a door's sweep (the quarter disc its leaf turns
/// through, on the side it opens into) away from the mapped walls: there a return is the leaf
/// at whatever angle it stands, or someone in the doorway, not the floor plan. X_ML: the laser
/// in M by the estimate before this scan.
LaserScan WithoutDoorSweeps(const LaserScan& scan, const MissionMap& map, const Pose2& X_ML);

}  // namespace egress::behavior::detail
