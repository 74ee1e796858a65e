#pragma once
/// @file
/// Door rules: the geometry of a door as the robot approaches it, who is in its zone, and
/// whether its leaf and its operator's hold window leave the robot time to pass. Shared by the
/// executive (door zones for the preemption figure) and the door task nodes.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "egress/behavior/task_services.h"

namespace egress::behavior {

/// Geometry of one door as the robot approaches it.
struct DoorPass {
  Eigen::Vector2d centre;  ///< Middle of the opening [m].
  Eigen::Vector2d n_M;     ///< Unit normal of the door line pointing to the robot's side.
  double width{0.0};
};
/// @throws InvalidArgument for an unknown door id.
DoorPass CalcDoorPass(const MissionMap& map, const std::string& door, const Pose2& X_MB);
/// The same, with the normal pointing to the side the robot approached the door from, if
/// `visit` (a visit to this door) remembers one, else the side it is on now.
DoorPass CalcKnownPass(const TaskServices& task, const std::string& door, const DoorVisit* visit);
/// CalcKnownPass, remembering the side in `visit` the first time (the robot's side now).
DoorPass CalcApproachPass(const TaskServices& task, DoorVisit& visit);

/// True when `entry` holds `door` open standing out of the robot's lane through it: the strip
/// through the opening's middle, as wide as the footprint plus the person. Someone standing in
/// that lane blocks the way whatever the tracker reads as their intent (a person stopped in the
/// doorway face to face with the robot is still, next to an open leaf, and not holding it).
bool IsHoldingDoorAside(const TaskServices& task, const perception::TrackedPersonWithIntent& entry,
                        const std::string& door);
/// Whether a robot standing at p_MB would be in a door's way: within config.zone_depth of a
/// door line (and half a metre beside its opening), or where a door's leaf sweeps (with the
/// leaf clearance). A retreat ends outside them; the executive's last safe pose is outside.
bool IsInAnyDoorZone(const TaskServices& task, const Eigen::Vector2d& p_MB);
/// Whether the straight way from p_MFrom to p_MTo passes through a doorway: crosses a door's
/// line between its jambs (an end on the line counts).
bool PassesThroughAnyDoorway(const TaskServices& task, const Eigen::Vector2d& p_MFrom,
                             const Eigen::Vector2d& p_MTo);
/// True when a person (not one holding this door aside) is in, or forecast into, the zone of
/// `door`; or crossing it (TaskConfig::yield_to_crossing); or, on its far side, waiting for it
/// while its opening is young (TaskConfig::right_of_way_time).
bool IsDoorZoneOccupied(const TaskServices& task, const std::string& door);
/// True when someone (not holding `door` aside) would come within config.passage_clearance of
/// the middle of its opening within `horizon` [s], walking on at the velocity they are tracked
/// at: a robot passing the door in that time would be in the doorway beside them.
bool IsPassageBusy(const TaskServices& task, const std::string& door, double horizon);
/// IsPassageBusy false over `horizon` [s], and nobody within config.passage_clearance of the
/// opening's middle for at least `quiet_for` [s], by the belief's passage_used_at.
bool IsPassageClear(const TaskServices& task, const std::string& door, double horizon,
                    double quiet_for);
/// The zone of `door` has been free of people (IsDoorZoneOccupied false) for at least
/// `clear_for` [s], by the belief's zone_occupied_at.
bool IsDoorZoneClearFor(const TaskServices& task, const std::string& door, double clear_for);
/// The leaf leaves room for the footprint (plus `margin`) [m], is not closing, and — unless a
/// person holds it aside — the operator's hold window (from the robot's own press, or from when
/// it was first seen open; `visit` holds the robot's own press) leaves time to drive clear of the
/// leaf: past the line for a leaf that opens towards the robot (which then still has the time the
/// closing leaf takes to reach its lane), beyond the sweep on the far side otherwise. Needs
/// `task.motion` (door speed). `lead_time` [s]: how long before the robot can start driving clear
/// (a line-up still to come); it is spent out of the same window.
bool DoorPassable(const TaskServices& task, const std::string& door, double margin,
                  const DoorVisit* visit, double lead_time = 0.0);
/// DoorPassable without the clearance check: only whether the hold window (and the leaf not
/// closing) leaves time to drive clear after `lead_time` [s]. For a robot that cannot see the
/// leaf from where it waits (beside the lane, behind the jamb), which checks the clearance once it
/// can.
bool DoorWindowLeavesTime(const TaskServices& task, const std::string& door, const DoorVisit* visit,
                          double lead_time);
/// Clearance of the door's opening from the latest estimate, or nullopt if never observed.
std::optional<double> DoorClearance(const TaskServices& task, const std::string& door);

}  // namespace egress::behavior
