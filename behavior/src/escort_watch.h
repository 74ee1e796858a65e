#pragma once
// Internal to behavior/src: what the escort's nodes (escort_nodes.cpp) see round a door they
// hold for the residents being evacuated — who is near it on the robot's side, and whether anyone
// is coming.

#include <string>

#include "egress/behavior/belief.h"
#include "egress/behavior/door_rules.h"

namespace egress::behavior::detail {

/// [m] A person on the far side of the door line by more than this is through.
inline constexpr double kThroughM = 0.3;
/// [m/s] A tracked person faster than this is on the move.
inline constexpr double kMovingMps = 0.2;
/// [m] A tracked person this far from where they last stood (and on the move) walked off.
inline constexpr double kWalkedOffM = 0.3;
/// [s] A tracked person counts as on the move only if a sensor measured them this recently (2
/// laser frames and a half): a track out of view coasts on its last velocity, and that is the
/// tracker's guess, not someone seen walking.
inline constexpr double kSeenMovingWithinSec = 0.25;

/// [s] Someone near on the move this long on end (gaps under kStirGapSec) came: a stir in a group
/// standing about (tracks hopping between neighbours) lasted up to 2.1 s (27 runs of the office,
/// atrium and two wards before their alarms: 122 stirs, 5 over 1 s); residents walking to the
/// door from the watch radius, several seconds.
inline constexpr double kComingForSec = 2.5;
inline constexpr double kStirGapSec = 0.35;

/// Who is near a door on the robot's side (or in its doorway), and whether anyone there is on
/// the move.
struct Surroundings {
  bool near{false};
  bool moving{false};
  std::string mover;  ///< who or what moved first, for the notes
};

/// Tracked people within `watch_radius` [m] of the doorway on `pass`'s side (moving: faster than
/// kMovingMps, kWalkedOffM from where they last stood, and measured within
/// kSeenMovingWithinSec) and the laser's returns off the map within `near_door` [m] (moving:
/// Belief::moving_returns), but for those where a leaf estimated opening or closing sweeps (the
/// leaf itself, drawn in the costmap behind it). The laser sees all round, the camera
/// only ahead. (Furniture off the map near a door counts as someone near: such a door is held until
/// max_hold.)
Surroundings LookAround(const Belief& belief, const DoorPass& pass, double watch_radius,
                        double near_door);

/// Who stands by `pass`'s doorway on the robot's side: each tracked person within 1.5 m (plus a
/// body of `person_radius`) of the doorway's centre, and each laser return off the map on a body
/// that does — the returns linked to one within 1.5 m by steps of under 0.15 m (one body's
/// outline; its far side may be further out), or on such a tracked person's body. And whether
/// anyone else stands on this side within `radius` of p_MS (the standoff) [m]: tracked people,
/// and returns off the map other than those within 0.3 m of a mapped wall or leaf (a wall seen a
/// little off from metres away).
struct AtTheDoorway {
  bool someone{false};  ///< someone stands by the doorway
  bool alone{true};     ///< nobody else is within the radius of the standoff
  bool only{false};     ///< both: those near are waiting at the door
};
AtTheDoorway ByTheDoorway(const Belief& belief, const DoorPass& pass, const Eigen::Vector2d& p_MS,
                          double radius, double person_radius);

}  // namespace egress::behavior::detail
