#pragma once
/// @file
/// The laser returns localization may match against the building map. A door's leaf is not on
/// the floor plan (a doorway is a gap in it), so returns off a leaf, wherever it stands, would
/// pull the estimate towards the jambs: passing an open exit with little else in view they
/// turned it 0.4 rad, and pressing a button beside a shut door that opens away from the robot,
/// its leaf filling half the view, they moved it 0.12 m and 3.5 deg (an L-shaped test building
/// with 0.9 m doors, not committed).

#include "egress/behavior/mission_map.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/perception/world_state.h"

namespace egress::behavior::detail {

/// How far past a leaf's reach a return still counts as in its sweep [m].
constexpr double kSweepMarginM = 0.1;
/// A return this near a mapped wall is the wall (kept for localization, in a sweep or not) [m].
constexpr double kWallMatchM = 0.1;
/// Returns this near a door's line, between its jambs, on either side, are its closed leaf (half
/// its 4 cm thickness, range noise and the estimate's own error) [m].
constexpr double kClosedLeafBandM = 0.1;

/// Whether p_M lies within kWallMatchM of an occupied cell of the building map.
bool NearMappedWall(const perception::OccupancyGrid& grid, const Eigen::Vector2d& p_M);

/// `scan` with every return that ends on a door's leaf set to no return (+inf): within
/// kSweepMarginM of the quarter disc the leaf turns through, where it stands at whatever angle;
/// elsewhere on its swing side within its reach but away from the mapped walls (someone in the
/// doorway); and on the door's line between its jambs, where the closed leaf stands, seen from
/// either side. X_ML: the laser in M by the estimate before this scan.
LaserScan WithoutDoorLeaves(const LaserScan& scan, const MissionMap& map, const Pose2& X_ML);

/// Whether p_M lies within `margin` of `door`'s leaf where it was last estimated (the segment
/// from the hinge to the free edge at state.angle) [m]; false for a door never observed.
bool NearEstimatedLeaf(const perception::TrackedDoor& door, const Eigen::Vector2d& p_M,
                       double margin);

}  // namespace egress::behavior::detail
