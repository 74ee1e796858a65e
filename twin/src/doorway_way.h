#pragma once
/// @file
/// Evacuees at a doorway, as pure functions of its geometry and people's places (all in W,
/// metres and m/s): who keeps an evacuee waiting at a doorway they are about to go through (the
/// rule of TwinWorld::Impl::DoorwayTaken for evacuees), and where someone who cannot operate a
/// shut door waits clear of its actuator (TwinWorld::Impl::ClearOfActuator) and of the robot's
/// way to it (TwinWorld::Impl::OutOfRobotsWayTo).

#include <functional>
#include <optional>

#include <Eigen/Core>

namespace egress::twin::world_detail {

/// A doorway's place in W: its centre on the door line, the door line's unit normal, the unit
/// direction along it, and half the width of its opening [m].
struct DoorwayFrame {
  Eigen::Vector2d p_WD{Eigen::Vector2d::Zero()};
  Eigen::Vector2d normal{Eigen::Vector2d::UnitY()};
  Eigen::Vector2d along{Eigen::Vector2d::UnitX()};
  double half_width{0.475};
};

/// Beyond a doorway, someone walking back towards it faster than this keeps an evacuee waiting
/// at it [m/s]; on the evacuee's side, or beyond it walking on away from it this fast, nobody
/// does.
constexpr double kComingBackMps = 0.2;
/// Beyond a doorway, someone within this of its door line, between its jambs, stands in its
/// opening and keeps an evacuee waiting [m].
constexpr double kInOpeningM = 0.4;

/// Whether someone at `p_WO` moving at `v_WO`, near the doorway `d`, keeps an evacuee at `p_WE`
/// (about to go through it) waiting. In an evacuation people go through one behind the other:
/// only someone coming the other way does — beyond the door, walking back towards it or
/// standing in its opening. Someone there walking along a corridor past it, or standing clear of
/// its opening, does not (clinic two wards seed 2, with the robot: a resident who had just come
/// through door_a turned along the corridor 0.7 m beyond it, and a wheelchair user at its
/// closing leaf, 67 degrees open, waited for them until it shut; unable to operate it, they
/// were left behind).
bool KeepsEvacueeWaiting(const DoorwayFrame& d, const Eigen::Vector2d& p_WE,
                         const Eigen::Vector2d& p_WO, const Eigen::Vector2d& v_WO);

/// A door's leaf, for whoever keeps out of its sweep: its hinge, the side of the door line it
/// swings to (+1 along the doorway's normal, -1 against it, 0 for a sliding leaf) and how far from
/// the hinge is clear of it for the one keeping out (the leaf's reach, their body and a margin)
/// [m].
struct LeafSweep {
  Eigen::Vector2d p_WH{Eigen::Vector2d::Zero()};
  double swing_side{0.0};
  double clear_radius{0.0};
};

/// Where someone at `p_WP`, waiting on the `side` (+1 or -1 along d.normal) of a shut door whose
/// actuator they cannot operate, waits instead, so that whoever can (a resident, the robot) may
/// stand at `p_WS`, the spot before the actuator, and get there:
/// - within `lane_half` of the spot along the door line, further out into the room than it (on
///   the way to it, square to the door from the room) or within `keep` of it (between it and
///   its wall, where stepping straight away from it walks into the wall): across that lane, on
///   the doorway's side, at their distance from the door line, or out of the `leaf`'s sweep if
///   it swings to their side;
/// - else within `keep` of the spot: `keep` from it, straight away;
/// - else (or with the spot on the doorway's axis) nowhere else: nullopt.
/// Walls are the caller's (the point may be in one).
std::optional<Eigen::Vector2d> WaitClearOfActuator(const DoorwayFrame& d, double side,
                                                   const Eigen::Vector2d& p_WS,
                                                   const Eigen::Vector2d& p_WP, double keep,
                                                   double lane_half, const LeafSweep& leaf);

/// Where someone at `p_WP` steps to, out of the robot's straight way from `p_WB` to the spot
/// `p_WS` before an actuator, to stand `keep` from it [m]: square to the way, on the side they
/// stand, moved out of any wall by `clear_of_walls`; on the other side if that point is still
/// nearer the way than `keep` (less 2 cm). Nullopt if they stand `keep` or more from the way
/// already, or the robot is at the spot, or a wall (`wall_between`, from them to the point) is
/// between them and the point: cleared of the walls, a point in one may come out on its far
/// side, and they stay on their side, out of the way of whoever comes to operate the door.
std::optional<Eigen::Vector2d> AsideOfRobotsWay(
    const Eigen::Vector2d& p_WP, const Eigen::Vector2d& p_WB, const Eigen::Vector2d& p_WS,
    double keep, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& clear_of_walls,
    const std::function<bool(const Eigen::Vector2d&, const Eigen::Vector2d&)>& wall_between);

}  // namespace egress::twin::world_detail
