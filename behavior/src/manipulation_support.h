#pragma once
// Internal to behavior/src: what the hand's nodes share (grasp_nodes.cpp, manipulation_nodes.cpp):
// the palm's targets, whole-body reach, and what the depth image says about a payload's
// surroundings.

#include <optional>
#include <string_view>

#include "task_node_support.h"

namespace egress::behavior::detail {

inline constexpr double kGraspDepthInPalm = 0.07;  ///< grasp centre ahead of the palm [m]
inline constexpr double kPreGraspOffset = 0.12;    ///< pre-grasp / pre-place this far short [m]
inline constexpr double kHandError = 0.005;        ///< [m] a grasp or release this close is good

/// "x;y;z" → point. @throws InvalidArgument naming the text.
Eigen::Vector3d ParsePoint3(std::string_view text);

/// The palm target that holds a grasp centre `p_M`, approached along the unit `approach_M`.
planning::IkTarget PalmTarget(const Eigen::Vector3d& p_M, const Eigen::Vector3d& approach_M);

/// Where the base stands, and the arm there, for the hand to hold a grasp centre.
struct HandReach {
  Pose2 X_MB;
  ArmPose arm;
};
/// The hand holding a grasp centre `p_M` approached along `approach_M` (horizontally, or
/// straight down) by a robot coming from the horizontal direction `toward_M` (whole-body IK from
/// 0.6 m short); nullopt if out of reach.
std::optional<HandReach> SolveHandReach(const TaskServices& task, const Eigen::Vector3d& p_M,
                                        const Eigen::Vector3d& approach_M,
                                        const Eigen::Vector3d& toward_M);

/// The unit horizontal direction from the robot to `p_M` (the robot's heading if it is there).
Eigen::Vector3d HorizontalApproach(const Pose2& X_MB, const Eigen::Vector3d& p_M);

/// How far a payload's centre stands above the surface it rests on [m]: a bottle upright, a
/// flashlight lying; unknown kinds get a middle value.
double PayloadCentreHeight(std::string_view kind);

/// Something low standing out of the surface the payload rests on (`surface_z`) in the corridor
/// the hand sweeps horizontally towards a grasp centre `p_M` along `approach_M` (from the
/// pre-grasp to just before the payload, within a hand's width of the line): the highest of its
/// depth points, and how far back from p_M along the approach its nearest face is.
struct ClutterBeforeGrasp {
  double top_z;  ///< [m]
  double reach;  ///< from p_M back to its face towards the robot [m]
};
/// The clutter before a grasp (see ClutterBeforeGrasp), or nullopt if there is none.
std::optional<ClutterBeforeGrasp> FindClutterBeforeGrasp(const TaskServices& task,
                                                         const Eigen::Vector3d& p_M,
                                                         const Eigen::Vector3d& approach_M,
                                                         double payload_radius, double surface_z);

/// The centre of a low payload lying on a surface at `surface_z`, from the depth points that
/// stand out of the surface within `radius` of the estimate `p_M` (the centroid of what the
/// camera sees of it, horizontally): a grasp from above has no slack along the approach, where
/// the detection's single depth sample may be centimetres off. nullopt if too few points.
std::optional<Eigen::Vector3d> LowPayloadCentre(const TaskServices& task,
                                                const Eigen::Vector3d& p_M, double surface_z,
                                                double radius);

/// The blackboard port a plan travels on, and the leaf that writes it.
template <typename PlanT>
struct PlanPortTraits;
template <>
struct PlanPortTraits<GraspPlan> {
  static constexpr const char* kPort = "grasp";
  static constexpr const char* kWriter = "PlanGrasp";
  static constexpr const char* kWhat =
      "the grasp planned by PlanGrasp (centre, approach, base pose, arm)";
};
template <>
struct PlanPortTraits<ReleasePlan> {
  static constexpr const char* kPort = "release";
  static constexpr const char* kWriter = "PlanPlacement or PlanHandOver";
  static constexpr const char* kWhat =
      "the release planned by PlanPlacement / PlanHandOver (where, approach, arm)";
};

/// A plan's port (default key `{grasp}` / `{release}`): the planning leaf writes it, the leaves
/// after it read (and may refine) it.
template <typename PlanT>
std::pair<std::string, bt::PortInfo> PlanPort(bt::PortDirection direction) {
  using Traits = PlanPortTraits<PlanT>;
  auto port =
      bt::BidirectionalPort<PlanT>(Traits::kPort, Traits::kWhat, StrCat("{", Traits::kPort, "}"));
  port.second.direction = direction;
  return port;
}

/// Base of the leaves that carry out a plan another leaf wrote on its port.
template <typename PlanT>
class PlannedLeaf : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;

 protected:
  /// The plan on the port, or nullopt with a note naming the leaf that should have written it.
  std::optional<PlanT> Plan() {
    using Traits = PlanPortTraits<PlanT>;
    std::optional<PlanT> plan = Shared<PlanT>(Traits::kPort);
    if (!plan) {
      Note(StrCat("no ", Traits::kPort, " planned (", Traits::kWriter, " writes the `",
                  Traits::kPort, "` port)"));
    }
    return plan;
  }
  NoteFn Noter() {
    return [this](const std::string& t) { Note(t); };
  }
};

}  // namespace egress::behavior::detail
