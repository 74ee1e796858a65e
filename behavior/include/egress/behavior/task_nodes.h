#pragma once
/// @file
/// The executive's task nodes (behavior/trees/egress_nodes.xml is their TreeNodesModel),
/// registered with a BehaviorTreeFactory. Each is built with the TaskServices: conditions read the
/// Belief (and have no side effects), actions start motions on the MotionExecutor and watch them
/// finish; halting an action stops its motion in the same tick. State the nodes hand each other
/// travels on blackboard ports: the door nodes' `visit` (a DoorVisit, default key
/// `{door_visit}`) and `retreating` (RetractToSafe → IsPathClear, default `{retreating}`).
///
/// The nodes live in families, one file each in behavior/src/: conditions (IsPathClear,
/// IsDoorOpen, IsPersonHoldingDoor, IsHoldingPayload), navigation (NavigateTo, RetractToSafe,
/// WaitForClear), doors (ButtonType, ApproachButton, PressButton, WaveAtPlate, TraverseDoor; the
/// door rules they share are egress/behavior/door_rules.h) and manipulation (DetectPayload,
/// GraspPayload, PlacePayload, HandOver). A tree naming any other node fails to load with an
/// unknown-node error naming the file and line.

#include "egress/behavior/mission_map.h"
#include "egress/behavior/task_services.h"
#include "egress/bt/factory.h"

namespace egress::behavior {

/// Registers the task nodes; `services` (and what it points to) must outlive every tree created
/// from `factory`. @throws InvalidArgument when a service is missing.
void RegisterTaskNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services);

/// The task nodes' TreeNodesModel (Groot2's palette; behavior/trees/egress_nodes.xml), written
/// from their registrations: `egress bt model` prints it.
std::string TaskNodesModelXml();

/// "x;y;yaw" → pose. @throws InvalidArgument naming the text.
Pose2 ParsePose2(std::string_view text);
/// A goal as a mission gives it: a place of the building (its pose; a place without a heading
/// is reached facing the way from X_MB) or a pose "x;y;yaw" / "x;y".
/// @throws InvalidArgument naming the text and the building's places.
Pose2 ResolveGoal(const MissionMap& map, std::string_view text, const Pose2& X_MB);

}  // namespace egress::behavior
