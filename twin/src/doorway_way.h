#pragma once
/// @file
/// Who keeps an evacuee waiting at a doorway they are about to go through: the rule of
/// TwinWorld::Impl::DoorwayTaken for evacuees, as a pure function of the doorway's geometry and
/// the two people's places and the other's velocity (all in W, metres and m/s).

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

}  // namespace egress::twin::world_detail
