#pragma once
/// @file
/// The executive's task nodes (behavior/trees/egress_nodes.xml is their TreeNodesModel),
/// registered with a BehaviorTreeFactory. Each works through the TaskContext: conditions read the
/// world state, actions start motions on the MotionExecutor and watch them finish; halting an
/// action stops its motion in the same tick.
///
/// Registered now: IsPathClear, IsDoorOpen, IsPersonHoldingDoor, IsHoldingPayload, ButtonType,
/// NavigateTo, ApproachButton, PressButton, WaveAtPlate, TraverseDoor, RetractToSafe,
/// WaitForClear, DetectPayload, GraspPayload. Not yet: PlacePayload, HandOver (a tree using them
/// fails to load with an unknown-node error naming the file and line).

#include "egress/behavior/task_context.h"
#include "egress/bt/factory.h"

namespace egress::behavior {

/// Registers the task nodes; `context` must outlive every tree created from `factory`.
void RegisterTaskNodes(bt::BehaviorTreeFactory& factory, TaskContext* context);

/// "x;y;yaw" → pose. @throws InvalidArgument naming the text.
Pose2 ParsePose2(std::string_view text);

}  // namespace egress::behavior
